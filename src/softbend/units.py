"""Units: conversion factors, a column's unit from its name, values with units.

One place for what a unit means, used by every reader of tables, measurements and command
options, by actuator descriptions, identification and the control rig:
``PRESSURE_UNITS`` (factor to MPa), ``SECONDS_PER_UNIT`` (factor to s),
:func:`unit_from_name` (the unit a column's name ends with, ``p1_kpa`` → ``kPa``, in one
spelling whatever the case), :func:`column_unit` (the pressure or angle unit of a name),
:func:`pressure_unit_of` (a pressure column's unit and its units per MPa),
:func:`seconds_per_unit` (a time column's), :func:`check_column_unit` (a declared unit
that disagrees with the column's name is refused, naming both) and :func:`parse_pressure`
(``"20psi"``, ``"138 kPa"`` or a bare number in a default unit).
"""

from __future__ import annotations

import math
import re
from collections.abc import Iterable

from softbend.errors import InputError

__all__ = [
    "ANGLE_UNITS",
    "PRESSURE_UNITS",
    "SECONDS_PER_UNIT",
    "UNIT_KINDS",
    "check_column_unit",
    "column_unit",
    "convert_pressure",
    "outside",
    "parse_pressure",
    "pressure_unit_of",
    "seconds_per_unit",
    "unit_from_name",
]

#: Factor from each pressure unit to MPa. Pa is read (a recording may use it); the four
#: units an actuator is described in are kPa, MPa, bar and psi.
PRESSURE_UNITS: dict[str, float] = {
    "Pa": 1e-6,
    "kPa": 1e-3,
    "MPa": 1.0,
    "bar": 0.1,
    "psi": 6.894757293168e-3,
}

#: Angle units, by their spelling in a column's name.
ANGLE_UNITS: dict[str, str] = {"deg": "deg", "rad": "rad"}

#: Seconds per time unit.
SECONDS_PER_UNIT: dict[str, float] = {"s": 1.0, "ms": 1e-3, "µs": 1e-6, "min": 60.0, "h": 3600.0}

#: The units a column's name may end with, by kind, each in its one spelling.
UNIT_KINDS: dict[str, tuple[str, ...]] = {
    "time": tuple(SECONDS_PER_UNIT),
    "pressure": tuple(PRESSURE_UNITS),
    "length": ("m", "cm", "mm", "µm"),
    "angle": tuple(ANGLE_UNITS),
    "force": ("N",),
    "mass": ("g", "kg"),
    "electric": ("V", "mA", "A"),
    "volume": ("mL",),
    "fraction": ("%",),
}

#: Name suffixes (lower case) that spell a unit otherwise than its lower case.
_ASCII: dict[str, str] = {"µs": "us", "µm": "um", "%": "pct"}

#: ``{suffix: (unit, kind)}`` for every unit of :data:`UNIT_KINDS`.
_BY_SUFFIX: dict[str, tuple[str, str]] = {
    _ASCII.get(unit, unit.lower()): (unit, kind)
    for kind, names in UNIT_KINDS.items()
    for unit in names
}

_VALUE = re.compile(r"^\s*([-+]?(?:\d+\.?\d*|\.\d+)(?:[eE][-+]?\d+)?)\s*([A-Za-z]*)\s*$")


def unit_from_name(name: str, kinds: Iterable[str] | None = None) -> str:
    """The unit a column's name ends with, in its one spelling, or ``""``.

    Only the part after the last underscore counts, in any case: ``p1_kpa`` → ``kPa``,
    ``x_mm`` → ``mm``, ``t_us`` → ``µs``, ``angle_DEG`` → ``deg``, ``rho`` → ``""``.

    Parameters
    ----------
    name : str
        The column's name.
    kinds : iterable of str, optional
        Keys of :data:`UNIT_KINDS` the unit must be of (default: any).
    """
    if "_" not in name:
        return ""
    found = _BY_SUFFIX.get(name.rsplit("_", 1)[-1].strip().lower())
    if found is None or (kinds is not None and found[1] not in set(kinds)):
        return ""
    return found[0]


def column_unit(name: str) -> str:
    """The pressure or angle unit a column's name ends with, in its one spelling, or ``""``.

    ``pressure_psi`` → ``psi``, ``p_KPA`` → ``kPa``, ``angle_deg`` → ``deg``,
    ``pressure`` → ``""`` (:func:`unit_from_name` of those two kinds).
    """
    return unit_from_name(name, ("pressure", "angle"))


def pressure_unit_of(name: str) -> tuple[str, float] | None:
    """The pressure unit a column's name ends with and its units per MPa, else None.

    ``p_kpa`` → ``("kPa", 1000.0)``; ``angle_deg`` → None.
    """
    unit = unit_from_name(name, ("pressure",))
    return (unit, 1.0 / PRESSURE_UNITS[unit]) if unit else None


def seconds_per_unit(name: str) -> float | None:
    """Seconds per unit of a time column, from its name (``time_s`` → 1.0, ``t_ms`` → 0.001).

    None when the name carries no time unit.
    """
    unit = unit_from_name(name, ("time",))
    return SECONDS_PER_UNIT[unit] if unit else None


def check_column_unit(column: str, unit: str, option: str, *, key: str | None = None) -> None:
    """Refuse a declared ``unit`` that disagrees with the unit ``column``'s name carries.

    Parameters
    ----------
    column
        The column's name, as in the file (``pressure_psi``).
    unit
        The unit declared for it (by ``option`` or a description), any case.
    option
        What declared the unit, named in the error (``--pressure-unit``).
    key
        The library key of what declared the unit (``pressure_unit``): given, the error
        carries it (the command line names its option, a file its field) and the message
        is the predicate ("is kPa, but the column 'pressure_psi' is named in psi; ...").

    Raises
    ------
    InputError
        When the name carries a unit (see :func:`column_unit`) other than ``unit``.
    """
    named = column_unit(column)
    if not named or named.lower() == str(unit).strip().lower():
        return
    if key is not None:
        raise InputError(
            f"is {unit}, but the column '{column}' is named in {named}; give {named} or "
            "rename the column",
            key=key,
        )
    raise InputError(
        f"The column '{column}' is named in {named}, but {option} says {unit}; "
        f"give {option} {named} or rename the column."
    )


def convert_pressure(value: float, from_unit: str, to_unit: str) -> float:
    """``value`` in ``from_unit`` expressed in ``to_unit`` (both keys of :data:`PRESSURE_UNITS`)."""
    factor = PRESSURE_UNITS[_pressure_unit(from_unit)] / PRESSURE_UNITS[_pressure_unit(to_unit)]
    return value * factor


def parse_pressure(text: str | float, unit: str, option: str) -> float:
    """A pressure given on the command line, in ``unit``.

    ``text`` is a number in ``unit`` (``"20"``) or a number with a unit suffix
    (``"20psi"``, ``"138 kPa"``, ``"0.1MPa"``, ``"1.5bar"``; any case), converted to ``unit``.

    Raises
    ------
    InputError
        Naming ``option``, for text that is not a finite number with an optional unit, or an
        unknown unit (listing the allowed ones).
    """
    target = _pressure_unit(unit)
    if isinstance(text, int | float) and not isinstance(text, bool):
        value, given = float(text), target
    else:
        match = _VALUE.match(str(text))
        if match is None:
            raise InputError(
                f"{option} must be a pressure: a number, optionally with a unit "
                f"({', '.join(PRESSURE_UNITS)}), e.g. 20{target}; got {text!r}."
            )
        value = float(match.group(1))
        given = target if not match.group(2) else _pressure_unit(match.group(2), option)
    if not math.isfinite(value):
        raise InputError(f"{option} must be a finite pressure; got {text!r}.")
    return convert_pressure(value, given, target)


def _pressure_unit(unit: str, option: str = "unit") -> str:
    found = {u.lower(): u for u in PRESSURE_UNITS}.get(str(unit).strip().lower())
    if found is None:
        raise InputError(
            f"{option}: unknown pressure unit {unit!r}; allowed: {', '.join(PRESSURE_UNITS)}."
        )
    return found


def outside(values: Iterable[float], span: tuple[float, float] | None) -> list[float]:
    """The ``values`` outside ``span`` (``(low, high)``, inclusive), in order; none without one.

    For pressures asked of a model beyond those it was trained on, in the model's unit.
    """
    if span is None:
        return []
    low, high = span
    return [float(v) for v in values if v < low or v > high]
