"""Measured bending curves of any described actuator, from a plain CSV.

A lab refining a surrogate of its own actuator (one trained on its simulation
table, :mod:`softbend.surrogates.tables`) measures a few built actuators and
writes one row per reading::

    # synthetic: false
    # rig: bench 2
    actuator,n_chambers,n_layers,wall_mm,height_mm,p_kpa,angle_deg
    A1,10,2,2.0,12,0,0.4
    A1,10,2,2.0,12,20,41.8

Columns: ``actuator`` (the id of the built actuator), the model's design
columns (its :class:`~softbend.actuators.Actuator` parameters, categorical
ones by level), its pressure column in its unit and its angle column, in
degrees. Nothing else: a file that lacks a design column, or names one the
model does not have, is one error naming both. The ``# key: value`` header
lines are optional (``synthetic: true`` marks simulated readings). Every design
must lie in the model's description (ranges, kinds, constraints); an actuator
has one design; pressures are finite and >= 0; angles finite, and refused when
they look like radians (no ``|angle|`` above a full turn in radians while the
pressure reaches past a tenth of the file's largest — pass ``force`` to read
them as given).

:class:`ActuatorMeasurements` offers what transfer learning reads from paper
B's :class:`~softbend.transfer.measurements.Measurements`: ``features`` (the
model's inputs), ``angle_deg``, ``groups``, ``actuator_ids``, ``subset``,
``per_actuator``, ``synthetic`` and ``provenance``.
"""

from __future__ import annotations

import math
import os
import warnings
from collections.abc import Iterable, Mapping, Sequence
from dataclasses import dataclass, field
from pathlib import Path
from typing import Any

import numpy as np
import pandas as pd

from softbend.actuators import Actuator, ActuatorError
from softbend.errors import DatasetError
from softbend.limits import check_file_size

__all__ = ["ACTUATOR_COLUMN", "ActuatorMeasurements", "load_actuator_measurements"]

#: The column naming the built actuator of each reading.
ACTUATOR_COLUMN = "actuator"
_RADIAN_MAX = 2.0 * math.pi * 1.05


@dataclass(frozen=True, eq=False)
class ActuatorMeasurements:
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

    def __len__(self) -> int:
        return len(self.frame)

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

    @property
    def angle_deg(self) -> np.ndarray:
        """Measured bending angles, degrees."""
        return self.frame["angle_deg"].to_numpy(dtype=np.float64, copy=True)

    @property
    def groups(self) -> np.ndarray:
        """Actuator id of each row, for leave-one-actuator-out."""
        return self.frame["actuator_id"].to_numpy(dtype=object, copy=True)

    @property
    def synthetic(self) -> np.ndarray:
        """Whether each reading comes from a ``# synthetic: true`` file."""
        assert self.provenance is not None
        return self.provenance["synthetic"].to_numpy(dtype=bool, copy=True)

    def per_actuator(self) -> pd.DataFrame:
        """Per actuator: ``points``, ``pmax`` (the pressure unit) and ``angle_max`` (deg)."""
        return self.frame.groupby("actuator_id", sort=False).agg(
            points=("angle_deg", "size"),
            pmax=(self.actuator.pressure_column, "max"),
            angle_max=("angle_deg", "max"),
        )

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


def _read_one(path: Path, actuator: Actuator, force: bool) -> tuple[pd.DataFrame, dict[str, str]]:
    if not path.exists():
        raise DatasetError(f"Measurement file not found: {path}.")
    if path.is_dir():
        raise DatasetError(f"{path} is a folder; a measurement CSV file is required.")
    check_file_size(path, str(path))
    try:
        text = path.read_text(encoding="utf-8-sig")
    except UnicodeDecodeError:
        raise DatasetError(f"{path} is not UTF-8 text; a measurement file is a CSV.") from None
    metadata: dict[str, str] = {}
    body: list[str] = []
    numbers: list[int] = []
    for number, line in enumerate(text.splitlines(), start=1):
        stripped = line.strip()
        if not stripped:
            continue
        if stripped.startswith("#"):
            key, sep, value = stripped[1:].partition(":")
            if sep and not body and key.strip() and " " not in key.strip():
                metadata[key.strip()] = value.strip()
            continue
        body.append(line)
        numbers.append(number)
    if not body:
        raise DatasetError(f"{path} has no header row.")
    from io import StringIO

    try:
        raw = pd.read_csv(StringIO("\n".join(body)), dtype=str, skipinitialspace=True)
    except (pd.errors.ParserError, pd.errors.EmptyDataError) as err:
        raise DatasetError(f"{path}: not a readable CSV ({err}).") from None
    raw.columns = [str(c).strip() for c in raw.columns]
    expected = [ACTUATOR_COLUMN, *actuator.names, actuator.pressure_column, actuator.angle_column]
    missing = [c for c in expected if c not in raw.columns]
    unknown = [c for c in raw.columns if c not in expected]
    if missing or unknown:
        parts = []
        if missing:
            parts.append(f"lacks the column(s) {', '.join(missing)}")
        if unknown:
            parts.append(f"has column(s) {', '.join(unknown)} the model does not know")
        raise ActuatorError(
            f"{path} {' and '.join(parts)}; a measurement file of the actuator {actuator.name} "
            f"has the columns {', '.join(expected)}."
        )
    if raw.empty:
        raise DatasetError(f"{path}: the header row is followed by no data rows.")
    line_of = dict(enumerate(numbers[1:]))
    frame = pd.DataFrame({"actuator_id": raw[ACTUATOR_COLUMN].fillna("").str.strip()})
    empty = frame["actuator_id"] == ""
    if empty.any():
        raise ActuatorError(
            f"{path}, line {line_of[int(np.argmax(empty))]}, column {ACTUATOR_COLUMN!r}: "
            "every reading names its actuator."
        )
    for parameter in actuator.parameters:
        codes = []
        for pos, cell in enumerate(raw[parameter.name].tolist()):
            where = f"{path}, line {line_of[pos]}, column {parameter.name!r}"
            if not isinstance(cell, str) or not cell.strip():
                raise ActuatorError(f"{where}: an empty cell; every reading gives its design.")
            try:
                codes.append(parameter.encode(cell.strip()))
            except ActuatorError as err:
                raise ActuatorError(f"{where}: {err}") from None
        frame[parameter.name] = np.asarray(codes, dtype=np.float64)
    for column, name in (
        (actuator.pressure_column, actuator.pressure_column),
        (actuator.angle_column, "angle_deg"),
    ):
        values = pd.to_numeric(raw[column], errors="coerce").to_numpy(dtype=np.float64)
        bad = ~np.isfinite(values)
        if bad.any():
            pos = int(np.argmax(bad))
            raise ActuatorError(
                f"{path}, line {line_of[pos]}, column {column!r}: must be a finite number; "
                f"got {raw[column].iloc[pos]!r}."
            )
        frame[name] = values
    frame["direction"] = "loading"  # a plain file records the loading branch
    pressure = frame[actuator.pressure_column].to_numpy()
    if (pressure < 0).any():
        pos = int(np.argmax(pressure < 0))
        raise ActuatorError(
            f"{path}, line {line_of[pos]}, column {actuator.pressure_column!r}: gauge pressures "
            f"are >= 0 {actuator.pressure_unit}; got {pressure[pos]:g}."
        )
    for pos, row in enumerate(frame[list(actuator.names)].to_numpy()):
        try:
            actuator.check_designs(row[None, :])
        except ActuatorError as err:
            raise ActuatorError(f"{path}, line {line_of[pos]}: {err}") from None
    angles = np.abs(frame["angle_deg"].to_numpy())
    if angles.max() <= _RADIAN_MAX and pressure.max() > 0:
        message = (
            f"{path}, column {actuator.angle_column!r}: the angles reach only {angles.max():.4g} "
            "over the whole file; they look like radians: multiply by 180/π (57.2958) for degrees"
        )
        if not force:
            raise ActuatorError(message + " (or read them as given with --force).")
        warnings.warn(message + "; read as given (force).", UserWarning, stacklevel=3)
    return frame, metadata


def load_actuator_measurements(
    paths: str | os.PathLike[str] | Sequence[str | os.PathLike[str]],
    actuator: Actuator,
    *,
    force: bool = False,
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
    for item in files:
        path = Path(item)
        frame, metadata = _read_one(path, actuator, force)
        frames.append(frame)
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
        raise ActuatorError(
            f"The actuator {twice[0]!r} has two designs in {', '.join(map(str, files))}; "
            "each built actuator has one (give the others their own ids)."
        )
    return ActuatorMeasurements(
        frame,
        actuator,
        shared or {},
        ", ".join(str(f) for f in files),
        pd.concat(provenance, ignore_index=True),
    )


def is_actuator_measurements(data: Any) -> bool:
    """Whether ``data`` holds readings of a described actuator (not paper B's format)."""
    return isinstance(data, ActuatorMeasurements)
