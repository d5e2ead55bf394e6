"""Reading and writing time series of any actuator as CSV (:class:`TimeSeriesSet`).

A recording is a CSV file, or a folder of them, with one header line and one
line per sample; the caller names the columns that are inputs and outputs::

    # rig: bench 2
    run,t_s,p1_kpa,p2_kpa,x_mm,y_mm
    a,0.0,0.0,0.0,0.0,0.0
    a,0.01,4.5,0.0,0.12,0.01

Other columns are ignored. Lines whose first non-blank character is ``#`` are
comments, and blank lines are skipped. A folder holds one experiment per
``*.csv`` file, named by its stem and read in sorted name order; an
``experiment`` column (any name, given by the caller) instead splits a file
into contiguous runs of the same value. Without a time column the sample index
(0, 1, 2, ...) is the time. Errors are one line naming the file, the line as an
editor numbers it (from 1, comments and blank lines counted) and the column.
Files are read with :func:`softbend.tables.read_table`, within the
``file_mib`` and ``csv_rows`` limits of :mod:`softbend.limits`.

:func:`save_timeseries` writes a set as one such file with an ``experiment``
column, floats as the shortest text that parses back to the same double, so
reading it again gives the same numbers bit for bit.
"""

from __future__ import annotations

import csv
import io
import logging
import os
from collections.abc import Sequence
from pathlib import Path

import numpy as np

from softbend._io import atomic_file
from softbend._validation import check_int, must_be
from softbend.errors import DatasetError, InputError
from softbend.identification.data import experiment_files
from softbend.identification.ranges import MAX_ABS_VALUE, MIN_OUTPUT_RANGE, NEAR_CONSTANT_RTOL
from softbend.identification.timeseries import Series, TimeSeriesSet
from softbend.tables import Column, Table, TableFormat, read_table

logger = logging.getLogger(__name__)

__all__ = [
    "SAMPLE_TIME_NAME",
    "check_experiments_for_lags",
    "check_holdout",
    "check_signals",
    "load_timeseries",
    "save_timeseries",
]

#: ``time_name`` of a set read without a time column (the time is the sample index).
SAMPLE_TIME_NAME = "sample"
#: Name of the experiment column :func:`save_timeseries` writes.
EXPERIMENT_COLUMN = "experiment"

_FORMAT_LINE = "softbend time series v1"


# --------------------------------------------------------------------- loading
def _names(value: str | Sequence[str], key: str) -> tuple[str, ...]:
    """Column names given as one name or a sequence of names, checked (``key`` is the parameter)."""
    names = (value,) if isinstance(value, str) else tuple(value)
    if not names or not all(isinstance(n, str) and n.strip() for n in names):
        raise InputError(must_be("one or more non-empty column names", value), key=key)
    names = tuple(n.strip() for n in names)
    duplicates = sorted({n for n in names if names.count(n) > 1})
    if duplicates:
        raise InputError(
            f"must name distinct columns; got {', '.join(duplicates)} more than once", key=key
        )
    return names


def _column(value: str | None, key: str) -> str | None:
    if value is None:
        return None
    if not isinstance(value, str) or not value.strip():
        raise InputError(must_be("a non-empty column name or None", value), key=key)
    return value.strip()


def _check_roles(
    inputs: tuple[str, ...], outputs: tuple[str, ...], time: str | None, experiment: str | None
) -> None:
    """No column may play two roles (input, output, time, experiment)."""
    roles: dict[str, str] = {}
    for role, names in (
        ("inputs", inputs),
        ("outputs", outputs),
        ("time", (time,) if time else ()),
        ("experiment", (experiment,) if experiment else ()),
    ):
        for name in names:
            if name in roles:
                raise InputError(
                    f"must not name a column that is already in {roles[name]!r}; "
                    f"got {name!r} in both",
                    key=role,
                )
            roles[name] = role


def _format(
    inputs: tuple[str, ...], outputs: tuple[str, ...], experiment: str | None, time: str | None
) -> TableFormat:
    """The time-series CSV of these columns, as :mod:`softbend.tables` reads it."""
    columns = [Column(experiment, kind="text")] if experiment else []
    columns += [Column(time, increasing=True)] if time else []
    columns += [Column(name) for name in (*inputs, *outputs)]
    return TableFormat("time-series CSV", tuple(columns), other_columns="ignore", group=experiment,
                       contiguous_groups=True)  # fmt: skip


def _runs(table: Table, column: str) -> list[tuple[str, int, int]]:
    """The runs ``(name, start, stop)`` of the experiment column (contiguous: the format's)."""
    names = table.frame[column].tolist()
    starts = [i for i in range(len(names)) if i == 0 or names[i] != names[i - 1]]
    stops = [*starts[1:], len(names)]
    return [(names[a], a, b) for a, b in zip(starts, stops, strict=True)]


def _read_file(
    path: Path,
    inputs: tuple[str, ...],
    outputs: tuple[str, ...],
    experiment: str | None,
    time: str | None,
    first: tuple[Path, tuple[str, ...]] | None,
) -> tuple[list[Series], tuple[str, ...]]:
    """The experiments of one CSV file, and its columns."""
    try:
        table = read_table(path, _format(inputs, outputs, experiment, time))
    except DatasetError as error:
        if first is not None and error.detail.startswith("lacks the column"):
            error.args = (f"{error.detail} (unlike the first file {first[0]}, which has "
                          f"{', '.join(first[1])})",)  # fmt: skip
        raise
    runs = _runs(table, experiment) if experiment else [(path.stem, 0, len(table.frame))]
    values = {c: table.frame[c].to_numpy(dtype=np.float64) for c in (*inputs, *outputs)}
    inputs_array = np.column_stack([values[c] for c in inputs])
    outputs_array = np.column_stack([values[c] for c in outputs])
    series = []
    for name, start, stop in runs:
        if time:  # increasing in each experiment: held so by the format
            times = table.frame[time].to_numpy(dtype=np.float64)[start:stop]
        else:
            times = np.arange(stop - start, dtype=np.float64)
        series.append(
            Series(
                name,
                times,
                inputs_array[start:stop],
                outputs_array[start:stop],
                source=str(path),
            )
        )
    return series, table.columns


def load_timeseries(
    path: str | os.PathLike[str],
    inputs: str | Sequence[str],
    outputs: str | Sequence[str],
    *,
    experiment: str | None = None,
    time: str | None = None,
) -> TimeSeriesSet:
    """Read the time series of any actuator from a CSV file or a folder of CSV files.

    Parameters
    ----------
    path : str or path-like
        A CSV file, or a folder whose ``*.csv`` files are read in sorted name
        order, each file one experiment named by its stem (unless
        ``experiment`` is given). See the module docstring for the format.
    inputs, outputs : str or sequence of str
        The columns of the inputs and of the outputs, in the order the set keeps
        them; at least one each, no column in both. Values in the columns' units.
    experiment : str, optional
        Column naming the experiment of each line: a file is split into
        contiguous runs of the same value. Default: one experiment per file.
    time : str, optional
        Column of the sample times (its unit is the set's time unit). Default:
        the sample index 0, 1, 2, ... of each experiment, with ``time_name``
        ``"sample"``.

    Returns
    -------
    TimeSeriesSet
        The experiments in file order, and within a file in line order; each
        :class:`Series` has ``source`` set to its file.

    Raises
    ------
    DatasetError
        One line naming the file and, where it applies, the line (as an editor
        numbers it, comments counted) and the column: path not found, folder
        without CSV files, empty file or no data lines, a named column missing
        (listing the file's columns, and for a later file of a folder those of
        the first) or repeated, a line with the wrong number of fields, a
        non-numeric, empty, NaN or infinite value, time not strictly increasing
        within an experiment, an experiment whose lines are not contiguous or
        whose name is empty, or the same experiment name in two files.
    LimitError
        A file over the ``file_mib`` limit or with more data lines than the
        ``csv_rows`` limit of :mod:`softbend.limits`.
    ValueError
        ``inputs`` or ``outputs`` empty or repeating a name, or a column named
        for two roles.
    """
    input_names = _names(inputs, "inputs")
    output_names = _names(outputs, "outputs")
    experiment = _column(experiment, "experiment")
    time = _column(time, "time")
    _check_roles(input_names, output_names, time, experiment)
    files = experiment_files(path)
    experiments: list[Series] = []
    seen: dict[str, str] = {}
    first: tuple[Path, tuple[str, ...]] | None = None
    for file in files:
        series, header = _read_file(file, input_names, output_names, experiment, time, first)
        if first is None:
            first = (file, header)
        for item in series:
            if item.name in seen:
                raise DatasetError(
                    f"experiment {item.name!r} was already read from "
                    f"{seen[item.name]}; experiment names must be unique",
                    file=str(file),
                )
            seen[item.name] = item.source
            experiments.append(item)
    logger.debug("Loaded %d experiment(s) from %s.", len(experiments), path)
    return TimeSeriesSet(input_names, output_names, tuple(experiments), time or SAMPLE_TIME_NAME)


# ---------------------------------------------------------------------- saving
def _csv_text(cells: Sequence[str]) -> str:
    """One CSV line (no line end), quoted where needed."""
    buffer = io.StringIO()
    csv.writer(buffer, lineterminator="").writerow(cells)
    return buffer.getvalue()


def _check_writable(name: object, what: str) -> str:
    """A column or experiment name that reads back unchanged, else ValueError."""
    if (
        not isinstance(name, str)
        or not name
        or name != name.strip()
        or "\n" in name
        or "\r" in name
    ):
        raise ValueError(
            f"The {what} of save_timeseries must be non-empty text without line breaks or "
            f"surrounding spaces (it could not be read back unchanged). Got {name!r} instead."
        )
    return name


def save_timeseries(data: TimeSeriesSet, path: str | os.PathLike[str]) -> Path:
    """Write a time-series set to one CSV file, atomically.

    Parameters
    ----------
    data : TimeSeriesSet
        What to write.
    path : str or path-like
        The CSV file (its folder is created if missing; an existing file is replaced).

    Returns
    -------
    pathlib.Path
        The file written.

    Raises
    ------
    ValueError
        ``data`` not a set, ``path`` a folder, a column or experiment name that
        would not read back unchanged (empty, line breaks, surrounding spaces),
        or the same column name twice (``experiment``, the time column, the
        inputs and the outputs must all differ).

    Notes
    -----
    The columns are ``experiment``, the set's time column, the inputs and the
    outputs, after the comment lines ``# softbend time series v1``,
    ``# time: <name>``, ``# inputs: a,b`` and ``# outputs: x,y``. Floats are
    written with :func:`repr`, the shortest text that parses back to the same
    double, so ``load_timeseries(path, data.input_names, data.output_names,
    experiment="experiment", time=data.time_name)`` gives the same numbers bit
    for bit (``source`` becomes the file). The file is written to a temporary
    file beside it and moved into place, so a reader never sees half of it.
    """
    if not isinstance(data, TimeSeriesSet):
        raise ValueError(
            "The 'data' of save_timeseries must be a TimeSeriesSet. "
            f"Got {type(data).__name__} instead."
        )
    target = Path(path)
    if target.is_dir():
        raise ValueError(
            f"The 'path' of save_timeseries must be a file. Got the folder {target} instead."
        )
    columns = [EXPERIMENT_COLUMN, data.time_name, *data.input_names, *data.output_names]
    for name in columns:
        _check_writable(name, "column name")
    duplicates = sorted({c for c in columns if columns.count(c) > 1})
    if duplicates:
        raise ValueError(
            "The columns of save_timeseries (experiment, time, inputs, outputs) must have "
            f"distinct names. Got {', '.join(map(repr, duplicates))} more than once."
        )
    labels = {}
    for item in data.experiments:
        _check_writable(item.name, "experiment name")
        label = _csv_text([item.name])
        labels[item.name] = f'"{label}"' if label.startswith("#") else label
    with atomic_file(target, "w") as handle:
        handle.write(f"# {_FORMAT_LINE}\n")
        handle.write(f"# time: {_csv_text([data.time_name])}\n")
        handle.write(f"# inputs: {_csv_text(data.input_names)}\n")
        handle.write(f"# outputs: {_csv_text(data.output_names)}\n")
        handle.write(_csv_text(columns) + "\n")
        for item in data.experiments:
            label = labels[item.name]
            table = np.column_stack([item.time, item.inputs, item.outputs]).tolist()
            handle.writelines(f"{label},{','.join(map(repr, row))}\n" for row in table)
        handle.flush()
        os.fsync(handle.fileno())
    logger.debug("Saved %d experiment(s) to %s.", len(data.experiments), target)
    return target


# ---------------------------------------------------------------------- checks
def check_experiments_for_lags(data: TimeSeriesSet, max_lag: int) -> None:
    """Refuse experiments too short for NARX regressors of ``max_lag`` lags.

    The first ``max_lag`` samples of an experiment are initial conditions, so a
    regressor row needs ``max_lag + 1`` samples.

    Parameters
    ----------
    data : TimeSeriesSet
        The experiments.
    max_lag : int
        The largest lag, in samples (>= 0).

    Raises
    ------
    DatasetError
        An experiment with fewer than ``max_lag + 1`` samples: the first one is
        named with its file, its sample count and the count needed.
    ValueError
        ``max_lag`` not an integer >= 0.
    """
    max_lag = check_int(max_lag, "max_lag")
    need = max_lag + 1
    short = [e for e in data.experiments if e.n_samples < need]
    if short:
        e = short[0]
        source = f" ({e.source})" if e.source else ""
        others = (
            f"; {len(short) - 1} other experiment(s) are too short too" if len(short) > 1 else ""
        )
        raise DatasetError(
            f"Experiment {e.name!r}{source} has {e.n_samples} sample(s), but lags up to "
            f"{max_lag} need at least {need} (the first {max_lag} are initial "
            f"conditions){others}."
        )


def check_holdout(
    data: TimeSeriesSet,
    validate_on: str | Sequence[str] | None,
) -> None:
    """Check that experiments can be held out for validation and the rest selected on.

    Parameters
    ----------
    data : TimeSeriesSet
        The experiments.
    validate_on : str or sequence of str, optional
        The experiments held out (one name or several). None: one experiment is
        to be held out at a time, which needs at least two.

    Raises
    ------
    InputError
        With the key ``validate_on``: a name that is not an experiment of
        ``data`` (the message lists them),
        a name given twice, ``validate_on`` empty or leaving fewer than two
        experiments to train on (the selection holds one out at a time), or
        ``validate_on`` None with a single experiment (nothing to hold out).
    """
    known = data.names
    if validate_on is None:
        if len(known) < 2:
            raise InputError(
                f"has nothing to hold out: the data has one experiment ({known[0]!r}); "
                "validation needs at least two (one to train on, one to hold out)",
                key="validate_on",
            )
        return
    names = (validate_on,) if isinstance(validate_on, str) else tuple(validate_on)
    if not names:
        raise InputError(
            "must name at least one experiment, or be None; got none", key="validate_on"
        )
    unknown = [n for n in names if n not in known]
    if unknown:
        raise InputError(
            f"must name experiments of the data ({', '.join(known)}); "
            f"got {', '.join(map(repr, unknown))}",
            key="validate_on",
        )
    repeated = sorted({n for n in names if names.count(n) > 1})
    if repeated:
        raise InputError(
            f"must name each experiment once; got {', '.join(map(repr, repeated))} more than once",
            key="validate_on",
        )
    left = [n for n in known if n not in names]
    if len(left) < 2:
        raise InputError(
            f"must leave at least 2 of the {len(known)} experiments to train on "
            f"(the selection holds one out at a time); got {', '.join(map(repr, names))}, "
            f"which leaves {', '.join(map(repr, left)) or 'none'}",
            key="validate_on",
        )


def check_signals(data: TimeSeriesSet, validate_on: str | Sequence[str] | None = None) -> None:
    """Refuse, before any fit, signals whose identification figures could not be finite or
    would be made up.

    Every input and output value must lie within ±:data:`~softbend.identification.ranges.
    MAX_ABS_VALUE` (1e50: the fourth powers of larger values overflow a polynomial fit).
    No input or output may be constant or near-constant over the training experiments
    (those not in ``validate_on``): a column is near-constant when its range (max − min)
    is at most :data:`~softbend.identification.ranges.NEAR_CONSTANT_RTOL` (1e-9) times its
    largest magnitude, a constant up to rounding. A model has nothing to learn from such
    an output (its error over its range, the NRMSE, is undefined), and the gain and time
    constant of such an input would be made up. Every output must also vary by at least
    :data:`~softbend.identification.ranges.MIN_OUTPUT_RANGE` to be standardized.

    Parameters
    ----------
    data : TimeSeriesSet
        The experiments (finite, as every :class:`Series` is).
    validate_on : str or sequence of str, optional
        The validation experiments, left out of the signals' ranges.

    Raises
    ------
    DatasetError
        One line naming the column and, for a value too large, the experiment,
        its file and the value.
    """
    held = {validate_on} if isinstance(validate_on, str) else set(validate_on or ())
    for kind, names, attribute in (
        ("input", data.input_names, "inputs"),
        ("output", data.output_names, "outputs"),
    ):
        for e in data.experiments:
            values = getattr(e, attribute)
            too_large = np.abs(values) > MAX_ABS_VALUE
            if too_large.any():
                row, column = (int(i[0]) for i in np.nonzero(too_large))
                source = f" ({e.source})" if e.source else ""
                raise DatasetError(
                    f"The {kind} column '{names[column]}' of experiment {e.name!r}{source} "
                    f"holds {float(values[row, column])!r} at sample {row}: values must lie "
                    f"within ±{MAX_ABS_VALUE:g} (larger ones overflow a polynomial fit); "
                    "rescale the column (e.g. a larger unit)."
                )
    train = [e for e in data.experiments if e.name not in held] or list(data.experiments)
    for kind, names, attribute in (
        ("input", data.input_names, "inputs"),
        ("output", data.output_names, "outputs"),
    ):
        _check_varies(kind, names, np.vstack([getattr(e, attribute) for e in train]))


def _check_varies(kind: str, names: Sequence[str], values: np.ndarray) -> None:
    """Refuse a constant or near-constant column of ``values`` (samples × columns)."""
    spans = np.ptp(values, axis=0)
    scales = np.max(np.abs(values), axis=0)
    why = (
        "a model of it has nothing to learn and its error over its range (NRMSE) is undefined"
        if kind == "output"
        else "a model cannot learn its effect, and a gain or time constant read from it "
        "would be made up"
    )
    for column, name in enumerate(names):
        if spans[column] == 0:
            raise DatasetError(
                f"The {kind} column '{name}' is constant over the training experiments "
                f"(every sample {float(values[0, column])!r}): {why}; leave it out of "
                f"the {kind}s."
            )
        if spans[column] <= NEAR_CONSTANT_RTOL * scales[column]:
            raise DatasetError(
                f"The {kind} column '{name}' is near-constant over the training experiments: "
                f"it varies by only {float(spans[column]):.3g} around "
                f"{float(values[0, column]):.6g}, at most {NEAR_CONSTANT_RTOL:g} of its "
                f"magnitude (a constant up to rounding): {why}; leave it out of the {kind}s."
            )
        if kind == "output" and spans[column] < MIN_OUTPUT_RANGE:
            raise DatasetError(
                f"The output column '{name}' varies by only {float(spans[column])!r} over the "
                f"training experiments, less than {MIN_OUTPUT_RANGE:g}: too little to "
                "standardize in double precision; rescale it (e.g. a smaller unit)."
            )
