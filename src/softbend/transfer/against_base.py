"""Measurements held against the base model they refine: its pressure range, its angles.

``transfer loco`` and ``transfer refine`` read a lab's measurement files with
:func:`load_for_base`, which reads them in the format of the base model's actuator
(paper B's measurement CSV, or a described actuator's plain CSV) and, before any
strategy is fitted, checks two slips of units against the model itself:

- **Pressures** (:func:`check_pressures`): the measured pressures must stay within
  :data:`PRESSURE_MARGIN` (1.5) times the top of the pressure range the base was
  trained on (``metadata["training_ranges"]``, else its support), and be >= 0. Beyond,
  the column is most likely in another unit (kPa numbers left in a psi column are 6.9
  times too large): the error gives both ranges in the model's unit and the unit the
  numbers look like, if one fits. A top :data:`SMALL_RATIO` (20) or more times below
  the trained top is refused too when the factor is that between two units (MPa
  numbers in a kPa column are 1000 times too small); a lab that measured only low
  pressures, by no such factor, passes.
- **Radians** (:func:`check_angles`): an actuator whose measured angles are about
  57.3 (180/π) times smaller than the base predicts at the same design and pressures
  was measured in radians. A stiff actuator that truly bends little bends little in
  the model too, so it passes, however small its angles.

``force=True`` (``--force``) uses the readings as given, with a warning, and the
record (:func:`load_for_base`'s second value) says what was forced; the commands save
it with their results.
"""

from __future__ import annotations

import math
import os
import warnings
from collections.abc import Sequence
from typing import TYPE_CHECKING, Any

import numpy as np

from softbend.errors import DatasetError
from softbend.units import PRESSURE_UNITS

if TYPE_CHECKING:
    from softbend.surrogates.persistence import SavedSurrogate
    from softbend.transfer.measurements import ActuatorMeasurements, Measurements

__all__ = [
    "PRESSURE_MARGIN",
    "RADIAN_MIN_PREDICTED_DEG",
    "check_angles",
    "check_pressures",
    "load_for_base",
    "trained_pressure_range",
]

#: Measured pressures may reach this many times the top of the base's trained range.
PRESSURE_MARGIN = 1.5
#: Measured pressures whose top is this many times below the trained top, by the factor
#: between two units (1000: MPa numbers in a kPa column), are refused too.
SMALL_RATIO = 20.0
#: Degrees per radian: a curve measured in radians is this much smaller than in degrees.
DEGREES_PER_RADIAN = 180.0 / math.pi
#: The radians rule's factors: measured at most 1/10 of the prediction, and the measured
#: angles times 57.3 within a factor 3 of it.
RADIAN_SMALLER = 10.0
RADIAN_MATCH = 3.0
#: The base must predict at least this much (degrees) for the radians rule to judge an
#: actuator: below, a curve is too flat to tell degrees from radians.
RADIAN_MIN_PREDICTED_DEG = 2.0


def load_for_base(
    paths: str | os.PathLike[str] | Sequence[str | os.PathLike[str]],
    saved: SavedSurrogate,
    *,
    force: bool = False,
) -> tuple[Measurements | ActuatorMeasurements, dict[str, Any]]:
    """Read measurement files in the format of ``saved``'s actuator and hold them against it.

    Parameters
    ----------
    paths : path or sequence of paths
        The measurement CSV files, joined.
    saved : SavedSurrogate
        The base model (:func:`softbend.surrogates.load_surrogate`).
    force : bool, default False
        Use pressures past the trained range and angles that look like radians as given,
        each with a warning, instead of raising.

    Returns
    -------
    data : Measurements or ActuatorMeasurements
        The readings (paper B's format for paper B's actuator, the plain CSV otherwise).
    forced : dict
        What ``force`` let through, for the command's record: ``pressure`` (the measured
        and trained ranges, in ``unit``) and ``radians`` (the actuators), each only when
        it applies; empty when the readings pass.

    Raises
    ------
    DatasetError
        The files' own errors, pressures past the range or angles in radians (key
        ``measurements`` or the angle column), unless ``force``.
    """
    from softbend.transfer.measurements import read_measurements

    data = read_measurements(paths, saved.actuator)
    forced: dict[str, Any] = {}
    pressure = check_pressures(data, saved, force=force)
    if pressure is not None:
        forced["pressure"] = pressure
    radians = check_angles(data, saved, force=force)
    if radians:
        forced["radians"] = radians
    return data, forced


def trained_pressure_range(saved: SavedSurrogate) -> tuple[float, float] | None:
    """The pressures ``saved`` was trained on, in its actuator's unit, or None if unrecorded.

    :func:`softbend.surrogates.support.trained_pressure_range` of its metadata.
    """
    from softbend.surrogates.support import trained_pressure_range as recorded

    return recorded(saved.metadata, saved.actuator.pressure_column)


def _where(data: Measurements | ActuatorMeasurements, row: int) -> str:
    """The actuator and file of reading ``row``, in words."""
    assert data.provenance is not None
    source = str(data.provenance["source"].iloc[row])
    return f"the actuator {data.groups[row]!r} in {source}"


def _looks_like(ratio: float, unit: str) -> str:
    """The unit that a column ``ratio`` times too large (or small) was most likely written in."""
    best, closest = "", math.inf
    for other, to_mpa in PRESSURE_UNITS.items():
        if other == unit:
            continue
        factor = PRESSURE_UNITS[unit] / to_mpa  # numbers in ``other`` read as ``unit``
        off = abs(math.log(ratio / factor))
        if off < closest:
            best, closest = other, off
    return best if closest < math.log(1.25) else ""


def check_pressures(
    data: Measurements | ActuatorMeasurements, saved: SavedSurrogate, *, force: bool = False
) -> dict[str, Any] | None:
    """Refuse measured pressures past :data:`PRESSURE_MARGIN` times the base's trained top (or
    negative, or below it by the factor between two units).

    Parameters
    ----------
    data : Measurements or ActuatorMeasurements
        The readings, pressures in the actuator's unit.
    saved : SavedSurrogate
        The base model; a model without a recorded range is not checked.
    force : bool, default False
        Warn instead of raising, and return the record.

    Returns
    -------
    dict or None
        With ``force`` and pressures out of range: ``measured_range`` and
        ``trained_range`` (``[low, high]`` in ``unit``), ``unit`` and ``forced``
        (True); otherwise None.

    Raises
    ------
    DatasetError
        Key ``measurements``: both ranges in the model's unit, the reading at fault
        (actuator and file) and the unit the numbers look like, unless ``force``; also
        for a top :data:`SMALL_RATIO` times below the trained one by a factor between
        two units (see the module docstring).
    """
    trained = trained_pressure_range(saved)
    if trained is None or len(data) == 0:
        return None
    actuator = saved.actuator
    unit = actuator.pressure_unit
    pressure = data.frame[actuator.pressure_column].to_numpy(dtype=np.float64)
    low, high = float(pressure.min()), float(pressure.max())
    ratio = high / trained[1] if trained[1] > 0 else math.inf
    other = _looks_like(ratio, unit) if 0 < ratio < math.inf else ""
    too_small = ratio <= 1 / SMALL_RATIO and other != ""
    if low >= 0 and ratio <= PRESSURE_MARGIN and not too_small:
        return None
    row = int(np.argmin(pressure)) if low < 0 else int(np.argmax(pressure))
    shown = f"{pressure[row]:g} {unit}"
    ranges = (
        f"the measured pressures span {low:.4g}–{high:.4g} {unit}; the base model was trained on "
        f"{trained[0]:.4g}–{trained[1]:.4g} {unit}"
    )
    check = f"Check the unit of the column {actuator.pressure_column} (the model takes {unit})"
    if low < 0:
        text = f"a negative pressure ({shown}, {_where(data, row)}): {ranges}"
    elif too_small:
        text = (
            f"the pressures reach only {shown} ({_where(data, row)}), 1/{1 / ratio:.4g} of the "
            f"top of the base model's range: {ranges}; they look like {other}. {check}"
        )
    else:
        hint = f"; they look like {other}" if other else ""
        text = (
            f"the pressures reach {shown} ({_where(data, row)}), {ratio:.3g}× the top of the "
            f"base model's range and more than the {PRESSURE_MARGIN:g}× allowed: {ranges}"
            f"{hint}. {check}"
        )
    if not force:
        raise DatasetError(f"{text}, or pass force=True (--force) to use them", key="measurements")
    warnings.warn(f"measurements: {text}; used as given (force).", UserWarning, stacklevel=3)
    return {
        "measured_range": [low, high],
        "trained_range": [trained[0], trained[1]],
        "unit": unit,
        "forced": True,
    }


def check_angles(
    data: Measurements | ActuatorMeasurements, saved: SavedSurrogate, *, force: bool = False
) -> list[str]:
    """Refuse an actuator's angles that look like radians next to the base's own prediction.

    For each actuator, with ``m`` the largest measured ``|angle|`` and ``q`` the largest
    ``|angle|`` the base predicts at the same design and pressures (the pressurized
    readings within the base's trained pressure range, where its prediction holds), the
    angles are taken for radians when all of these hold:

    - ``q >= RADIAN_MIN_PREDICTED_DEG`` (2°): the model expects a curve to compare with;
    - ``m <= q / RADIAN_SMALLER`` (10): the readings are an order of magnitude too small;
    - ``q / RADIAN_MATCH <= m · 57.3 <= q · RADIAN_MATCH`` (3): read as radians, they
      match the prediction within the gap a transfer can close.

    A stiff actuator that truly reaches 6.4° is predicted to bend little too (``m`` is
    not ten times smaller than ``q``) and passes; a curve in radians is 57 times smaller
    than its prediction and is caught, whatever the pressure.

    Returns
    -------
    list of str
        With ``force``, the actuators read as given (a warning each); else empty.

    Raises
    ------
    DatasetError
        Keyed by the angle column, naming the file, the actuator and both angles,
        unless ``force``.
    """
    actuator = saved.actuator
    trained = trained_pressure_range(saved)
    pressure = data.frame[actuator.pressure_column].to_numpy(dtype=np.float64)
    inside = (pressure > 0) & (pressure <= (trained[1] if trained is not None else np.inf))
    groups = data.groups
    measured = np.abs(data.angle_deg)
    with np.errstate(all="ignore"):
        predicted = np.abs(np.asarray(saved.model.predict(data.features), dtype=np.float64))
    forced = []
    for name in data.actuator_ids:
        rows = np.flatnonzero((groups == name) & inside)
        if rows.size == 0:
            continue
        m, q = float(measured[rows].max()), float(np.nanmax(predicted[rows], initial=0.0))
        if not (
            q >= RADIAN_MIN_PREDICTED_DEG
            and m <= q / RADIAN_SMALLER
            and q / RADIAN_MATCH <= m * DEGREES_PER_RADIAN <= q * RADIAN_MATCH
        ):
            continue
        assert data.provenance is not None
        source = str(data.provenance["source"].iloc[rows[0]])
        text = (
            f"the actuator {name!r} reaches only {m:.4g} where the base model predicts "
            f"{q:.4g}° at the same pressures; they look like radians ({m:.4g} rad = "
            f"{m * DEGREES_PER_RADIAN:.4g}°): multiply by 180/π (57.2958) for degrees"
        )
        column = actuator.angle_column
        if not force:
            raise DatasetError(
                f"{text}, or pass force=True (--force) to read them as given",
                key=column,
                file=source,
            )
        warnings.warn(
            f"{source}: {column}: {text}; read as given (force).", UserWarning, stacklevel=3
        )
        forced.append(str(name))
    return forced
