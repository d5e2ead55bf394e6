"""Identification experiments of the curling actuator and their CSV format.

An experiment is what paper A records (§4.1): the commanded pressure and the tip
position ``(x, y)`` measured by a camera, sampled in time. Bending grade ``rho``
and arc length ``L`` follow from the tip by constant-curvature kinematics
(paper A eqs. 16–17, :func:`softbend.kinematics.bending_from_tip`).

CSV format
----------
One header row and one row per sample::

    # synthetic: false
    # rest_length_mm: 15.25
    time_s,pressure_kpa,x_mm,y_mm
    0.0,0.0,0.0,0.0
    0.02,12.5,0.41,0.03

Required columns ``time_s`` (s), ``pressure_kpa`` (kPa gauge, commanded),
``x_mm`` and ``y_mm`` (tip position, mm, in the frame of paper A eq. 12: the tip
at rest at the origin, ``y`` towards the base). An optional ``experiment``
column holds several experiments in one file; without it the file stem is the
experiment's name. Other columns are ignored. Lines starting with ``#`` are
comments; ``# key: value`` comments before the header set ``synthetic``,
``rest_length_mm`` and ``metadata`` (a JSON object). Errors point at rows as
an editor shows them: row 1 is the first line of the file, comments included.
A file is refused before its rows are parsed when it exceeds the ``file_mib``
or ``csv_rows`` limit of :mod:`softbend.limits`, and a value outside the
plausible range of its column (:mod:`softbend.plausibility`) is an error naming
the file, line and column.
"""

from __future__ import annotations

import csv
import json
import logging
import math
import os
import re
import tempfile
from collections.abc import Iterable
from dataclasses import dataclass, field
from pathlib import Path
from typing import TYPE_CHECKING, Any, Literal

import numpy as np
from numpy.typing import ArrayLike

from softbend._io import new_file_mode
from softbend._jsontext import check_json_nesting
from softbend._validation import check_range, must_be
from softbend.errors import DatasetError, LimitError, keyed
from softbend.kinematics import bending_from_tip
from softbend.limits import check_file_size
from softbend.tables import (
    Column,
    HeaderKey,
    Table,
    TableFormat,
    not_increasing,
    not_increasing_text,
    read_table,
)

if TYPE_CHECKING:
    import pandas as pd

logger = logging.getLogger(__name__)

#: Columns every experiment CSV must have, in the order they are written.
REQUIRED_COLUMNS: tuple[str, ...] = ("time_s", "pressure_kpa", "x_mm", "y_mm")
#: Optional column naming the experiment of each row.
EXPERIMENT_COLUMN = "experiment"
#: Default rest length of paper A's curling actuator, mm.
DEFAULT_REST_LENGTH_MM = 15.25
#: The plausible range (:mod:`softbend.plausibility`) of each required column.
COLUMN_QUANTITIES: dict[str, str] = {
    "time_s": "time_s",
    "pressure_kpa": "pressure_kpa",
    "x_mm": "coordinate_mm",
    "y_mm": "coordinate_mm",
}

_FORMAT_LINE = "softbend experiment CSV v1"
_SAFE_NAME = re.compile(r"[A-Za-z0-9][A-Za-z0-9._-]*")


def _readonly(values: ArrayLike, name: str) -> np.ndarray:
    array = np.array(values, dtype=float)  # a private copy
    if array.ndim != 1:
        raise DatasetError(
            f"The '{name}' of Experiment must be a 1-D array. Got shape {array.shape} instead."
        )
    array.flags.writeable = False
    return array


@dataclass(frozen=True, eq=False)
class Experiment:
    """One time series of commanded pressure and measured tip position.

    Parameters
    ----------
    name : str
        Name of the experiment (non-empty).
    time_s : array_like
        Sample times, s; strictly increasing.
    pressure_kpa : array_like
        Commanded gauge pressure, kPa (negative under vacuum).
    x_mm, y_mm : array_like
        Tip position, mm, in the frame of paper A eq. 12 (tip at rest at the
        origin, ``x`` sideways with the sign of the bending, ``y`` towards the base).
    rest_length_mm : float
        Rest length ``L0`` of the actuator, mm.
    synthetic : bool
        True for generated data (never a measurement).
    metadata : dict
        Free-form, JSON-serializable provenance (copied).

    Raises
    ------
    DatasetError
        Columns of different lengths, fewer than 3 samples, a non-finite value
        (naming the column and the first bad sample index), time not strictly
        increasing, or a tip position no constant-curvature arc of positive
        length reaches.
    ValueError
        Empty name or non-positive rest length.

    Notes
    -----
    The arrays are stored as read-only float copies; ``rho`` and ``length_mm``
    are computed once, on construction. Two experiments compare equal when
    every field is identical (arrays element by element).
    """

    name: str
    time_s: np.ndarray
    pressure_kpa: np.ndarray
    x_mm: np.ndarray
    y_mm: np.ndarray
    rest_length_mm: float = DEFAULT_REST_LENGTH_MM
    synthetic: bool = False
    metadata: dict[str, Any] = field(default_factory=dict)
    #: Computed in __post_init__ (read them as ``rho`` and ``length_mm``).
    _rho: np.ndarray = field(init=False, repr=False, compare=False)
    _length_mm: np.ndarray = field(init=False, repr=False, compare=False)

    def __post_init__(self) -> None:
        if not isinstance(self.name, str) or not self.name.strip():
            raise ValueError(
                f"The 'name' of Experiment must be a non-empty string. Got {self.name!r} instead."
            )
        object.__setattr__(
            self,
            "rest_length_mm",
            check_range(self.rest_length_mm, "rest_length_mm", low=0.0, high=math.inf),
        )
        object.__setattr__(self, "synthetic", bool(self.synthetic))
        object.__setattr__(self, "metadata", dict(self.metadata or {}))
        columns = {}
        for column in REQUIRED_COLUMNS:
            columns[column] = _readonly(getattr(self, column), column)
            object.__setattr__(self, column, columns[column])
        lengths = {column: values.size for column, values in columns.items()}
        if len(set(lengths.values())) > 1:
            detail = ", ".join(f"{c}: {n}" for c, n in lengths.items())
            raise DatasetError(
                f"The columns of Experiment {self.name!r} must have equal lengths. "
                f"Got {detail} instead."
            )
        if lengths["time_s"] < 3:
            raise DatasetError(
                f"Experiment {self.name!r} must have at least 3 samples. "
                f"Got {lengths['time_s']} instead."
            )
        for column, values in columns.items():
            bad = ~np.isfinite(values)
            if bad.any():
                row = int(np.flatnonzero(bad)[0])
                raise DatasetError(
                    f"The '{column}' of Experiment {self.name!r} must be finite. "
                    f"Got {float(values[row])!r} at sample {row} "
                    f"({int(bad.sum())} non-finite in all)."
                )
        late = not_increasing(columns["time_s"])
        if late is not None:
            text = not_increasing_text(columns["time_s"], late, f"sample {late - 1}", self.name)
            raise DatasetError(text, key="time_s")
        try:
            rho, length = bending_from_tip(
                columns["x_mm"], columns["y_mm"], rest_length_mm=self.rest_length_mm
            )
        except DatasetError as exc:
            raise DatasetError(
                f"The tip of Experiment {self.name!r} must be reachable by a constant-curvature "
                f"arc of rest length {self.rest_length_mm:g} mm: {exc}"
            ) from None
        object.__setattr__(self, "_rho", _readonly(rho, "rho"))
        object.__setattr__(self, "_length_mm", _readonly(length, "length_mm"))

    def __eq__(self, other: object) -> bool:
        if not isinstance(other, Experiment):
            return NotImplemented
        return (
            self.name == other.name
            and self.rest_length_mm == other.rest_length_mm
            and self.synthetic == other.synthetic
            and self.metadata == other.metadata
            and all(np.array_equal(getattr(self, c), getattr(other, c)) for c in REQUIRED_COLUMNS)
        )

    __hash__ = None  # type: ignore[assignment]

    @property
    def rho(self) -> np.ndarray:
        """Bending grade ``theta/(2 pi)`` from the tip position (paper A eq. 16), signed."""
        return self._rho

    @property
    def length_mm(self) -> np.ndarray:
        """Arc length from the tip position (paper A eq. 17), mm."""
        return self._length_mm

    @property
    def n_samples(self) -> int:
        """Number of samples."""
        return int(self.time_s.size)

    @property
    def dt_s(self) -> float:
        """Median sample interval, s."""
        return float(np.median(np.diff(self.time_s)))

    @property
    def sign(self) -> Literal["positive", "negative"]:
        """``"negative"`` if the pressure of largest magnitude is a vacuum, else ``"positive"``."""
        extreme = self.pressure_kpa[int(np.argmax(np.abs(self.pressure_kpa)))]
        return "negative" if extreme < 0 else "positive"

    def to_frame(self) -> pd.DataFrame:
        """The samples as a table.

        Returns
        -------
        pandas.DataFrame
            Columns ``experiment``, ``time_s``, ``pressure_kpa``, ``x_mm``,
            ``y_mm``, ``rho`` and ``length_mm``.
        """
        import pandas as pd

        return pd.DataFrame(
            {
                EXPERIMENT_COLUMN: self.name,
                "time_s": self.time_s,
                "pressure_kpa": self.pressure_kpa,
                "x_mm": self.x_mm,
                "y_mm": self.y_mm,
                "rho": self.rho,
                "length_mm": self.length_mm,
            }
        )


# --------------------------------------------------------------------- loading
def _is_flag(text: str) -> bool:
    return text.lower() in ("true", "false")


def _is_length(text: str) -> bool:
    try:
        return 0.0 < float(text) < math.inf
    except ValueError:
        return False


#: The experiment CSV as :mod:`softbend.tables` reads it: the required columns
#: with their plausible ranges, the optional experiment column, the header keys
#: (in any case; other keys are remarks) and other columns ignored.
EXPERIMENT_FORMAT = TableFormat(
    name="experiment CSV",
    columns=(
        *(
            Column(name, unit, quantity=COLUMN_QUANTITIES[name], increasing=name == "time_s")
            for name, unit in zip(REQUIRED_COLUMNS, ("s", "kPa", "mm", "mm"), strict=True)
        ),
        Column(EXPERIMENT_COLUMN, kind="text", required=False),
    ),
    header=(
        HeaderKey("synthetic", "true or false", _is_flag),
        HeaderKey("rest_length_mm", "a positive number (mm)", _is_length, quantity="length_mm"),
        HeaderKey("metadata", "a JSON object"),
    ),
    other_keys="ignore",
    other_columns="ignore",
    fold_keys=True,
    repeated_keys=True,
    group=EXPERIMENT_COLUMN,
)


def _metadata(table: Table) -> dict[str, Any]:
    """The ``# metadata`` line of a file as a JSON object (empty without one)."""
    if "metadata" not in table.header:
        return {}
    value = table.header["metadata"]
    line = table.header_lines["metadata"]
    with keyed("metadata", file=table.file):
        try:
            check_json_nesting(value, "the value")
        except LimitError as error:
            error.line = line
            raise
    try:
        metadata = json.loads(value)
    except json.JSONDecodeError as exc:
        raise DatasetError(
            f"must be a JSON object; got invalid JSON ({exc.msg})",
            key="metadata",
            file=table.file,
            line=line,
        ) from None
    except RecursionError:
        raise DatasetError(
            "is nested too deeply to read", key="metadata", file=table.file, line=line
        ) from None
    if not isinstance(metadata, dict):
        raise DatasetError(
            must_be("a JSON object", value), key="metadata", file=table.file, line=line
        )
    return metadata


def _read_csv(path: Path, rest_length_mm: float | None) -> list[Experiment]:
    table = read_table(path, EXPERIMENT_FORMAT)
    metadata = _metadata(table)
    frame = table.frame
    if EXPERIMENT_COLUMN in frame.columns:
        names = frame[EXPERIMENT_COLUMN].to_numpy(dtype=object)
    else:
        names = np.full(len(frame), path.stem, dtype=object)
    rest = (
        rest_length_mm
        if rest_length_mm is not None
        else float(table.header.get("rest_length_mm", DEFAULT_REST_LENGTH_MM))
    )
    synthetic = table.header.get("synthetic", "false").lower() == "true"
    columns = {c: frame[c].to_numpy(dtype=np.float64) for c in REQUIRED_COLUMNS}
    experiments = []
    for name in dict.fromkeys(names.tolist()):
        rows = np.flatnonzero(names == name)
        times = columns["time_s"][rows]  # increasing: held so by EXPERIMENT_FORMAT
        if rows.size < 3:
            raise DatasetError(
                f"experiment {name!r} has {rows.size} sample(s); at least 3 are needed",
                file=table.file,
            )
        x, y = columns["x_mm"][rows], columns["y_mm"][rows]
        try:
            experiment = Experiment(
                name=name,
                time_s=times,
                pressure_kpa=columns["pressure_kpa"][rows],
                x_mm=x,
                y_mm=y,
                rest_length_mm=rest,
                synthetic=synthetic,
                metadata=metadata,
            )
        except DatasetError:
            # Columns were checked above, so the tip is out of reach: find its row.
            for k in range(rows.size):
                try:
                    bending_from_tip(x[k], y[k], rest_length_mm=rest)
                except DatasetError:
                    raise table.error(
                        f"the tip (x_mm={float(x[k])!r}, y_mm={float(y[k])!r}) of experiment "
                        f"{name!r} is not reachable by a constant-curvature arc of rest length "
                        f"{rest:g} mm",
                        row=int(rows[k]),
                        column="x_mm",
                    ) from None
            raise
        except ValueError as exc:
            raise DatasetError(f"experiment {name!r}: {exc}", file=table.file) from None
        experiments.append(experiment)
    return experiments


def experiment_files(path: str | os.PathLike[str]) -> list[Path]:
    """The CSV files :func:`load_experiments` reads from ``path``, their sizes checked.

    Parameters
    ----------
    path : str or path-like
        A CSV file, or a folder whose ``*.csv`` files are taken in sorted name order.

    Returns
    -------
    list of pathlib.Path
        The files, none of them over the ``file_mib`` limit of :mod:`softbend.limits`.

    Raises
    ------
    DatasetError
        The path does not exist, or the folder has no CSV files.
    LimitError
        A file is larger than the ``file_mib`` limit (the message names it).
    """
    source = Path(path)
    if not source.exists():
        raise DatasetError(f"Experiment file or folder not found: {source}.")
    if source.is_dir():
        files = sorted(p for p in source.iterdir() if p.is_file() and p.suffix.lower() == ".csv")
        if not files:
            raise DatasetError(f"The folder {source} has no CSV files (*.csv).")
    else:
        files = [source]
    for file in files:
        check_file_size(file)
    return files


def load_experiments(
    path: str | os.PathLike[str], *, rest_length_mm: float | None = None
) -> list[Experiment]:
    """Read experiments from a CSV file or from every ``*.csv`` file in a folder.

    Parameters
    ----------
    path : str or path-like
        A CSV file in the format of this module, or a folder whose CSV files
        are read in sorted name order.
    rest_length_mm : float, optional
        Rest length ``L0``, mm, overriding the files' ``# rest_length_mm``
        comment; default: that comment, else 15.25 (paper A).

    Returns
    -------
    list of Experiment
        In file order, and within a file in order of first appearance.

    Raises
    ------
    DatasetError
        One line naming the file and, where it applies, the column, the row (as
        an editor numbers the file's lines) and the experiment: path not found,
        folder without CSV files, empty file, missing columns, a non-numeric,
        empty, NaN or infinite value, a value outside its column's plausible
        range (:mod:`softbend.plausibility`: ``time_s`` as time, ``pressure_kpa``
        as gauge pressure in kPa, ``x_mm`` and ``y_mm`` as positions), time not
        strictly increasing, fewer than 3 samples, or the same experiment name twice.
    LimitError
        A file over the ``file_mib`` limit or with more data rows than the
        ``csv_rows`` limit of :mod:`softbend.limits` (checked before its rows
        are parsed), or a ``# metadata`` comment nested deeper than ``nesting``.
    """
    if rest_length_mm is not None:
        rest_length_mm = check_range(rest_length_mm, "rest_length_mm", low=0.0, high=math.inf)
    source = Path(path)
    files = experiment_files(source)
    experiments: list[Experiment] = []
    seen: dict[str, Path] = {}
    for file in files:
        for experiment in _read_csv(file, rest_length_mm):
            if experiment.name in seen:
                raise DatasetError(
                    f"experiment {experiment.name!r} was already read from "
                    f"{seen[experiment.name]}; experiment names must be unique",
                    file=str(file),
                )
            seen[experiment.name] = file
            experiments.append(experiment)
    logger.debug("Loaded %d experiment(s) from %s.", len(experiments), source)
    return experiments


# ---------------------------------------------------------------------- saving
def _file_stem(name: str) -> str:
    """A file name for an experiment: the name itself if safe, else a sanitized form."""
    if _SAFE_NAME.fullmatch(name):
        return name
    stem = re.sub(r"[^A-Za-z0-9._-]+", "_", name).strip("._-")
    return stem or "experiment"


def _format(value: float) -> str:
    """Shortest text that parses back to the identical float."""
    return repr(float(value))


def _header_lines(experiment: Experiment) -> list[str]:
    lines = [f"# {_FORMAT_LINE}"]
    if experiment.synthetic:
        label = experiment.metadata.get("label", "SYNTHETIC DATA generated by softbend")
        lines.append(f"# {label}".replace("\n", " "))
    lines.append(f"# synthetic: {'true' if experiment.synthetic else 'false'}")
    lines.append(f"# rest_length_mm: {_format(experiment.rest_length_mm)}")
    if experiment.metadata:
        text = json.dumps(experiment.metadata, sort_keys=True, default=str, ensure_ascii=True)
        lines.append(f"# metadata: {text}")
    return lines


def save_experiments(
    experiments: Experiment | Iterable[Experiment], path: str | os.PathLike[str]
) -> list[Path]:
    """Write each experiment to its own CSV file in a folder.

    Parameters
    ----------
    experiments : Experiment or iterable of Experiment
        What to write.
    path : str or path-like
        Folder for the files (created if missing). Each file is
        ``<name>.csv``; a name that is not a safe file name is sanitized and
        kept exactly in an ``experiment`` column.

    Returns
    -------
    list of pathlib.Path
        The files written, in the order of ``experiments``.

    Notes
    -----
    Floats are written with :func:`repr`, the shortest text that parses back
    to the same double, so :func:`load_experiments` returns experiments equal
    to the ones saved (metadata round-trips as JSON). Header comments record
    ``synthetic``, the rest length and the metadata; synthetic data get a
    label line. Each file is written to a temporary file in the same folder and
    moved into place with :func:`os.replace`, so a reader never sees half a file.
    """
    items = [experiments] if isinstance(experiments, Experiment) else list(experiments)
    for item in items:
        if not isinstance(item, Experiment):
            raise ValueError(
                "The 'experiments' of save_experiments must be Experiment objects. "
                f"Got {type(item).__name__} instead."
            )
    folder = Path(path)
    if folder.exists() and not folder.is_dir():
        raise ValueError(
            f"The 'path' of save_experiments must be a folder. Got the file {folder} instead."
        )
    stems: dict[str, str] = {}
    for item in items:
        stem = _file_stem(item.name)
        if stem.lower() in stems:
            raise ValueError(
                f"The 'experiments' of save_experiments must have distinct file names. "
                f"Got {item.name!r} and {stems[stem.lower()]!r}, both written as {stem}.csv."
            )
        stems[stem.lower()] = item.name
    folder.mkdir(parents=True, exist_ok=True)
    written = []
    for item in items:
        stem = _file_stem(item.name)
        target = folder / f"{stem}.csv"
        named = stem != item.name
        header = list(REQUIRED_COLUMNS) + ([EXPERIMENT_COLUMN] if named else [])
        descriptor, temporary = tempfile.mkstemp(prefix=f".{stem}.", suffix=".tmp", dir=folder)
        try:
            os.chmod(temporary, new_file_mode(target))  # as a plain open would, not 0600
            with os.fdopen(descriptor, "w", encoding="utf-8", newline="") as handle:
                for line in _header_lines(item):
                    handle.write(line + "\n")
                writer = csv.writer(handle, lineterminator="\n")
                writer.writerow(header)
                for row in zip(*(getattr(item, c) for c in REQUIRED_COLUMNS), strict=True):
                    cells = [_format(v) for v in row]
                    writer.writerow([*cells, item.name] if named else cells)
                handle.flush()
                os.fsync(handle.fileno())
            os.replace(temporary, target)
        except BaseException:
            Path(temporary).unlink(missing_ok=True)
            raise
        written.append(target)
    logger.debug("Saved %d experiment(s) to %s.", len(written), folder)
    return written
