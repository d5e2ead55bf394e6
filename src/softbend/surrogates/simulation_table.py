"""Training data from any actuator's simulation table (CSV, Parquet or a campaign database).

A lab whose actuator softbend's FEM does not model exports its own
simulations (Abaqus, SOFA, COMSOL, FEBio) as one row per (design, pressure):
the design parameters, the gauge pressure and the bending angle in degrees.
:func:`table_training_data` reads such a table by the names of its columns,
describes the actuator from them (or checks them against a registered
description, :mod:`softbend.actuators`), and returns the
:class:`~softbend.surrogates.features.TrainingData` the surrogate search
takes, grouped by design for cross-validation.

Rules
-----
- Pressure units: kPa, MPa, bar or psi (:data:`softbend.actuators.PRESSURE_UNITS`);
  the model keeps the table's unit and records it.
- Angles in degrees. A column named ``*_rad``, or angles that never exceed a
  full turn in radians (2π·1.05 ≈ 6.6) while the table spans more than one
  design, are refused with the factor 180/π in the message.
- A negative angle is valid (a pre-curved actuator bends back at zero pressure).
- Rows with a missing or non-finite value are left out and counted.
- A design is one distinct combination of the design columns; a ``design_id``
  column, when present, is used instead.
"""

from __future__ import annotations

import math
import os
from collections.abc import Sequence
from pathlib import Path
from typing import TYPE_CHECKING

import numpy as np

from softbend._progress import read_phase, report
from softbend._validation import must_be, short_repr
from softbend.actuators import Actuator, ActuatorError, parse_ranges, pressure_to_mpa
from softbend.errors import DatasetError
from softbend.limits import check_file_size
from softbend.surrogates.features import GROUP, TrainingData, data_hash
from softbend.tables import (
    Column,
    Table,
    TableFormat,
    check_columns,
    column_kind,
    infer_cells,
    kind_conflict,
    reads_as_number,
)
from softbend.tables import read_table as read_csv_table
from softbend.units import check_column_unit

if TYPE_CHECKING:
    import pandas as pd

__all__ = ["TABLE_SUFFIXES", "read_table", "table_training_data"]

#: File suffixes read as tables (anything else must be a campaign database).
TABLE_SUFFIXES: tuple[str, ...] = (".csv", ".parquet", ".pq")
#: The most rows a training table may have.
MAX_ROWS = 5_000_000
_RADIAN_MAX = 2.0 * math.pi * 1.05


#: A simulation table as :mod:`softbend.tables` reads a CSV of it: any columns,
#: each read as numbers where every filled cell is one, else as text (empty
#: cells NaN); ``# key: value`` lines are remarks.
SIMULATION_TABLE = TableFormat(
    name="simulation table", columns=(), other_columns="keep", max_rows=MAX_ROWS
)


def read_table(path: str | os.PathLike[str]) -> pd.DataFrame:
    """A CSV (``#`` comment lines allowed) or Parquet file as a DataFrame, or one clear error.

    A CSV goes through :func:`softbend.tables.read_table`; a Parquet file is
    read by pandas. Both hold at most :data:`MAX_ROWS` rows. A column of text
    whose every filled cell reads as a number is read as numbers, in a Parquet
    file as in a CSV. A large file reports its progress from the start of the
    read (:func:`softbend._progress.read_phase`).
    """
    return _read(Path(path))[0]


def _read(source: Path) -> tuple[pd.DataFrame, Table | None]:
    """:func:`read_table`'s frame, and for a CSV the table that knows each row's line."""
    import pandas as pd

    if not source.is_file():
        raise FileNotFoundError(f"No table at {source}.")
    check_file_size(source, str(source))
    suffix = source.suffix.lower()
    if suffix == ".csv":
        table = read_csv_table(source, SIMULATION_TABLE)
        return table.frame, table
    if suffix not in (".parquet", ".pq"):
        raise DatasetError(
            f"a training table must be a CSV or Parquet file ({', '.join(TABLE_SUFFIXES)}) "
            f"or a campaign database; got {suffix or 'no suffix'}",
            file=str(source),
        )
    phase = read_phase(source)
    if phase is not None:  # one call reads the whole file: shown from its start
        report(phase, 0, 100)
    try:
        frame = pd.read_parquet(source)
    except (OSError, ValueError) as err:  # pyarrow: not a Parquet file
        raise DatasetError(
            f"is not a readable {suffix[1:]} table ({err})", file=str(source)
        ) from None
    if phase is not None:
        report(phase, 100, 100)
    if len(frame) > MAX_ROWS:
        raise DatasetError(
            f"has {len(frame)} rows; a training table holds at most {MAX_ROWS}", file=str(source)
        )
    frame.columns = [str(c).strip() for c in frame.columns]
    for name in frame.columns:
        series = frame[name]
        if series.dtype.kind == "O" or str(series.dtype) == "string":
            cells = series.astype(object).where(series.notna(), None).tolist()
            if column_kind(cells) == "number":  # numbers written as text: numbers, as in a CSV
                frame[name] = infer_cells(cells)
    return frame, None


def _check_kinds(
    frame: pd.DataFrame,
    table: Table | None,
    designs: Sequence[str],
    actuator: Actuator | None,
    source: Path,
    numbers: Sequence[str] = (),
) -> None:
    """Each design column's cells of one kind: numbers, or text for a categorical parameter;
    each column of ``numbers`` (the pressure and the angle) numbers.

    A column is categorical when ``actuator`` declares it so or, without a
    description, when none of its filled cells is a number. The error names
    the file, the line (a Parquet file's row), the column and the cell.
    """
    for name in [*designs, *numbers]:
        kind = (
            "number"
            if name in numbers
            else actuator.parameter(name).kind
            if actuator is not None
            else None
        )
        series = frame[name]
        if kind == "categorical" or (series.dtype.kind != "O" and str(series.dtype) != "string"):
            continue
        cells = series.tolist()
        if kind is None:
            conflict = kind_conflict(cells)
            if conflict is None:
                continue  # wholly text: the levels of a categorical parameter
            row, others = conflict
            if reads_as_number(cells[row]):
                message = (
                    f"mixes numbers and text: {others} filled cells are text, this one the "
                    f"number {str(cells[row]).strip()}; a categorical column's levels are all "
                    "text (or an actuator description declares the column categorical)"
                )
            else:
                message = (
                    f"must be a number, as the column's other {others} filled cells are; got "
                    f"{short_repr(cells[row])} (a design column is categorical only when none "
                    "of its cells is a number, or when an actuator description declares it so)"
                )
        else:
            row = next(
                (i for i, c in enumerate(cells) if isinstance(c, str) and not reads_as_number(c)),
                -1,
            )
            if row < 0:
                continue
            declared = (
                f" (the actuator {actuator.name} declares {name} {kind})"
                if actuator is not None and name not in numbers
                else ""
            )
            message = f"must be a number{declared}; got {short_repr(cells[row])}"
        if table is not None:
            raise table.error(message, row=row, column=name)
        raise DatasetError(f"row {row}: {message}", key=name, file=str(source))


def _columns(text: str | Sequence[str], key: str) -> list[str]:
    """Column names given as ``"a,b,c"`` or a sequence; ``key`` is the parameter."""
    names = [c.strip() for c in text.split(",")] if isinstance(text, str) else list(text)
    if not names or any(not n for n in names):
        raise ActuatorError(must_be("comma-separated column names", text), key=key)
    repeated = sorted({n for n in names if names.count(n) > 1})
    if repeated:
        raise ActuatorError(f"names {', '.join(repeated)} twice", key=key)
    return names


def _check_present(frame: pd.DataFrame, names: Sequence[str], key: str, source: str) -> None:
    missing = [n for n in names if n not in frame.columns]
    if missing:
        raise ActuatorError(
            f"names no column {', '.join(map(repr, missing))} of {source}; its columns are "
            f"{', '.join(map(str, frame.columns))}",
            key=key,
        )


def table_training_data(
    path: str | os.PathLike[str],
    *,
    design_columns: str | Sequence[str] | None = None,
    pressure_column: str | None = None,
    pressure_unit: str | None = None,
    angle_column: str = "angle_deg",
    actuator: Actuator | None = None,
    name: str | None = None,
    ranges: Sequence[str] = (),
) -> TrainingData:
    """The training data of a simulation table, described by its columns.

    Parameters
    ----------
    path : path
        CSV or Parquet file, one row per (design, pressure).
    design_columns : str or sequence of str, optional
        The design parameters' columns, in model-input order (``"A,B,C"``);
        default: ``actuator``'s parameters.
    pressure_column : str, optional
        The gauge-pressure column (default: ``actuator``'s).
    pressure_unit : {"kPa", "MPa", "bar", "psi"}, optional
        Its unit (default: ``actuator``'s; required without one).
    angle_column : str, default "angle_deg"
        The bending-angle column, degrees.
    actuator : Actuator, optional
        A registered description the table must fit: its columns are the
        defaults, and every design must lie in its ranges, kinds and constraints.
        Without one, the description is read off the table
        (:meth:`~softbend.actuators.Actuator.from_table`).
    name : str, optional
        The described actuator's name (default: the file's stem).
    ranges : sequence of str, optional
        Declared ranges ``NAME=LOW:HIGH`` of design parameters of a description
        read off the table (:func:`~softbend.actuators.parse_ranges`); a
        parameter not named keeps the table's span as its sampled range, which
        a model flags (not refuses) a design outside of.

    Raises
    ------
    softbend.actuators.ActuatorError
        A missing column (naming it and the table's columns), a unit not one of
        the four, a design outside ``actuator``'s description, radians; the key
        is the parameter at fault (``design_columns``, ``pressure_unit``, ...).
    softbend.errors.InputError
        A pressure column whose name carries a unit other than the one given
        (``pressure_psi`` in kPa; :func:`softbend.units.check_column_unit`), key
        ``pressure_unit``.
    softbend.errors.DatasetError
        An unreadable file, no usable row, or a pressure or angle column that
        is not numbers or a negative pressure (:func:`softbend.tables.check_columns`).
    """
    import pandas as pd

    source = Path(path)
    if actuator is not None:
        if ranges:
            raise ActuatorError(
                f"declares ranges of a description read off the table; the actuator "
                f"{actuator.name}'s description declares its own (leave out one of the two)",
                key="ranges",
            )
        designs = _columns(design_columns or actuator.names, "design_columns")
        if designs != list(actuator.names):
            raise ActuatorError(
                f"must be those of the actuator {actuator.name} ({','.join(actuator.names)}); "
                f"got {','.join(designs)}",
                key="design_columns",
            )
        pressure_column = pressure_column or actuator.pressure_column
        unit = pressure_unit or actuator.pressure_unit
        if unit != actuator.pressure_unit:
            raise ActuatorError(
                f"must be that of the actuator {actuator.name} ({actuator.pressure_unit}); "
                f"got {unit}",
                key="pressure_unit",
            )
    else:
        if design_columns is None:
            raise ActuatorError(
                f"is required to train on the table {source} (the design parameters' columns, "
                "such as n_chambers,wall_mm)",
                key="design_columns",
            )
        designs = _columns(design_columns, "design_columns")
        if pressure_column is None:
            raise ActuatorError(
                f"is required to train on the table {source}", key="pressure_column"
            )
        if pressure_unit is None:
            raise ActuatorError(
                f"is required to train on the table {source} (kPa, MPa, bar or psi)",
                key="pressure_unit",
            )
        unit = pressure_unit
    declared = parse_ranges(ranges, designs)
    pressure_to_mpa(unit)
    if angle_column.lower().endswith("_rad"):
        raise ActuatorError(
            f"{angle_column!r} looks like radians; softbend learns angles in degrees: multiply "
            "by 180/π (57.2958) and name the column e.g. angle_deg",
            key="angle_column",
        )
    for key, column in (("pressure_column", pressure_column), ("angle_column", angle_column)):
        if column in designs:
            raise ActuatorError(
                f"{column!r} is also one of the design columns ({','.join(designs)})", key=key
            )
    frame, table = _read(source)
    _check_present(frame, designs, "design_columns", str(source))
    _check_present(frame, [pressure_column], "pressure_column", str(source))
    _check_present(frame, [angle_column], "angle_column", str(source))
    check_column_unit(pressure_column, unit, "pressure_unit", key="pressure_unit")
    describing = f"describing {source.name}'s designs" if read_phase(source) else None
    if describing is not None:  # a large table: what follows its read takes seconds too
        report(describing, 0, 3)
    _check_kinds(frame, table, designs, actuator, source, (pressure_column, angle_column))
    check_columns(
        frame,
        TableFormat(
            name="simulation table",
            columns=(
                Column(pressure_column, unit, low=0.0, missing=True),
                Column(angle_column, "deg", missing=True),
            ),
        ),
        file=str(source),
    )
    if actuator is None:
        actuator = Actuator.from_table(
            frame,
            design_columns=designs,
            pressure_column=pressure_column,
            pressure_unit=unit,
            angle_column=angle_column,
            name=name or _name_of(source),
            title=f"the actuator of {source.name}",
            ranges=declared,
        )
    if describing is not None:
        report(describing, 1, 3)
    codes = np.empty((len(frame), len(designs)))
    for j, parameter in enumerate(actuator.parameters):
        column = frame[parameter.name]
        if parameter.kind == "categorical":
            codes[:, j] = [
                parameter.encode(v) if isinstance(v, str) or not _missing(v) else np.nan
                for v in column
            ]
        else:
            if column.dtype.kind not in "iuf":
                raise ActuatorError(
                    must_be(f"numbers ({parameter.kind})", f"values such as {column.iloc[0]!r}"),
                    key=parameter.name,
                    file=str(source),
                )
            codes[:, j] = column.to_numpy(dtype=np.float64, na_value=np.nan)
    pressures = frame[pressure_column].to_numpy(dtype=np.float64, na_value=np.nan)
    angles = frame[angle_column].to_numpy(dtype=np.float64, na_value=np.nan)
    keep = np.isfinite(codes).all(axis=1) & np.isfinite(pressures) & np.isfinite(angles)
    if not keep.any():
        raise DatasetError(
            f"has no row with finite {', '.join([*designs, pressure_column, angle_column])} "
            f"({len(frame)} rows in all)",
            file=str(source),
        )
    every = bool(keep.all())  # the usual table: no row dropped, no copies
    if not every:
        codes, pressures, angles = codes[keep], pressures[keep], angles[keep]
    try:
        actuator.check_designs(codes)
    except ActuatorError as err:
        raise ActuatorError(err.detail, file=str(source)) from None
    if describing is not None:
        report(describing, 2, 3)
    if GROUP in frame.columns:
        names = frame[GROUP].to_numpy()
        if names.dtype != object or pd.api.types.infer_dtype(names, skipna=False) != "string":
            names = frame[GROUP].astype(str).to_numpy()
        groups = names.copy() if every else names[keep]  # not a view of the frame
    else:
        _, index = np.unique(codes, axis=0, return_inverse=True)
        groups = np.array([f"d{i:05d}" for i in index.ravel()])
    if np.abs(angles).max() <= _RADIAN_MAX and np.any(groups != groups[0]):  # two designs
        raise ActuatorError(
            f"no |angle| exceeds {np.abs(angles).max():.4g} over the whole table; they look "
            "like radians: multiply by 180/π (57.2958) for degrees",
            key=angle_column,
            file=str(source),
        )
    if describing is not None:
        report(describing, 3, 3)
    X = np.ascontiguousarray(np.column_stack([codes, pressures]))
    y = np.array(angles, dtype=np.float64)  # a copy: the column may be the frame's, read-only
    return TrainingData(
        X=X,
        y=y,
        groups=groups,
        data_hash=data_hash(X, y, groups),
        n_dropped=int((~keep).sum()),
        actuator=actuator,
    )


def _missing(value: object) -> bool:
    return value is None or (isinstance(value, float) and math.isnan(value))


def _name_of(source: Path) -> str:
    stem = "".join(c if c.isalnum() or c == "_" else "_" for c in source.stem) or "table"
    return stem if not stem[0].isdigit() else f"t_{stem}"
