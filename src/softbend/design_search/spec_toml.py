"""Specifications from a TOML file: one ``[[spec]]`` table per specification.

:func:`load_specifications` reads the file with
:func:`softbend._tomltext.read_toml` (size, UTF-8 and nesting limits) and
checks every key of every table, with its type and range, before any search
starts; a ``[[spec]]`` name becomes a folder of the output only through
:func:`softbend._names.output_name`.
"""

from __future__ import annotations

import os
import reprlib
from collections.abc import Collection, Mapping
from typing import Any

from softbend._names import output_name
from softbend._tomltext import read_toml
from softbend.actuators import Actuator
from softbend.design_search.space import PAPER_B, SearchSpace, space_of
from softbend.design_search.spec import (
    ANGLE,
    CURVE_POINTS,
    SPECS,
    STEP,
    TOLERANCE,
    Objective,
    ParameterRange,
    Specification,
    Target,
    default_step,
    is_number,
    pressure_range,
    step_problem,
)
from softbend.design_search.spec_text import code_of
from softbend.errors import DatasetError, InputError
from softbend.parameters import Range

__all__ = ["load_specifications"]


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

    For another actuator (``actuator``, the model's), the tables name its
    parameters and give its pressures in its unit::

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
        if not is_number(value) or not allowed.contains(value):
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
        if self.space.kind(name) != "categorical" and not is_number(value):
            raise self.fail(f"{key}.{name}", "a number", value)
        try:
            return code_of(self.space, name, value)
        except InputError as exc:
            raise DatasetError(
                f"{self.where} '{key}.{name}': {exc.detail}; found {_found(value)}."
            ) from None

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
        """``minimize`` and ``maximize``: names of the search's objectives
        (:attr:`SearchSpace.objectives <softbend.design_search.space.SearchSpace.objectives>`),
        an array or one text."""
        space = self.space
        allowed = space.objectives
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
                out.append(Objective(name, sense, allowed[name]))
        return tuple(out)

    def steps(self) -> dict[str, float]:
        """``resolution``: one step of every continuous parameter, or a table by parameter;
        each checked against its kind and declared resolution (:func:`~.spec.step_problem`)."""
        space = self.space
        value = self.table.get("resolution")
        what = "a step (each parameter's unit; 0 searches continuously)"
        steps = {n: default_step(space, n) for n in space.names if space.kind(n) != "categorical"}
        if value is None:
            return steps
        if isinstance(value, dict):
            given = {
                name: (f"resolution.{name}", self.number(f"resolution.{name}", STEP, what, step))
                for name, step in self.per_parameter("resolution", "steps").items()
            }
        elif is_number(value):
            step = self.number("resolution", STEP, what)
            given = {n: ("resolution", step) for n in space.names if space.kind(n) == "continuous"}
        else:
            raise self.fail("resolution", f"{what}, or a table of steps by parameter", value)
        for name, (key, step) in given.items():
            problem = step_problem(space, name, step)
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
            unit = space.unit(name)
            if space.kind(name) == "categorical":
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
        try:
            return Specification(
                target, ranges, objectives, name, steps, margin, self.space.actuator
            )
        except ValueError as exc:
            keys = [k for k in ("minimize", "maximize") if k in table]
            about = f" '{' and '.join(keys)}'" if keys and "objective" in str(exc) else ""
            raise DatasetError(f"{self.where}{about}: {exc}") from None
