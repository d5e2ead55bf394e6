"""A specification from command-line text: ``NAME=VALUE``, ``NAME=LOW:HIGH``, a target.

:func:`parse_value` and :func:`parse_span` read the parameters of any
actuator's search (paper B's by their short names or columns);
:func:`build_ranges` turns ``--fix``, ``--range`` and ``--resolution`` into
the ranges and steps of a :class:`~.spec.Specification`,
:func:`parse_objectives` ``--minimize`` and ``--maximize``, and
:func:`target_from_options` the target options. Every error is one
:class:`~softbend.errors.InputError` keyed by the option or parameter at fault.
"""

from __future__ import annotations

import math
from collections.abc import Sequence

from softbend._validation import must_be
from softbend.actuators import ActuatorError
from softbend.design_search.space import PAPER_B, SearchSpace
from softbend.design_search.spec import (
    CURVE_POINTS,
    STEP,
    TOLERANCE,
    Objective,
    ParameterRange,
    Specification,
    Target,
    check_angle,
    check_pressure,
    default_step,
    is_number,
    search_resolution,
    step_problem,
    value_problem,
)
from softbend.errors import InputError, keyed

__all__ = [
    "build_ranges",
    "code_of",
    "option_pressure",
    "parse_objectives",
    "parse_span",
    "parse_value",
    "specification_from_options",
    "target_from_options",
]


def _unit_of(space: SearchSpace, name: str) -> str:
    unit = space.unit(name)
    return f" {unit}" if unit else ""


def code_of(space: SearchSpace, key: str, value: object) -> float:
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
    problem = value_problem(space, key, code)
    resolution = search_resolution(space, key)
    if problem is None and p.kind == "continuous" and resolution is not None:
        ratio = code / resolution
        if abs(ratio - round(ratio)) > 1e-6:
            problem = (
                f"is not a multiple of the resolution {resolution:g}{_unit_of(space, key)} "
                f"the actuator {space.actuator.name} declares"
            )
    if problem is not None:
        raise InputError(_said(space, value, problem), key=key)
    return code


def _said(space: SearchSpace, value: object, problem: str) -> str:
    """A value's problem as a command line says it: after the value, except against the
    limits of a design (:attr:`Actuator.search_limits
    <softbend.actuators.Actuator.search_limits>`), whose interval the problem names."""
    return problem if space.actuator.search_limits else f"{value} {problem}"


def _named(space: SearchSpace, name: str, text: str) -> str:
    """The parameter ``name`` of ``space``, or one line listing them."""
    key = space.canonical(name)
    if key is None:
        raise InputError(
            f"names {name!r}, which is not a design parameter of the model's actuator "
            f"{space.actuator.name}: give a NAME among {space.listing()}; got {text!r}",
        )
    return key


def parse_value(space: SearchSpace, text: object) -> tuple[str, float]:
    """``("layer", 1.0)`` from ``"layer=paper"``: a parameter of ``space`` and the code
    of its value (a level's index), checked against its description; one line (keyed
    by the parameter where one is named) otherwise."""
    name, sep, value = str(text).partition("=")
    name, value = name.strip(), value.strip()
    if not sep or not name:
        raise InputError(must_be(f"NAME=VALUE with NAME among {space.listing()}", text))
    key = _named(space, name, str(text))
    return key, code_of(space, key, value)


def parse_span(space: SearchSpace, text: str) -> tuple[str, float, float]:
    """``("wall_mm", 1.0, 2.0)`` from ``"wall_mm=1:2"``: a range of ``space``'s
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
        problem = value_problem(space, key, end)
        if problem is not None:
            raise InputError(f"{_said(space, f'{end:g}', problem)}; got {value!r}", key=key)
    return key, a, b


def parse_objectives(
    minimize: Sequence[str], maximize: Sequence[str], space: SearchSpace | None = None
) -> tuple[Objective, ...]:
    """Objectives from comma-separated names to minimise and to maximise, in order given
    (of ``space``'s objectives, :attr:`SearchSpace.objectives
    <softbend.design_search.space.SearchSpace.objectives>`; default paper B's)."""
    space = PAPER_B if space is None else space
    allowed = space.objectives
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
                    out.append(Objective(name, sense, allowed[name]))
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

    The names are the parameters of ``space`` (default paper B's, by their short
    names): ``--fix`` takes a level by name, a whole number or a number (on the
    resolution the description declares), ``--range`` refuses a categorical
    parameter and takes whole ends for an integer one; ``steps`` are
    ``NAME=STEP`` per parameter, and ``step`` is the step of every continuous
    parameter not named there (the others stay on their whole numbers and
    levels; by default :func:`~.spec.default_step`: a mould's step, a continuous
    parameter's resolution, else :meth:`SearchSpace.grid_steps
    <softbend.design_search.space.SearchSpace.grid_steps>`' round step). A
    parameter both fixed and ranged, or named twice, is refused. Returns the
    ranges given and the step of every parameter that is not categorical (for
    those left to their training range).
    """
    space = PAPER_B if space is None else space
    if step is not None and not STEP.contains(step):
        raise InputError(
            must_be(
                f"a finite number >= 0 (in each continuous parameter's unit; {STEP.why})", step
            ),
            key="step",
        )
    per_step = {n: default_step(space, n) for n in space.names}
    if step is not None:
        for name in space.names:
            if space.kind(name) == "continuous":
                problem = step_problem(space, name, float(step))
                if problem is not None:
                    raise InputError(f"{step:g} of {name!r} {problem}", key="step")
                per_step[name] = float(step)
    for text in steps:
        key, number = _step_of(space, text)
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


def _step_of(space: SearchSpace, text: str) -> tuple[str, float]:
    """``("l", 1.0)`` from ``--resolution l=1``, checked (keyed ``steps``)."""
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
    problem = step_problem(space, key, number)
    if problem is not None:
        raise InputError(f"{key} ({value.strip()}) {problem}", key="steps")
    return key, number


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
    if not (is_number(tolerance) and TOLERANCE.contains(tolerance)):
        raise InputError(
            must_be(f"in {TOLERANCE.describe()} ({TOLERANCE.why})", tolerance), key="tolerance"
        )
    for key, value in (("at", at), ("max_pressure", max_pressure), ("max_angle_at", max_angle_at)):
        if value is not None:
            check_pressure(value, key, unit)
    if angle is not None:
        check_angle(angle, "angle")
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
        check_pressure(pressure, None, unit, f"point {item!r}: ")
        check_angle(angle, None, f"point {item!r}: ")
        if pressure in seen:
            raise InputError(
                f"gives {pressure:g} {unit} twice ({seen[pressure]!r} and {item!r}); a curve "
                "gives each pressure once (one angle at each)",
            )
        seen[pressure] = item
        points.append((pressure, angle))
    return tuple(points)


def option_pressure(text: str | None, unit: str, flag: str) -> float | None:
    """A pressure option in the model's ``unit``: a number, or one with a unit (``20psi``).

    A bare number (``inf`` too) is returned as given, for the target's own range check;
    ``flag`` names the option in messages (``"--at"``).
    """
    from softbend.units import parse_pressure

    if text is None:
        return None
    try:
        return float(text)
    except ValueError:
        return parse_pressure(text, unit, flag)


def _every_step(resolution: Sequence[str]) -> float | None:
    """The one bare number of ``--resolution`` (the step of every parameter), or None."""
    numbers = [s for s in resolution if "=" not in s]
    if len(numbers) > 1:
        raise InputError(f"gives a number {len(numbers)} times; give it once", key="resolution")
    try:
        return float(numbers[0]) if numbers else None
    except ValueError:
        raise InputError(must_be("a number or NAME=STEP", numbers[0]), key="resolution") from None


def specification_from_options(
    space: SearchSpace,
    *,
    angle: float | None = None,
    at: str | None = None,
    max_pressure: str | None = None,
    max_angle_at: str | None = None,
    curve: str | None = None,
    tolerance: float = 3.0,
    margin: float = 0.0,
    minimize: Sequence[str] = (),
    maximize: Sequence[str] = (),
    fixes: Sequence[str] = (),
    ranges: Sequence[str] = (),
    resolution: Sequence[str] = (),
) -> Specification:
    """The specification ``design find`` names by its options (``spec``), checked.

    Parameters
    ----------
    space : SearchSpace
        The parameters of the model's actuator: the names of ``fixes``,
        ``ranges``, ``resolution`` and the objectives, and the unit of every
        pressure.
    angle : float, optional
        ``--angle``, degrees.
    at, max_pressure, max_angle_at : str, optional
        ``--at``, ``--max-pressure``, ``--max-angle-at``: a pressure in the
        model's unit, or with a unit of its own (``20psi``).
    curve : str, optional
        ``--curve P:ANGLE,...``.
    tolerance, margin : float
        ``--tolerance`` and ``--margin``, degrees.
    minimize, maximize : sequence of str
        ``--minimize`` and ``--maximize``: comma-separated objectives.
    fixes, ranges : sequence of str
        ``--fix NAME=VALUE`` and ``--range NAME=LOW:HIGH``.
    resolution : sequence of str
        ``--resolution``: one number for every parameter and ``NAME=STEP`` each.

    Raises
    ------
    InputError
        Keyed by the option at fault.
    """
    unit = space.pressure_unit
    target = target_from_options(
        angle=angle,
        at=option_pressure(at, unit, "--at"),
        max_pressure=option_pressure(max_pressure, unit, "--max-pressure"),
        max_angle_at=option_pressure(max_angle_at, unit, "--max-angle-at"),
        curve=curve,
        tolerance=tolerance,
        unit=unit,
    )
    if not 0 <= margin < tolerance:
        raise InputError(
            must_be(
                f"in [0, {tolerance:g}) degrees (below --tolerance, the miss the "
                "surrogate's own error may take)",
                margin,
            ),
            key="margin",
        )
    given, steps = build_ranges(
        fixes,
        ranges,
        [s for s in resolution if "=" in s],
        step=_every_step(resolution),
        space=space,
    )
    objectives = parse_objectives(minimize, maximize, space)
    return Specification(target, given, objectives, "spec", steps, margin, space.actuator)
