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

from softbend.actuators import Actuator, ActuatorError, pressure_to_mpa
from softbend.errors import DatasetError
from softbend.limits import check_file_size
from softbend.surrogates.features import GROUP, TrainingData, data_hash

if TYPE_CHECKING:
    import pandas as pd

__all__ = ["TABLE_SUFFIXES", "read_table", "table_training_data"]

#: File suffixes read as tables (anything else must be a campaign database).
TABLE_SUFFIXES: tuple[str, ...] = (".csv", ".parquet", ".pq")
#: The most rows a training table may have.
MAX_ROWS = 5_000_000
_RADIAN_MAX = 2.0 * math.pi * 1.05


def read_table(path: str | os.PathLike[str]) -> pd.DataFrame:
    """A CSV (``#`` comment lines allowed) or Parquet file as a DataFrame, or one clear error."""
    import pandas as pd

    source = Path(path)
    if not source.is_file():
        raise FileNotFoundError(f"No table at {source}.")
    check_file_size(source, str(source))
    suffix = source.suffix.lower()
    try:
        if suffix == ".csv":
            frame = pd.read_csv(source, comment="#", skipinitialspace=True)
        elif suffix in (".parquet", ".pq"):
            frame = pd.read_parquet(source)
        else:
            raise DatasetError(
                f"{source}: a training table must be a CSV or Parquet file "
                f"({', '.join(TABLE_SUFFIXES)}) or a campaign database; "
                f"got {suffix or 'no suffix'}."
            )
    except (UnicodeDecodeError, pd.errors.ParserError, pd.errors.EmptyDataError, OSError) as err:
        if isinstance(err, FileNotFoundError):
            raise
        raise DatasetError(f"{source}: not a readable {suffix[1:]} table ({err}).") from None
    except ValueError as err:  # pyarrow: not a Parquet file
        raise DatasetError(f"{source}: not a readable {suffix[1:]} table ({err}).") from None
    if len(frame) > MAX_ROWS:
        raise DatasetError(
            f"{source} has {len(frame)} rows; a training table holds at most {MAX_ROWS}."
        )
    frame.columns = [str(c).strip() for c in frame.columns]
    return frame


def _columns(text: str | Sequence[str], option: str) -> list[str]:
    names = [c.strip() for c in text.split(",")] if isinstance(text, str) else list(text)
    if not names or any(not n for n in names):
        raise ActuatorError(f"The {option} must be comma-separated column names; got {text!r}.")
    repeated = sorted({n for n in names if names.count(n) > 1})
    if repeated:
        raise ActuatorError(f"The {option} names {', '.join(repeated)} twice.")
    return names


def _check_present(frame: pd.DataFrame, names: Sequence[str], option: str, source: str) -> None:
    missing = [n for n in names if n not in frame.columns]
    if missing:
        raise ActuatorError(
            f"{source} has no column {', '.join(map(repr, missing))} (from {option}); its columns "
            f"are {', '.join(map(str, frame.columns))}."
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

    Raises
    ------
    softbend.actuators.ActuatorError
        A missing column (naming it and the table's columns), a unit not one of
        the four, a design outside ``actuator``'s description, radians.
    softbend.errors.DatasetError
        An unreadable file, or no usable row.
    """
    source = Path(path)
    frame = read_table(source)
    if actuator is not None:
        designs = _columns(design_columns or actuator.names, "--design-columns")
        if designs != list(actuator.names):
            raise ActuatorError(
                f"The --design-columns {','.join(designs)} are not those of the actuator "
                f"{actuator.name} ({','.join(actuator.names)})."
            )
        pressure_column = pressure_column or actuator.pressure_column
        unit = pressure_unit or actuator.pressure_unit
        if unit != actuator.pressure_unit:
            raise ActuatorError(
                f"The --pressure-unit {unit} is not that of the actuator {actuator.name} "
                f"({actuator.pressure_unit})."
            )
    else:
        if design_columns is None:
            raise ActuatorError(
                f"Training on the table {source} needs --design-columns (the design "
                "parameters' columns, such as n_chambers,wall_mm)."
            )
        designs = _columns(design_columns, "--design-columns")
        if pressure_column is None:
            raise ActuatorError(f"Training on the table {source} needs --pressure-column.")
        if pressure_unit is None:
            raise ActuatorError(
                f"Training on the table {source} needs --pressure-unit (kPa, MPa, bar or psi)."
            )
        unit = pressure_unit
    pressure_to_mpa(unit, field="--pressure-unit")
    if angle_column.lower().endswith("_rad"):
        raise ActuatorError(
            f"The --angle-column {angle_column!r} looks like radians; softbend learns angles "
            "in degrees: multiply by 180/π (57.2958) and name the column e.g. angle_deg."
        )
    for label, column in (("--pressure-column", pressure_column), ("--angle-column", angle_column)):
        if column in designs:
            raise ActuatorError(f"The {label} {column!r} is also one of the --design-columns.")
    _check_present(frame, designs, "--design-columns", str(source))
    _check_present(frame, [pressure_column], "--pressure-column", str(source))
    _check_present(frame, [angle_column], "--angle-column", str(source))
    for column in (pressure_column, angle_column):
        if frame[column].dtype.kind not in "iuf":
            raise ActuatorError(
                f"{source}, column {column!r} must hold numbers; got {frame[column].dtype} values "
                f"such as {frame[column].iloc[0]!r}."
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
        )
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
                    f"{source}, column {parameter.name!r} must hold numbers ({parameter.kind}); "
                    f"got values such as {column.iloc[0]!r}."
                )
            codes[:, j] = column.to_numpy(dtype=np.float64, na_value=np.nan)
    pressures = frame[pressure_column].to_numpy(dtype=np.float64, na_value=np.nan)
    angles = frame[angle_column].to_numpy(dtype=np.float64, na_value=np.nan)
    keep = np.isfinite(codes).all(axis=1) & np.isfinite(pressures) & np.isfinite(angles)
    if not keep.any():
        raise DatasetError(
            f"{source} has no row with finite "
            f"{', '.join([*designs, pressure_column, angle_column])} ({len(frame)} rows in all)."
        )
    codes, pressures, angles = codes[keep], pressures[keep], angles[keep]
    if (pressures < 0).any():
        raise ActuatorError(
            f"{source}, column {pressure_column!r}: gauge pressures must be >= 0 {unit}; "
            f"got {pressures.min():g}."
        )
    actuator.check_designs(codes, where=f"in {source}")
    if GROUP in frame.columns:
        groups = frame[GROUP].astype(str).to_numpy()[keep]
    else:
        _, index = np.unique(codes, axis=0, return_inverse=True)
        groups = np.array([f"d{i:05d}" for i in index.ravel()])
    if np.unique(groups).size > 1 and np.abs(angles).max() <= _RADIAN_MAX:
        raise ActuatorError(
            f"{source}, column {angle_column!r}: no |angle| exceeds {np.abs(angles).max():.4g} "
            "over the whole table; they look like radians: multiply by 180/π (57.2958) for "
            "degrees."
        )
    X = np.ascontiguousarray(np.column_stack([codes, pressures]))
    y = np.ascontiguousarray(angles)
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
