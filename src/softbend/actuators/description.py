"""The description of an actuator: its design parameters, constraints and columns.

:class:`Actuator` is what the learning pipeline knows of an actuator;
:data:`ACTUATORS` holds the registered ones (:func:`get_actuator`,
:func:`actuator_from`, :func:`load_actuator`).
"""

from __future__ import annotations

import ast
import json
import math
import os
from collections.abc import Callable, Mapping, Sequence
from dataclasses import dataclass, field
from typing import TYPE_CHECKING, Any, Literal

import numpy as np
from numpy.typing import ArrayLike

from softbend import units
from softbend._validation import must_be, short_repr
from softbend.actuators.constraints import evaluate, parse_constraint
from softbend.actuators.parameters import (
    PRESSURE_UNITS,
    ActuatorError,
    DesignParameter,
    Kind,
    check_name,
    pressure_to_mpa,
)
from softbend.errors import keyed
from softbend.registry import Registry

if TYPE_CHECKING:
    import pandas as pd

    from softbend.parameters import Range


@dataclass(frozen=True)
class Actuator:
    """A bending actuator as the learning pipeline sees it.

    Parameters
    ----------
    name : str
        Registry name (``"sfrba"``) or a lab's own name.
    title : str
        One line saying what the actuator is, for reports.
    parameters : tuple of DesignParameter
        The design parameters, in the column order of every model input.
    pressure_column : str
        Name of the gauge-pressure input (``"pressure_mpa"``, ``"p_kpa"``).
    pressure_unit : {"kPa", "MPa", "bar", "psi"}
        Unit of the pressure column; a column whose name ends in a unit
        (``p_psi``) must be in that one.
    angle_column : str
        Name of the bending-angle column, degrees (a name ending ``_rad`` is refused).
    constraints : tuple of str
        Comparisons between parameters that every design meets
        (``"t_mm < r_mm"``), in the parameters' units and codes.
    fem_family : str, optional
        The FEM actuator family that simulates this actuator, if any
        (``design find --verify`` runs only then).
    chamber_volume_mm3 : float, optional
        Cavity volume at zero pressure, mm³, for the simulated rig (paper B's
        actuator computes it from its geometry instead).
    volume_growth_mm3_per_mpa : float, optional
        Slope of the cavity volume with pressure, mm³/MPa, for the simulated rig.
    quantities : mapping of str to str
        Input column → the quantity of :data:`softbend.plausibility.RANGES` its
        values lie in (``{"pressure_mpa": "pressure_mpa"}``): a saved model's
        training ranges, a correction's means and the readings a transfer
        strategy fits are checked against those ranges; an input not named is
        only checked to be finite.
    mape_floor_deg : float, optional
        A fixed floor of the cross-validated MAPE of its surrogates, degrees (paper
        B: 1°, as §4.1); None: :func:`softbend.metrics.mape_floor` of the table.
    transfer_mape_floor_deg : float, optional
        A fixed floor of the MAPE of its transfer strategies, degrees (paper B: 0,
        only exact zeros left out, as §5); None: ``mape_floor`` of the readings.
    analytical : bool
        Whether :mod:`softbend.analytical`'s closed-form model describes it (a
        transfer baseline of its readings).
    published_cv : mapping of str to mapping
        Published cross-validated figures of its surrogates by family (paper B's
        Figure 5), shown beside those ``softbend train`` finds.
    named_in_outputs : bool
        Whether the records of train, predict and transfer name it (False for paper
        B's, whose records are unchanged since before descriptions existed).
    search_steps : tuple of float, optional
        A mould's step of each parameter in a design search, in parameter order
        (paper B's: 0.5 mm, 1° of fibre angle): a search's default grid, which then
        keeps no value to the declared ``resolution``. Empty: each parameter's
        resolution, else a round step of its range.
    search_limits : tuple of Range, optional
        The values a design may take, in parameter order, when the parameters'
        ranges are only such limits (paper B's: (0, 50] mm of wall): a search checks
        its values against them and takes its ranges from the model's training
        ranges alone. Empty: the parameters' ranges, a box a search may cover.

    design_ids : {"named", "values"}
        How a design's id is computed (:attr:`~softbend.actuators.design.Design.design_id`):
        ``"named"`` hashes ``FAMILY:name=value,...`` (``FAMILY`` the FEM family, else the
        name), ``"values"`` the values alone (paper B's ids, older than named ones).
    short_names : tuple of str
        Short names of the parameters, in order (paper B's ``l, r, t, b, phi, lc``):
        what a design search specification calls them; empty: their own names.
    grid : tuple of tuple of float
        A published grid of designs: the levels of each parameter, in order
        (paper B's Table 1); empty when none.
    check_values : callable, optional
        ``check_values({name: value}) -> {name: value}``: the description's own
        check of one design's values, run before its ranges, kinds and
        constraints (:meth:`Design.checked <softbend.actuators.Design.checked>`),
        raising :class:`~softbend.errors.InputError` keyed by the parameter at
        fault with the description's own words (paper B's open bounds, its wall
        thinner than the radius).
    cavity_volume : callable, optional
        ``cavity_volume({name: value}) -> float``: the undeformed cavity volume of
        one design, mm³, from its geometry (paper B's ½·π·r²·l), read as
        :attr:`Design.cavity_volume_mm3 <softbend.actuators.Design.cavity_volume_mm3>`.
    elastomer_volume : callable, optional
        ``elastomer_volume(rows) -> volumes``: the elastomer of each design, mm³,
        from rows of design values in the parameters' order (paper B's wall, layer
        and end caps); an actuator that gives it can be searched for the objective
        ``volume``.

    The fields from ``quantities`` on are softbend's knowledge of a registered
    actuator, not part of its description: :meth:`to_dict` does not write them and
    equality ignores them; a model's recorded description that equals a registered
    one is read back as that one (:meth:`registered`,
    :func:`softbend.surrogates.persistence.actuator_of`).
    """

    name: str
    title: str
    parameters: tuple[DesignParameter, ...]
    pressure_column: str = "pressure_mpa"
    pressure_unit: str = "MPa"
    angle_column: str = "angle_deg"
    constraints: tuple[str, ...] = ()
    fem_family: str | None = None
    chamber_volume_mm3: float | None = None
    volume_growth_mm3_per_mpa: float | None = None
    quantities: Mapping[str, str] = field(default_factory=dict, compare=False)
    mape_floor_deg: float | None = field(default=None, compare=False)
    transfer_mape_floor_deg: float | None = field(default=None, compare=False)
    analytical: bool = field(default=False, compare=False)
    published_cv: Mapping[str, Mapping[str, Any]] = field(default_factory=dict, compare=False)
    named_in_outputs: bool = field(default=True, compare=False)
    search_steps: tuple[float, ...] = field(default=(), compare=False)
    search_limits: tuple[Range, ...] = field(default=(), compare=False)
    design_ids: Literal["named", "values"] = field(default="named", compare=False)
    short_names: tuple[str, ...] = field(default=(), compare=False)
    grid: tuple[tuple[float, ...], ...] = field(default=(), compare=False)
    check_values: Callable[[dict[str, float]], dict[str, float]] | None = field(
        default=None, compare=False
    )
    cavity_volume: Callable[[Mapping[str, float]], float] | None = field(
        default=None, compare=False
    )
    elastomer_volume: Callable[[np.ndarray], np.ndarray] | None = field(default=None, compare=False)
    _trees: tuple[ast.Compare, ...] = field(default=(), repr=False, compare=False)

    def __post_init__(self) -> None:
        check_name(self.name.replace("-", "_"), "name of an actuator")
        if not self.parameters:
            raise ActuatorError(f"The actuator {self.name!r} needs at least one design parameter.")
        object.__setattr__(self, "parameters", tuple(self.parameters))
        names = [p.name for p in self.parameters]
        check_name(self.pressure_column, "pressure column")
        check_name(self.angle_column, "angle column")
        columns = [*names, self.pressure_column, self.angle_column]
        repeated = sorted({n for n in columns if columns.count(n) > 1})
        if repeated:
            raise ActuatorError(
                f"The actuator {self.name!r} names the column(s) {', '.join(repeated)} twice; "
                "design, pressure and angle columns must differ."
            )
        with keyed("pressure_unit"):
            pressure_to_mpa(self.pressure_unit)
        _check_column_units(self.pressure_column, self.pressure_unit, self.angle_column)
        for key in ("chamber_volume_mm3", "volume_growth_mm3_per_mpa"):
            value = getattr(self, key)
            if value is not None and not (math.isfinite(value) and value >= 0):
                raise ActuatorError(
                    f"The {key} of actuator {self.name!r} must be finite and >= 0; got {value!r}."
                )
        if self.design_ids not in ("named", "values"):
            raise ActuatorError(
                f"The design_ids of actuator {self.name!r} must be 'named' or 'values'; "
                f"got {self.design_ids!r}."
            )
        for key in ("short_names", "grid"):
            given = tuple(getattr(self, key))
            if given and len(given) != len(self.parameters):
                raise ActuatorError(
                    f"The {key} of actuator {self.name!r} must hold one entry per design "
                    f"parameter ({len(self.parameters)}); got {len(given)}."
                )
            object.__setattr__(self, key, given)
        object.__setattr__(self, "constraints", tuple(self.constraints))
        trees = tuple(parse_constraint(text, names) for text in self.constraints)
        object.__setattr__(self, "_trees", trees)

    # --- names ---------------------------------------------------------------------------------

    @property
    def names(self) -> tuple[str, ...]:
        """The design parameters' names, in model-input order."""
        return tuple(p.name for p in self.parameters)

    @property
    def features(self) -> tuple[str, ...]:
        """Model inputs: the design parameters then the pressure column."""
        return (*self.names, self.pressure_column)

    @property
    def units(self) -> dict[str, str]:
        """Unit of every input and of the angle."""
        return {
            **{p.name: p.unit for p in self.parameters},
            self.pressure_column: self.pressure_unit,
            self.angle_column: "deg",
        }

    @property
    def to_mpa(self) -> float:
        """Factor from the pressure column's unit to MPa."""
        return PRESSURE_UNITS[self.pressure_unit]

    def parameter(self, name: str) -> DesignParameter:
        """The parameter called ``name``, or one error listing the names."""
        for p in self.parameters:
            if p.name == name:
                return p
        raise ActuatorError(
            f"The actuator {self.name!r} has no design parameter {name!r}; "
            f"its parameters are {', '.join(self.names)}."
        )

    # --- designs -------------------------------------------------------------------------------

    def parse_design(
        self,
        text: str,
    ) -> np.ndarray:
        """A design from text: ``A=1,B=2,...`` by name, or the values in column order.

        Returns the model-input codes (levels as their index), checked against
        the ranges, kinds and constraints. Errors carry the key ``design``.
        """
        if not isinstance(text, str) or not text.strip():
            raise ActuatorError(must_be(self.design_hint(), text), key="design")
        items = [item.strip() for item in text.split(",")]
        if any("=" in item for item in items):
            values: dict[str, Any] = {}
            for item in items:
                name, sep, value = item.partition("=")
                name = name.strip()
                if not sep:
                    raise ActuatorError(
                        f"mixes NAME=VALUE and bare values ({item!r}); give {self.design_hint()}",
                        key="design",
                    )
                if name not in self.names:
                    raise ActuatorError(
                        f"names {name!r}, which is not a design parameter of {self.name}; "
                        f"its parameters are {', '.join(self.names)}",
                        key="design",
                    )
                if name in values:
                    raise ActuatorError(f"gives {name!r} twice", key="design")
                values[name] = value.strip()
            missing = [n for n in self.names if n not in values]
            if missing:
                raise ActuatorError(
                    f"lacks {', '.join(missing)}; give {self.design_hint()}", key="design"
                )
            return self.design_codes(values)
        if len(items) != len(self.parameters):
            raise ActuatorError(
                f"must be {self.design_hint()} ({len(self.parameters)} values); "
                f"got {len(items)} in {text!r}",
                key="design",
            )
        return self.design_codes(dict(zip(self.names, items, strict=True)))

    def design_hint(self) -> str:
        """``A=…,B=…`` with each parameter's unit, for messages and help."""
        return ",".join(f"{p.name}=V" for p in self.parameters) + (
            f" (or the values in that order; {self.units_text()})"
        )

    def units_text(self) -> str:
        """``A in mm, B a whole number, C one of x/y`` for messages."""
        parts = []
        for p in self.parameters:
            if p.kind == "categorical":
                parts.append(f"{p.name} one of {'/'.join(map(str, p.levels or ()))}")
            elif p.kind == "integer":
                parts.append(f"{p.name} a whole number")
            else:
                parts.append(f"{p.name} in {p.unit}" if p.unit else p.name)
        return ", ".join(parts)

    def design_codes(
        self,
        values: Mapping[str, Any],
    ) -> np.ndarray:
        """Model-input codes of one design given by name, checked (errors keyed ``design``)."""
        with keyed("design"):
            codes = np.array([p.encode(values[p.name]) for p in self.parameters], dtype=float)
            self.check_designs(codes[None, :])
        return codes

    def check_designs(self, codes: ArrayLike) -> np.ndarray:
        """Rows of design codes checked against ranges, kinds and constraints.

        Returns the rows as a float array of shape (n, n_parameters). An error
        names the parameter or constraint at fault in its message.
        """
        rows = np.atleast_2d(np.asarray(codes, dtype=float))
        if rows.shape[1] != len(self.parameters):
            raise ActuatorError(
                f"a design of {self.name} has {len(self.parameters)} values "
                f"({', '.join(self.names)}); got {rows.shape[1]}"
            )
        for j, p in enumerate(self.parameters):
            p.check(rows[:, j])
        met = self.constraints_met(rows)
        if not met.all():
            i = int(np.argmin(met))
            with np.errstate(divide="ignore", invalid="ignore", over="ignore"):
                broken = next(
                    text
                    for text, tree in zip(self.constraints, self._trees, strict=True)
                    if not evaluate(tree, self._columns(rows[i : i + 1]))[0]
                )
            raise ActuatorError(
                f"the design {self.describe(rows[i])} breaks the constraint {broken} of {self.name}"
            )
        return rows

    def constraints_met(self, codes: ArrayLike) -> np.ndarray:
        """Whether each row of design codes meets every constraint (bool array)."""
        rows = np.atleast_2d(np.asarray(codes, dtype=float))
        met = np.ones(rows.shape[0], dtype=bool)
        columns = self._columns(rows)
        # A design where a side divides by zero (inf) or is undefined (NaN) is
        # compared as computed: a NaN side meets no comparison.
        with np.errstate(divide="ignore", invalid="ignore", over="ignore"):
            for tree in self._trees:
                met &= np.asarray(evaluate(tree, columns), dtype=bool)
        return met

    def _columns(self, rows: np.ndarray) -> dict[str, np.ndarray]:
        return {name: rows[:, j] for j, name in enumerate(self.names)}

    def describe(self, codes: Sequence[float] | np.ndarray) -> str:
        """``A=1, B=2.5 mm, layer=paper``: one design by name, in its units."""
        parts = []
        for p, code in zip(self.parameters, codes, strict=True):
            value = p.decode(float(code))
            shown = f"{value:g}" if isinstance(value, float) else str(value)
            unit = f" {p.unit}" if p.unit and p.kind != "categorical" else ""
            parts.append(f"{p.name}={shown}{unit}")
        return ", ".join(parts)

    def design_record(self, codes: Sequence[float] | np.ndarray) -> dict[str, Any]:
        """``{name: value}`` of one design (levels by name), JSON-friendly."""
        return {
            p.name: p.decode(float(code)) for p, code in zip(self.parameters, codes, strict=True)
        }

    def bounds(self) -> tuple[np.ndarray, np.ndarray]:
        """Lower and upper bounds of the design codes (finite where declared)."""
        return (
            np.array([p.low for p in self.parameters]),
            np.array([p.high for p in self.parameters]),
        )

    # --- serialisation -------------------------------------------------------------------------

    def to_dict(self) -> dict[str, Any]:
        """JSON-friendly form, saved in every model (:meth:`from_dict` reads it back)."""
        out: dict[str, Any] = {
            "name": self.name,
            "title": self.title,
            "parameters": [p.to_dict() for p in self.parameters],
            "pressure_column": self.pressure_column,
            "pressure_unit": self.pressure_unit,
            "angle_column": self.angle_column,
            "constraints": list(self.constraints),
        }
        for key in ("fem_family", "chamber_volume_mm3", "volume_growth_mm3_per_mpa"):
            if getattr(self, key) is not None:
                out[key] = getattr(self, key)
        return out

    @classmethod
    def from_dict(cls, data: Mapping[str, Any]) -> Actuator:
        """The description :meth:`to_dict` wrote; one :class:`ActuatorError` for a bad one."""
        if not isinstance(data, Mapping):
            raise ActuatorError(f"An actuator description must be an object; got {data!r}.")
        allowed = {
            "name",
            "title",
            "parameters",
            "pressure_column",
            "pressure_unit",
            "angle_column",
            "constraints",
            "fem_family",
            "chamber_volume_mm3",
            "volume_growth_mm3_per_mpa",
        }
        unknown = sorted(set(data) - allowed)
        if unknown:
            raise ActuatorError(
                f"Unknown key(s) {', '.join(unknown)} in an actuator description; "
                f"allowed: {', '.join(sorted(allowed))}."
            )
        parameters = data.get("parameters")
        if not isinstance(parameters, list | tuple):
            raise ActuatorError("An actuator description's 'parameters' must be a list.")
        constraints = data.get("constraints", [])
        if not isinstance(constraints, list | tuple):
            raise ActuatorError("An actuator description's 'constraints' must be a list of text.")
        described = cls(
            name=str(data.get("name", "")),
            title=str(data.get("title", "")),
            parameters=tuple(DesignParameter.from_dict(p) for p in parameters),
            pressure_column=data.get("pressure_column", "pressure_mpa"),
            pressure_unit=data.get("pressure_unit", "MPa"),
            angle_column=data.get("angle_column", "angle_deg"),
            constraints=tuple(constraints),
            fem_family=data.get("fem_family"),
            chamber_volume_mm3=data.get("chamber_volume_mm3"),
            volume_growth_mm3_per_mpa=data.get("volume_growth_mm3_per_mpa"),
        )
        return described.registered()

    def registered(self) -> Actuator:
        """The registered description this one records (same name and record), else itself.

        A record read back from a saved model lacks what only the registered
        description holds (its id scheme, short names, grid); the registered
        description that writes the same record is the one it was saved from.
        """
        if self.name not in ACTUATORS:
            return self
        known = ACTUATORS.get(self.name)
        return known if known.to_dict() == self.to_dict() else self

    @classmethod
    def from_table(
        cls,
        table: pd.DataFrame,
        *,
        design_columns: Sequence[str],
        pressure_column: str,
        pressure_unit: str,
        angle_column: str = "angle_deg",
        name: str = "table",
        title: str = "",
        units: Mapping[str, str] | None = None,
        ranges: Mapping[str, tuple[float, float]] | None = None,
    ) -> Actuator:
        """A description read off a simulation table's columns.

        A numeric column of whole numbers becomes an integer parameter, a text
        column a categorical one (its levels sorted), any other a continuous
        one. Text that reads as numbers in every cell is numbers. A numeric
        parameter's range is the one ``ranges`` declares, else the column's
        span, marked as only sampled (:attr:`DesignParameter.sampled`): a
        design outside it is an extrapolation, not an error.

        Parameters
        ----------
        ranges : dict of str to (float, float), optional
            Declared ranges ``{name: (low, high)}`` in the parameters' units
            (:func:`parse_ranges`), each holding the column's values.

        Raises
        ------
        ActuatorError
            A text column with a cell that reads as a number, naming the column
            and the cell: its kind is not the table's to guess. A declared range
            of a categorical parameter or one that leaves out the column's
            values (keyed ``ranges``).
        """
        import pandas as pd

        from softbend.tables import column_kind, infer_cells, kind_conflict

        parameters = []
        for column in design_columns:
            values = table[column]
            unit = (units or {}).get(column, _unit_from_name(column))
            if values.dtype.kind in "OUS" or str(values.dtype) == "string":
                cells = values.astype(object).where(values.notna(), None).tolist()
                kind_of_cells = column_kind(cells)
                if kind_of_cells == "number":  # numbers written as text are numbers
                    values = pd.Series(infer_cells(cells))
                conflict = kind_conflict(cells) if kind_of_cells == "mixed" else None
                if conflict is not None:
                    cell = values.iloc[conflict[0]]
                    raise ActuatorError(
                        f"mixes numbers and text (row {conflict[0]}: {short_repr(cell)}); a "
                        "design column is numbers, or text for a categorical parameter",
                        key=column,
                    )
            declared = (ranges or {}).get(column)
            if values.dtype.kind in "OUSb" or str(values.dtype) in ("category", "string"):
                if declared is not None:
                    raise ActuatorError(
                        f"gives a range of {column}, a categorical parameter (its text "
                        "levels); a range is for a numeric column",
                        key="ranges",
                    )
                levels = tuple(sorted({str(v) for v in values.dropna()}))
                if len(levels) < 2:
                    levels = (*levels, f"{levels[0]}_other") if levels else ("a", "b")
                parameters.append(DesignParameter(column, "", kind="categorical", levels=levels))
                continue
            numbers = values.to_numpy(dtype=float)
            finite = numbers[np.isfinite(numbers)]
            low, high = (float(finite.min()), float(finite.max())) if finite.size else (0.0, 0.0)
            whole = finite.size > 0 and bool(np.all(finite == np.round(finite)))
            kind: Kind = "integer" if whole and values.dtype.kind in "iu" else "continuous"
            if declared is None:
                parameters.append(DesignParameter(column, unit, low, high, kind=kind, sampled=True))
                continue
            if finite.size and (low < declared[0] or high > declared[1]):
                raise ActuatorError(
                    f"declares {column} in [{declared[0]:g}, {declared[1]:g}]{unit and ' '}{unit}, "
                    f"but the table's {column} spans [{low:g}, {high:g}]; a declared range "
                    "holds every design of the table",
                    key="ranges",
                )
            parameters.append(DesignParameter(column, unit, *declared, kind=kind))
        return cls(
            name=name,
            title=title or f"actuator of the table's {len(parameters)} design columns",
            parameters=tuple(parameters),
            pressure_column=pressure_column,
            pressure_unit=pressure_unit,
            angle_column=angle_column,
        )


def _check_column_units(pressure_column: str, pressure_unit: str, angle_column: str) -> None:
    """Refuse a pressure or angle column whose name carries a unit other than the declared one.

    ``pressure_psi`` declared in kPa is refused naming both (key ``pressure_unit``), and an
    angle column named in radians (``angle_rad``) is refused (key ``angle_column``): softbend
    learns angles in degrees. :func:`softbend.units.check_column_unit` reads the names.
    """
    from softbend.errors import InputError
    from softbend.units import check_column_unit, column_unit

    try:
        check_column_unit(pressure_column, pressure_unit, "pressure_unit", key="pressure_unit")
    except InputError as err:
        raise ActuatorError(err.detail, key=err.key) from None
    if column_unit(angle_column) == "rad":
        raise ActuatorError(
            f"{angle_column!r} is named in radians; softbend learns angles in degrees: "
            "multiply by 180/π (57.2958) and name the column e.g. angle_deg",
            key="angle_column",
        )


def parse_ranges(texts: Sequence[str], names: Sequence[str]) -> dict[str, tuple[float, float]]:
    """Declared ranges ``{name: (low, high)}`` from ``NAME=LOW:HIGH`` texts (``wall_mm=1:3``).

    Parameters
    ----------
    texts : sequence of str
        The texts, such as the repeated values of ``train --range``; each
        LOW and HIGH in the parameter's unit, finite, LOW < HIGH.
    names : sequence of str
        The design parameters a range may name.

    Raises
    ------
    ActuatorError
        Keyed ``ranges``: the form, the allowed names and the text received;
        or a name given twice.
    """
    allowed = ", ".join(names)
    out: dict[str, tuple[float, float]] = {}
    for text in texts:
        name, _, span = str(text).partition("=")
        name = name.strip()
        low_text, colon, high_text = span.partition(":")
        try:
            low, high = (float(low_text), float(high_text)) if colon else (math.nan, math.nan)
        except ValueError:
            low, high = math.nan, math.nan
        if name not in names or not (math.isfinite(low) and math.isfinite(high) and low < high):
            raise ActuatorError(
                must_be(f"NAME=LOW:HIGH with NAME one of {allowed} and numbers LOW < HIGH", text),
                key="ranges",
            )
        if name in out:
            raise ActuatorError(f"gives a range of {name} twice; give it once", key="ranges")
        out[name] = (low, high)
    return out


def _unit_from_name(column: str) -> str:
    """A design parameter's unit from its column's name (``wall_mm`` → mm), else ``""``."""
    return units.unit_from_name(column, ("length", "angle", "mass", "pressure"))


def load_actuator(path: str | os.PathLike[str]) -> Actuator:
    """An actuator description from a JSON file (the form :meth:`Actuator.to_dict` writes).

    Raises
    ------
    ActuatorError
        A file that is not such a description, naming the file.
    """
    from pathlib import Path

    from softbend._jsontext import check_json_nesting
    from softbend.limits import check_file_size

    source = Path(path)
    if not source.is_file():
        raise ActuatorError(f"No actuator description at {source}.")
    check_file_size(source, str(source))
    try:
        text = source.read_text(encoding="utf-8")
        check_json_nesting(text, str(source))
        data = json.loads(text)
    except (UnicodeDecodeError, json.JSONDecodeError) as err:
        raise ActuatorError(f"{source} is not a JSON actuator description ({err}).") from None
    try:
        return Actuator.from_dict(data)
    except ActuatorError as err:
        raise ActuatorError(f"{source}: {err}") from None


def actuator_from(
    text: str,
) -> Actuator:
    """A registered description by name, or one read from a ``.json`` file."""
    if text.lower().endswith(".json"):
        return load_actuator(text)
    return get_actuator(text)


#: Registered actuator descriptions, by name.
ACTUATORS: Registry[Actuator] = Registry("actuator")


def get_actuator(
    name: str,
) -> Actuator:
    """The registered description ``name`` (one error, keyed ``actuator``, listing the names)."""
    with keyed("actuator"):
        return ACTUATORS.get(name)
