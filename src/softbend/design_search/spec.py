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

A specification of another actuator (``actuator=``, the description its model
was trained with) names that actuator's parameters (:mod:`.space`): a
categorical one fixed by level name, an integer one on whole numbers, and its
pressures in the actuator's pressure unit (``Target(..., unit="kPa")``).

Specifications come from code, from command-line text (:func:`parse_assignment`,
:func:`parse_range`) or from a TOML file (:func:`load_specifications`: one
``[[spec]]`` table per specification). Every number is held to a declared
range (:data:`ANGLE`, :data:`PRESSURE`, :data:`TOLERANCE`, the limits of a
design), and a ``[[spec]]`` name becomes a folder of the output only through
:func:`softbend._names.output_name`, all before any design is scored.
"""

from __future__ import annotations

import math
import os
import reprlib
from collections.abc import Collection, Mapping, Sequence
from dataclasses import dataclass, field
from typing import Any, TypeGuard

from softbend._names import output_name
from softbend._tomltext import read_toml
from softbend._validation import must_be
from softbend.actuators import PRESSURE_UNITS, Actuator, ActuatorError
from softbend.design import DESIGN_LIMITS, PARAMETERS
from softbend.design_search.space import PAPER_B, SearchSpace, aligned, space_of
from softbend.errors import DatasetError, InputError, keyed
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
    "build_ranges",
    "load_specifications",
    "parse_assignment",
    "parse_objectives",
    "parse_range",
    "parse_span",
    "parse_value",
    "pressure_range",
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
                _check_pressure(point[0], "points", self.unit, "a point's pressure ")
                _check_angle(point[1], "points", "a point's angle ")
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
        _check_pressure(self.pressure_mpa, "pressure_mpa", self.unit)
        if self.kind != "max_angle":
            _check_angle(self.angle_deg, "angle_deg")

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

    ``name`` is one of :data:`OBJECTIVES` (paper B's actuator); for another
    actuator's search it is one of :attr:`SearchSpace.objectives
    <softbend.design_search.space.SearchSpace.objectives>` and ``unit`` its
    unit (:func:`parse_objectives` and :class:`Specification` set it).
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
        if self.sense not in ("min", "max"):
            raise ValueError(
                f"The sense of an objective must be 'min' or 'max'. Got {self.sense!r} instead."
            )

    def __str__(self) -> str:
        unit = OBJECTIVES[self.name] if self.unit is None else self.unit
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
        :data:`DEFAULT_STEPS` for paper B's actuator; for another,
        :meth:`SearchSpace.default_step
        <softbend.design_search.space.SearchSpace.default_step>`: a continuous
        parameter's declared resolution, else a round step of about a hundredth
        of its range, and 1 for an integer one; 0: continuous).
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
        if not space.paper_b:
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
        if space.paper_b:
            object.__setattr__(self, "steps", {**DEFAULT_STEPS, **steps})
            return
        for key, value in steps.items():
            if key not in space.names:
                raise ValueError(
                    f"The steps of a specification must name parameters among "
                    f"{space.listing()}. Got {key!r}."
                )
            if isinstance(value, bool) or not isinstance(value, int | float):
                raise ValueError(f"The step of {key!r} must be a number. Got {value!r}.")
            problem = None if STEP.contains(value) else "must be finite and >= 0"
            problem = problem or space.step_problem(key, float(value))
            if problem is not None:
                raise ValueError(f"The step of {key!r} ({value:g}) {problem}.")
        filled = {n: float(steps.get(n, space.default_step(n))) for n in space.names}
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

        For another actuator than paper B's, a parameter left out takes its
        training range within the range its description declares; an integer or
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
        if not self.space.paper_b:
            return self._resolved_other(training_ranges, allow_extrapolation)
        out = {}
        for name in NAMES:
            trained = None
            if training_ranges is not None and COLUMNS[name] in training_ranges:
                low, high = (float(v) for v in training_ranges[COLUMNS[name]])
                trained = (low, high)
            given = self.ranges.get(name)
            if given is None:
                if trained is None:
                    raise InputError(
                        f"must give the parameter {name!r} a range ({name}=LOW:HIGH, or fix "
                        f"{name}=VALUE): the model records no training ranges",
                        key="ranges",
                    )
                given = ParameterRange(trained[0], trained[1], float(self.steps[name]))
            for end in (given.low, given.high):
                problem = _design_value_problem(name, end)
                if problem is not None:
                    raise ValueError(
                        f"The range of {name!r} ({given.low:g}:{given.high:g} {UNITS[name]}) "
                        f"{problem}."
                    )
            outside = trained is not None and (
                given.low < trained[0] - 1e-9 or given.high > trained[1] + 1e-9
            )
            if outside and trained is not None and not allow_extrapolation:
                raise InputError(
                    f"must be set for the range of {name!r} ({given.low:g}:{given.high:g} "
                    f"{UNITS[name]}), which leaves the model's training range "
                    f"[{trained[0]:g}, {trained[1]:g}] (the answers outside are then "
                    "flagged); or narrow the range",
                    key="allow_extrapolation",
                )
            if not given.fixed and given.step > 0 and given.count() < 1:
                raise ValueError(f"The range of {name!r} holds no value on its step.")
            if not given.fixed and given.step > given.high - given.low + 1e-9:
                raise ValueError(
                    f"The resolution of {name!r} ({given.step:g} {UNITS[name]}) is wider than "
                    f"its range {given.low:g}:{given.high:g}; fix it or refine the resolution."
                )
            out[name] = given
        return out

    def _resolved_other(
        self, training: Mapping[str, Sequence[float]] | None, allow_extrapolation: bool
    ) -> dict[str, ParameterRange]:
        """:meth:`resolved` for another actuator than paper B's."""
        space = self.space
        out: dict[str, ParameterRange] = {}
        for name in space.names:
            p = space.parameter(name)
            unit = f" {p.unit}" if p.unit else ""
            trained = None
            if training is not None and p.name in training:
                trained = tuple(float(v) for v in training[p.name])
            given = self.ranges.get(name)
            if given is None:
                low, high = p.low, p.high
                if trained is not None:
                    low, high = max(low, trained[0]), min(high, trained[1])
                if not (math.isfinite(low) and math.isfinite(high)):
                    raise InputError(
                        f"must give the parameter {name!r} a range ({name}=LOW:HIGH, or fix "
                        f"{name}=VALUE): the model records no training range of it and the "
                        f"actuator {space.actuator.name} declares none",
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
                given = ParameterRange(low, high, float(self.steps[name]))
            else:
                for end in (given.low, given.high):
                    problem = space.value_problem(name, end)
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
        if step > 0:
            problem = space.step_problem(name, step)
            if problem is not None:
                raise ValueError(f"The step of {name!r} ({step:g}{unit}) {problem}.")
        else:
            resolution = space.parameter(name).resolution
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

        def value(n: str, code: float) -> str:
            return f"{code:g}" if space.paper_b else space.shown(n, code)

        fixed = [f"{n} = {value(n, r.low)}" for n, r in self.ranges.items() if r.fixed]
        ranged = [f"{n} in {r.low:g}:{r.high:g}" for n, r in self.ranges.items() if not r.fixed]
        parts = [self.target.describe(), *fixed, *ranged, ", ".join(map(str, self.objectives))]
        return "; ".join(parts)


def _design_value_problem(name: str, value: float) -> str | None:
    """Why ``value`` cannot be the parameter ``name`` of a design (its limits), or None."""
    low, high, low_inclusive = DESIGN_LIMITS[name]
    allowed = Range(low, high, UNITS[name], low_inclusive=low_inclusive)
    if allowed.contains(value):
        return None
    return f"leaves the values a design may take, {allowed.describe()}"


def pressure_range(unit: str = "MPa") -> Range:
    """:data:`PRESSURE` in ``unit`` (``(0, 1000] kPa``)."""
    if unit == "MPa":
        return PRESSURE
    high = float(f"{PRESSURE.high / PRESSURE_UNITS[unit]:.6g}")
    return Range(0.0, high, unit, "a gauge pressure of at most 1 MPa", low_inclusive=False)


def _check_pressure(value: object, key: str | None, unit: str = "MPa", subject: str = "") -> None:
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


def _check_angle(value: object, key: str | None, subject: str = "") -> None:
    """Refuse a value that is not an angle of :data:`ANGLE` (keyed ``key``)."""
    if isinstance(value, bool) or not isinstance(value, int | float) or not math.isfinite(value):
        raise InputError(subject + must_be("a number of degrees", value), key=key)
    if not ANGLE.contains(value):
        raise InputError(subject + must_be(f"in {ANGLE.describe()} ({ANGLE.why})", value), key=key)


def parse_assignment(text: str) -> tuple[str, float]:
    """``("phi", 10.0)`` from ``"phi=10"`` (or ``"phi_deg=10"``); one clear line for
    anything else (keyed by the parameter where one is named). Paper B's parameters;
    :func:`parse_value` reads another actuator's."""
    name, sep, value = text.partition("=")
    name = PAPER_B.canonical(name.strip()) or name.strip()
    if not sep or name not in NAMES:
        raise InputError(must_be(f"NAME=VALUE with NAME among {', '.join(NAMES)}", text))
    try:
        number = float(value)
    except ValueError:
        raise InputError(must_be(f"a number ({UNITS[name]})", value), key=name) from None
    if not math.isfinite(number):
        raise InputError(must_be("finite", value), key=name)
    return name, number


def parse_range(text: str) -> tuple[str, float, float]:
    """``("t", 3.0, 4.0)`` from ``"t=3:4"``; one clear line for anything else (keyed
    by the parameter where one is named). Paper B's parameters; :func:`parse_span` reads
    another actuator's."""
    name, sep, value = text.partition("=")
    name = PAPER_B.canonical(name.strip()) or name.strip()
    low, colon, high = value.partition(":")
    if not sep or name not in NAMES or not colon:
        raise InputError(must_be(f"NAME=LOW:HIGH with NAME among {', '.join(NAMES)}", text))
    try:
        a, b = float(low), float(high)
    except ValueError:
        raise InputError(must_be(f"LOW:HIGH, numbers ({UNITS[name]})", value), key=name) from None
    if not (math.isfinite(a) and math.isfinite(b)) or a > b:
        raise InputError(must_be("finite LOW <= HIGH", value), key=name)
    return name, a, b


def _named(space: SearchSpace, name: str, text: str) -> str:
    """The parameter ``name`` of ``space``, or one line listing them."""
    key = space.canonical(name)
    if key is None:
        raise InputError(
            f"names {name!r}, which is not a design parameter of the model's actuator "
            f"{space.actuator.name}; its parameters are {space.listing()}; got {text!r}",
        )
    return key


def _unit_of(space: SearchSpace, name: str) -> str:
    unit = space.unit(name)
    return f" {unit}" if unit else ""


def parse_value(space: SearchSpace, text: object) -> tuple[str, float]:
    """``("layer", 1.0)`` from ``"layer=paper"``: a parameter of another actuator and the code
    of its value (a level's index), checked against its description; one line (keyed
    by the parameter where one is named) otherwise."""
    name, sep, value = str(text).partition("=")
    name, value = name.strip(), value.strip()
    if not sep or not name:
        raise InputError(must_be(f"NAME=VALUE with NAME among {space.listing()}", text))
    key = _named(space, name, str(text))
    return key, _code_of(space, key, value)


def _code_of(space: SearchSpace, key: str, value: object) -> float:
    """The code of ``value`` (a level, a whole number, a number) for ``key``, checked.

    Raises
    ------
    InputError
        Keyed ``key`` (``layer: must be one of its levels ...``).
    """
    p = space.parameter(key)
    if p.kind == "categorical":
        try:
            code = p.encode(value)
        except ActuatorError:
            levels = ", ".join(map(str, p.levels or ()))
            raise InputError(must_be(f"one of its levels {levels}", value), key=key) from None
        return code
    if isinstance(value, bool):
        value = "true" if value else "false"
    try:
        code = float(value)  # type: ignore[arg-type]  # anything float() reads; else refused
    except (TypeError, ValueError, OverflowError):
        unit = space.unit(key)
        kind = "a whole number" if p.kind == "integer" else "a number"
        raise InputError(must_be(kind + (f" ({unit})" if unit else ""), value), key=key) from None
    problem = space.value_problem(key, code)
    if problem is None and p.kind == "continuous" and p.resolution is not None:
        ratio = code / p.resolution
        if abs(ratio - round(ratio)) > 1e-6:
            problem = (
                f"is not a multiple of the resolution {p.resolution:g}{_unit_of(space, key)} "
                f"the actuator {space.actuator.name} declares"
            )
    if problem is not None:
        raise InputError(f"{value} {problem}", key=key)
    return code


def parse_span(space: SearchSpace, text: str) -> tuple[str, float, float]:
    """``("wall_mm", 1.0, 2.0)`` from ``"wall_mm=1:2"``: a range of another actuator's
    parameter inside its description (whole ends for an integer one); a categorical one
    is refused (fix one level, or leave it out for every level). Errors are keyed by the
    parameter where one is named."""
    name, sep, value = text.partition("=")
    low, colon, high = value.partition(":")
    if not sep or not colon or not name.strip():
        raise InputError(must_be(f"NAME=LOW:HIGH with NAME among {space.listing()}", text))
    key = _named(space, name.strip(), text)
    p = space.parameter(key)
    if p.kind == "categorical":
        levels = list(map(str, p.levels or ()))
        raise InputError(
            f"cannot span the categorical parameter {key!r}: fix one level "
            f"({key}={levels[0]}) or leave it out to search every level ({', '.join(levels)})",
            key=key,
        )
    try:
        a, b = float(low), float(high)
    except ValueError:
        raise InputError(must_be("LOW:HIGH, numbers", value), key=key) from None
    if not (math.isfinite(a) and math.isfinite(b)) or a > b:
        raise InputError(must_be("finite LOW <= HIGH", value), key=key)
    for end in (a, b):
        problem = space.value_problem(key, end)
        if problem is not None:
            raise InputError(f"{end:g} {problem}; got {value!r}", key=key)
    return key, a, b


def parse_objectives(
    minimize: Sequence[str], maximize: Sequence[str], space: SearchSpace | None = None
) -> tuple[Objective, ...]:
    """Objectives from comma-separated names to minimise and to maximise, in order given
    (of ``space``'s objectives; default paper B's, :data:`OBJECTIVES`)."""
    space = PAPER_B if space is None else space
    allowed = OBJECTIVES if space.paper_b else space.objectives
    out = []
    for sense, texts in (("min", minimize), ("max", maximize)):
        for text in texts:
            for name in (n.strip() for n in text.split(",")):
                if name:
                    name = space.canonical(name) or name
                    if name not in allowed:
                        raise InputError(
                            must_be(f"objectives among {', '.join(allowed)}", name),
                            key="minimize" if sense == "min" else "maximize",
                        )
                    unit = None if space.paper_b else allowed[name]
                    out.append(Objective(name, sense, unit))
    return tuple(out)


def build_ranges(
    fixes: Sequence[str] = (),
    ranges: Sequence[str] = (),
    steps: Sequence[str] = (),
    *,
    step: float | None = None,
    space: SearchSpace | None = None,
) -> tuple[dict[str, ParameterRange], dict[str, float]]:
    """Ranges and steps from ``--fix NAME=V``, ``--range NAME=LOW:HIGH``, ``--resolution``.

    ``steps`` are ``NAME=STEP`` per parameter; ``step`` is the step of every
    parameter not named there (None: :data:`DEFAULT_STEPS`). A parameter both
    fixed and ranged, or named twice, is refused. Returns the ranges given and
    the step of every parameter (for those left to their training range).

    With the ``space`` of another actuator than paper B's, the names are its
    parameters: ``--fix`` takes a level by name, a whole number or a number
    (on the resolution the description declares), ``--range`` refuses a
    categorical parameter and takes whole ends for an integer one, and
    ``step`` is the step of the continuous parameters only (the others stay on
    their whole numbers and levels; by default a continuous parameter's
    resolution, else :meth:`SearchSpace.grid_steps
    <softbend.design_search.space.SearchSpace.grid_steps>`' round step).
    """
    if space is not None and not space.paper_b:
        return _build_other(space, fixes, ranges, steps, step)
    if step is not None and not STEP.contains(step):
        raise InputError(
            must_be(f"a finite number >= 0 (mm and deg; {STEP.why})", step), key="step"
        )
    per_step = dict(DEFAULT_STEPS) if step is None else dict.fromkeys(NAMES, float(step))
    for text in steps:
        with keyed("steps"):
            name, value = parse_assignment(text)
        if value < 0:
            raise InputError(f"{name} {must_be('>= 0', value)}", key="steps")
        per_step[name] = value
    given: list[tuple[str, ParameterRange, str]] = []
    for text in fixes:
        with keyed("fixes"):
            name, value = parse_assignment(text)
            _check_design_values(name, (value,), text)
        given.append((name, ParameterRange(value, value, 0.0), "fixes"))
    for text in ranges:
        with keyed("ranges"):
            name, low, high = parse_range(text)
            _check_design_values(name, (low, high), text)
        given.append((name, ParameterRange(low, high, per_step[name]), "ranges"))
    return _once(given), per_step


def _once(given: Sequence[tuple[str, ParameterRange, str]]) -> dict[str, ParameterRange]:
    """The ranges by parameter, each given once (by ``fixes`` or ``ranges``).

    Each entry is ``(name, range, key)``; a name given twice is refused keyed by the
    option of its second mention (``fixes`` or ``ranges``).
    """
    out: dict[str, ParameterRange] = {}
    for name, chosen, key in given:
        if name in out:
            raise InputError(f"{name!r} is given twice (fixed or ranged); give it once", key=key)
        out[name] = chosen
    return out


def _build_other(
    space: SearchSpace,
    fixes: Sequence[str],
    ranges: Sequence[str],
    steps: Sequence[str],
    step: float | None,
) -> tuple[dict[str, ParameterRange], dict[str, float]]:
    """:func:`build_ranges` for another actuator than paper B's."""
    if step is not None and not STEP.contains(step):
        raise InputError(
            must_be(
                f"a finite number >= 0 (in each continuous parameter's unit; {STEP.why})", step
            ),
            key="step",
        )
    per_step = {n: space.default_step(n) for n in space.names}
    if step is not None:
        for name in space.names:
            if space.kind(name) == "continuous":
                problem = space.step_problem(name, float(step))
                if problem is not None:
                    raise InputError(f"{step:g} of {name!r} {problem}", key="step")
                per_step[name] = float(step)
    for text in steps:
        name, sep, value = text.partition("=")
        if not sep:
            raise InputError(
                must_be(f"a number or NAME=STEP with NAME among {space.listing()}", text),
                key="steps",
            )
        with keyed("steps"):
            key = _named(space, name.strip(), text)
        try:
            number = float(value)
        except ValueError:
            raise InputError(f"{key} {must_be('a number', value)}", key="steps") from None
        if not STEP.contains(number):
            raise InputError(f"{key} {must_be('a finite number >= 0', value)}", key="steps")
        problem = space.step_problem(key, number)
        if problem is not None:
            raise InputError(f"{key} ({value.strip()}) {problem}", key="steps")
        per_step[key] = number
    given: list[tuple[str, ParameterRange, str]] = []
    for text in fixes:
        with keyed("fixes"):
            key, code = parse_value(space, text)
        given.append((key, ParameterRange(code, code, 0.0), "fixes"))
    for text in ranges:
        with keyed("ranges"):
            key, low, high = parse_span(space, text)
        given.append((key, ParameterRange(low, high, per_step[key]), "ranges"))
    return _once(given), {n: v for n, v in per_step.items() if space.kind(n) != "categorical"}


def _check_design_values(name: str, values: Sequence[float], text: str) -> None:
    """Refuse a value (of ``text``) that a design's parameter ``name`` cannot take."""
    for value in values:
        problem = _design_value_problem(name, value)
        if problem is not None:
            raise InputError(f"{problem}; got {text!r}", key=name)


def load_specifications(
    path: str | os.PathLike[str],
    *,
    reserved: Collection[str] = (),
    actuator: Actuator | None = None,
) -> list[Specification]:
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
    for a curve (each pressure once).

    For another actuator than paper B's (``actuator``, the model's), the
    tables name its parameters and give its pressures in its unit::

        [[spec]]
        angle = 90.0
        at = 30.0                 # kPa, the model's pressure unit
        minimize = ["n_chambers"]
        fix = {layer = "paper"}   # a level by name
        range = {wall_mm = [1.0, 2.0]}
        resolution = {wall_mm = 0.1}

    ``resolution`` as one number is then the step of its continuous
    parameters; an integer one steps by whole numbers, a categorical one
    takes every level unless fixed (a ``range`` of it is refused). The file is read by
    :func:`softbend._tomltext.read_toml` (size, UTF-8 and nesting limits), and
    every key of every table is checked, with its type and range, before any
    search starts. Each ``name`` (default ``specN``) names the folder of that
    spec's results, so it must be a plain name of a folder
    (:func:`softbend._names.output_name`), unlike the other names ignoring case,
    and not one of ``reserved``.

    Parameters
    ----------
    path : path
        The TOML file.
    reserved : collection of str
        Names the caller writes beside the specs' folders (``search.json``).
    actuator : Actuator, optional
        The description of the model's actuator (None: paper B's).

    Returns
    -------
    list of Specification
        One per ``[[spec]]``, in the file's order.

    Raises
    ------
    FileNotFoundError
        No such file.
    DatasetError
        A file over the size limit, not UTF-8, not TOML, nested too deep, with
        no ``[[spec]]`` or more than :data:`SPECS`, or a table that is not a
        specification: one line naming the file, the ``[[spec]]`` number, the
        key, what was expected and what was found.
    """
    source = str(os.fspath(path))
    data = read_toml(path, source, DatasetError)
    others = sorted(k for k in data if k != "spec")
    if others:
        raise DatasetError(
            f"{source}: unknown key(s) {', '.join(map(repr, others))} at the top; a "
            "specification file holds [[spec]] tables only."
        )
    tables = data.get("spec")
    if not isinstance(tables, list) or not tables:
        raise DatasetError(
            f"{source}: expected at least one [[spec]] table; found "
            f"{'none' if tables is None else _found(tables)}."
        )
    if not SPECS.contains(len(tables)):
        raise DatasetError(
            f"{source}: holds {len(tables):,} [[spec]] tables, more than {SPECS.high:g} "
            f"({SPECS.why}); split it into several files."
        )
    specs: list[Specification] = []
    names: list[str] = []
    for i, table in enumerate(tables, start=1):
        where = f"{source}, [[spec]] {i}"
        if not isinstance(table, dict):
            raise DatasetError(f"{where}: expected a table; found {_found(table)}.")
        spec = _SpecTable(table, where, space_of(actuator)).specification(f"spec{i}")
        try:
            output_name(spec.name, reserved=reserved, taken=names)
        except InputError as exc:
            raise DatasetError(f"{where} 'name': {exc.detail}") from None
        names.append(spec.name)
        specs.append(spec)
    return specs


#: The keys of a ``[[spec]]`` table.
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

#: The keys that each give a kind of target; a table gives one.
_TARGET_KEYS = ("at", "max_pressure", "max_angle_at", "curve")

_SHORT = reprlib.Repr()
_SHORT.maxstring = 40
_SHORT.maxother = 40
_SHORT.maxlist = 4
_SHORT.maxdict = 4
_SHORT.maxlevel = 3
_SHORT.maxlong = 40


def _found(value: object) -> str:
    """A value of a TOML file, short, with its kind."""
    if isinstance(value, bool):
        return f"{'true' if value else 'false'} (a boolean)"
    if isinstance(value, str):
        return f"the text {_SHORT.repr(value)}"
    if isinstance(value, int | float):
        return _SHORT.repr(value)
    if isinstance(value, list):
        return f"an array of {len(value)} {_SHORT.repr(value)}"
    if isinstance(value, dict):
        return f"a table {_SHORT.repr(value)}"
    return f"{type(value).__name__} {_SHORT.repr(value)}"


def _is_number(value: object) -> TypeGuard[int | float]:
    """Whether ``value`` is a number of a TOML file a float can hold."""
    if isinstance(value, bool) or not isinstance(value, int | float):
        return False
    try:
        float(value)
    except OverflowError:  # an integer of hundreds of digits
        return False
    return True


class _SpecTable:
    """One ``[[spec]]`` table read key by key; every error names ``where`` and the key."""

    def __init__(self, table: dict[str, Any], where: str, space: SearchSpace = PAPER_B) -> None:
        self.table = table
        self.where = where
        self.space = space

    def fail(self, key: str, expected: str, found: object) -> DatasetError:
        """The error of ``key``: what was expected and what was found."""
        return DatasetError(f"{self.where} '{key}': expected {expected}; found {_found(found)}.")

    def number(self, key: str, allowed: Range, what: str, value: object = None) -> float:
        """The number at ``key`` (or ``value``) in ``allowed``."""
        value = self.table[key] if value is None else value
        expected = f"{what} in {allowed.describe()}" + (f" ({allowed.why})" if allowed.why else "")
        if not _is_number(value) or not allowed.contains(value):
            raise self.fail(key, expected, value)
        return float(value)

    def per_parameter(self, key: str, what: str) -> dict[str, Any]:
        """The table at ``key`` whose keys are parameter names (each once, by its name)."""
        names = self.space.listing()
        value = self.table.get(key, {})
        if not isinstance(value, dict):
            raise self.fail(key, f"a table of {what} by parameter ({names})", value)
        unknown = [k for k in value if self.space.canonical(k) is None]
        if unknown:
            raise DatasetError(
                f"{self.where} '{key}': expected parameters among {names}; found "
                f"{', '.join(map(repr, unknown))}."
            )
        out: dict[str, Any] = {}
        for k, v in value.items():
            name = self.space.canonical(k)
            assert name is not None  # checked above
            if name in out:
                raise DatasetError(f"{self.where} '{key}': gives {name!r} twice ({k!r}).")
            out[name] = v
        return out

    def design_number(self, key: str, name: str, value: object) -> float:
        """``value`` as a value of the parameter ``name`` of a design (its code)."""
        if not self.space.paper_b:
            if self.space.kind(name) != "categorical" and not _is_number(value):
                raise self.fail(f"{key}.{name}", "a number", value)
            try:
                return _code_of(self.space, name, value)
            except InputError as exc:
                raise DatasetError(f"{self.where} '{key}.{name}': {exc.detail}") from None
        low, high, low_inclusive = DESIGN_LIMITS[name]
        allowed = Range(low, high, UNITS[name], "the values a design may take", low_inclusive)
        return self.number(f"{key}.{name}", allowed, "a number", value)

    def target(self) -> Target:
        """The table's target, from exactly one of :data:`_TARGET_KEYS`."""
        table = self.table
        unit = self.space.pressure_unit
        kinds = [k for k in _TARGET_KEYS if k in table]
        if len(kinds) != 1:
            found = " and ".join(map(repr, kinds)) if kinds else "none of them"
            raise DatasetError(
                f"{self.where}: expected exactly one target key, 'at', 'max_pressure', "
                f"'max_angle_at' or 'curve'; found {found}."
            )
        kind = kinds[0]
        tolerance = self.number("tolerance", TOLERANCE, "degrees") if "tolerance" in table else 3.0
        if kind in ("max_angle_at", "curve") and "angle" in table:
            raise DatasetError(
                f"{self.where} 'angle': has no meaning with '{kind}' (the "
                f"{'curve gives its angles' if kind == 'curve' else 'angle is maximised'}); "
                "leave it out."
            )
        if kind == "curve":
            return Target("curve", tolerance_deg=tolerance, points=self.curve(), unit=unit)
        pressure = self.number(kind, pressure_range(unit), "a pressure")
        if kind == "max_angle_at":
            return Target("max_angle", pressure_mpa=pressure, tolerance_deg=tolerance, unit=unit)
        if "angle" not in table:
            raise DatasetError(f"{self.where} 'angle': expected with '{kind}'; found none.")
        angle = self.number("angle", ANGLE, "degrees")
        return Target(
            "angle_at" if kind == "at" else "pressure_for",
            angle_deg=angle,
            pressure_mpa=pressure,
            tolerance_deg=tolerance,
            unit=unit,
        )

    def curve(self) -> tuple[tuple[float, float], ...]:
        """The points of ``curve``: [[pressure, angle], ...], each pressure once."""
        value = self.table["curve"]
        unit = self.space.pressure_unit
        expected = (
            f"an array of {CURVE_POINTS.low:g} to {CURVE_POINTS.high:g} [pressure {unit}, "
            "angle deg] pairs"
        )
        if not isinstance(value, list) or not CURVE_POINTS.contains(len(value)):
            raise self.fail("curve", expected, value)
        points: list[tuple[float, float]] = []
        for k, point in enumerate(value, start=1):
            key = f"curve[{k}]"
            if not isinstance(point, list) or len(point) != 2:
                raise self.fail(key, f"a pair [pressure {unit}, angle deg]", point)
            pressure = self.number(key, pressure_range(unit), "a pressure first", point[0])
            angle = self.number(key, ANGLE, "an angle second", point[1])
            if any(pressure == p for p, _ in points):
                raise DatasetError(
                    f"{self.where} '{key}': gives {pressure:g} {unit} a second time; a curve "
                    "gives each pressure once (one angle at each)."
                )
            points.append((pressure, angle))
        return tuple(points)

    def objectives(self) -> tuple[Objective, ...]:
        """``minimize`` and ``maximize``: names of :data:`OBJECTIVES` (another actuator: of
        its search's objectives), an array or one text."""
        space = self.space
        allowed = OBJECTIVES if space.paper_b else space.objectives
        out = []
        for key, sense in (("minimize", "min"), ("maximize", "max")):
            value = self.table.get(key, [])
            items = value.split(",") if isinstance(value, str) else value
            expected = f"an array of objectives among {', '.join(allowed)}"
            if not isinstance(items, list):
                raise self.fail(key, expected, value)
            for item in items:
                name = space.canonical(item.strip()) if isinstance(item, str) else None
                name = name or (item.strip() if isinstance(item, str) else None)
                if name not in allowed:
                    raise self.fail(key, expected, item)
                assert name is not None
                out.append(Objective(name, sense, None if space.paper_b else allowed[name]))
        return tuple(out)

    def steps(self) -> dict[str, float]:
        """``resolution``: one step for every parameter, or a table by parameter."""
        if not self.space.paper_b:
            return self._other_steps()
        value = self.table.get("resolution")
        what = "a step of the mould (mm, deg for phi)"
        if value is None:
            return dict(DEFAULT_STEPS)
        if isinstance(value, dict):
            steps = dict(DEFAULT_STEPS)
            for name, step in self.per_parameter("resolution", "steps").items():
                steps[name] = self.number(f"resolution.{name}", STEP, what, step)
            return steps
        if not _is_number(value):
            raise self.fail("resolution", f"{what}, or a table of steps by parameter", value)
        return dict.fromkeys(NAMES, self.number("resolution", STEP, what))

    def _other_steps(self) -> dict[str, float]:
        """``resolution`` of another actuator: one step of every continuous parameter, or a
        table by parameter; each checked against its kind and declared resolution."""
        space = self.space
        value = self.table.get("resolution")
        what = "a step (each parameter's unit; 0 searches continuously)"
        steps = {n: space.default_step(n) for n in space.names if space.kind(n) != "categorical"}
        if value is None:
            return steps
        if isinstance(value, dict):
            given = {
                name: (f"resolution.{name}", self.number(f"resolution.{name}", STEP, what, step))
                for name, step in self.per_parameter("resolution", "steps").items()
            }
        elif _is_number(value):
            step = self.number("resolution", STEP, what)
            given = {n: ("resolution", step) for n in space.names if space.kind(n) == "continuous"}
        else:
            raise self.fail("resolution", f"{what}, or a table of steps by parameter", value)
        for name, (key, step) in given.items():
            problem = space.step_problem(name, step)
            if problem is not None:
                raise DatasetError(
                    f"{self.where} '{key}': the step {step:g} of {name!r} {problem}."
                )
            steps[name] = step
        return steps

    def ranges(self, steps: Mapping[str, float]) -> dict[str, ParameterRange]:
        """``fix`` (a value by parameter) and ``range`` ([low, high] by parameter)."""
        space = self.space
        out: dict[str, ParameterRange] = {}
        for name, value in self.per_parameter("fix", "values").items():
            fixed = self.design_number("fix", name, value)
            out[name] = ParameterRange(fixed, fixed, 0.0)
        for name, value in self.per_parameter("range", "[low, high] pairs").items():
            key = f"range.{name}"
            unit = UNITS[name] if space.paper_b else space.unit(name)
            if not space.paper_b and space.kind(name) == "categorical":
                levels = ", ".join(map(str, space.parameter(name).levels or ()))
                raise DatasetError(
                    f"{self.where} '{key}': a categorical parameter takes no range; fix one "
                    f"level ('fix') or leave it out to search every level ({levels})."
                )
            if not isinstance(value, list) or len(value) != 2:
                numbers = f"two numbers of {unit}" if unit else "two numbers"
                raise self.fail(key, f"[low, high], {numbers}", value)
            low, high = (self.design_number("range", name, v) for v in value)
            if low > high:
                raise self.fail(key, "[low, high] with low <= high", value)
            if name in out:
                raise DatasetError(
                    f"{self.where} 'range.{name}': {name!r} is also in 'fix'; give it once."
                )
            out[name] = ParameterRange(low, high, float(steps[name]))
        return out

    def specification(self, default_name: str) -> Specification:
        """The table as a :class:`Specification` (its name not yet checked as a path)."""
        table = self.table
        unknown = [k for k in table if k not in _TABLE_KEYS]
        if unknown:
            raise DatasetError(
                f"{self.where}: unknown key(s) {', '.join(map(repr, unknown))}; the keys are "
                f"{', '.join(_TABLE_KEYS)}."
            )
        name = table.get("name", default_name)
        if not isinstance(name, str):
            raise self.fail("name", "a text, the name of the spec's folder of results", name)
        try:
            target = self.target()
        except ValueError as exc:
            if isinstance(exc, DatasetError):
                raise
            raise DatasetError(f"{self.where}: {exc}") from None
        steps = self.steps()
        ranges = self.ranges(steps)
        objectives = self.objectives()
        margin = 0.0
        if "margin" in table:
            allowed = Range(0.0, target.tolerance_deg, "deg", "below the tolerance", True, False)
            margin = self.number("margin", allowed, "degrees kept from the tolerance")
        actuator = None if self.space.paper_b else self.space.actuator
        try:
            return Specification(target, ranges, objectives, name, steps, margin, actuator)
        except ValueError as exc:
            keys = [k for k in ("minimize", "maximize") if k in table]
            about = f" '{' and '.join(keys)}'" if keys and "objective" in str(exc) else ""
            raise DatasetError(f"{self.where}{about}: {exc}") from None


def target_from_options(
    *,
    angle: float | None = None,
    at: float | None = None,
    max_pressure: float | None = None,
    max_angle_at: float | None = None,
    curve: str | None = None,
    tolerance: float = 3.0,
    unit: str = "MPa",
) -> Target:
    """The :class:`Target` a command line names (``--angle`` with ``--at`` or
    ``--max-pressure``, ``--max-angle-at``, or ``--curve P:ANGLE,...``), its
    pressures in ``unit`` (the model's pressure unit).

    Raises
    ------
    ValueError
        None or several kinds of target, a missing ``--angle``, or a bad curve.
    """
    given = [
        name
        for name, value in (
            ("at", at),
            ("max_pressure", max_pressure),
            ("max_angle_at", max_angle_at),
            ("curve", curve),
        )
        if value is not None
    ]
    if len(given) != 1:
        raise InputError(
            "The target must be one of angle A at P, angle A max_pressure P, max_angle_at P "
            f"or curve P:A,P:A,...; got {', '.join(given) or 'none'}",
            key=given[1] if given else None,
        )
    if not (_is_number(tolerance) and TOLERANCE.contains(tolerance)):
        raise InputError(
            must_be(f"in {TOLERANCE.describe()} ({TOLERANCE.why})", tolerance), key="tolerance"
        )
    for key, value in (("at", at), ("max_pressure", max_pressure), ("max_angle_at", max_angle_at)):
        if value is not None:
            _check_pressure(value, key, unit)
    if angle is not None:
        _check_angle(angle, "angle")
    if curve is not None:
        if angle is not None:
            raise InputError(
                "has no meaning with curve (the curve gives its angles); leave it out", key="angle"
            )
        with keyed("curve"):
            points = _curve_points(curve, unit)
        return Target("curve", tolerance_deg=tolerance, points=points, unit=unit)
    if max_angle_at is not None:
        if angle is not None:
            raise InputError("has no meaning with max_angle_at; leave it out", key="angle")
        return Target("max_angle", pressure_mpa=max_angle_at, tolerance_deg=tolerance, unit=unit)
    if angle is None:
        raise InputError(f"is needed with {given[0]} (degrees)", key="angle")
    kind, pressure = ("angle_at", at) if at is not None else ("pressure_for", max_pressure)
    assert pressure is not None  # exactly one of at and max_pressure, checked above
    return Target(
        kind, angle_deg=angle, pressure_mpa=float(pressure), tolerance_deg=tolerance, unit=unit
    )


def _curve_points(text: str, unit: str = "MPa") -> tuple[tuple[float, float], ...]:
    """The points of ``P:ANGLE,...``: each pressure once, each number in its range."""
    items = [x.strip() for x in text.split(",") if x.strip()]
    if not CURVE_POINTS.contains(len(items)):
        raise InputError(
            f"must give {CURVE_POINTS.low:g} to {CURVE_POINTS.high:g} points PRESSURE:ANGLE "
            f"({CURVE_POINTS.why}); got {len(items):,}",
        )
    points: list[tuple[float, float]] = []
    seen: dict[float, str] = {}
    for item in items:
        p, colon, a = item.partition(":")
        try:
            pressure, angle = float(p), float(a)
        except ValueError:
            example = "0.05:40,0.1:95" if unit == "MPa" else "10:40,20:95"
            raise InputError(
                must_be(f"PRESSURE:ANGLE pairs ({unit}:deg), e.g. {example}", item)
            ) from None
        if not colon:
            raise InputError(f"point {item!r} lacks ':ANGLE'")
        _check_pressure(pressure, None, unit, f"point {item!r}: ")
        _check_angle(angle, None, f"point {item!r}: ")
        if pressure in seen:
            raise InputError(
                f"gives {pressure:g} {unit} twice ({seen[pressure]!r} and {item!r}); a curve "
                "gives each pressure once (one angle at each)",
            )
        seen[pressure] = item
        points.append((pressure, angle))
    return tuple(points)
