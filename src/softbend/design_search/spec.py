"""A designer's specification: a target bending, the parameters allowed, what to minimise.

A :class:`Specification` says what an actuator must do and what may be chosen:

- a :class:`Target`, one of

  - ``angle_at``: bend ``angle_deg`` (± ``tolerance_deg``) at ``pressure_mpa``;
  - ``pressure_for``: reach ``angle_deg`` at a pressure no higher than
    ``pressure_mpa`` (the pressure it takes is then an objective, ``pressure``);
  - ``max_angle``: bend as far as possible at ``pressure_mpa`` (no tolerance);
  - ``curve``: follow the points ``(pressure_mpa, angle_deg)`` of a table, each
    within ``tolerance_deg``;

- for each design parameter (:data:`NAMES`: ``l, r, t, b, phi, lc`` in mm and
  degrees) a :class:`ParameterRange`: a range, or one fixed value, and a step
  (the mould's resolution; ``0`` searches the range continuously);
- :class:`Objective` s to minimise or maximise among the designs that meet the
  target: a parameter, ``pressure``, ``volume`` (of elastomer, mm³),
  ``sensitivity`` (dθ/dp at the target pressure, deg/MPa), ``angle`` (at the
  target pressure) or ``error`` (the miss of the target, degrees, the default).

Specifications come from code, from command-line text (:func:`parse_assignment`,
:func:`parse_range`) or from a TOML file (:func:`load_specifications`: one
``[[spec]]`` table per specification).
"""

from __future__ import annotations

import math
import os
import tomllib
from collections.abc import Mapping, Sequence
from dataclasses import dataclass, field
from pathlib import Path
from typing import Any

from softbend.design import PARAMETERS
from softbend.errors import DatasetError

__all__ = [
    "DEFAULT_STEPS",
    "NAMES",
    "OBJECTIVES",
    "TARGETS",
    "Objective",
    "ParameterRange",
    "Specification",
    "Target",
    "build_ranges",
    "load_specifications",
    "parse_assignment",
    "parse_objectives",
    "parse_range",
    "target_from_options",
]

#: Short names of the design parameters, in the order of :data:`softbend.design.PARAMETERS`.
NAMES: tuple[str, ...] = ("l", "r", "t", "b", "phi", "lc")

#: Short name → column of the surrogates' inputs.
COLUMNS: dict[str, str] = dict(zip(NAMES, PARAMETERS, strict=True))

#: Unit of each parameter.
UNITS: dict[str, str] = {name: "deg" if name == "phi" else "mm" for name in NAMES}

#: The default step of each parameter: a mould's resolution (0.5 mm) and 1° of fibre angle.
DEFAULT_STEPS: dict[str, float] = {name: 1.0 if name == "phi" else 0.5 for name in NAMES}

#: The kinds of :class:`Target`.
TARGETS: tuple[str, ...] = ("angle_at", "pressure_for", "max_angle", "curve")

#: What an :class:`Objective` may name, with its unit.
OBJECTIVES: dict[str, str] = {
    **UNITS,
    "pressure": "MPa",
    "volume": "mm³",
    "sensitivity": "deg/MPa",
    "angle": "deg",
    "error": "deg",
}

_OWNER = "Specification"


@dataclass(frozen=True)
class ParameterRange:
    """The values a design parameter may take.

    Attributes
    ----------
    low, high : float
        The range, mm or degrees (``low == high``: fixed).
    step : float
        Spacing of the allowed values from ``low`` (the mould's resolution), > 0;
        0 for any value in the range.
    """

    low: float
    high: float
    step: float = 0.0

    def __post_init__(self) -> None:
        for name in ("low", "high", "step"):
            value = getattr(self, name)
            if isinstance(value, bool) or not isinstance(value, int | float):
                raise ValueError(f"The '{name}' of a parameter range must be a number.")
            if not math.isfinite(value):
                raise ValueError(f"The '{name}' of a parameter range must be finite.")
        if self.low > self.high:
            raise ValueError(
                f"A parameter range must have low <= high. Got {self.low:g}:{self.high:g}."
            )
        if self.step < 0:
            raise ValueError(f"The step of a parameter must be >= 0. Got {self.step:g}.")

    @property
    def fixed(self) -> bool:
        """Whether the parameter is fixed to one value."""
        return self.low == self.high

    def values(self) -> list[float]:
        """The allowed values on the step's grid (``[low]`` when fixed), rounded to 1e-9."""
        if self.fixed or self.step == 0:
            return [self.low] if self.fixed else []
        count = math.floor((self.high - self.low) / self.step + 1e-9)
        return [round(self.low + i * self.step, 9) for i in range(count + 1)]


@dataclass(frozen=True)
class Target:
    """What the actuator must do.

    Attributes
    ----------
    kind : str
        One of :data:`TARGETS`.
    angle_deg : float
        The angle to reach, degrees (``angle_at``, ``pressure_for``).
    pressure_mpa : float
        The pressure, MPa gauge: where the angle is read (``angle_at``,
        ``max_angle``) or the most that may be used (``pressure_for``).
    tolerance_deg : float
        How far the angle may miss, degrees (not ``max_angle``).
    points : tuple of (float, float)
        ``(pressure_mpa, angle_deg)`` of a ``curve``.
    """

    kind: str
    angle_deg: float = math.nan
    pressure_mpa: float = math.nan
    tolerance_deg: float = 3.0
    points: tuple[tuple[float, float], ...] = ()

    def __post_init__(self) -> None:
        if self.kind not in TARGETS:
            raise ValueError(
                f"The 'kind' of a target must be one of {', '.join(TARGETS)}. "
                f"Got {self.kind!r} instead."
            )
        if not (math.isfinite(self.tolerance_deg) and self.tolerance_deg > 0):
            raise ValueError(
                f"The tolerance of a target must be > 0 degrees. Got {self.tolerance_deg!r}."
            )
        if self.kind == "curve":
            if len(self.points) < 2:
                raise ValueError("A 'curve' target needs at least 2 (pressure, angle) points.")
            for p, a in self.points:
                _check_pressure(p, "a point's pressure")
                _check_angle(a, "a point's angle")
            object.__setattr__(
                self, "points", tuple(sorted((float(p), float(a)) for p, a in self.points))
            )
            return
        _check_pressure(self.pressure_mpa, "pressure")
        if self.kind != "max_angle":
            _check_angle(self.angle_deg, "angle")

    @property
    def pressures_mpa(self) -> tuple[float, ...]:
        """The pressures the target reads the angle at, MPa."""
        if self.kind == "curve":
            return tuple(p for p, _ in self.points)
        return (self.pressure_mpa,)

    def describe(self) -> str:
        """The target in words, units included."""
        if self.kind == "angle_at":
            return f"{self.angle_deg:g}° ± {self.tolerance_deg:g}° at {self.pressure_mpa:g} MPa"
        if self.kind == "pressure_for":
            return (
                f"{self.angle_deg:g}° ± {self.tolerance_deg:g}° at no more than "
                f"{self.pressure_mpa:g} MPa"
            )
        if self.kind == "max_angle":
            return f"the largest angle at {self.pressure_mpa:g} MPa"
        pts = ", ".join(f"{a:g}° at {p:g}" for p, a in self.points)
        return f"the curve {pts} MPa, each ± {self.tolerance_deg:g}°"


@dataclass(frozen=True)
class Objective:
    """One quantity to minimise (``sense="min"``) or maximise (``"max"``): a name of
    :data:`OBJECTIVES`."""

    name: str
    sense: str = "min"

    def __post_init__(self) -> None:
        if self.name not in OBJECTIVES:
            raise ValueError(
                f"An objective must be one of {', '.join(OBJECTIVES)}. Got {self.name!r} instead."
            )
        if self.sense not in ("min", "max"):
            raise ValueError(
                f"The sense of an objective must be 'min' or 'max'. Got {self.sense!r} instead."
            )

    def __str__(self) -> str:
        return f"{self.sense} {self.name} ({OBJECTIVES[self.name]})"


@dataclass(frozen=True)
class Specification:
    """A target, the parameters' ranges and the objectives of a design search.

    Attributes
    ----------
    target : Target
    ranges : dict of str to ParameterRange
        Per short name of :data:`NAMES`; a parameter left out takes the model's
        training range at its default step (:meth:`resolved`).
    objectives : tuple of Objective
        Default: the smallest miss of the target (``max angle`` for ``max_angle``).
    name : str
        A label for tables and files.
    steps : dict of str to float
        The step of each parameter left out of ``ranges`` (default
        :data:`DEFAULT_STEPS`; 0: continuous).
    margin_deg : float
        A design margin, degrees: on the surrogate a design must meet the target
        within ``tolerance − margin``, so that the surrogate's own error (a degree
        or two against the FEM) does not push the answers past the tolerance;
        the FEM check keeps the whole tolerance. In [0, tolerance).
    """

    target: Target
    ranges: Mapping[str, ParameterRange] = field(default_factory=dict)
    objectives: tuple[Objective, ...] = ()
    name: str = "spec"
    steps: Mapping[str, float] = field(default_factory=lambda: dict(DEFAULT_STEPS))
    margin_deg: float = 0.0

    def __post_init__(self) -> None:
        margin = self.margin_deg
        if (
            isinstance(margin, bool)
            or not isinstance(margin, int | float)
            or not (0 <= margin < self.target.tolerance_deg)
        ):
            raise ValueError(
                f"The margin must lie in [0, {self.target.tolerance_deg:g}) degrees (below the "
                f"tolerance). Got {margin!r} instead."
            )
        unknown = sorted(set(self.ranges) - set(NAMES))
        if unknown:
            raise ValueError(
                f"The ranges of a specification must name parameters among "
                f"{', '.join(NAMES)}. Got {', '.join(unknown)}."
            )
        objectives = tuple(self.objectives) or (
            (Objective("angle", "max"),)
            if self.target.kind == "max_angle"
            else (Objective("error", "min"),)
        )
        names = [o.name for o in objectives]
        if len(set(names)) != len(names):
            raise ValueError(f"Each objective may be named once. Got {', '.join(names)}.")
        if "pressure" in names and self.target.kind != "pressure_for":
            raise ValueError(
                "The objective 'pressure' needs a 'pressure_for' target (the pressure it "
                "takes to reach the angle); with the others the pressure is given."
            )
        if "sensitivity" in names and self.target.kind == "curve":
            raise ValueError("The objective 'sensitivity' needs a target at one pressure.")
        object.__setattr__(self, "objectives", objectives)
        object.__setattr__(self, "ranges", dict(self.ranges))
        object.__setattr__(self, "steps", {**DEFAULT_STEPS, **dict(self.steps)})

    def resolved(
        self,
        training_ranges: Mapping[str, Sequence[float]] | None,
        *,
        allow_extrapolation: bool = False,
    ) -> dict[str, ParameterRange]:
        """Every parameter's range: given, or the model's training range at the default step.

        Raises
        ------
        ValueError
            A range reaching outside the training ranges (unless
            ``allow_extrapolation``), a parameter without a range and without
            training ranges to take one from, or a range holding no value on its step.
        """
        out = {}
        for name in NAMES:
            trained = None
            if training_ranges is not None and COLUMNS[name] in training_ranges:
                low, high = (float(v) for v in training_ranges[COLUMNS[name]])
                trained = (low, high)
            given = self.ranges.get(name)
            if given is None:
                if trained is None:
                    raise ValueError(
                        f"The parameter {name!r} needs a range (--range {name}=LOW:HIGH or "
                        f"--fix {name}=VALUE): the model records no training ranges."
                    )
                given = ParameterRange(trained[0], trained[1], float(self.steps[name]))
            outside = trained is not None and (
                given.low < trained[0] - 1e-9 or given.high > trained[1] + 1e-9
            )
            if outside and trained is not None and not allow_extrapolation:
                raise ValueError(
                    f"The range of {name!r} ({given.low:g}:{given.high:g} "
                    f"{UNITS[name]}) leaves the model's training range "
                    f"[{trained[0]:g}, {trained[1]:g}]; narrow it, or pass "
                    "--allow-extrapolation (the answers outside are then flagged)."
                )
            if not given.fixed and given.step > 0 and not given.values():
                raise ValueError(f"The range of {name!r} holds no value on its step.")
            if not given.fixed and given.step > given.high - given.low + 1e-9:
                raise ValueError(
                    f"The resolution of {name!r} ({given.step:g} {UNITS[name]}) is wider than "
                    f"its range {given.low:g}:{given.high:g}; fix it or refine the resolution."
                )
            out[name] = given
        return out

    def describe(self) -> str:
        """The specification in one line."""
        fixed = [f"{n} = {r.low:g}" for n, r in self.ranges.items() if r.fixed]
        ranged = [f"{n} in {r.low:g}:{r.high:g}" for n, r in self.ranges.items() if not r.fixed]
        parts = [self.target.describe(), *fixed, *ranged, ", ".join(map(str, self.objectives))]
        return "; ".join(parts)


def _check_pressure(value: Any, what: str) -> None:
    if isinstance(value, bool) or not isinstance(value, int | float) or not math.isfinite(value):
        raise ValueError(f"The target's {what} must be a number of MPa. Got {value!r} instead.")
    if not 0 < value <= 1.0:
        raise ValueError(
            f"The target's {what} must be a gauge pressure in (0, 1] MPa. Got {value:g}; "
            "a value in kPa? (0.08 MPa = 80 kPa)"
        )


def _check_angle(value: Any, what: str) -> None:
    if isinstance(value, bool) or not isinstance(value, int | float) or not math.isfinite(value):
        raise ValueError(f"The target's {what} must be a number of degrees. Got {value!r}.")
    if not 0 < value <= 360:
        raise ValueError(f"The target's {what} must lie in (0, 360] degrees. Got {value:g}.")


def parse_assignment(text: str, field_name: str = "--fix") -> tuple[str, float]:
    """``("phi", 10.0)`` from ``"phi=10"``; one clear line for anything else."""
    name, sep, value = text.partition("=")
    name = name.strip()
    if not sep or name not in NAMES:
        raise ValueError(
            f"The '{field_name}' must be NAME=VALUE with NAME among {', '.join(NAMES)}. "
            f"Got {text!r} instead."
        )
    try:
        number = float(value)
    except ValueError:
        raise ValueError(
            f"The '{field_name}' value of {name!r} must be a number ({UNITS[name]}). "
            f"Got {value!r} instead."
        ) from None
    if not math.isfinite(number):
        raise ValueError(f"The '{field_name}' value of {name!r} must be finite. Got {value!r}.")
    return name, number


def parse_range(text: str, field_name: str = "--range") -> tuple[str, float, float]:
    """``("t", 3.0, 4.0)`` from ``"t=3:4"``; one clear line for anything else."""
    name, sep, value = text.partition("=")
    name = name.strip()
    low, colon, high = value.partition(":")
    if not sep or name not in NAMES or not colon:
        raise ValueError(
            f"The '{field_name}' must be NAME=LOW:HIGH with NAME among {', '.join(NAMES)}. "
            f"Got {text!r} instead."
        )
    try:
        a, b = float(low), float(high)
    except ValueError:
        raise ValueError(
            f"The '{field_name}' ends of {name!r} must be numbers ({UNITS[name]}). "
            f"Got {value!r} instead."
        ) from None
    if not (math.isfinite(a) and math.isfinite(b)) or a > b:
        raise ValueError(
            f"The '{field_name}' of {name!r} must have finite LOW <= HIGH. Got {value!r}."
        )
    return name, a, b


def parse_objectives(minimize: Sequence[str], maximize: Sequence[str]) -> tuple[Objective, ...]:
    """Objectives from comma-separated names to minimise and to maximise, in order given."""
    out = []
    for sense, texts in (("min", minimize), ("max", maximize)):
        for text in texts:
            for name in (n.strip() for n in text.split(",")):
                if name:
                    if name not in OBJECTIVES:
                        option = "--minimize" if sense == "min" else "--maximize"
                        raise ValueError(
                            f"The '{option}' must name objectives among "
                            f"{', '.join(OBJECTIVES)}. Got {name!r} instead."
                        )
                    out.append(Objective(name, sense))
    return tuple(out)


def build_ranges(
    fixes: Sequence[str] = (),
    ranges: Sequence[str] = (),
    steps: Sequence[str] = (),
    *,
    step: float | None = None,
) -> tuple[dict[str, ParameterRange], dict[str, float]]:
    """Ranges and steps from ``--fix NAME=V``, ``--range NAME=LOW:HIGH``, ``--resolution``.

    ``steps`` are ``NAME=STEP`` per parameter; ``step`` is the step of every
    parameter not named there (None: :data:`DEFAULT_STEPS`). A parameter both
    fixed and ranged, or named twice, is refused. Returns the ranges given and
    the step of every parameter (for those left to their training range).
    """
    per_step = dict(DEFAULT_STEPS) if step is None else dict.fromkeys(NAMES, float(step))
    for text in steps:
        name, value = parse_assignment(text, "--resolution")
        per_step[name] = value
    for name, value in per_step.items():
        if value < 0:
            raise ValueError(f"The '--resolution' of {name!r} must be >= 0. Got {value:g}.")
    out: dict[str, ParameterRange] = {}
    given: list[tuple[str, ParameterRange]] = []
    for text in fixes:
        name, value = parse_assignment(text, "--fix")
        given.append((name, ParameterRange(value, value, 0.0)))
    for text in ranges:
        name, low, high = parse_range(text)
        given.append((name, ParameterRange(low, high, per_step[name])))
    for name, chosen in given:
        if name in out:
            raise ValueError(f"The parameter {name!r} is given twice (--fix or --range).")
        out[name] = chosen
    return out, per_step


def load_specifications(path: str | os.PathLike[str]) -> list[Specification]:
    """The ``[[spec]]`` tables of a TOML file, each a :class:`Specification`.

    A table::

        [[spec]]
        name = "gripper finger"
        angle = 90.0              # degrees
        at = 0.08                 # MPa (angle_at); or max_pressure = 0.1 (pressure_for)
        tolerance = 3.0           # degrees
        minimize = ["l"]          # objectives; maximize = [...]
        fix = {phi = 10.0}
        range = {t = [3.0, 4.0]}
        resolution = 0.5          # mm (deg for phi), every parameter; or {l = 1.0}
        margin = 1.0              # degrees kept from the tolerance on the surrogate

    ``max_angle_at = P`` asks for the largest angle at P; ``curve = [[p, angle], ...]``
    for a curve.

    Raises
    ------
    DatasetError
        A file that is not TOML, has no ``[[spec]]``, or a table that is not a
        specification, naming the file, the table and what is wrong.
    """
    file = Path(path)
    try:
        data = tomllib.loads(file.read_text(encoding="utf-8"))
    except OSError as exc:
        raise DatasetError(f"The specification file {file} cannot be read: {exc}.") from None
    except tomllib.TOMLDecodeError as exc:
        raise DatasetError(f"The specification file {file} is not TOML: {exc}.") from None
    tables = data.get("spec")
    if not isinstance(tables, list) or not tables:
        raise DatasetError(f"The specification file {file} must hold at least one [[spec]].")
    specs = []
    for i, table in enumerate(tables, start=1):
        try:
            specs.append(_spec_from_table(table, f"spec{i}"))
        except (ValueError, TypeError) as exc:
            raise DatasetError(f"{file}, [[spec]] number {i}: {exc}") from None
    return specs


_TABLE_KEYS = (
    "name",
    "angle",
    "at",
    "max_pressure",
    "max_angle_at",
    "curve",
    "tolerance",
    "minimize",
    "maximize",
    "fix",
    "range",
    "resolution",
    "margin",
)


def _spec_from_table(table: Any, default_name: str) -> Specification:
    if not isinstance(table, dict):
        raise ValueError("a [[spec]] must be a table")
    unknown = sorted(set(table) - set(_TABLE_KEYS))
    if unknown:
        raise ValueError(
            f"unknown key(s) {', '.join(unknown)}; the keys are {', '.join(_TABLE_KEYS)}"
        )
    tolerance = float(table.get("tolerance", 3.0))
    kinds = [k for k in ("at", "max_pressure", "max_angle_at", "curve") if k in table]
    if len(kinds) != 1:
        raise ValueError("give exactly one of at, max_pressure, max_angle_at or curve")
    kind = kinds[0]
    if kind == "curve":
        target = Target("curve", tolerance_deg=tolerance, points=tuple(map(tuple, table["curve"])))
    elif kind == "max_angle_at":
        target = Target("max_angle", pressure_mpa=float(table["max_angle_at"]))
    else:
        if "angle" not in table:
            raise ValueError(f"'{kind}' needs 'angle' (degrees)")
        target = Target(
            "angle_at" if kind == "at" else "pressure_for",
            angle_deg=float(table["angle"]),
            pressure_mpa=float(table[kind]),
            tolerance_deg=tolerance,
        )
    step = table.get("resolution")
    steps = step if isinstance(step, dict) else {}
    fixes = [f"{k}={v}" for k, v in dict(table.get("fix", {})).items()]
    ranges = [f"{k}={v[0]}:{v[1]}" for k, v in dict(table.get("range", {})).items()]
    built, per_step = build_ranges(
        fixes,
        ranges,
        [f"{k}={v}" for k, v in steps.items()],
        step=None if isinstance(step, dict) or step is None else float(step),
    )
    objectives = parse_objectives(list(table.get("minimize", [])), list(table.get("maximize", [])))
    margin = float(table.get("margin", 0.0))
    name = str(table.get("name", default_name))
    return Specification(target, built, objectives, name, per_step, margin)


def target_from_options(
    *,
    angle: float | None = None,
    at: float | None = None,
    max_pressure: float | None = None,
    max_angle_at: float | None = None,
    curve: str | None = None,
    tolerance: float = 3.0,
) -> Target:
    """The :class:`Target` a command line names (``--angle`` with ``--at`` or
    ``--max-pressure``, ``--max-angle-at``, or ``--curve P:ANGLE,...``).

    Raises
    ------
    ValueError
        None or several kinds of target, a missing ``--angle``, or a bad curve.
    """
    given = [
        name
        for name, value in (
            ("--at", at),
            ("--max-pressure", max_pressure),
            ("--max-angle-at", max_angle_at),
            ("--curve", curve),
        )
        if value is not None
    ]
    if len(given) != 1:
        raise ValueError(
            "The target must be one of --angle A --at P, --angle A --max-pressure P, "
            f"--max-angle-at P or --curve P:A,P:A,... Got {', '.join(given) or 'none'}."
        )
    if curve is not None:
        points = []
        for item in (x.strip() for x in curve.split(",") if x.strip()):
            p, colon, a = item.partition(":")
            try:
                points.append((float(p), float(a)))
            except ValueError:
                raise ValueError(
                    f"The '--curve' must be PRESSURE:ANGLE pairs (MPa:deg), e.g. 0.05:40,0.1:95. "
                    f"Got {item!r} instead."
                ) from None
            if not colon:
                raise ValueError(f"The '--curve' point {item!r} lacks ':ANGLE'.")
        return Target("curve", tolerance_deg=tolerance, points=tuple(points))
    if max_angle_at is not None:
        if angle is not None:
            raise ValueError("The '--angle' has no meaning with --max-angle-at; leave it out.")
        return Target("max_angle", pressure_mpa=max_angle_at, tolerance_deg=tolerance)
    if angle is None:
        raise ValueError(f"The target {given[0]} needs '--angle' (degrees).")
    kind, pressure = ("angle_at", at) if at is not None else ("pressure_for", max_pressure)
    assert pressure is not None  # exactly one of --at and --max-pressure, checked above
    return Target(kind, angle_deg=angle, pressure_mpa=float(pressure), tolerance_deg=tolerance)
