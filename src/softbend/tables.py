"""The one reader of softbend's CSV tables: a format is a declaration, a file is read against it.

Every CSV format of the project (paper B's measurements, another actuator's
measurements, the identification time series, a simulation table) is a
:class:`TableFormat`: the ``# key: value`` lines it accepts before its column
header (:class:`HeaderKey`) and its columns (:class:`Column`: unit, kind,
required or optional, plausible range). :func:`read_table` reads a file against
a format and returns a :class:`Table`: a :class:`pandas.DataFrame` of the
checked cells and the header's values. :func:`check_columns` holds a frame from
elsewhere (a Parquet file) to the same column checks.

A file is read as UTF-8 (a byte-order mark is dropped) within the ``file_mib``
and ``csv_rows`` limits of :mod:`softbend.limits`. Lines end at ``\\n``,
``\\r\\n`` or ``\\r`` and are numbered from 1 as an editor shows them; blank
lines are skipped, and a line whose first non-blank character is ``#`` is a
comment (before the column header, one with a colon is a ``key: value`` line).
The first other line is the column header; the rest are rows.

Every error is one :class:`~softbend.errors.DatasetError` (or
:class:`~softbend.errors.LimitError`) that carries the file, the line, the
column (1-based position in the row) and the key (the column's or the header
key's name), in the wording of :func:`softbend._validation.must_be`::

    bench.csv:7:8: angle_deg: must be a finite number; got 'n/a'

The first problem met reading the file in order is the one reported.
"""

from __future__ import annotations

import codecs
import math
import os
from collections.abc import Callable, Mapping
from dataclasses import dataclass, field
from pathlib import Path
from typing import TYPE_CHECKING, Literal

import numpy as np

from softbend._io import read_header_csv
from softbend._progress import read_phase, report
from softbend._validation import must_be, short_repr
from softbend.column_values import (
    MAX_INTEGER,
    column_kind,
    infer_cells,
    infer_written,
    kind_conflict,
    not_increasing,
    not_increasing_text,
    reads_as_number,
)
from softbend.errors import DatasetError
from softbend.plausibility import implausible_index, implausible_text
from softbend.table_rows import parse_rows, row_lines
from softbend.units import unit_from_name

if TYPE_CHECKING:
    import pandas as pd

__all__ = [
    "Column",
    "HeaderKey",
    "Table",
    "TableFormat",
    "check_columns",
    "column_kind",
    "infer_cells",
    "kind_conflict",
    "not_increasing",
    "not_increasing_text",
    "read_table",
    "reads_as_number",
]

#: How a column's cells are read: a finite ``"number"``, an ``"integer"``
#: (``2`` and ``2.0``), non-empty one-line ``"text"``, one of the column's
#: ``"choice"`` values, or ``"any"`` (text as written, a number where every
#: filled cell of the column is one).
Kind = Literal["number", "integer", "text", "choice", "any"]

_KIND_WORDS: dict[str, str] = {
    "number": "a finite number",
    "integer": "an integer",
    "text": "non-empty text",
}


@dataclass(frozen=True)
class Column:
    """One column of a table format.

    Attributes
    ----------
    name : str
        The header's name of the column (case-sensitive).
    unit : str, optional
        Its unit, for messages and the documentation; default the unit its name
        ends with (:func:`softbend.units.unit_from_name`: ``time_s`` → s), else none.
    kind : {"number", "integer", "text", "choice", "any"}, default "number"
        How its cells are read (:data:`Kind`).
    required : bool, default True
        Whether every file has it.
    quantity : str, optional
        A key of :data:`softbend.plausibility.RANGES`: every value must be plausible.
    low : float, optional
        The least value allowed (``0`` for a gauge pressure), included.
    choices : tuple of str
        The values of a ``"choice"`` column.
    missing : bool, default False
        Whether a cell may be empty (read as NaN, or ``""`` for text).
    increasing : bool, default False
        Whether its values increase strictly down the file (a time column), within
        each run of the format's ``group`` column when it has one.
    """

    name: str
    unit: str = ""
    kind: Kind = "number"
    required: bool = True
    quantity: str | None = None
    low: float | None = None
    choices: tuple[str, ...] = ()
    missing: bool = False
    increasing: bool = False

    def __post_init__(self) -> None:
        if not self.unit:
            object.__setattr__(self, "unit", unit_from_name(self.name))

    def requirement(self) -> str:
        """What a cell must be, for :func:`~softbend._validation.must_be`."""
        if self.kind == "choice":
            return "one of " + ", ".join(repr(c) for c in self.choices)
        words = _KIND_WORDS.get(self.kind, "a value")
        if self.kind == "integer" and self.low is not None:
            words = f"an integer >= {self.low:g}"
        elif self.low is not None:
            words = f"{words} >= {self.low:g}" + (f" {self.unit}" if self.unit else "")
        return words


def _always(text: str) -> bool:
    return True


@dataclass(frozen=True)
class HeaderKey:
    """One ``# key: value`` line a format accepts before its column header.

    Attributes
    ----------
    name : str
        The key.
    requirement : str, default "text on one line"
        What the value must be, for the message.
    check : callable, default any text
        ``check(value) -> bool`` on the stripped value.
    required : bool, default False
        Whether every file gives it.
    quantity : str, optional
        A key of :data:`softbend.plausibility.RANGES`: a value that passes
        ``check`` must also be plausible.
    """

    name: str
    requirement: str = "text on one line"
    check: Callable[[str], bool] = _always
    required: bool = False
    quantity: str | None = None


@dataclass(frozen=True)
class TableFormat:
    """A CSV format: its header lines and its columns.

    Attributes
    ----------
    name : str
        The format as messages name it (``"measurement CSV"``).
    columns : tuple of Column
        The columns it reads, in the order they are written.
    header : tuple of HeaderKey
        The ``# key: value`` lines it reads.
    other_keys : {"error", "ignore", "keep"}, default "ignore"
        A ``# key: value`` line of another key: an error, a remark left out,
        or kept as given when the key has no spaces (a comment such as
        ``# note to self: ...`` stays a remark).
    other_columns : {"error", "ignore", "keep"}, default "error"
        A column the format does not declare: an error, left out, or kept as
        text (``"any"``).
    fold_keys : bool, default False
        Header keys are matched in any case (stored lower-case).
    repeated_keys : bool, default False
        A header key may come twice (the last one counts).
    min_rows : int, default 1
        The fewest data rows.
    max_rows : int, optional
        The most data rows; default the ``csv_rows`` limit of :mod:`softbend.limits`.
    separator : str, default ","
        The cell separator.
    group : str, optional
        The column that names the experiment a row is of: an ``increasing``
        column increases within each experiment's rows.
    contiguous_groups : bool, default False
        Whether each experiment's rows must be contiguous (else they may interleave).
    """

    name: str
    columns: tuple[Column, ...]
    header: tuple[HeaderKey, ...] = ()
    other_keys: Literal["error", "ignore", "keep"] = "ignore"
    other_columns: Literal["error", "ignore", "keep"] = "error"
    fold_keys: bool = False
    repeated_keys: bool = False
    min_rows: int = 1
    max_rows: int | None = None
    separator: str = ","
    group: str | None = None
    contiguous_groups: bool = False
    _by_name: Mapping[str, Column] = field(init=False, repr=False, compare=False)

    def __post_init__(self) -> None:
        object.__setattr__(self, "_by_name", {c.name: c for c in self.columns})

    def column(self, name: str) -> Column | None:
        """The declared column ``name``, or None."""
        return self._by_name.get(name)

    @property
    def required(self) -> tuple[str, ...]:
        """The names of the required columns."""
        return tuple(c.name for c in self.columns if c.required)

    @property
    def optional(self) -> tuple[str, ...]:
        """The names of the optional columns."""
        return tuple(c.name for c in self.columns if not c.required)

    def columns_text(self) -> str:
        """``a, b, c (optional: d, e)`` for messages."""
        text = ", ".join(self.required)
        return text + (f" (optional: {', '.join(self.optional)})" if self.optional else "")


@dataclass(frozen=True)
class Table:
    """What :func:`read_table` returns.

    Attributes
    ----------
    frame : pandas.DataFrame
        One row per data row, the file's columns in file order (those the
        format reads): numbers as float64, integers as int64, text as ``object``.
    header : dict of str to str
        The ``# key: value`` lines the format reads.
    file : str
        The file read.
    lines : numpy.ndarray
        The line of each row in the file (int64).
    header_line : int
        The line of the column header.
    positions : dict of str to int
        The 1-based position of each column in the file's rows.
    header_lines : dict of str to int
        The line of each header key.
    columns : tuple of str
        Every column of the file's header, in order (read or not).
    """

    frame: pd.DataFrame
    header: dict[str, str]
    file: str
    lines: np.ndarray
    header_line: int
    positions: dict[str, int]
    header_lines: dict[str, int]
    columns: tuple[str, ...] = ()

    def error(
        self, message: str, *, row: int | None = None, column: str | None = None
    ) -> DatasetError:
        """A :class:`DatasetError` about the row at position ``row`` and the column ``column``.

        For the checks a reader adds to the format's (a design outside its
        ranges, a time that does not increase): the error names the file, the
        line, the column's position and its name as the key.
        """
        line = int(self.lines[row]) if row is not None else self.header_line
        position = self.positions.get(column) if column is not None else None
        return DatasetError(message, key=column, file=self.file, line=line, column=position)


def _error(
    message: str, file: str, line: int | None, column: int | None = None, key: str | None = None
) -> DatasetError:
    return DatasetError(message, key=key, file=file, line=line, column=column)


def _got(cell: str) -> str:
    return "an empty cell" if cell == "" else short_repr(cell)


def _read_header_key(
    fmt: TableFormat,
    key: str,
    value: str,
    file: str,
    number: int,
    header: dict[str, str],
    lines: dict[str, int],
) -> None:
    name = key.lower() if fmt.fold_keys else key
    declared = next((h for h in fmt.header if h.name == name), None)
    if declared is None:
        if fmt.other_keys == "keep" and not any(ch.isspace() for ch in name):
            header[name] = value
            lines[name] = number
            return
        if fmt.other_keys != "error":
            return
        known = ", ".join(h.name for h in fmt.header)
        raise _error(
            f"is not a header key of the {fmt.name}; the keys are {known}. Write other "
            "remarks as '# note: ...' or as a comment without ':'",
            file,
            number,
            key=name,
        )
    if name in header and not fmt.repeated_keys:
        raise _error(
            f"is set twice (also on line {lines[name]}); each key may appear once",
            file,
            number,
            key=name,
        )
    if not declared.check(value):
        raise _error(f"must be {declared.requirement}; got {value!r}", file, number, key=name)
    if declared.quantity is not None:
        problem = implausible_text(float(value), declared.quantity)
        if problem is not None:
            raise _error(problem, file, number, key=name)
    header[name] = value
    lines[name] = number


def _cell_value(column: Column, cell: str) -> float | int | str:
    """One cell read by its column's kind; ``ValueError`` naming what it must be."""
    if column.kind in ("text", "any"):
        if column.kind == "text" and not cell and not column.missing:
            raise ValueError(column.requirement())
        return cell
    if column.kind == "choice":
        if cell not in column.choices and not (column.missing and not cell):
            raise ValueError(column.requirement())
        return cell
    if not cell and column.missing:
        return math.nan
    try:
        number = float(cell)
    except ValueError:
        raise ValueError(column.requirement()) from None
    if math.isnan(number) and column.missing:
        return number
    if not math.isfinite(number):
        raise ValueError(column.requirement())
    if column.kind == "integer":
        if not number.is_integer() or abs(number) > MAX_INTEGER:
            raise ValueError(column.requirement())
        number = int(number)
    if column.low is not None and number < column.low:
        raise ValueError(column.requirement())
    return number


def _convert(column: Column, cells: list[str]) -> tuple[np.ndarray, int | None]:
    """A column's cells as an array, and the position of the first bad cell (or None)."""
    if column.kind == "any":
        return infer_written(cells), None
    if column.kind in ("number", "integer") and not column.missing and column.low is None:
        try:
            array = np.array(cells, dtype=np.float64)
        except ValueError:
            array = None
        if array is not None and np.isfinite(array).all():
            if column.kind == "number":
                return array, None
            whole = (array == np.round(array)) & (np.abs(array) <= MAX_INTEGER)
            if whole.all():
                return array.astype(np.int64), None
    values = []
    for pos, cell in enumerate(cells):
        try:
            values.append(_cell_value(column, cell))
        except ValueError:
            return np.empty(0), pos
    if column.kind == "number":
        return np.asarray(values, dtype=np.float64), None
    if column.kind == "integer":
        return np.asarray(values, dtype=np.int64), None
    return np.asarray(values, dtype=object), None


def read_table(path: str | os.PathLike[str], fmt: TableFormat) -> Table:
    """Read the CSV file ``path`` against the format ``fmt``.

    Parameters
    ----------
    path : path
        The file.
    fmt : TableFormat
        Its declaration.

    Returns
    -------
    Table
        The checked cells as a DataFrame, the header's values and where each came from.

    Raises
    ------
    DatasetError
        One line naming the file and, where one applies, the line, the column
        and the key: a file that is missing, a folder or not UTF-8 text, a line
        the :mod:`csv` module cannot read, a header key unknown to the format,
        given twice or with a value not of its kind, a required header key
        missing, no column header, a column missing, repeated or unknown, a row
        with the wrong number of cells, too few data rows, a cell not of its
        column's kind, or an implausible value
        (:mod:`softbend.plausibility`, naming a pressure that looks like kPa).
    LimitError
        A file over the ``file_mib`` limit or with more data rows than the
        ``csv_rows`` limit, checked before its rows are parsed.

    Notes
    -----
    A file of :data:`~softbend._progress.READ_REPORT_BYTES` or more reports its
    progress to a listener (:mod:`softbend._progress`) from before its first
    byte is read: the percent of its lines read, then its columns checked.
    """
    import pandas as pd

    source = Path(path)
    file = str(source)
    if not source.exists():
        raise _error(f"no such file (a {fmt.name} is required)", file, None)
    if source.is_dir():
        raise _error(f"is a folder; a {fmt.name} file is required", file, None)
    read = _read_plain(source, fmt, file) or _read_lines(source, fmt, file)
    header, header_lines, names, header_line, data, positions, lines = read
    _check_plausible(fmt, data, positions, file, lines)
    _check_increasing(fmt, data, positions, file, lines)
    # text stays the object array it was read as (not converted to pandas' own strings)
    frame = pd.DataFrame(
        {name: pd.Series(values, dtype=values.dtype, copy=False) for name, values in data.items()},
        columns=list(data),
        copy=False,
    )
    return Table(
        frame=frame,
        header=header,
        file=file,
        lines=lines,
        header_line=header_line,
        positions=positions,
        header_lines=header_lines,
        columns=tuple(names),
    )


#: What :func:`_read_plain` and :func:`_read_lines` give :func:`read_table`: the header's
#: values and lines, the column names, the header's line, the columns read, their positions
#: and each row's line.
_Read = tuple[
    dict[str, str],
    dict[str, int],
    list[str],
    int,
    dict[str, np.ndarray],
    dict[str, int],
    np.ndarray,
]


def _read_plain(source: Path, fmt: TableFormat, file: str) -> _Read | None:
    """The file read by pandas' C parser where its data rows are plain, else None.

    The ``# key: value`` lines and the column header are read here, the rows by
    :mod:`softbend.table_rows`. Any problem (a header key, a column name, a row
    that is not plain, a cell not of its column's kind, a limit) declines the
    file to :func:`_read_lines`, which reports the first one in file order.
    """
    import csv

    from softbend._io import read_input_bytes  # looked up at the call: a test may replace it
    from softbend.limits import limit

    phase = read_phase(source)
    if phase is not None:  # before a byte is read: a large file shows at once
        report(phase, 0, 100)
    # the bytes, not the text: the header lines are decoded here, the data section stays
    # bytes for pandas (a file that is not UTF-8 is the line reader's to name)
    raw = read_input_bytes(source, file)
    header: dict[str, str] = {}
    header_lines: dict[str, int] = {}
    first = len(codecs.BOM_UTF8) if raw.startswith(codecs.BOM_UTF8) else 0
    start, number, line = first, 0, ""
    try:
        while start < len(raw):
            end = raw.find(b"\n", start)
            end = len(raw) if end < 0 else end
            number += 1
            line, start = raw[start:end].decode("utf-8").strip(), end + 1
            if line.startswith("#"):
                key, sep, value = line[1:].partition(":")
                if sep and key.strip():
                    _read_header_key(
                        fmt, key.strip(), value.strip(), file, number, header, header_lines
                    )
            elif line:
                break
        else:
            return None  # no column header
        preamble = raw[first:start]
        if preamble.count(b"\r") != preamble.count(b"\r\n"):
            return None  # a lone '\r' ends a line: the line reader numbers those
        if '"' in line or "\0" in line or len(line) > csv.field_size_limit():
            return None
        names = [cell.strip() for cell in line.split(fmt.separator)]
        _check_names(fmt, names, file, number)
    except (DatasetError, UnicodeDecodeError):
        return None
    if phase is not None:
        report(phase, 20, 100)
    rows = row_lines(raw, fmt.separator, len(names), csv.field_size_limit(), start)
    bound = limit("csv_rows") if fmt.max_rows is None else fmt.max_rows
    absent = any(h.required and h.name not in header for h in fmt.header)
    if rows is None or not fmt.min_rows <= rows.size <= bound or absent:
        return None
    if phase is not None:
        report(phase, 40, 100)
    kept: list[tuple[int, Column]] = []
    for position, name in enumerate(names):
        column = fmt.column(name)
        if column is None and fmt.other_columns == "keep":
            column = Column(name, kind="any", missing=True)
        if column is not None:
            kept.append((position, column))
    parsed = parse_rows(raw, fmt.separator, len(names), kept, rows.size, start)
    if parsed is None:
        return None
    if phase is not None:
        report(phase, 100, 100)
        report(f"checking {source.name}'s columns", len(names), len(names))
    data = {names[position]: parsed[position] for position, _ in kept}
    positions = {names[position]: position + 1 for position, _ in kept}
    return header, header_lines, names, number, data, positions, number + 1 + rows


def _read_lines(source: Path, fmt: TableFormat, file: str) -> _Read:
    """The file read line by line (:func:`softbend._io.read_header_csv`): any file, and the
    first problem in it reported."""
    header: dict[str, str] = {}
    header_lines: dict[str, int] = {}
    names: list[str] | None = None
    header_line = 0
    rows: list[tuple[str, ...]] = []
    lines: list[int] = []
    width = 0
    for line in read_header_csv(source, separator=fmt.separator, max_rows=fmt.max_rows):
        if line.kind == "meta":
            _read_header_key(fmt, line.key, line.value, file, line.number, header, header_lines)
        elif line.kind == "header":
            names, header_line = list(line.cells), line.number
            _check_names(fmt, names, file, header_line)
            width = len(names)
        else:
            if len(line.cells) != width:
                raise _error(
                    f"has {len(line.cells)} cells, but the header (line {header_line}) has "
                    f"{width} columns",
                    file,
                    line.number,
                )
            rows.append(line.cells)
            lines.append(line.number)
    absent = [h for h in fmt.header if h.required and h.name not in header]
    if absent:
        raise _error(
            f"lacks the header line '# {absent[0].name}: ...' ({absent[0].requirement})",
            file,
            None,
            key=absent[0].name,
        )
    if names is None:
        raise _error(f"has no column header: expected the columns {fmt.columns_text()}", file, None)
    if len(rows) < fmt.min_rows:
        raise _error(
            f"the column header is followed by {len(rows)} data row(s); "
            f"at least {fmt.min_rows} needed",
            file,
            header_line,
        )
    data: dict[str, np.ndarray] = {}
    positions: dict[str, int] = {}
    bad: tuple[int, int, str, str] | None = None  # (row, position, column, requirement)
    checking = f"checking {source.name}'s columns" if read_phase(source) else None
    for position, name in enumerate(names, start=1):
        if checking is not None:
            report(checking, position - 1, len(names))
        column = fmt.column(name)
        if column is None:
            if fmt.other_columns != "keep":
                continue
            column = Column(name, kind="any", missing=True)
        cells = [row[position - 1] for row in rows]
        values, at = _convert(column, cells)
        if at is not None:
            if bad is None or (at, position) < bad[:2]:
                bad = (at, position, name, column.requirement())
            continue
        data[name] = values
        positions[name] = position
    if checking is not None:
        report(checking, len(names), len(names))
    if bad is not None:
        at, position, name, requirement = bad
        cell = rows[at][position - 1]
        raise _error(f"must be {requirement}; got {_got(cell)}", file, lines[at], position, name)
    return header, header_lines, names, header_line, data, positions, np.asarray(lines, np.int64)


def _check_names(fmt: TableFormat, names: list[str], file: str, line: int) -> None:
    """Each column once, every required one, nothing unknown (unless allowed): one error."""
    for position, name in enumerate(names, start=1):
        if name in names[: position - 1]:
            raise _error(
                "appears twice in the column header; each column may appear once",
                file,
                line,
                position,
                name,
            )
    missing = [c for c in fmt.required if c not in names]
    unknown = [c for c in names if fmt.other_columns == "error" and fmt.column(c) is None]
    if missing or unknown:
        parts = []
        if missing:
            parts.append(f"lacks the column(s) {', '.join(missing)}")
        if unknown:
            parts.append(
                f"has column(s) {', '.join(unknown)} the {fmt.name} does not have "
                "(names are case-sensitive)"
            )
        raise _error(
            f"{' and '.join(parts)}; the {fmt.name} has the columns {fmt.columns_text()}; "
            f"the file has {', '.join(names) or 'none'}",
            file,
            line,
            names.index(unknown[0]) + 1 if unknown else None,
            unknown[0] if unknown else missing[0],
        )


def _check_plausible(
    fmt: TableFormat,
    data: Mapping[str, np.ndarray],
    positions: Mapping[str, int],
    file: str | None,
    lines: np.ndarray | None,
) -> None:
    """The first implausible value in file order, whichever column it is in."""
    first: tuple[int, int, str, int] | None = None  # (row, position, column, index)
    for name, values in data.items():
        column = fmt.column(name)
        if column is None or column.quantity is None:
            continue
        index = implausible_index(values, column.quantity)
        if index is not None and (first is None or (index, positions[name]) < first[:2]):
            first = (index, positions[name], name, index)
    if first is not None:
        index, position, name, _ = first
        column = fmt.column(name)
        assert column is not None and column.quantity is not None
        value = float(data[name][index])
        text = implausible_text(value, column.quantity) or must_be("plausible", value)
        where = "" if lines is not None else f"row {index}: "
        raise DatasetError(
            where + text,
            key=name,
            file=file,
            line=int(lines[index]) if lines is not None else None,
            column=position if lines is not None else None,
        )


def _check_increasing(
    fmt: TableFormat,
    data: Mapping[str, np.ndarray],
    positions: Mapping[str, int],
    file: str,
    lines: np.ndarray,
) -> None:
    """The first value of an ``increasing`` column that does not increase, in file order."""
    groups = data.get(fmt.group) if fmt.group is not None else None
    if groups is not None and fmt.contiguous_groups:
        _check_contiguous(fmt.group or "", groups, positions, file, lines)
    first: tuple[int, int, str, np.ndarray, int, object] | None = None  # row, position, ...
    for name, values in data.items():
        column = fmt.column(name)
        if column is None or not column.increasing:
            continue
        runs = [None] if groups is None else list(dict.fromkeys(groups.tolist()))
        for run in runs:
            rows = np.arange(len(values)) if run is None else np.flatnonzero(groups == run)
            k = not_increasing(values[rows])
            if k is not None and (first is None or (rows[k], positions[name]) < first[:2]):
                first = (int(rows[k]), positions[name], name, rows, k, run)
    if first is not None:
        row, position, name, rows, k, run = first
        text = not_increasing_text(data[name][rows], k, f"line {int(lines[rows[k - 1]])}", run)
        raise _error(text, file, int(lines[row]), position, name)


def _check_contiguous(
    name: str, groups: np.ndarray, positions: Mapping[str, int], file: str, lines: np.ndarray
) -> None:
    """Each experiment's rows in one block: the first row of one that appears again, an error."""
    ended: dict[object, int] = {}
    values = groups.tolist()
    for row, value in enumerate(values):
        if row and value != values[row - 1]:
            if value in ended:
                raise _error(
                    f"experiment {value!r} appears again after {values[row - 1]!r} (its rows "
                    f"ended at line {int(lines[ended[value]])}); the rows of an experiment must be "
                    "contiguous",
                    file,
                    int(lines[row]),
                    positions[name],
                    name,
                )
            ended[values[row - 1]] = row - 1


def check_columns(frame: pd.DataFrame, fmt: TableFormat, *, file: str | None = None) -> None:
    """Hold a frame read elsewhere (Parquet) to ``fmt``'s columns: present, kinds, plausible.

    Errors name the file, the column as the key and the row by its position.
    """
    names = [str(c) for c in frame.columns]
    missing = [c for c in fmt.required if c not in names]
    if missing:
        raise DatasetError(
            f"missing column(s) {', '.join(map(repr, missing))}; the {fmt.name} has the columns "
            f"{fmt.columns_text()}; the table has {', '.join(names) or 'none'}",
            key=missing[0],
            file=file,
        )
    data: dict[str, np.ndarray] = {}
    for name in names:
        column = fmt.column(name)
        if column is None or column.kind not in ("number", "integer"):
            continue
        series = frame[name]
        if series.dtype.kind not in "iuf":
            raise DatasetError(
                f"must be {column.requirement()} in every row; got {series.dtype} values",
                key=name,
                file=file,
            )
        values = series.to_numpy(dtype=np.float64, na_value=np.nan)
        bad = ~np.isfinite(values)
        if column.missing:
            bad &= ~np.isnan(values)
        if column.low is not None:
            with np.errstate(invalid="ignore"):
                bad |= values < column.low
        if bad.any():
            row = int(np.flatnonzero(bad)[0])
            raise DatasetError(
                f"row {row}: " + must_be(column.requirement(), float(values[row])),
                key=name,
                file=file,
            )
        data[name] = values
    _check_plausible(fmt, data, {n: i for i, n in enumerate(names, start=1)}, file, None)
