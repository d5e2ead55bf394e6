"""Physical plausibility of values read from files: absurd but finite numbers are errors.

A reader that checks only for NaN lets ``1e300`` through, and a fit on it saves a
scale of -9e295. Every reader of the project checks its columns against the
ranges here, which are wide (no real soft actuator lies near their ends) but
finite, and names the file, line and column of the first value outside.

=====================  ===================  =========================================
quantity               range                why
=====================  ===================  =========================================
``angle_deg``          -3600 to 3600        ten turns; the FEM data end near 300°
``pressure_mpa``       -0.1013 to 2         gauge; no vacuum below -1 atm, and 2 MPa
                                            bursts any silicone actuator
``pressure_kpa``       -101.3 to 2000       the same in kPa
``length_mm``          0 to 10 000          geometry, tip coordinates' magnitude
``fiber_angle_deg``    0 to 90              winding angle from the circumferential
                                            direction (paper B Table 1: 5 to 15)
``coordinate_mm``      -10 000 to 10 000    tip positions
``time_s``             0 to 1e7             about four months of recording
``stress_mpa``         -1000 to 1000        silicones reach a few MPa
``strain``             -1 to 100            engineering strain (stretch 0 to 101)
``modulus_mpa``        -1000 to 1e6         material constants (Kevlar: 3.1e4)
``kernel_width``       1e-6 to 1e6          kernel length scales and widths,
                                            standardized inputs
=====================  ===================  =========================================

A pressure column whose values fit kPa but not MPa gets a hint to that effect.
"""

from __future__ import annotations

from collections.abc import Callable, Mapping, Sequence
from dataclasses import dataclass

import numpy as np
from numpy.typing import ArrayLike

from softbend.errors import DatasetError

__all__ = [
    "RANGES",
    "PlausibleRange",
    "check_plausible",
    "check_plausible_columns",
    "implausible_index",
    "implausible_text",
]


@dataclass(frozen=True)
class PlausibleRange:
    """The plausible range of one quantity (both ends included)."""

    low: float
    high: float
    unit: str
    label: str


RANGES: dict[str, PlausibleRange] = {
    "angle_deg": PlausibleRange(-3600.0, 3600.0, "°", "bending angle"),
    "pressure_mpa": PlausibleRange(-0.1013, 2.0, "MPa", "gauge pressure"),
    "pressure_kpa": PlausibleRange(-101.3, 2000.0, "kPa", "gauge pressure"),
    "length_mm": PlausibleRange(0.0, 10_000.0, "mm", "length"),
    "fiber_angle_deg": PlausibleRange(0.0, 90.0, "°", "fiber winding angle"),
    "coordinate_mm": PlausibleRange(-10_000.0, 10_000.0, "mm", "position"),
    "time_s": PlausibleRange(0.0, 1e7, "s", "time"),
    "stress_mpa": PlausibleRange(-1000.0, 1000.0, "MPa", "stress"),
    "strain": PlausibleRange(-1.0, 100.0, "", "strain"),
    "modulus_mpa": PlausibleRange(-1000.0, 1e6, "MPa", "material constant"),
    "kernel_width": PlausibleRange(1e-6, 1e6, "", "kernel width"),
}


def implausible_index(values: ArrayLike, quantity: str) -> int | None:
    """Index of the first finite value of ``values`` outside ``quantity``'s range, or None.

    NaN and missing values are left to the caller's own check.
    """
    bounds = _range(quantity)
    array = np.asarray(values, dtype=np.float64).ravel()
    with np.errstate(invalid="ignore"):
        outside = np.isfinite(array) & ((array < bounds.low) | (array > bounds.high))
        outside |= np.isinf(array)
    hits = np.flatnonzero(outside)
    return int(hits[0]) if hits.size else None


def implausible_text(value: float, quantity: str) -> str | None:
    """Why ``value`` is not a plausible ``quantity``, in words, or None if it is.

    For a single field (of a JSON or TOML file) whose caller names it itself.
    """
    if implausible_index([value], quantity) is None:
        return None
    bounds = _range(quantity)
    unit = f" {bounds.unit}" if bounds.unit else ""
    hint = ""
    if quantity == "pressure_mpa" and 2.0 < abs(value) <= 2000.0:
        hint = " It looks like kPa: divide by 1000 for MPa."
    return (
        f"{value:g} is not a plausible {bounds.label} "
        f"(allowed {bounds.low:g} to {bounds.high:g}{unit}).{hint}"
    )


def check_plausible(
    values: ArrayLike,
    quantity: str,
    *,
    source: str,
    column: str,
    lines: Sequence[int] | None = None,
    first_line: int = 2,
    where: Callable[[int], str] | None = None,
) -> None:
    """Raise :class:`~softbend.errors.DatasetError` at the first implausible value.

    Parameters
    ----------
    values : array_like
        The column's values, in file order.
    quantity : str
        A key of :data:`RANGES`.
    source : str
        The file (or object) the values came from, for the message.
    column : str
        The column (or field) name.
    lines : sequence of int, optional
        The file line of each value; default ``first_line + index`` (a CSV whose
        header is line 1 and whose rows follow without gaps).
    first_line : int, default 2
        The line of the first value when ``lines`` is not given.
    where : callable, optional
        ``where(index)`` places a value in words instead of a line (e.g. ``"row 3"``
        of a table in memory, or ``"field 'sigma'"`` of a JSON file).
    """
    index = implausible_index(values, quantity)
    if index is None:
        return
    value = float(np.asarray(values, dtype=np.float64).ravel()[index])
    if where is not None:
        place = where(index)
    else:
        place = f"line {lines[index] if lines is not None else first_line + index}"
    raise DatasetError(f"{source}, {place}, column '{column}': {implausible_text(value, quantity)}")


def check_plausible_columns(
    columns: Mapping[str, tuple[ArrayLike, str]], *, source: str, lines: Sequence[int]
) -> None:
    """:func:`check_plausible` over several columns of one file, in the file's order.

    ``columns`` maps each column name to its values and quantity; ``lines`` is the
    file line of each row. The error names the first implausible value as a reader
    of the file meets it, whichever column it is in.
    """
    first: tuple[int, str] | None = None
    for column, (values, quantity) in columns.items():
        index = implausible_index(values, quantity)
        if index is not None and (first is None or lines[index] < first[0]):
            first = (lines[index], column)
    if first is not None:
        values, quantity = columns[first[1]]
        check_plausible(values, quantity, source=source, column=first[1], lines=lines)


def _range(quantity: str) -> PlausibleRange:
    if quantity not in RANGES:
        raise ValueError(
            f"Unknown quantity {quantity!r}; the quantities are {', '.join(sorted(RANGES))}."
        )
    return RANGES[quantity]
