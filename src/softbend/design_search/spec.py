"""A designer's specification: a target bending, the parameters allowed, what to minimise.

A :class:`Specification` says what an actuator must do and what may be chosen:

- a :class:`Target`, one of

  - ``angle_at``: bend ``angle_deg`` (± ``tolerance_deg``) at ``pressure_mpa``;
  - ``pressure_for``: reach ``angle_deg`` at a pressure no higher than
    ``pressure_mpa`` (the pressure it takes is then an objective, ``pressure``);
  - ``max_angle``: bend as far as possible at ``pressure_mpa`` (no tolerance);
  - ``curve``: follow the points ``(pressure_mpa, angle_deg)`` of a table, each
    within ``tolerance_deg``;

- for each design parameter of the actuator searched (:mod:`.space`: paper B's
  short names ``l, r, t, b, phi, lc`` in mm and degrees, or another
  description's own) a :class:`ParameterRange`: a range, or one fixed value,
  and a step (the mould's resolution; ``0`` searches the range continuously);
- :class:`Objective` s to minimise or maximise among the designs that meet the
  target: a parameter, ``pressure``, ``volume`` (of elastomer, mm³),
  ``sensitivity`` (dθ/dp at the target pressure, deg/MPa), ``angle`` (at the
  target pressure) or ``error`` (the miss of the target, degrees, the default).

A categorical parameter is fixed by level name, an integer one searched on
whole numbers, and the pressures are in the actuator's pressure unit
(``Target(..., unit="kPa")``).

This module holds the data classes and the checks of their numbers; a
specification is read from command-line text by :mod:`.spec_text` and from a
TOML file by :mod:`.spec_toml`. Every number is held to a declared range
(:data:`ANGLE`, :data:`PRESSURE`, :data:`TOLERANCE`, the limits of a design).
"""

from __future__ import annotations

import math
from collections.abc import Mapping, Sequence
from dataclasses import dataclass, field
from typing import TypeGuard

from softbend._validation import must_be
from softbend.actuators import PRESSURE_UNITS, SFRBA, Actuator
from softbend.design_search.space import SearchSpace, aligned, space_of
from softbend.errors import InputError
from softbend.parameters import Range

__all__ = [
    "ANGLE",
    "CURVE_POINTS",
    "DEFAULT_STEPS",
    "NAMES",
    "OBJECTIVES",
    "PRESSURE",
    "SPECS",
    "STEP",
    "TARGETS",
    "TOLERANCE",
    "Objective",
    "ParameterRange",
    "Specification",
    "Target",
    "check_angle",
    "check_pressure",
    "default_step",
    "is_number",
    "pressure_range",
    "search_resolution",
    "step_problem",
    "value_problem",
]

#: Short names of the design parameters, in the order of :data:`softbend.design.PARAMETERS`.
NAMES: tuple[str, ...] = ("l", "r", "t", "b", "phi", "lc")

#: Unit of each parameter.
UNITS: dict[str, str] = {name: "deg" if name == "phi" else "mm" for name in NAMES}

#: Paper B's default step of each parameter: a mould's resolution (0.5 mm) and 1° of fibre
#: angle (:attr:`Actuator.search_steps <softbend.actuators.Actuator.search_steps>`).
DEFAULT_STEPS: dict[str, float] = dict(zip(NAMES, SFRBA.search_steps, strict=True))

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

#: A target's angle.
ANGLE = Range(0.0, 360.0, "deg", "a bending angle, one turn at most", low_inclusive=False)

#: A target's pressure.
PRESSURE = Range(
    0.0,
    1.0,
    "MPa",
    "a gauge pressure; a larger value is likely kPa (0.08 MPa = 80 kPa)",
    low_inclusive=False,
)

#: How far a target's angle may miss.
TOLERANCE = Range(0.0, 90.0, "deg", "a wider miss accepts nearly any design", low_inclusive=False)

#: The points of a ``curve`` target.
CURVE_POINTS = Range(
    2, 50, "points", "two make a curve; each is one more pass of the surrogate over every design"
)

#: The ``[[spec]]`` tables of one file.
SPECS = Range(1, 100, "tables", "each is a search of up to 20 million designs")

#: A mould's step (``--resolution``): finite, 0 for a continuous search.
STEP = Range(0.0, math.inf, "", "0 searches continuously", high_inclusive=False)

#: The most values one parameter's grid is built with (:meth:`ParameterRange.values`).
_MAX_VALUES = 20_000_000


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

    def count(self) -> int:
        """How many values :meth:`values` holds, counted without building them (0 when
        continuous; at most 10**30 for a step too fine to count in floats)."""
        if self.fixed:
            return 1
        if self.step == 0:
            return 0
        spans = (self.high - self.low) / self.step
        if not math.isfinite(spans) or spans > 1e30:
            return 10**30
        return math.floor(spans + 1e-9) + 1

    def values(self) -> list[float]:
        """The allowed values on the step's grid (``[low]`` when fixed), rounded to 1e-9.

        Raises
        ------
        ValueError
            More than 20 million values (a step far finer than any mould's).
        """
        count = self.count()
        if count > _MAX_VALUES:
            raise ValueError(
                f"A parameter range of {self.low:g}:{self.high:g} at a step of {self.step:g} "
                f"holds {count:,} values, more than the {_MAX_VALUES:,} one search builds."
            )
        if self.fixed or self.step == 0:
            return [self.low] if self.fixed else []
        return [round(self.low + i * self.step, 9) for i in range(count)]


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
        The pressure, gauge, in ``unit`` (MPa for paper B's actuator): where
        the angle is read (``angle_at``, ``max_angle``) or the most that may
        be used (``pressure_for``).
    tolerance_deg : float
        How far the angle may miss, degrees (not ``max_angle``).
    points : tuple of (float, float)
        ``(pressure, angle_deg)`` of a ``curve``, pressures in ``unit``.
    unit : {"MPa", "kPa", "bar", "psi"}
        Unit of the pressures: the model's pressure input (its actuator's
        ``pressure_unit``). Whatever the unit, a pressure is at most 1 MPa.
    """

    kind: str
    angle_deg: float = math.nan
    pressure_mpa: float = math.nan
    tolerance_deg: float = 3.0
    points: tuple[tuple[float, float], ...] = ()
    unit: str = "MPa"

    def __post_init__(self) -> None:
        if not isinstance(self.unit, str) or self.unit not in PRESSURE_UNITS:
            raise ValueError(
                f"The 'unit' of a target must be one of {', '.join(PRESSURE_UNITS)}. "
                f"Got {self.unit!r} instead."
            )
        if self.kind not in TARGETS:
            raise ValueError(
                f"The 'kind' of a target must be one of {', '.join(TARGETS)}. "
                f"Got {self.kind!r} instead."
            )
        tolerance = self.tolerance_deg
        if (
            isinstance(tolerance, bool)
            or not isinstance(tolerance, int | float)
            or not TOLERANCE.contains(tolerance)
        ):
            raise ValueError(
                f"The tolerance of a target must lie in {TOLERANCE.describe()} "
                f"({TOLERANCE.why}). Got {tolerance!r}."
            )
        if self.kind == "curve":
            points = tuple(self.points)
            if not CURVE_POINTS.contains(len(points)):
                raise ValueError(
                    f"A 'curve' target needs at least {CURVE_POINTS.low:g} and at most "
                    f"{CURVE_POINTS.high:g} (pressure, angle) points ({CURVE_POINTS.why}). "
                    f"Got {len(points)}."
                )
            for point in points:
                if not isinstance(point, Sequence) or len(point) != 2:
                    raise ValueError(
                        f"A point of a 'curve' target must be (pressure, angle). Got {point!r}."
                    )
                check_pressure(point[0], "points", self.unit, "a point's pressure ")
                check_angle(point[1], "points", "a point's angle ")
            pressures = [float(p) for p, _ in points]
            twice = sorted({p for p in pressures if pressures.count(p) > 1})
            if twice:
                raise ValueError(
                    "A 'curve' target gives each pressure once (one angle at each); "
                    f"{', '.join(f'{p:g}' for p in twice)} {self.unit} is given more than once."
                )
            object.__setattr__(
                self, "points", tuple(sorted((float(p), float(a)) for p, a in points))
            )
            return
        check_pressure(self.pressure_mpa, "pressure_mpa", self.unit)
        if self.kind != "max_angle":
            check_angle(self.angle_deg, "angle_deg")

    @property
    def pressures_mpa(self) -> tuple[float, ...]:
        """The pressures the target reads the angle at, in :attr:`unit`."""
        if self.kind == "curve":
            return tuple(p for p, _ in self.points)
        return (self.pressure_mpa,)

    def describe(self) -> str:
        """The target in words, units included."""
        unit = self.unit
        if self.kind == "angle_at":
            return f"{self.angle_deg:g}° ± {self.tolerance_deg:g}° at {self.pressure_mpa:g} {unit}"
        if self.kind == "pressure_for":
            return (
                f"{self.angle_deg:g}° ± {self.tolerance_deg:g}° at no more than "
                f"{self.pressure_mpa:g} {unit}"
            )
        if self.kind == "max_angle":
            return f"the largest angle at {self.pressure_mpa:g} {unit}"
        pts = ", ".join(f"{a:g}° at {p:g}" for p, a in self.points)
        return f"the curve {pts} {unit}, each ± {self.tolerance_deg:g}°"


@dataclass(frozen=True)
class Objective:
    """One quantity to minimise (``sense="min"``) or maximise (``"max"``).

    ``name`` is one of :attr:`SearchSpace.objectives
    <softbend.design_search.space.SearchSpace.objectives>` of the actuator
    searched and ``unit`` its unit (:class:`Specification` sets it); left out,
    the unit is that of :data:`OBJECTIVES` (a pressure in MPa), and ``name``
    must be one of them.
    """

    name: str
    sense: str = "min"
    unit: str | None = None

    def __post_init__(self) -> None:
        if self.unit is None and self.name not in OBJECTIVES:
            raise ValueError(
                f"An objective must be one of {', '.join(OBJECTIVES)}. Got {self.name!r} instead."
            )
        if not isinstance(self.name, str) or not isinstance(self.unit, str | None):
            raise ValueError("The name and unit of an objective must be text.")
        if self.unit is None:
            object.__setattr__(self, "unit", OBJECTIVES[self.name])
        if self.sense not in ("min", "max"):
            raise ValueError(
                f"The sense of an objective must be 'min' or 'max'. Got {self.sense!r} instead."
            )

    def __str__(self) -> str:
        unit = self.unit
        return f"{self.sense} {self.name} ({unit})" if unit else f"{self.sense} {self.name}"


@dataclass(frozen=True)
class Specification:
    """A target, the parameters' ranges and the objectives of a design search.

    Attributes
    ----------
    target : Target
    ranges : dict of str to ParameterRange
        Per short name of :data:`NAMES` (paper B's actuator; its column names
        ``l_mm`` … are read as those), or per parameter name of ``actuator``;
        a parameter left out takes the model's training range (within
        ``actuator``'s own range) at its default step (:meth:`resolved`). A
        categorical parameter's values are its levels' indices.
    objectives : tuple of Objective
        Default: the smallest miss of the target (``max angle`` for ``max_angle``).
    name : str
        A label for tables and files.
    steps : dict of str to float
        The step of each parameter left out of ``ranges`` (default
        :func:`default_step`: a mould's step, paper B's :data:`DEFAULT_STEPS`;
        else a continuous parameter's declared resolution, else a round step of
        about a hundredth of its range, and 1 for an integer one; 0: continuous).
    margin_deg : float
        A design margin, degrees: on the surrogate a design must meet the target
        within ``tolerance − margin``, so that the surrogate's own error (a degree
        or two against the FEM) does not push the answers past the tolerance;
        the FEM check keeps the whole tolerance. In [0, tolerance).
    actuator : Actuator, optional
        The description of the actuator searched (that of the model): None or
        :data:`softbend.actuators.SFRBA` for paper B's. The target's ``unit``
        must be its pressure unit.
    """

    target: Target
    ranges: Mapping[str, ParameterRange] = field(default_factory=dict)
    objectives: tuple[Objective, ...] = ()
    name: str = "spec"
    steps: Mapping[str, float] = field(default_factory=dict)
    margin_deg: float = 0.0
    actuator: Actuator | None = None

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
        space = self.space
        if self.target.unit != space.pressure_unit:
            raise ValueError(
                f"The target's pressures are in {self.target.unit}, but the actuator "
                f"{space.actuator.name} takes its pressure in {space.pressure_unit}; give the "
                f"target in {space.pressure_unit} (Target(..., unit={space.pressure_unit!r}))."
            )
        ranges = {(space.canonical(k) or k): v for k, v in dict(self.ranges).items()}
        unknown = sorted(set(ranges) - set(space.names))
        if unknown:
            raise ValueError(
                f"The ranges of a specification must name parameters among "
                f"{space.listing()}. Got {', '.join(unknown)}."
            )
        objectives = tuple(self.objectives) or (
            (Objective("angle", "max"),)
            if self.target.kind == "max_angle"
            else (Objective("error", "min"),)
        )
        allowed = space.objectives
        for o in objectives:
            if o.name not in allowed:
                raise ValueError(
                    f"An objective of a search of {space.actuator.name} must be one of "
                    f"{', '.join(allowed)}. Got {o.name!r} instead."
                )
        objectives = tuple(Objective(o.name, o.sense, allowed[o.name]) for o in objectives)
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
        object.__setattr__(self, "ranges", ranges)
        steps = {(space.canonical(k) or k): v for k, v in dict(self.steps).items()}
        for key, value in steps.items():
            if key not in space.names:
                raise ValueError(
                    f"The steps of a specification must name parameters among "
                    f"{space.listing()}. Got {key!r}."
                )
            if isinstance(value, bool) or not isinstance(value, int | float):
                raise ValueError(f"The step of {key!r} must be a number. Got {value!r}.")
            problem = None if STEP.contains(value) else "must be finite and >= 0"
            problem = problem or step_problem(space, key, float(value))
            if problem is not None:
                raise ValueError(f"The step of {key!r} ({value:g}) {problem}.")
        filled = {n: float(steps.get(n, default_step(space, n))) for n in space.names}
        object.__setattr__(self, "steps", filled)

    @property
    def space(self) -> SearchSpace:
        """The parameters searched (:mod:`softbend.design_search.space`)."""
        return space_of(self.actuator)

    def resolved(
        self,
        training_ranges: Mapping[str, Sequence[float]] | None,
        *,
        allow_extrapolation: bool = False,
    ) -> dict[str, ParameterRange]:
        """Every parameter's range: given, or the model's training range at the default step.

        A parameter left out takes its training range, within the range its
        description declares (not for a description whose ranges are only the
        limits of a design, :attr:`Actuator.search_limits
        <softbend.actuators.Actuator.search_limits>`: paper B's); an integer or
        categorical one takes whole numbers (levels' indices), a continuous one
        with a step the multiples of the step inside its range.

        Raises
        ------
        ValueError
            A range reaching outside the training ranges (unless
            ``allow_extrapolation``) or outside the actuator's description, a
            parameter without a range and without training ranges to take one
            from, or a range holding no value on its step.
        """
        space = self.space
        out: dict[str, ParameterRange] = {}
        for name in space.names:
            p = space.parameter(name)
            unit = f" {p.unit}" if p.unit else ""
            trained = None
            if training_ranges is not None and p.name in training_ranges:
                low, high = (float(v) for v in training_ranges[p.name])
                trained = (low, high)
            given = self.ranges.get(name)
            if given is None:
                given = self._trained_range(name, trained, unit)
            else:
                for end in (given.low, given.high):
                    problem = value_problem(space, name, end)
                    if problem is None and p.kind == "categorical" and end != round(end):
                        problem = "is not a level's index (a whole number)"
                    if problem is not None:
                        raise ValueError(
                            f"The range of {name!r} ({given.low:g}:{given.high:g}{unit}) {problem}."
                        )
                outside = trained is not None and (
                    given.low < trained[0] - 1e-9 or given.high > trained[1] + 1e-9
                )
                if outside and trained is not None and not allow_extrapolation:
                    raise InputError(
                        f"must be set for the range of {name!r} ({given.low:g}:{given.high:g}"
                        f"{unit}), which leaves the model's training range [{trained[0]:g}, "
                        f"{trained[1]:g}] (the answers outside are then flagged); or narrow the "
                        "range",
                        key="allow_extrapolation",
                    )
            out[name] = self._on_step(name, given, unit)
        return out

    def _trained_range(
        self, name: str, trained: tuple[float, float] | None, unit: str
    ) -> ParameterRange:
        """The range of a parameter left out: its training range, within the range its
        description declares (a box to search; none where the description declares only
        the limits of a design), at its default step."""
        space = self.space
        p = space.parameter(name)
        low, high = (-math.inf, math.inf) if space.actuator.search_limits else (p.low, p.high)
        if trained is not None:
            low, high = max(low, trained[0]), min(high, trained[1])
        if not (math.isfinite(low) and math.isfinite(high)):
            raise InputError(
                f"must give the parameter {name!r} a range ({name}=LOW:HIGH, or fix "
                f"{name}=VALUE): the model records no training range of it and the "
                f"actuator {space.actuator.name} declares none to search",
                key="ranges",
            )
        if p.kind != "continuous":
            low, high = float(math.ceil(low - 1e-9)), float(math.floor(high + 1e-9))
        if low > high:
            raise InputError(
                f"must give {name!r} a range ({name}=LOW:HIGH, or fix {name}=VALUE): "
                f"the model's training range of it does not meet the range "
                f"[{p.low:g}, {p.high:g}]{unit} the actuator {space.actuator.name} "
                "describes",
                key="ranges",
            )
        return ParameterRange(low, high, float(self.steps[name]))

    def _on_step(self, name: str, given: ParameterRange, unit: str) -> ParameterRange:
        """``given`` on the step of its kind: whole numbers, or multiples of the step."""
        space = self.space
        kind = space.kind(name)
        if given.fixed:
            return ParameterRange(given.low, given.high, 0.0)
        if kind == "categorical":
            return ParameterRange(given.low, given.high, 1.0)
        step = given.step
        if kind == "integer":
            step = step or 1.0
            problem = space.step_problem(name, step)
            if problem is not None:
                raise ValueError(f"The step of {name!r} ({step:g}) {problem}.")
            return ParameterRange(given.low, given.high, step)
        if step > given.high - given.low + 1e-9:
            raise ValueError(
                f"The resolution of {name!r} ({step:g}{unit}) is wider than its range "
                f"{given.low:g}:{given.high:g}; fix it or refine the resolution."
            )
        if step > 0:
            problem = step_problem(space, name, step)
            if problem is not None:
                raise ValueError(f"The step of {name!r} ({step:g}{unit}) {problem}.")
        else:
            resolution = search_resolution(space, name)
            if resolution is None:
                return given
            step = resolution  # a continuous search still ends on the resolution: it must hold one
        first, last = aligned(given.low, given.high, step)
        if first > last:
            raise ValueError(
                f"The range of {name!r} ({given.low:g}:{given.high:g}{unit}) holds no multiple "
                f"of its step {step:g}{unit}; widen it or refine the resolution."
            )
        if given.step == 0:
            return given
        return ParameterRange(first, last, step)

    def describe(self) -> str:
        """The specification in one line."""
        space = self.space

        fixed = [f"{n} = {space.shown(n, r.low)}" for n, r in self.ranges.items() if r.fixed]
        ranged = [f"{n} in {r.low:g}:{r.high:g}" for n, r in self.ranges.items() if not r.fixed]
        parts = [self.target.describe(), *fixed, *ranged, ", ".join(map(str, self.objectives))]
        return "; ".join(parts)


def default_step(space: SearchSpace, name: str) -> float:
    """The step of ``name`` when none is given: the mould's (:attr:`Actuator.search_steps
    <softbend.actuators.Actuator.search_steps>`, paper B's 0.5 mm and 1°), else
    :meth:`SearchSpace.default_step <softbend.design_search.space.SearchSpace.default_step>`."""
    mould = dict(zip(space.names, space.actuator.search_steps, strict=False))
    return float(mould[name]) if name in mould else space.default_step(name)


def search_resolution(space: SearchSpace, name: str) -> float | None:
    """The step a search keeps a continuous value of ``name`` to: its declared resolution,
    none on a mould's grid (:attr:`Actuator.search_steps
    <softbend.actuators.Actuator.search_steps>`), whose step is the resolution."""
    return None if space.actuator.search_steps else space.parameter(name).resolution


def step_problem(space: SearchSpace, name: str, step: float) -> str | None:
    """Why ``step`` cannot be the step of ``name`` (:meth:`SearchSpace.step_problem
    <softbend.design_search.space.SearchSpace.step_problem>`, a continuous one held to
    :func:`search_resolution`), or None."""
    if space.kind(name) == "continuous" and search_resolution(space, name) is None:
        return None
    return space.step_problem(name, step)


def value_problem(space: SearchSpace, name: str, value: float) -> str | None:
    """Why ``value`` cannot be a value of ``name``: outside the limits of a design the
    description declares (:attr:`Actuator.search_limits
    <softbend.actuators.Actuator.search_limits>`), else outside its parameter's range or
    not a whole number (:meth:`SearchSpace.value_problem
    <softbend.design_search.space.SearchSpace.value_problem>`); None when it can."""
    limits = dict(zip(space.names, space.actuator.search_limits, strict=False))
    if name not in limits:
        return space.value_problem(name, value)
    if limits[name].contains(value):
        return None
    return f"leaves the values a design may take, {limits[name].describe()}"


def pressure_range(unit: str = "MPa") -> Range:
    """:data:`PRESSURE` in ``unit`` (``(0, 1000] kPa``)."""
    if unit == "MPa":
        return PRESSURE
    high = float(f"{PRESSURE.high / PRESSURE_UNITS[unit]:.6g}")
    return Range(0.0, high, unit, "a gauge pressure of at most 1 MPa", low_inclusive=False)


def check_pressure(value: object, key: str | None, unit: str = "MPa", subject: str = "") -> None:
    """Refuse a value that is not a gauge pressure of :func:`pressure_range` (keyed ``key``;
    ``subject`` names a part of it, ``"point '0.1:40' "``)."""
    if isinstance(value, bool) or not isinstance(value, int | float) or not math.isfinite(value):
        raise InputError(subject + must_be(f"a number of {unit}", value), key=key)
    allowed = pressure_range(unit)
    if not allowed.contains(value):
        hint = (
            " (a value in kPa? 0.08 MPa = 80 kPa)"
            if unit == "MPa" and value > PRESSURE.high
            else ""
        )
        raise InputError(
            subject + must_be(f"a gauge pressure in {allowed.describe()}", value) + hint, key=key
        )


def check_angle(value: object, key: str | None, subject: str = "") -> None:
    """Refuse a value that is not an angle of :data:`ANGLE` (keyed ``key``)."""
    if isinstance(value, bool) or not isinstance(value, int | float) or not math.isfinite(value):
        raise InputError(subject + must_be("a number of degrees", value), key=key)
    if not ANGLE.contains(value):
        raise InputError(subject + must_be(f"in {ANGLE.describe()} ({ANGLE.why})", value), key=key)


def is_number(value: object) -> TypeGuard[int | float]:
    """Whether ``value`` is a number of a TOML file a float can hold."""
    if isinstance(value, bool) or not isinstance(value, int | float):
        return False
    try:
        float(value)
    except OverflowError:  # an integer of hundreds of digits
        return False
    return True
