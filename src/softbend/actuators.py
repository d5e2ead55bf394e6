"""Actuator descriptions: the named design parameters a lab's actuator is described by.

softbend's learning pipeline (train → predict → transfer → design search →
control) does not depend on an actuator's geometry, only on its description:
the design parameters (name, unit, range, kind, manufacturing resolution), the
constraints between them, and the pressure and angle columns with their units.
Paper B's fiber-reinforced actuator is one registered description
(``"sfrba"``); a lab's own actuator is another, registered in Python or read
from the columns of its simulation table (:meth:`Actuator.from_table`).

Every model saved by ``softbend train`` records the description it was
trained with (:meth:`Actuator.to_dict`), so that predict, transfer, design
search and control name the model's own parameters and check them in their
own units::

    from softbend.actuators import ACTUATORS, Actuator, DesignParameter

    pneunet = Actuator(
        name="my-pneunet",
        title="PneuNet, 8 to 14 chambers",
        parameters=(
            DesignParameter("n_chambers", "", 8, 14, kind="integer"),
            DesignParameter("wall_mm", "mm", 1.0, 3.0, resolution=0.1),
            DesignParameter("layer", "", kind="categorical", levels=("paper", "fabric")),
        ),
        pressure_column="p_kpa",
        pressure_unit="kPa",
        constraints=("wall_mm <= 3",),
    )
    ACTUATORS.register(pneunet.name, pneunet)

A categorical parameter's levels are stored as their index (0, 1, …) in
every model input; :meth:`DesignParameter.encode` and
:meth:`DesignParameter.decode` convert.
"""

from __future__ import annotations

import ast
import json
import math
import operator
import os
import re
from collections.abc import Callable, Mapping, Sequence
from dataclasses import dataclass, field
from typing import TYPE_CHECKING, Any, Literal

import numpy as np
from numpy.typing import ArrayLike

from softbend import units
from softbend._validation import must_be, short_repr
from softbend.errors import SoftbendError, keyed
from softbend.registry import Registry

if TYPE_CHECKING:
    import pandas as pd

    from softbend.parameters import Range

__all__ = [
    "ACTUATORS",
    "PRESSURE_UNITS",
    "Actuator",
    "ActuatorError",
    "DesignParameter",
    "actuator_from",
    "get_actuator",
    "load_actuator",
    "parse_ranges",
    "pressure_to_mpa",
]

#: Factor from each pressure unit an actuator is described in to MPa (:mod:`softbend.units`).
PRESSURE_UNITS: dict[str, float] = {u: f for u, f in units.PRESSURE_UNITS.items() if u != "Pa"}

Kind = Literal["continuous", "integer", "categorical"]
KINDS: tuple[str, ...] = ("continuous", "integer", "categorical")

_NAME = re.compile(r"^[A-Za-z_][A-Za-z0-9_]{0,63}$")


class ActuatorError(SoftbendError, ValueError):
    """A description, design or table that breaks an actuator's declared parameters."""


def pressure_to_mpa(
    unit: str,
) -> float:
    """The factor from ``unit`` (kPa, MPa, bar or psi; case as written) to MPa.

    Raises
    ------
    ActuatorError
        For any other unit (key ``pressure_unit``), naming the four allowed.
    """
    if unit not in PRESSURE_UNITS:
        lowered = {u.lower(): u for u in PRESSURE_UNITS}
        hint = f" (did you mean {lowered[unit.lower()]}?)" if str(unit).lower() in lowered else ""
        raise ActuatorError(
            must_be(f"one of {', '.join(PRESSURE_UNITS)}", unit) + hint, key="pressure_unit"
        )
    return PRESSURE_UNITS[unit]


def _check_name(name: object, what: str) -> str:
    if not isinstance(name, str) or not _NAME.match(name):
        raise ActuatorError(
            f"The {what} must be a name of letters, digits and '_' (not starting with a digit, "
            f"at most 64 characters); got {name!r}."
        )
    return name


@dataclass(frozen=True)
class DesignParameter:
    """One named design parameter of an actuator.

    Parameters
    ----------
    name : str
        Column name in tables and models (``"l_mm"``, ``"n_chambers"``).
    unit : str
        Unit of its values (``"mm"``, ``"deg"``; ``""`` for a count or a level).
    low, high : float
        The range the description covers (inclusive). For a categorical
        parameter they are taken from its levels (0 to len(levels) - 1).
    kind : {"continuous", "integer", "categorical"}
        Continuous values, whole numbers, or one of ``levels``.
    levels : tuple, optional
        A categorical parameter's levels (strings or numbers), in the order
        of their index codes.
    resolution : float, optional
        Manufacturing resolution (the step a design search rounds to), in ``unit``.
    description : str
        What the parameter is, for tables and documentation.
    sampled : bool, default False
        Whether ``low`` and ``high`` are only the span a simulation table
        sampled (:meth:`Actuator.from_table`), not a declared range: a value
        outside them is not refused here, and a model trained on the table
        flags it as outside its training ranges instead.
    """

    name: str
    unit: str = ""
    low: float = -math.inf
    high: float = math.inf
    kind: Kind = "continuous"
    levels: tuple[Any, ...] | None = None
    resolution: float | None = None
    description: str = ""
    sampled: bool = False

    def __post_init__(self) -> None:
        _check_name(self.name, "name of a design parameter")
        if self.kind not in KINDS:
            raise ActuatorError(
                f"The kind of design parameter {self.name!r} must be one of "
                f"{', '.join(KINDS)}; got {self.kind!r}."
            )
        if self.kind == "categorical":
            levels = self.levels or ()
            if len(levels) < 2 or len(set(map(str, levels))) != len(levels):
                raise ActuatorError(
                    f"The categorical design parameter {self.name!r} needs two or more distinct "
                    f"levels; got {self.levels!r}."
                )
            object.__setattr__(self, "levels", tuple(levels))
            object.__setattr__(self, "low", 0.0)
            object.__setattr__(self, "high", float(len(levels) - 1))
        elif self.levels is not None:
            raise ActuatorError(
                f"Only a categorical design parameter has levels; {self.name!r} is {self.kind}."
            )
        low, high = float(self.low), float(self.high)
        if math.isnan(low) or math.isnan(high) or low > high:
            raise ActuatorError(
                f"The range of design parameter {self.name!r} must have low <= high; "
                f"got [{self.low}, {self.high}]."
            )
        object.__setattr__(self, "low", low)
        object.__setattr__(self, "high", high)
        if self.resolution is not None and not (
            math.isfinite(self.resolution) and self.resolution > 0
        ):
            raise ActuatorError(
                f"The resolution of design parameter {self.name!r} must be finite and > 0; "
                f"got {self.resolution!r}."
            )

    @property
    def label(self) -> str:
        """``name (unit)`` for table headers and axis labels."""
        return f"{self.name} ({self.unit})" if self.unit else self.name

    def encode(self, value: object) -> float:
        """The model input of ``value``: a level's index for a categorical parameter."""
        if self.kind == "categorical":
            assert self.levels is not None
            for index, level in enumerate(self.levels):
                if str(level) == str(value).strip() or (
                    not isinstance(level, str) and _same_number(level, value)
                ):
                    return float(index)
            raise ActuatorError(
                f"{self.name} must be one of the levels {', '.join(map(str, self.levels))}; "
                f"got {short_repr(value)}"
            )
        try:
            number = float(value)  # type: ignore[arg-type]  # refused by except
        except (TypeError, ValueError):
            raise ActuatorError(
                f"{self.name} must be a number ({self._what()}); got {short_repr(value)}"
            ) from None
        return number

    def decode(self, code: float) -> Any:
        """The value a model input ``code`` stands for (a level for a categorical parameter)."""
        if self.kind == "categorical":
            assert self.levels is not None
            return self.levels[round(code)]
        if self.kind == "integer":
            return round(code)
        return float(code)

    def snap(self, values: np.ndarray) -> np.ndarray:
        """``values`` moved to the nearest buildable value: a level, a whole number,
        or a multiple of the resolution, inside the range."""
        out = np.clip(np.asarray(values, dtype=float), self.low, self.high)
        if self.kind in ("integer", "categorical"):
            return np.clip(np.round(out), math.ceil(self.low), math.floor(self.high))
        if self.resolution is not None:
            out = np.round(out / self.resolution) * self.resolution
            return np.clip(out, self.low, self.high)
        return out

    def check(self, codes: np.ndarray) -> None:
        """Raise one :class:`ActuatorError` for the first code outside the range or kind.

        The message names the parameter (``n_folds must be a whole number in [3, 9];
        got 5.5``), so an error re-keyed to the input it came from keeps it.
        """
        values = np.asarray(codes, dtype=float)
        bad = ~np.isfinite(values)
        if bad.any():
            raise ActuatorError(
                f"{self.name} must be finite ({self._what()}); got {float(values[bad][0])!r}"
            )
        eps = 1e-9 * max(1.0, abs(self.low), abs(self.high))
        outside = (values < self.low - eps) | (values > self.high + eps)
        if outside.any() and not (self.sampled and self.kind != "categorical"):
            shown = (
                self.decode(values[outside][0])
                if self.kind == "categorical"
                else values[outside][0]
            )
            got = f"{shown:g}" if isinstance(shown, float) else repr(shown)
            raise ActuatorError(f"{self.name} must be {self._what()}; got {got}")
        if self.kind in ("integer", "categorical"):
            fractional = np.abs(values - np.round(values)) > 1e-9
            if fractional.any():
                raise ActuatorError(
                    f"{self.name} must be {self._what()}; got {values[fractional][0]:g}"
                )

    def _what(self) -> str:
        if self.kind == "categorical":
            assert self.levels is not None
            return f"one of {', '.join(map(str, self.levels))}"
        unit = f" {self.unit}" if self.unit else ""
        if self.sampled and self.kind == "integer":
            return "a whole number"
        if self.sampled:
            return f"in{unit}" if unit else "any value"
        span = f"in [{self.low:g}, {self.high:g}]{unit}"
        return f"a whole number {span}" if self.kind == "integer" else span

    def to_dict(self) -> dict[str, Any]:
        """JSON-friendly form (:meth:`from_dict` reads it back)."""
        out: dict[str, Any] = {"name": self.name, "unit": self.unit, "kind": self.kind}
        if self.kind == "categorical":
            out["levels"] = list(self.levels or ())
        else:
            out["low"], out["high"] = self.low, self.high
        if self.resolution is not None:
            out["resolution"] = self.resolution
        if self.description:
            out["description"] = self.description
        if self.sampled:
            out["sampled"] = True
        return out

    @classmethod
    def from_dict(cls, data: Mapping[str, Any]) -> DesignParameter:
        """The parameter :meth:`to_dict` wrote; one :class:`ActuatorError` for a bad record."""
        if not isinstance(data, Mapping):
            raise ActuatorError(f"A design parameter must be an object; got {data!r}.")
        allowed = {
            "name",
            "unit",
            "kind",
            "levels",
            "low",
            "high",
            "resolution",
            "description",
            "sampled",
        }
        unknown = sorted(set(data) - allowed)
        if unknown:
            raise ActuatorError(
                f"Unknown key(s) {', '.join(unknown)} in design parameter "
                f"{data.get('name')!r}; allowed: {', '.join(sorted(allowed))}."
            )
        levels = data.get("levels")
        sampled = data.get("sampled", False)
        if not isinstance(sampled, bool):
            raise ActuatorError(
                f"The 'sampled' of design parameter {data.get('name')!r} must be true or false; "
                f"got {sampled!r}."
            )
        return cls(
            name=data.get("name"),  # type: ignore[arg-type]  # checked in __post_init__
            unit=str(data.get("unit", "")),
            low=_number(data.get("low", -math.inf)),
            high=_number(data.get("high", math.inf)),
            kind=data.get("kind", "continuous"),
            levels=tuple(levels) if isinstance(levels, list | tuple) else levels,
            resolution=None if data.get("resolution") is None else _number(data["resolution"]),
            description=str(data.get("description", "")),
            sampled=sampled,
        )


def _number(value: object) -> float:
    if isinstance(value, bool) or not isinstance(value, int | float):
        raise ActuatorError(f"A bound or resolution must be a number; got {value!r}.")
    return float(value)


def _same_number(level: object, value: object) -> bool:
    try:
        return float(level) == float(value)  # type: ignore[arg-type]  # refused by except
    except (TypeError, ValueError):
        return False


# --- constraints -------------------------------------------------------------------------------

_COMPARE: dict[type, Callable[[Any, Any], Any]] = {
    ast.Lt: operator.lt,
    ast.LtE: operator.le,
    ast.Gt: operator.gt,
    ast.GtE: operator.ge,
}
_ARITHMETIC: dict[type, Callable[[Any, Any], Any]] = {
    ast.Add: operator.add,
    ast.Sub: operator.sub,
    ast.Mult: operator.mul,
    ast.Div: operator.truediv,
}


def _parse_constraint(text: str, names: Sequence[str]) -> ast.Compare:
    """``text`` as one comparison of arithmetic on ``names`` and numbers (nothing else)."""
    if not isinstance(text, str) or len(text) > 200:
        raise ActuatorError(f"A constraint must be text of at most 200 characters; got {text!r}.")
    try:
        tree = ast.parse(text, mode="eval").body
    except SyntaxError:
        raise ActuatorError(
            f"The constraint {text!r} is not a comparison such as 't_mm < r_mm' or "
            "'2*wall_mm + gap_mm <= 10'."
        ) from None
    if not isinstance(tree, ast.Compare) or not all(type(op) in _COMPARE for op in tree.ops):
        raise ActuatorError(
            f"The constraint {text!r} must compare with <, <=, > or >= (such as 't_mm < r_mm')."
        )
    for node in ast.walk(tree):
        if isinstance(node, ast.Name) and node.id not in names:
            raise ActuatorError(
                f"The constraint {text!r} names {node.id!r}, which is not a design parameter "
                f"({', '.join(names)})."
            )
        allowed = (ast.Compare, ast.BinOp, ast.UnaryOp, ast.USub, ast.UAdd, ast.Name, ast.Load)
        if isinstance(node, ast.Constant):
            if isinstance(node.value, bool) or not isinstance(node.value, int | float):
                raise ActuatorError(f"The constraint {text!r} may hold only numbers and names.")
        elif (
            not isinstance(node, allowed)
            and type(node) not in _COMPARE
            and type(node) not in _ARITHMETIC
        ):
            raise ActuatorError(
                f"The constraint {text!r} may use only + - * / and comparisons of the "
                "design parameters and numbers."
            )
    for side in (tree.left, *tree.comparators):
        _fold(side, text)
    return tree


def _part(text: str, node: ast.AST) -> str:
    """The part of the constraint ``text`` that ``node`` was parsed from, as typed."""
    return ast.get_source_segment(text, node) or ast.unparse(node)


def _fold(node: ast.AST, text: str) -> float | None:
    """The value of ``node`` if it holds no name (None otherwise), checked finite.

    Each part of a constraint made of numbers alone is computed once, when the
    description is read: one that divides by zero or is not a finite number is
    refused there, naming the constraint, instead of failing (or, on arrays,
    silently giving inf or NaN) while designs are checked.
    """
    if isinstance(node, ast.Constant):
        value = float(node.value)  # type: ignore[arg-type]  # a number, as parsed
    elif isinstance(node, ast.Name):
        return None
    elif isinstance(node, ast.UnaryOp):
        inner = _fold(node.operand, text)
        if inner is None:
            return None
        value = -inner if isinstance(node.op, ast.USub) else inner
    else:
        assert isinstance(node, ast.BinOp)
        left, right = _fold(node.left, text), _fold(node.right, text)
        if left is None or right is None:
            return None
        try:
            value = _ARITHMETIC[type(node.op)](left, right)
        except ZeroDivisionError:
            raise ActuatorError(
                f"The constraint {text!r} divides by zero ({_part(text, node)}); its numbers "
                "must give finite values."
            ) from None
    if not math.isfinite(value):
        raise ActuatorError(
            f"The constraint {text!r} holds a number too large to compute "
            f"({_part(text, node)}); its numbers must give finite values."
        )
    return value


def _evaluate(node: ast.AST, values: Mapping[str, np.ndarray]) -> Any:
    if isinstance(node, ast.Constant):  # a number: _parse_constraint allows no other constant
        return float(node.value)  # type: ignore[arg-type]
    if isinstance(node, ast.Name):
        return values[node.id]
    if isinstance(node, ast.UnaryOp):
        inner = _evaluate(node.operand, values)
        return -inner if isinstance(node.op, ast.USub) else inner
    if isinstance(node, ast.BinOp):
        return _ARITHMETIC[type(node.op)](
            _evaluate(node.left, values), _evaluate(node.right, values)
        )
    assert isinstance(node, ast.Compare)
    result = np.ones(np.shape(next(iter(values.values()))), dtype=bool)
    left = _evaluate(node.left, values)
    for op, comparator in zip(node.ops, node.comparators, strict=True):
        right = _evaluate(comparator, values)
        result &= np.asarray(_COMPARE[type(op)](left, right), dtype=bool)
        left = right
    return result


# --- the description ---------------------------------------------------------------------------


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

    The fields from ``quantities`` on are softbend's knowledge of a registered
    actuator, not part of its description: :meth:`to_dict` does not write them and
    equality ignores them; a model's recorded description that equals a registered
    one is read back as that one (:func:`softbend.surrogates.persistence.actuator_of`).
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
    _trees: tuple[ast.Compare, ...] = field(default=(), repr=False, compare=False)

    def __post_init__(self) -> None:
        _check_name(self.name.replace("-", "_"), "name of an actuator")
        if not self.parameters:
            raise ActuatorError(f"The actuator {self.name!r} needs at least one design parameter.")
        object.__setattr__(self, "parameters", tuple(self.parameters))
        names = [p.name for p in self.parameters]
        _check_name(self.pressure_column, "pressure column")
        _check_name(self.angle_column, "angle column")
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
        object.__setattr__(self, "constraints", tuple(self.constraints))
        trees = tuple(_parse_constraint(text, names) for text in self.constraints)
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
                    if not _evaluate(tree, self._columns(rows[i : i + 1]))[0]
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
                met &= np.asarray(_evaluate(tree, columns), dtype=bool)
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
        return cls(
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


def _register_paper_b() -> Actuator:
    """Paper B's fiber-reinforced actuator (SFRBA), as its FEM and Table 1 describe it."""
    from softbend.design import _BOUNDS, FEATURE_QUANTITIES
    from softbend.parameters import Range
    from softbend.references import SURROGATES, values

    described = {
        "l_mm": ("mm", "chamber length"),
        "r_mm": ("mm", "inner radius of the semicircular chamber"),
        "t_mm": ("mm", "top wall thickness"),
        "b_mm": ("mm", "bottom wall thickness"),
        "phi_deg": ("deg", "fiber winding angle from the circumferential direction"),
        "lc_mm": ("mm", "distal cap length"),
    }
    parameters = tuple(
        DesignParameter(
            name,
            unit,
            low,
            high,
            resolution=0.1 if unit == "mm" else 1.0,
            description=text,
        )
        for name, (unit, text) in described.items()
        for low, high, _ in [_BOUNDS[name]]
    )
    sfrba = Actuator(
        name="sfrba",
        title="paper B's soft fiber-reinforced bending actuator",
        parameters=parameters,
        pressure_column="pressure_mpa",
        pressure_unit="MPa",
        angle_column="angle_deg",
        constraints=("t_mm < r_mm",),
        fem_family="sfrba",
        quantities=dict(FEATURE_QUANTITIES),
        mape_floor_deg=1.0,
        transfer_mape_floor_deg=0.0,
        analytical=True,
        published_cv=values(SURROGATES),
        named_in_outputs=False,
        search_steps=tuple(1.0 if unit == "deg" else 0.5 for unit, _ in described.values()),
        search_limits=tuple(
            Range(low, high, unit, "the values a design may take", low_inclusive)
            for name, (unit, _) in described.items()
            for low, high, low_inclusive in [_BOUNDS[name]]
        ),
    )
    return ACTUATORS.register(sfrba.name, sfrba)


#: Paper B's actuator: the description of every campaign and shipped model.
SFRBA: Actuator = _register_paper_b()


def _register_pneunet() -> Actuator:
    """The PneuNet's description (:mod:`softbend.fem.pneunet.description` is its FEM family)."""
    parameters = (
        DesignParameter(
            "n_chambers", "", 3, 8, kind="integer", description="number of chambers in the row"
        ),
        DesignParameter(
            "chamber_length_mm",
            "mm",
            5.0,
            12.0,
            resolution=0.1,
            description="outer length of one chamber along the actuator, walls included",
        ),
        DesignParameter(
            "chamber_width_mm",
            "mm",
            10.0,
            20.0,
            resolution=0.1,
            description="outer width of a chamber across the actuator (and of the base)",
        ),
        DesignParameter(
            "chamber_height_mm",
            "mm",
            8.0,
            25.0,
            resolution=0.1,
            description="outer height of a chamber above the base",
        ),
        DesignParameter(
            "wall_mm",
            "mm",
            0.8,
            2.5,
            resolution=0.1,
            description="thickness of the expanding walls facing the neighbouring chambers",
        ),
        DesignParameter(
            "outer_wall_mm",
            "mm",
            1.5,
            3.0,
            resolution=0.1,
            description="thickness of the side walls and the roof of a chamber",
        ),
        DesignParameter(
            "gap_mm",
            "mm",
            1.0,
            5.0,
            resolution=0.1,
            description="gap between neighbouring chambers",
        ),
        DesignParameter(
            "base_mm",
            "mm",
            1.0,
            4.0,
            resolution=0.1,
            description="thickness of the base under the chambers, strain-limiting layer below",
        ),
    )

    pneunet = Actuator(
        name="pneunet",
        title="PneuNet: a row of inflatable chambers on a strain-limiting layer",
        parameters=parameters,
        pressure_column="pressure_mpa",
        pressure_unit="MPa",
        angle_column="angle_deg",
        constraints=(
            "2 * wall_mm < chamber_length_mm",
            "2 * outer_wall_mm < chamber_width_mm",
            "outer_wall_mm < chamber_height_mm",
        ),
        fem_family="pneunet",
    )
    return ACTUATORS.register(pneunet.name, pneunet)


#: The PneuNet: a row of chambers on a strain-limiting layer, the FEM's second family.
PNEUNET: Actuator = _register_pneunet()
