"""Measured bending curves of any described actuator, from a plain CSV.

A lab refining a surrogate of its own actuator (one trained on its simulation
table, :mod:`softbend.surrogates.tables`) measures a few built actuators and
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

:class:`ActuatorMeasurements` offers what transfer learning reads from paper
B's :class:`~softbend.transfer.measurements.Measurements`: ``features`` (the
model's inputs), ``angle_deg``, ``groups``, ``actuator_ids``, ``subset``,
``per_actuator``, ``synthetic`` and ``provenance``.
"""

from __future__ import annotations

import os
from collections.abc import Iterable, Mapping, Sequence
from dataclasses import dataclass, field
from pathlib import Path

import numpy as np
import pandas as pd

from softbend.actuators import Actuator, ActuatorError
from softbend.errors import DatasetError
from softbend.tables import Column, Table, TableFormat, read_table

__all__ = [
    "ACTUATOR_COLUMN",
    "ActuatorMeasurements",
    "load_actuator_measurements",
    "measurement_format",
]

#: The column naming the built actuator of each reading.
ACTUATOR_COLUMN = "actuator"
#: The names the id column may have: a file gives one of them, or none (one actuator, the
#: file's stem).
ID_COLUMNS: tuple[str, ...] = (ACTUATOR_COLUMN, "actuator_id")


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
