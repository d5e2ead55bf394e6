"""Measured bending angles of built actuators and their CSV formats: paper B's, and any other's.

Transfer learning (paper B §4.2–4.3) refines a surrogate trained on simulations
with a few measurements of built actuators. A measurement is one bending angle of
one actuator at one gauge pressure; the actuator's design is the SFRBA tuple
``(l, r, t, b, phi, lc)`` of :class:`~softbend.actuators.Design`.

CSV format
----------
UTF-8, one header row and one row per measurement::

    # softbend measurements CSV v1
    # rig: bench 2
    # operator: AB
    l,r,t,b,phi,lc,pressure_mpa,angle_deg,actuator_id,cycle,direction
    100.0,6.0,2.0,2.0,5.0,8.0,0.0,0.0,A1,1,loading
    100.0,6.0,2.0,2.0,5.0,8.0,0.05,31.5,A1,1,loading

Required columns: ``l``, ``r``, ``t``, ``b`` (mm), ``phi`` (deg), ``lc`` (mm),
``pressure_mpa`` (gauge pressure, MPa, finite and >= 0) and ``angle_deg``
(bending angle, degrees, finite). Optional columns: ``actuator_id`` (text;
default: the design written ``"l,r,t,b,phi,lc"`` with ``%g`` numbers, e.g.
``"100,6,2,2,5,8"``), ``cycle`` (integer >= 1; default 1) and ``direction``
(``loading`` or ``unloading``; default ``loading``). Columns come in any order;
their names are case-sensitive and no other column is allowed. Whitespace
around cells is stripped; an empty cell is an error in every column.

Every number must be physically plausible (:mod:`softbend.plausibility`):
``angle_deg`` within ±3600°, ``pressure_mpa`` at most 2 MPa, the lengths ``l``,
``r``, ``t``, ``b`` and ``lc`` at most 10 000 mm and ``phi`` within 0–90°; the
design must also be one :class:`~softbend.actuators.Design` accepts.

Lines starting with ``#`` are comments; a ``# key: value`` comment before the
header row becomes an entry of :attr:`Measurements.metadata` (text split at the
first colon, both sides stripped). The keys are those of :data:`METADATA_KEYS`,
each with a value of its kind (``synthetic`` is ``true`` or ``false``; the
virtual lab's ``lab.*`` settings are numbers, flags or names): a header that
sets another key, or a value of the wrong kind, is an error (write other
remarks as ``# note: ...`` or as a comment without a colon). Blank lines are
skipped. Errors name the file and, where there is one, the line (numbered as an
editor shows it, from 1, comments included) and the column.

A file is read only if it is within the limits of :mod:`softbend.limits`
(``file_mib`` and ``csv_rows``).

Units
-----
A ``pressure_mpa`` column written in kPa is caught as an error naming the file, the
line and the column: it has a value above 2 MPa, the plausible limit, and the error
says it looks like kPa (divide by 1000). This one is not overridable: no strategy or
surrogate accepts a pressure above 2 MPa. Whether the angles are in radians, or the
pressures in another unit within that limit, depends on the actuator: where the
readings meet a base model, :mod:`softbend.transfer.against_base` compares them with
the model's own range and prediction.

Several files
-------------
:func:`load_measurements_files` reads one or more files and joins their
readings. Each file fills its own missing optional columns, and each reading
keeps its file's provenance in :attr:`Measurements.provenance` (``source``,
``synthetic``, ``date`` and the file's other ``# key: value`` entries); the
joined :attr:`Measurements.metadata` holds the entries every file gives alike.

Any described actuator
----------------------
A lab refining a surrogate of its own actuator (one trained on its simulation
table, :mod:`softbend.surrogates.simulation_table`) measures a few built actuators and
writes one row per reading::

    # synthetic: false
    # rig: bench 2
    actuator,n_chambers,n_layers,wall_mm,height_mm,p_kpa,angle_deg
    A1,10,2,2.0,12,0,0.4
    A1,10,2,2.0,12,20,41.8

Columns: ``actuator`` or ``actuator_id`` (the id of the built actuator), the
model's design columns (its :class:`~softbend.actuators.Actuator` parameters,
categorical ones by level), its pressure column in its unit and its angle column,
in degrees. A file without an id column is one actuator, named by the file's stem
(``A1.csv`` holds the readings of ``A1``), as labs keep one file per actuator.
Nothing else: a file that lacks a design column, or names one the model does not
have, is one error naming both. The ``# key: value`` header
lines are optional (``synthetic: true`` marks simulated readings). Every design
must lie in the model's description (ranges, kinds, constraints); an actuator
has one design; pressures are finite and >= 0; angles finite (whether they are
in radians depends on the actuator: :mod:`softbend.transfer.against_base` compares
them with the base model's prediction).

:class:`ActuatorMeasurements` offers what transfer learning reads from
:class:`Measurements` (their shared :class:`Readings`): ``features`` (the model's
inputs), ``angle_deg``, ``groups``, ``actuator_ids``, ``subset``, ``per_actuator``,
``synthetic``, ``provenance`` and ``actuator``. And :func:`read_measurements` is the one
reader a refinement calls: it reads an actuator's files in that actuator's format
(paper B's in the format above, :data:`MEASUREMENT_READERS`; any other's in the
plain one), and :func:`write_measurements` writes readings in the format it reads.
"""

from __future__ import annotations

import csv
import datetime
import hashlib
import io
import logging
import math
import numbers
import os
from collections.abc import Callable, Iterable, Mapping, Sequence
from dataclasses import dataclass, field
from pathlib import Path
from typing import Any

import numpy as np
import pandas as pd

from softbend._io import write_text_atomic
from softbend._validation import must_be
from softbend.actuators import SFRBA, Actuator, ActuatorError, Design
from softbend.design import FEATURE_QUANTITIES, FEATURES, PARAMETERS, sfrba_design
from softbend.errors import DatasetError, InputError, SoftbendError
from softbend.plausibility import implausible_index, implausible_text
from softbend.tables import Column, HeaderKey, Table, TableFormat, read_table

logger = logging.getLogger(__name__)

#: Columns every measurement table has: the design (mm, mm, mm, mm, deg, mm),
#: the gauge pressure (MPa) and the bending angle (deg), in the order written.
MEASUREMENT_COLUMNS: tuple[str, ...] = (
    "l",
    "r",
    "t",
    "b",
    "phi",
    "lc",
    "pressure_mpa",
    "angle_deg",
)
#: Columns a file may leave out; :class:`Measurements` fills them with defaults.
OPTIONAL_COLUMNS: tuple[str, ...] = ("actuator_id", "cycle", "direction")
#: Allowed values of the ``direction`` column.
DIRECTIONS: tuple[str, ...] = ("loading", "unloading")

_DESIGN_COLUMNS: tuple[str, ...] = MEASUREMENT_COLUMNS[:6]
_ALL_COLUMNS: tuple[str, ...] = MEASUREMENT_COLUMNS + OPTIONAL_COLUMNS
_COLUMN_OF: dict[str, str] = {
    **dict(zip(PARAMETERS, _DESIGN_COLUMNS, strict=True)),
    "pressure_mpa": "pressure_mpa",
}
#: Columns of :attr:`Measurements.features`, in :data:`softbend.design.FEATURES` order.
_FEATURE_COLUMNS: tuple[str, ...] = tuple(_COLUMN_OF[name] for name in FEATURES)
_FORMAT_LINE = "softbend measurements CSV v1"
#: Columns of :attr:`Measurements.provenance` every table has, before the other
#: metadata keys of the files: the file, its ``synthetic`` flag and its ``date``.
PROVENANCE_COLUMNS: tuple[str, ...] = ("source", "synthetic", "date")
_MAX_CYCLE = 2**53  # the largest integer a float64 holds exactly

#: Plausible range of each numeric column: a quantity of
#: :data:`softbend.plausibility.RANGES`.
_PLAUSIBLE: dict[str, str] = {
    **{_COLUMN_OF[name]: quantity for name, quantity in FEATURE_QUANTITIES.items()},
    "angle_deg": "angle_deg",
}


# ------------------------------------------------------------------ metadata keys
def _is_text(text: str) -> bool:
    return True


def _is_flag(text: str) -> bool:
    return text in ("true", "false")


def _is_bool(text: str) -> bool:
    return text in ("True", "False")


def _is_number(text: str) -> bool:
    try:
        return math.isfinite(float(text))
    except ValueError:
        return False


def _is_integer(low: int) -> Callable[[str], bool]:
    def check(text: str) -> bool:
        try:
            return int(text) >= low
        except ValueError:
            return False

    return check


def _is_plant(text: str) -> bool:
    return text in ("fem", "analytical")


def _is_date(text: str) -> bool:
    try:
        datetime.datetime.fromisoformat(text)
    except ValueError:
        return False
    return True


_TEXT = ("text on one line", _is_text)
_NUMBER = ("a finite number", _is_number)

#: The keys a ``# key: value`` header line may set: what each value must be
#: (for the messages) and its check. ``lab.*`` are the settings of the virtual
#: lab (:meth:`softbend.transfer.lab.VirtualLab.metadata`) that made a file.
METADATA_KEYS: dict[str, tuple[str, Callable[[str], bool]]] = {
    "synthetic": ("'true' or 'false'", _is_flag),
    "note": _TEXT,
    "generator": _TEXT,
    "command": _TEXT,
    "rig": _TEXT,
    "operator": _TEXT,
    "date": ("an ISO 8601 date or time, e.g. 2024-05-17 or 2024-05-17T14:30", _is_date),
    "lab.plant": ("'fem' or 'analytical'", _is_plant),
    "lab.elastomer": _TEXT,
    "lab.elastomer_max_stretch": _NUMBER,
    "lab.fabrication_error_mm": _NUMBER,
    "lab.hysteresis": _NUMBER,
    "lab.camera_noise_deg": _NUMBER,
    "lab.pressure_step_mpa": _NUMBER,
    "lab.pmax_mpa": _NUMBER,
    "lab.max_angle_deg": _NUMBER,
    "lab.unloading": ("'True' or 'False'", _is_bool),
    "lab.cycles": ("an integer >= 1", _is_integer(1)),
    "lab.seed": ("an integer >= 0", _is_integer(0)),
    "lab.elastomer_model": _TEXT,
    "lab.material": _TEXT,
    "lab.material_source": _TEXT,
    "lab.as_built": _TEXT,
}


def _metadata_problem(key: str, value: str) -> str | None:
    """What is wrong with the metadata entry ``key: value`` (both stripped), or None."""
    if key not in METADATA_KEYS:
        return (
            f"unknown metadata key {key!r}; the keys are {', '.join(METADATA_KEYS)}. "
            "Write other remarks as '# note: ...' or as a comment without ':'"
        )
    kind, check = METADATA_KEYS[key]
    if not check(value):
        return f"the metadata {key!r} must be {kind}; got {value!r}"
    return None


#: The measurement CSV as :mod:`softbend.tables` reads it: the columns with their
#: units, kinds and plausible ranges, and the header keys of :data:`METADATA_KEYS`.
MEASUREMENT_FORMAT = TableFormat(
    name="measurement CSV",
    columns=(
        *(
            Column(column, unit, quantity=_PLAUSIBLE[column])
            for column, unit in zip(
                _DESIGN_COLUMNS, ("mm", "mm", "mm", "mm", "deg", "mm"), strict=True
            )
        ),
        Column("pressure_mpa", "MPa", quantity="pressure_mpa", low=0.0),
        Column("angle_deg", "deg", quantity="angle_deg"),
        Column("actuator_id", kind="text", required=False),
        Column("cycle", kind="integer", required=False, low=1),
        Column("direction", kind="choice", required=False, choices=DIRECTIONS),
    ),
    header=tuple(HeaderKey(key, kind, check) for key, (kind, check) in METADATA_KEYS.items()),
    other_keys="error",
    other_columns="error",
)


class _Rows:
    """Where the rows being checked come from, for errors: a file's lines or a frame's labels."""

    def __init__(
        self, source: str, *, table: Table | None = None, index: pd.Index | None = None
    ) -> None:
        self.source = source
        self.table = table
        self.index = index

    def where(self, pos: int) -> str:
        """The row at position ``pos`` in words: ``line 7`` of a file, ``row 3`` of a frame."""
        if self.table is not None:
            return f"line {self.table.lines[pos]}"
        label = self.index[pos] if self.index is not None else pos
        return f"row {label}" if isinstance(label, numbers.Integral) else f"row {label!r}"

    def error(self, message: str, pos: int | None, column: str | None) -> DatasetError:
        """A :class:`DatasetError` about the row at ``pos`` and ``column`` (the key)."""
        if self.table is not None:
            return self.table.error(message, row=pos, column=column)
        where = f"{self.where(pos)}: " if pos is not None else ""
        return DatasetError(where + message, key=column, file=self.source or None)


class _CellError(Exception):
    """A cell failed its check; the message says what it must be and what came in."""


# ------------------------------------------------------------------ cell checks
def _is_missing(value: object) -> bool:
    if value is None or value is pd.NA or value is pd.NaT:
        return True
    return isinstance(value, float) and math.isnan(value)


def _got(value: object) -> str:
    if isinstance(value, np.generic):
        value = value.item()  # np.float64(1.5) -> 1.5
    if _is_missing(value):
        return "a missing value"
    if isinstance(value, str) and not value:
        return "an empty cell"
    return repr(value)


def _to_float(value: object) -> float:
    """``value`` as a finite float: a real number (not a bool) or a numeric string."""
    message = f"must be a finite number; got {_got(value)}"
    if isinstance(value, str):
        try:
            number = float(value.strip())
        except ValueError:
            raise _CellError(message) from None
    elif isinstance(value, numbers.Real) and not isinstance(value, bool | np.bool_):
        number = float(value)
    else:
        raise _CellError(message)
    if not math.isfinite(number):
        raise _CellError(message)
    return number


def _to_cycle(value: object) -> int:
    """``value`` as an integer >= 1 (``2`` and ``2.0`` pass, ``2.5`` does not)."""
    message = f"must be an integer >= 1; got {_got(value)}"
    if isinstance(value, numbers.Integral) and not isinstance(value, bool | np.bool_):
        number = int(value)
    else:
        try:
            real = _to_float(value)
        except _CellError:
            raise _CellError(message) from None
        if not real.is_integer() or abs(real) > _MAX_CYCLE:
            raise _CellError(message)
        number = int(real)
    if not 1 <= number <= _MAX_CYCLE:
        raise _CellError(message)
    return number


def _to_direction(value: object) -> str:
    text = value.strip() if isinstance(value, str) else None
    if text not in DIRECTIONS:
        allowed = ", ".join(repr(d) for d in DIRECTIONS)
        raise _CellError(f"must be one of {allowed}; got {_got(value)}")
    return text


def _to_actuator_id(value: object) -> str:
    """A non-empty single-line string; integers are accepted and written as text."""
    if isinstance(value, numbers.Integral) and not isinstance(value, bool | np.bool_):
        return str(int(value))
    text = value.strip() if isinstance(value, str) else ""
    if not text or "\n" in text or "\r" in text:
        raise _CellError(f"must be a non-empty text on one line (or an integer); got {_got(value)}")
    return text


def _convert(
    values: np.ndarray, convert: Callable[[Any], Any], rows: _Rows, column: str
) -> list[Any]:
    out = []
    for pos, value in enumerate(values):
        try:
            out.append(convert(value))
        except _CellError as exc:
            raise rows.error(str(exc), pos, column) from None
    return out


def _float_column(series: pd.Series, rows: _Rows, column: str) -> np.ndarray:
    """A column as finite float64 values, raising at the first bad cell."""
    dtype = series.dtype
    if pd.api.types.is_numeric_dtype(dtype) and not pd.api.types.is_bool_dtype(dtype):
        values = series.to_numpy(dtype=float, na_value=np.nan)
        bad = np.flatnonzero(~np.isfinite(values))
        if bad.size:
            pos = int(bad[0])
            raw = series.iloc[pos]
            raise rows.error(f"must be a finite number; got {_got(raw)}", pos, column)
        return values
    raw = series.to_numpy(dtype=object)
    return np.array(_convert(raw, _to_float, rows, column), dtype=float)


# ---------------------------------------------------------------- frame checks
def _check_columns(columns: list[Any], source: str) -> None:
    """Raise unless ``columns`` holds each required column once and nothing unknown."""
    file = source or None
    duplicates = [c for i, c in enumerate(columns) if c in columns[:i]]
    if duplicates:
        raise DatasetError(
            "appears twice in the columns; each column may appear once",
            key=str(duplicates[0]),
            file=file,
        )
    unknown = [c for c in columns if c not in _ALL_COLUMNS]
    if unknown:
        raise DatasetError(
            f"is not a column of the {MEASUREMENT_FORMAT.name}; the columns are "
            f"{MEASUREMENT_FORMAT.columns_text()} (names are case-sensitive)",
            key=str(unknown[0]),
            file=file,
        )
    missing = [c for c in MEASUREMENT_COLUMNS if c not in columns]
    if missing:
        names = ", ".join(repr(c) for c in missing)
        raise DatasetError(
            f"missing required column(s) {names}; the required columns are "
            f"{', '.join(MEASUREMENT_COLUMNS)} (optional: {', '.join(OPTIONAL_COLUMNS)})",
            key=missing[0],
            file=file,
        )


def _design_text(values: Iterable[float]) -> str:
    return ", ".join(f"{c}={float(v)!r}" for c, v in zip(_DESIGN_COLUMNS, values, strict=True))


def _check_column_plausible(values: np.ndarray, column: str, rows: _Rows) -> None:
    """Raise :class:`DatasetError` at the first implausible value of a numeric column."""
    pos = implausible_index(values, _PLAUSIBLE[column])
    if pos is not None:
        text = implausible_text(float(values[pos]), _PLAUSIBLE[column]) or "is not plausible"
        raise rows.error(text, pos, column)


def _normalize(frame: object, rows: _Rows) -> tuple[pd.DataFrame, dict[str, Design]]:
    """Check a table of measurements and return it in canonical form with its designs.

    Parameters
    ----------
    frame : pandas.DataFrame
        Required columns, optional columns or not; cells numbers or text.
    rows : _Rows
        Where the rows come from (a file's lines or a frame's labels), for errors.

    Returns
    -------
    frame : pandas.DataFrame
        All columns, in ``MEASUREMENT_COLUMNS + OPTIONAL_COLUMNS`` order, index 0..n-1.
    designs : dict
        ``{actuator_id: Design}`` in order of first appearance.
    """
    if not isinstance(frame, pd.DataFrame):
        raise DatasetError(
            must_be("a pandas DataFrame", type(frame).__name__),
            key="frame",
            file=rows.source or None,
        )
    _check_columns(list(frame.columns), rows.source)
    n = len(frame)
    if n == 0:
        raise DatasetError(
            "has no data rows; at least one measurement is required", file=rows.source or None
        )

    data: dict[str, Any] = {}
    for column in MEASUREMENT_COLUMNS:
        data[column] = _float_column(frame[column], rows, column)
        _check_column_plausible(data[column], column, rows)
    negative = np.flatnonzero(data["pressure_mpa"] < 0)
    if negative.size:
        pos = int(negative[0])
        raise rows.error(
            f"must be a gauge pressure >= 0 MPa; got {float(data['pressure_mpa'][pos])!r}",
            pos,
            "pressure_mpa",
        )

    # Designs: check each distinct tuple once, at its first row.
    design_values = np.column_stack([data[c] for c in _DESIGN_COLUMNS])
    _, first_rows, codes = np.unique(design_values, axis=0, return_index=True, return_inverse=True)
    codes = codes.reshape(-1)
    design_of_code: list[Design] = []
    for pos in first_rows:
        try:
            design_of_code.append(sfrba_design(*design_values[pos].tolist()))
        except ValueError as exc:
            key = exc.key if isinstance(exc, SoftbendError) else None
            if key is None:  # a check that names its parameters in the text
                key = next((p for p in PARAMETERS if f"'{p}'" in str(exc)), None)
            detail = exc.detail if isinstance(exc, SoftbendError) else str(exc)
            text = f"{key} {detail}" if isinstance(exc, SoftbendError) and key else detail
            raise rows.error(text, int(pos), _COLUMN_OF.get(key or "")) from None

    if "actuator_id" in frame.columns:
        raw = frame["actuator_id"].to_numpy(dtype=object)
        ids = np.array(_convert(raw, _to_actuator_id, rows, "actuator_id"), dtype=object)
        defaulted = False
    else:
        labels = np.array([str(d) for d in design_of_code], dtype=object)
        ids = labels[codes]
        defaulted = True

    # One design per actuator: compare each row's design with its actuator's first row.
    _, first_of_id, id_codes = np.unique(ids, return_index=True, return_inverse=True)
    id_codes = id_codes.reshape(-1)
    first_row = first_of_id[id_codes]
    conflicts = np.flatnonzero(codes != codes[first_row])
    if conflicts.size:
        pos = int(conflicts[0])
        first = int(first_row[pos])
        hint = (
            " (no actuator_id column: the ids were written from the designs with %g, which "
            "rounds to 6 significant digits; add an actuator_id column)"
            if defaulted
            else ""
        )
        raise rows.error(
            f"the actuator {ids[pos]!r} has the design ({_design_text(design_values[pos])}) "
            f"here but ({_design_text(design_values[first])}) on {rows.where(first)}; one "
            f"actuator_id must keep one design{hint}",
            pos,
            "actuator_id",
        )
    order = np.sort(first_of_id)
    designs = {str(ids[pos]): design_of_code[codes[pos]] for pos in order}

    if "cycle" in frame.columns:
        series = frame["cycle"]
        if pd.api.types.is_integer_dtype(series.dtype) and not series.isna().any():
            values = series.to_numpy(dtype=np.int64)
            bad = np.flatnonzero(values < 1)
            if bad.size:
                pos = int(bad[0])
                raise rows.error(f"must be an integer >= 1; got {int(values[pos])!r}", pos, "cycle")
            cycle = values
        else:
            raw = series.to_numpy(dtype=object)
            cycle = np.array(_convert(raw, _to_cycle, rows, "cycle"), dtype=np.int64)
    else:
        cycle = np.ones(n, dtype=np.int64)

    if "direction" in frame.columns:
        raw = frame["direction"].to_numpy(dtype=object)
        direction = np.array(_convert(raw, _to_direction, rows, "direction"), dtype=object)
    else:
        direction = np.full(n, DIRECTIONS[0], dtype=object)

    columns: dict[str, pd.Series] = {
        c: pd.Series(data[c], dtype=np.float64) for c in MEASUREMENT_COLUMNS
    }
    columns["actuator_id"] = pd.Series(ids, dtype=object)
    columns["cycle"] = pd.Series(cycle, dtype=np.int64)
    columns["direction"] = pd.Series(direction, dtype=object)
    return pd.DataFrame(columns, columns=list(_ALL_COLUMNS)), designs


def _check_metadata(metadata: object) -> dict[str, str]:
    """A stripped ``{str: str}`` copy that a ``# key: value`` line writes and reads back."""
    if not isinstance(metadata, Mapping):
        raise InputError(
            must_be("a mapping of text to text", type(metadata).__name__), key="metadata"
        )
    out: dict[str, str] = {}
    for key, value in metadata.items():
        if not isinstance(key, str):
            raise InputError(must_be("text keys", key), key="metadata")
        name, text = key.strip(), str(value).strip()
        if not name or ":" in name or any(ch in name for ch in "\r\n"):
            raise InputError(
                must_be("keys of non-empty text on one line without ':'", key), key="metadata"
            )
        if any(ch in text for ch in "\r\n"):
            raise InputError(
                f"value {name!r} must be text on one line; got {value!r}", key="metadata"
            )
        if name in out:
            raise InputError(
                f"keys must be unique after stripping; got {key!r} twice", key="metadata"
            )
        problem = _metadata_problem(name, text)
        if problem is not None:  # what a file could not read back
            raise InputError(problem, key="metadata")
        out[name] = text
    return out


def _provenance_of(n: int, source: str, metadata: Mapping[str, str]) -> pd.DataFrame:
    """``n`` readings all from ``source`` with ``metadata``: the default provenance."""
    columns: dict[str, Any] = {
        "source": [source] * n,
        "synthetic": np.full(n, metadata.get("synthetic", "") == "true", dtype=bool),
        "date": [metadata.get("date", "")] * n,
    }
    for key, value in metadata.items():
        if key not in columns:
            columns[key] = [value] * n
    return pd.DataFrame(columns)


def _check_provenance(
    provenance: object, n: int, source: str, metadata: Mapping[str, str]
) -> pd.DataFrame:
    """The provenance table of ``n`` readings, checked and copied (default: one source)."""
    if provenance is None:
        return _provenance_of(n, source, metadata)
    if not isinstance(provenance, pd.DataFrame):
        raise ValueError(
            "The 'provenance' of Measurements must be a pandas DataFrame or None. "
            f"Got {type(provenance).__name__} instead."
        )
    missing = [c for c in PROVENANCE_COLUMNS if c not in provenance.columns]
    if missing or len(provenance) != n:
        raise ValueError(
            f"The 'provenance' of Measurements must have one row per reading ({n}) and the "
            f"columns {', '.join(PROVENANCE_COLUMNS)}. Got {len(provenance)} rows with "
            f"columns {', '.join(map(str, provenance.columns))} instead."
        )
    out = provenance.reset_index(drop=True).copy()
    out["synthetic"] = out["synthetic"].astype(bool)
    return out


# ---------------------------------------------------------------- Measurements
class Readings:
    """What transfer learning reads of measured bending angles, in either format.

    :class:`Measurements` (paper B's CSV) and :class:`ActuatorMeasurements` (any
    described actuator's) hold a ``frame`` with ``actuator_id``, the actuator's
    pressure column and ``angle_deg``, a ``provenance`` table with ``synthetic``,
    and the ``actuator`` description they follow.
    """

    frame: pd.DataFrame
    provenance: pd.DataFrame | None
    actuator: Actuator

    def __len__(self) -> int:
        return len(self.frame)

    @property
    def angle_deg(self) -> np.ndarray:
        """Measured bending angles, degrees, shape (n,); a new array on every call."""
        return self.frame["angle_deg"].to_numpy(dtype=np.float64, copy=True)

    @property
    def groups(self) -> np.ndarray:
        """Actuator id of each row, shape (n,), for ``LeaveOneGroupOut``."""
        return self.frame["actuator_id"].to_numpy(dtype=object, copy=True)

    @property
    def synthetic(self) -> np.ndarray:
        """Whether each reading comes from a ``# synthetic: true`` file, shape (n,), bool."""
        assert self.provenance is not None  # set when the readings are made
        return self.provenance["synthetic"].to_numpy(dtype=bool, copy=True)

    def per_actuator(self) -> pd.DataFrame:
        """One row per actuator, in measured order: ``points``, ``pmax`` (the actuator's
        pressure unit: MPa for paper B's) and ``angle_max`` (deg).

        Indexed by ``actuator_id``: the readings, the highest pressure set and
        the largest angle read.
        """
        return self.frame.groupby("actuator_id", sort=False).agg(
            points=("angle_deg", "size"),
            pmax=(self.actuator.pressure_column, "max"),
            angle_max=("angle_deg", "max"),
        )


@dataclass(frozen=True, eq=False, repr=False)
class Measurements(Readings):
    """Measured bending angles of one or more actuators, one row per measurement.

    Parameters
    ----------
    frame : pandas.DataFrame
        Columns :data:`MEASUREMENT_COLUMNS` (``l``, ``r``, ``t``, ``b`` in mm,
        ``phi`` in deg, ``lc`` in mm, ``pressure_mpa`` in MPa gauge,
        ``angle_deg`` in deg) and any of :data:`OPTIONAL_COLUMNS`. It is
        checked and stored as a copy with every column, in the order
        ``MEASUREMENT_COLUMNS + OPTIONAL_COLUMNS``: floats as float64,
        ``cycle`` as int64, ``actuator_id`` and ``direction`` as ``object``
        columns of ``str``; index 0..n-1. Missing optional columns get their
        defaults (see the module docstring).
    metadata : mapping of str to str
        Free-form provenance (the ``# key: value`` lines of a file); stored as
        a ``dict`` copy with keys and values stripped, values converted to text.
    source : str
        The file the measurements came from, or a description; path-likes are
        converted to text.
    provenance : pandas.DataFrame, optional
        Where each reading comes from, one row per row of ``frame``: the columns
        :data:`PROVENANCE_COLUMNS` (``source`` text, ``synthetic`` bool,
        ``date`` text, empty if none) and any other metadata keys (text, empty
        where a file does not set them). Default: every reading from ``source``
        with ``metadata``. Stored as a copy with index 0..n-1.

    Raises
    ------
    DatasetError
        One line naming the ``source`` (or "the Measurements frame"), the row
        (by index label) and the column: a missing, duplicate or unknown
        column, no rows, a non-numeric, non-finite or implausible number
        (:mod:`softbend.plausibility`), a negative pressure, a cycle that is
        not an integer >= 1, a direction not in :data:`DIRECTIONS`, an empty
        actuator id, a design :class:`~softbend.actuators.Design` rejects, or
        one actuator id with two designs.
    ValueError
        Metadata that is not a mapping of single-line text (keys without ':'),
        or that a file could not hold: a key not in :data:`METADATA_KEYS` or a
        value not of its kind; a ``provenance`` that is not a table of one row
        per reading with the :data:`PROVENANCE_COLUMNS`.

    Notes
    -----
    Two instances compare equal when their frames are equal
    (:meth:`pandas.DataFrame.equals`) and their metadata are; ``source`` and
    ``provenance`` are not compared, so ``load_measurements(save_measurements(m, p)) == m``.
    """

    frame: pd.DataFrame
    metadata: Mapping[str, str] = field(default_factory=dict)
    source: str = ""
    provenance: pd.DataFrame | None = None
    _designs: dict[str, Design] = field(init=False, repr=False, compare=False)
    #: The description the readings follow: paper B's actuator's.
    actuator: Actuator = field(default=SFRBA, init=False, repr=False, compare=False)

    def __post_init__(self) -> None:
        source = os.fspath(self.source) if isinstance(self.source, os.PathLike) else self.source
        if not isinstance(source, str):
            raise ValueError(
                f"The 'source' of Measurements must be text. Got {type(source).__name__} instead."
            )
        index = self.frame.index if isinstance(self.frame, pd.DataFrame) else None
        frame, designs = _normalize(self.frame, _Rows(source, index=index))
        metadata = _check_metadata(self.metadata)
        object.__setattr__(self, "source", source)
        object.__setattr__(self, "frame", frame)
        object.__setattr__(self, "metadata", metadata)
        object.__setattr__(
            self, "provenance", _check_provenance(self.provenance, len(frame), source, metadata)
        )
        object.__setattr__(self, "_designs", designs)

    @classmethod
    def from_frame(
        cls,
        frame: pd.DataFrame,
        *,
        metadata: Mapping[str, str] | None = None,
        source: str = "",
    ) -> Measurements:
        """Check ``frame``, fill the optional columns with their defaults and wrap it.

        Parameters
        ----------
        frame : pandas.DataFrame
            The required columns and any optional ones; cells may be numbers or
            numeric text. Errors name rows by their index label (``row 3``).
        metadata : mapping of str to str, optional
            Provenance; default none.
        source : str
            Where the rows come from, first in error messages.
        """
        return cls(frame, metadata=dict(metadata or {}), source=source)

    def __eq__(self, other: object) -> bool:
        if not isinstance(other, Measurements):
            return NotImplemented
        return self.frame.equals(other.frame) and dict(self.metadata) == dict(other.metadata)

    def __repr__(self) -> str:
        return (
            f"Measurements(n={len(self)}, actuators={len(self._designs)}, source={self.source!r})"
        )

    @property
    def actuator_ids(self) -> tuple[str, ...]:
        """Actuator ids in order of first appearance."""
        return tuple(self._designs)

    def design_of(self, actuator_id: str) -> Design:
        """The design of one actuator.

        Raises
        ------
        ValueError
            ``actuator_id`` is not one of :attr:`actuator_ids`.
        """
        try:
            return self._designs[actuator_id]
        except (KeyError, TypeError):
            known = ", ".join(repr(a) for a in self._designs)
            raise ValueError(
                f"The 'actuator_id' of Measurements.design_of must be one of {known}. "
                f"Got {actuator_id!r} instead."
            ) from None

    @property
    def designs(self) -> tuple[Design, ...]:
        """One design per actuator, in :attr:`actuator_ids` order."""
        return tuple(self._designs.values())

    @property
    def features(self) -> np.ndarray:
        """Model inputs, shape (n, 7): :data:`softbend.design.FEATURES` order (mm, deg, MPa).

        Columns ``l``, ``r``, ``t``, ``b`` (mm), ``phi`` (deg), ``lc`` (mm),
        ``pressure_mpa`` (MPa); a new float64 array on every call.
        """
        return self.frame[list(_FEATURE_COLUMNS)].to_numpy(dtype=np.float64, copy=True)

    def subset(self, actuator_ids: Iterable[str]) -> Measurements:
        """The rows of some actuators, in their original order.

        Parameters
        ----------
        actuator_ids : iterable of str
            Ids from :attr:`actuator_ids` (a single ``str`` is one id).

        Raises
        ------
        ValueError
            No id, or an id that is not in :attr:`actuator_ids`.
        """
        wanted = [actuator_ids] if isinstance(actuator_ids, str) else list(actuator_ids)
        unknown = [a for a in wanted if not isinstance(a, str) or a not in self._designs]
        if unknown:
            known = ", ".join(repr(a) for a in self._designs)
            raise ValueError(
                f"The 'actuator_ids' of Measurements.subset must be among {known}. "
                f"Got unknown {', '.join(repr(a) for a in unknown)}."
            )
        if not wanted:
            raise ValueError(
                "The 'actuator_ids' of Measurements.subset must name at least one actuator. "
                "Got none."
            )
        mask = self.frame["actuator_id"].isin(wanted).to_numpy()
        frame = self.frame.loc[mask].reset_index(drop=True)
        provenance = None
        if self.provenance is not None:
            provenance = self.provenance.loc[mask].reset_index(drop=True)
        return Measurements(
            frame,
            metadata=dict(self.metadata),
            source=self.source,
            provenance=provenance,
        )


# --------------------------------------------------------------------- loading
def load_measurements(path: str | os.PathLike[str]) -> Measurements:
    """Read measurements from a CSV file in the format of this module.

    Parameters
    ----------
    path : str or path-like
        The CSV file.

    Returns
    -------
    Measurements
        With the file's ``# key: value`` header comments as metadata and the
        path as ``source``.

    Raises
    ------
    DatasetError
        One line naming the file and, where it applies, the line (as an editor
        numbers them, from 1) and the column: file not found or a folder, not
        UTF-8, no header row, a missing, duplicate or unknown column, a row with
        the wrong number of cells or a cell CSV cannot read, no data rows, a
        metadata key given twice, unknown or with a malformed value, an
        implausible number (:mod:`softbend.plausibility`; a pressure above
        2 MPa is said to look like kPa), or any cell check of :class:`Measurements`.
    LimitError
        The file is larger than the ``file_mib`` limit or has more data rows
        than the ``csv_rows`` limit (:mod:`softbend.limits`); checked before the
        rows are parsed.
    """
    source = Path(path)
    table = read_table(source, MEASUREMENT_FORMAT)
    frame, _ = _normalize(table.frame, _Rows(str(source), table=table))
    metadata = table.header
    measurements = Measurements(frame, metadata=metadata, source=str(source))
    logger.debug(
        "Loaded %d measurement(s) of %d actuator(s) from %s.",
        len(measurements),
        len(measurements.actuator_ids),
        source,
    )
    return measurements


def load_measurements_files(
    paths: str | os.PathLike[str] | Sequence[str | os.PathLike[str]],
) -> Measurements:
    """Read measurements from one or more CSV files and join their readings, in file order.

    Parameters
    ----------
    paths : path or sequence of paths
        The CSV files (:func:`load_measurements`); one path reads as
        :func:`load_measurements` does.

    Returns
    -------
    Measurements
        Every file's readings, each file's missing optional columns filled as
        that file alone fills them. :attr:`Measurements.provenance` holds each
        reading's file (``source``), its file's ``synthetic`` flag, ``date`` and
        other metadata; :attr:`Measurements.metadata` the entries every file
        gives with the same value; ``source`` the files joined by ``", "``.

    Raises
    ------
    DatasetError
        Any error of :func:`load_measurements`, naming its file; no file; the
        same file twice; or one actuator_id with two designs in two files
        (both files named).
    LimitError
        As for :func:`load_measurements`.
    """
    items = [paths] if isinstance(paths, str | os.PathLike) else list(paths)
    if not items:
        raise DatasetError("No measurement file given; at least one CSV file is required.")
    if len(items) == 1:
        return load_measurements(items[0])
    seen: dict[Path, str] = {}
    for item in items:
        key = Path(item).resolve()
        if key in seen:
            raise DatasetError(
                f"The measurement file {item} is given twice (also as {seen[key]}); "
                "give each file once."
            )
        seen[key] = str(item)
    parts = [load_measurements(item) for item in items]
    owner: dict[str, tuple[Design, str]] = {}
    for part in parts:
        for actuator in part.actuator_ids:
            design = part.design_of(actuator)
            if actuator in owner and owner[actuator][0] != design:
                first, where = owner[actuator]
                raise DatasetError(
                    f"{part.source}: the actuator {actuator!r} has the design "
                    f"({_design_text(design.as_array())}) here but "
                    f"({_design_text(first.as_array())}) in {where}; one actuator_id must keep "
                    "one design across files (rename one of them)."
                )
            owner.setdefault(actuator, (design, part.source))
    common = {
        key: value
        for key, value in parts[0].metadata.items()
        if all(p.metadata.get(key) == value for p in parts[1:])
    }
    provenance = pd.concat([p.provenance for p in parts], ignore_index=True).fillna("")
    provenance["synthetic"] = provenance["synthetic"].astype(bool)
    frame = pd.concat([p.frame for p in parts], ignore_index=True)
    return Measurements(
        frame,
        metadata=common,
        source=", ".join(p.source for p in parts),
        provenance=provenance,
    )


def files_record(
    paths: Sequence[str | os.PathLike[str]], measurements: Measurements
) -> list[dict[str, Any]]:
    """What a run records of its measurement files: path, SHA-256, readings, synthetic.

    Parameters
    ----------
    paths : sequence of path
        The files ``measurements`` were read from (:func:`load_measurements_files`).
    measurements : Measurements
        Their readings.

    Returns
    -------
    list of dict
        One ``{"path", "sha256", "readings", "synthetic"}`` per file, in order:
        the path as given, the hex SHA-256 of its bytes, its number of readings
        and whether its header says ``# synthetic: true``.
    """
    provenance = measurements.provenance
    assert provenance is not None  # set by Measurements.__post_init__
    out = []
    for item in paths:
        digest = hashlib.sha256()
        with open(item, "rb") as handle:
            for block in iter(lambda: handle.read(1 << 20), b""):
                digest.update(block)
        rows = provenance["source"].to_numpy(dtype=object) == str(Path(item))
        out.append(
            {
                "path": str(item),
                "sha256": digest.hexdigest(),
                "readings": int(rows.sum()),
                "synthetic": bool(provenance["synthetic"].to_numpy(dtype=bool)[rows].all()),
            }
        )
    return out


def synthetic_label(measurements: Measurements) -> str:
    """``"true"`` if every reading is synthetic, ``"false"`` if none, else ``"mixed"``.

    Readings of one file keep the text of its ``# synthetic:`` header
    (``"false"`` when it has none).
    """
    if "synthetic" in measurements.metadata:
        return str(measurements.metadata["synthetic"])
    flags = measurements.synthetic
    if flags.all() and len(flags):
        return "true"
    return "mixed" if flags.any() else "false"


# ---------------------------------------------------------------------- saving
def _format_float(value: float) -> str:
    """Shortest text that parses back to the identical float."""
    return repr(float(value))


def format_measurements(measurements: Measurements) -> str:
    """The CSV text :func:`save_measurements` writes (format comment, metadata, rows).

    Raises
    ------
    ValueError
        ``measurements`` is not a :class:`Measurements`.
    """
    if not isinstance(measurements, Measurements):
        raise ValueError(
            "The 'measurements' of save_measurements must be a Measurements object. "
            f"Got {type(measurements).__name__} instead."
        )
    buffer = io.StringIO()
    buffer.write(f"# {_FORMAT_LINE}\n")
    for key, value in measurements.metadata.items():
        buffer.write(f"# {key}: {value}\n")
    writer = csv.writer(buffer, lineterminator="\n")
    writer.writerow(_ALL_COLUMNS)
    frame = measurements.frame
    floats = [frame[c].to_numpy(dtype=np.float64) for c in MEASUREMENT_COLUMNS]
    ids = frame["actuator_id"].to_numpy(dtype=object)
    cycles = frame["cycle"].to_numpy(dtype=np.int64)
    directions = frame["direction"].to_numpy(dtype=object)
    for i in range(len(frame)):
        writer.writerow(
            [
                *(_format_float(column[i]) for column in floats),
                ids[i],
                int(cycles[i]),
                directions[i],
            ]
        )
    return buffer.getvalue()


def save_measurements(measurements: Measurements, path: str | os.PathLike[str]) -> Path:
    """Write measurements to a CSV file that :func:`load_measurements` reads back equal.

    Parameters
    ----------
    measurements : Measurements
        What to write.
    path : str or path-like
        The CSV file; its folder is created if needed, an existing file replaced.

    Returns
    -------
    pathlib.Path
        The file written.

    Notes
    -----
    The file starts with a format comment and the metadata as ``# key: value``
    lines, then the header with every column (``MEASUREMENT_COLUMNS +
    OPTIONAL_COLUMNS``). Floats are written with :func:`repr`, the shortest text
    that parses back to the same float, so the round trip is exact. The text is
    written to a temporary file in the same folder and moved into place, so a
    reader never sees half a file.
    """
    target = write_text_atomic(path, format_measurements(measurements))
    logger.debug("Saved %d measurement(s) to %s.", len(measurements), target)
    return target


# ------------------------------------------------------------ any described actuator
#: The column naming the built actuator of each reading.
ACTUATOR_COLUMN = "actuator"
#: The names the id column may have: a file gives one of them, or none (one actuator, the
#: file's stem).
ID_COLUMNS: tuple[str, ...] = (ACTUATOR_COLUMN, "actuator_id")


@dataclass(frozen=True, eq=False)
class ActuatorMeasurements(Readings):
    """Readings of built actuators of one described actuator, one row per reading.

    Parameters
    ----------
    frame : pandas.DataFrame
        Columns ``actuator_id`` (text), the design parameters as model-input
        codes, the pressure column (the actuator's unit) and ``angle_deg``.
    actuator : Actuator
        The description the codes follow.
    metadata : mapping of str to str
        The ``# key: value`` lines of the file(s).
    source : str
        The file(s) read.
    """

    frame: pd.DataFrame
    actuator: Actuator
    metadata: Mapping[str, str] = field(default_factory=dict)
    source: str = ""
    provenance: pd.DataFrame | None = None

    @property
    def actuator_ids(self) -> tuple[str, ...]:
        """Actuator ids in order of first appearance."""
        return tuple(dict.fromkeys(self.frame["actuator_id"].tolist()))

    def design_of(self, actuator_id: str) -> np.ndarray:
        """The design codes of one built actuator."""
        rows = self.frame.loc[self.frame["actuator_id"] == actuator_id, list(self.actuator.names)]
        if rows.empty:
            raise ValueError(
                f"No actuator {actuator_id!r} in {self.source}; known: "
                f"{', '.join(self.actuator_ids)}."
            )
        return rows.iloc[0].to_numpy(dtype=np.float64)

    @property
    def designs(self) -> tuple[np.ndarray, ...]:
        """One design (codes) per actuator, in :attr:`actuator_ids` order."""
        return tuple(self.design_of(a) for a in self.actuator_ids)

    @property
    def features(self) -> np.ndarray:
        """Model inputs, shape (n, n_parameters + 1): the design codes and the pressure."""
        return self.frame[list(self.actuator.features)].to_numpy(dtype=np.float64, copy=True)

    def subset(self, actuator_ids: Iterable[str]) -> ActuatorMeasurements:
        """The readings of some actuators, in their original order."""
        wanted = [actuator_ids] if isinstance(actuator_ids, str) else list(actuator_ids)
        unknown = [a for a in wanted if a not in self.actuator_ids]
        if unknown or not wanted:
            raise ValueError(
                f"The actuators of a subset must be among {', '.join(self.actuator_ids)}; "
                f"got {', '.join(map(repr, unknown)) or 'none'}."
            )
        mask = self.frame["actuator_id"].isin(wanted).to_numpy()
        provenance = None
        if self.provenance is not None:
            provenance = self.provenance.loc[mask].reset_index(drop=True)
        return ActuatorMeasurements(
            self.frame.loc[mask].reset_index(drop=True),
            self.actuator,
            dict(self.metadata),
            self.source,
            provenance,
        )


def measurement_format(actuator: Actuator) -> TableFormat:
    """The plain measurement CSV of ``actuator``, as :mod:`softbend.tables` reads it.

    The optional id column (``actuator`` or ``actuator_id``), the design columns
    (read as text: a categorical parameter gives its level), the pressure column
    (>= 0, the actuator's unit) and the angle column (degrees); any ``# key: value``
    line without spaces in its key is kept.
    """
    return TableFormat(
        name=f"measurement file of the actuator {actuator.name}",
        columns=(
            *(Column(name, kind="text", required=False) for name in ID_COLUMNS),
            *(Column(p.name, p.unit, kind="text") for p in actuator.parameters),
            Column(actuator.pressure_column, actuator.pressure_unit, low=0.0),
            Column(actuator.angle_column, "deg"),
        ),
        other_keys="keep",
        other_columns="error",
    )


def _ids(table: Table, path: Path) -> pd.Series:
    """Each reading's actuator: its id column (``actuator`` or ``actuator_id``), or, in a
    file with neither, the file's stem (the file is one actuator)."""
    given = [name for name in ID_COLUMNS if name in table.frame.columns]
    if len(given) > 1:
        raise ActuatorError(
            f"names the actuators twice, by the columns {' and '.join(given)}; keep one",
            key=given[1],
            file=table.file,
            line=table.header_line,
            column=table.positions[given[1]],
        )
    if given:
        return table.frame[given[0]].astype(object)
    return pd.Series([path.stem] * len(table.frame), dtype=object)


def _read_one(path: Path, actuator: Actuator) -> tuple[pd.DataFrame, dict[str, str], bool]:
    """One file's readings, its ``# key: value`` lines, and whether its file names its actuator."""
    try:
        table = read_table(path, measurement_format(actuator))
    except DatasetError as error:
        if error.key is None:  # the file itself: missing, not text, no rows
            raise
        raise ActuatorError(
            error.detail, key=error.key, file=error.file, line=error.line, column=error.column
        ) from None
    raw = table.frame
    frame = pd.DataFrame({"actuator_id": _ids(table, path)})
    for parameter in actuator.parameters:
        column = table.positions[parameter.name]
        codes = []
        for pos, cell in enumerate(raw[parameter.name].tolist()):
            try:
                codes.append(parameter.encode(cell))
            except ActuatorError as err:
                raise ActuatorError(
                    err.detail, file=table.file, line=int(table.lines[pos]), column=column
                ) from None
        values = np.asarray(codes, dtype=np.float64)
        try:
            parameter.check(values)
        except ActuatorError:  # find the first row at fault
            for pos, value in enumerate(values):
                try:
                    parameter.check(value[None])
                except ActuatorError as err:
                    raise ActuatorError(
                        err.detail, file=table.file, line=int(table.lines[pos]), column=column
                    ) from None
            raise
        frame[parameter.name] = values
    frame[actuator.pressure_column] = raw[actuator.pressure_column]
    frame["angle_deg"] = raw[actuator.angle_column]
    frame["direction"] = "loading"  # a plain file records the loading branch
    met = actuator.constraints_met(frame[list(actuator.names)].to_numpy())
    if not met.all():
        pos = int(np.argmin(met))
        try:
            actuator.check_designs(frame[list(actuator.names)].to_numpy()[pos])
        except ActuatorError as err:
            raise ActuatorError(err.detail, file=table.file, line=int(table.lines[pos])) from None
    return frame, table.header, not any(name in raw.columns for name in ID_COLUMNS)


def load_actuator_measurements(
    paths: str | os.PathLike[str] | Sequence[str | os.PathLike[str]],
    actuator: Actuator,
) -> ActuatorMeasurements:
    """Read one or more plain measurement CSV files of ``actuator`` (module docstring).

    Raises
    ------
    softbend.actuators.ActuatorError
        A missing or unknown column (naming it and the expected ones), a design
        outside the description, a bad cell (naming the line and column), one
        actuator id with two designs.
    softbend.errors.DatasetError
        A missing, unreadable or empty file.
    """
    files = [paths] if isinstance(paths, str | os.PathLike) else list(paths)
    frames, provenance, shared = [], [], None
    by_file: set[str] = set()  # actuators named by their file (no id column)
    for item in files:
        path = Path(item)
        frame, metadata, named_by_file = _read_one(path, actuator)
        frames.append(frame)
        if named_by_file:
            by_file.add(path.stem)
        flag = metadata.get("synthetic", "false").strip().lower() == "true"
        provenance.append(
            pd.DataFrame(
                {
                    "source": [str(path)] * len(frame),
                    "synthetic": [flag] * len(frame),
                    "date": [metadata.get("date", "")] * len(frame),
                }
            )
        )
        shared = (
            dict(metadata)
            if shared is None
            else {k: v for k, v in shared.items() if metadata.get(k) == v}
        )
    frame = pd.concat(frames, ignore_index=True)
    designs = frame.groupby("actuator_id", sort=False)[list(actuator.names)].nunique()
    twice = designs.index[(designs > 1).any(axis=1)].tolist()
    if twice:
        hint = (
            f" (a file without an {' or '.join(ID_COLUMNS)} column is one actuator, named by "
            "the file: add one of those columns to a file of several)"
            if twice[0] in by_file
            else ""
        )
        raise ActuatorError(
            f"the actuator {twice[0]!r} has two designs in {', '.join(map(str, files))}; "
            f"each built actuator has one (give the others their own ids){hint}",
            key=ACTUATOR_COLUMN,
        )
    return ActuatorMeasurements(
        frame,
        actuator,
        shared or {},
        ", ".join(str(f) for f in files),
        pd.concat(provenance, ignore_index=True),
    )


def is_actuator_measurements(data: object) -> bool:
    """Whether ``data`` holds readings of a described actuator (not paper B's format)."""
    return isinstance(data, ActuatorMeasurements)


#: Readers of measurement files in a format of an actuator's own, by the actuator's name:
#: ``(actuator, reader)``, ``reader(paths) -> measurements``. Any other actuator's files are
#: read in the plain format of its description (:func:`load_actuator_measurements`).
MEASUREMENT_READERS: dict[
    str, tuple[Actuator, Callable[[Sequence[str | os.PathLike[str]]], Measurements]]
] = {SFRBA.name: (SFRBA, load_measurements_files)}


def _write_paper_b(
    rows: pd.DataFrame, path: str | os.PathLike[str], metadata: Mapping[str, str]
) -> Path:
    """Paper B's readings in its own format (:func:`save_measurements`)."""
    names = dict(zip(SFRBA.names, MEASUREMENT_COLUMNS[:6], strict=True))
    frame = rows.rename(columns=names)
    return save_measurements(Measurements.from_frame(frame, metadata=metadata), path)


def _write_plain(
    rows: pd.DataFrame, path: str | os.PathLike[str], metadata: Mapping[str, str]
) -> Path:
    """Readings in the plain format (:func:`measurement_format`), metadata lines first."""
    lines = "".join(f"# {key}: {value}\n" for key, value in metadata.items())
    return write_text_atomic(path, lines + rows.to_csv(index=False))


#: Writers of measurement files in the format of an actuator's own, by the actuator's name:
#: ``(actuator, writer)``, ``writer(rows, path, metadata) -> path`` (the format
#: :data:`MEASUREMENT_READERS` reads).
MEASUREMENT_WRITERS: dict[
    str,
    tuple[Actuator, Callable[[pd.DataFrame, str | os.PathLike[str], Mapping[str, str]], Path]],
] = {SFRBA.name: (SFRBA, _write_paper_b)}


def write_measurements(
    rows: pd.DataFrame,
    actuator: Actuator,
    path: str | os.PathLike[str],
    metadata: Mapping[str, str] | None = None,
) -> Path:
    """Write readings of ``actuator`` in the format :func:`read_measurements` reads for it.

    Parameters
    ----------
    rows : pandas.DataFrame
        ``actuator_id``, the actuator's design parameters (its names and units),
        its pressure column (its unit) and ``angle_deg``, one row per reading
        (written under the actuator's own angle column).
    actuator : Actuator
    path : path
        The CSV file, written atomically.
    metadata : mapping of str to str, optional
        ``# key: value`` lines (:data:`METADATA_KEYS`: ``synthetic``, ``note`` ...).

    Returns
    -------
    pathlib.Path
        The file written.
    """
    columns = ["actuator_id", *actuator.names, actuator.pressure_column, "angle_deg"]
    own = MEASUREMENT_WRITERS.get(actuator.name)
    if own is not None and own[0] == actuator:
        return own[1](rows[columns], path, dict(metadata or {}))
    plain = rows[columns].rename(columns={"angle_deg": actuator.angle_column})
    return _write_plain(plain, path, dict(metadata or {}))


def read_measurements(
    paths: str | os.PathLike[str] | Sequence[str | os.PathLike[str]], actuator: Actuator
) -> Measurements | ActuatorMeasurements:
    """Read one or more measurement files of ``actuator``, in its format.

    Paper B's actuator reads its own CSV format (:func:`load_measurements_files`,
    :data:`MEASUREMENT_READERS`); any other the plain CSV of its description
    (:func:`load_actuator_measurements`).
    """
    files = [paths] if isinstance(paths, str | os.PathLike) else list(paths)
    own = MEASUREMENT_READERS.get(actuator.name)
    if own is not None and own[0] == actuator:
        return own[1](files)
    return load_actuator_measurements(files, actuator)
