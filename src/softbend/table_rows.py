"""The rows of a plain CSV file, parsed by pandas' C parser and checked column by column.

:func:`softbend.tables.read_table` reads the ``# key: value`` lines and the
column header itself, then hands the rest of the file here. A *plain* data
section (ASCII, no quotes, no comment lines, no spaces or tabs, lines ending at
``\\n`` or ``\\r\\n``, every non-blank line with the header's number of cells,
no line over the :mod:`csv` module's field limit) is read by
:func:`pandas.read_csv` with each column's dtype declared, and each column is
checked with array operations (:func:`column_values`). Where the file is not
plain, or a cell is not what its column needs, these functions return None and
the caller reads the file line by line, which finds and names the first problem
in file order: the same values and the same errors either way.
"""

from __future__ import annotations

import io
from collections.abc import Sequence
from typing import Protocol

import numpy as np

from softbend.column_values import MAX_INTEGER, infer_written

__all__ = ["ColumnSpec", "column_values", "parse_rows", "row_lines"]

#: Bytes that make a data section not plain: quotes, NUL, comments and the ASCII
#: whitespace :meth:`str.strip` removes from a cell.
_NOT_PLAIN = (b'"', b"\0", b"#", b" ", b"\t", b"\x0b", b"\x0c", b"\x1c", b"\x1d", b"\x1e", b"\x1f")


class ColumnSpec(Protocol):
    """What :func:`column_values` reads of a :class:`softbend.tables.Column`."""

    @property
    def kind(self) -> str: ...

    @property
    def missing(self) -> bool: ...

    @property
    def low(self) -> float | None: ...

    @property
    def choices(self) -> tuple[str, ...]: ...


def row_lines(
    data: bytes, separator: str, width: int, field_limit: int, start: int = 0
) -> np.ndarray | None:
    """The offsets of the data rows among the lines of a plain data section, or None.

    Parameters
    ----------
    data : bytes
        The file; its data section starts at ``start``, after its column header's line.
    separator : str
        The one-character cell separator.
    width : int
        The header's number of columns.
    field_limit : int
        The longest line read without the :mod:`csv` module (characters).
    start : int, default 0
        The data section's first byte in ``data`` (the section is not copied out).

    Returns
    -------
    ndarray of int64 or None
        For each data row, the number of lines before it in the section (blank lines
        are not rows); None where ``data`` is not plain (see the module) or a
        row has another number of cells than ``width``.
    """
    sep = separator.encode()
    if len(sep) != 1 or separator in "\r\n" or sep in _NOT_PLAIN:
        return None
    # plain: none of the bytes above (byte searches) and ASCII
    if start >= len(data) or any(data.find(byte, start) >= 0 for byte in _NOT_PLAIN):
        return None
    buffer = np.frombuffer(data, dtype=np.uint8, offset=start)
    if buffer.max() >= 128:
        return None
    returns = data.count(b"\r", start) if data.find(b"\r", start) >= 0 else 0
    if returns and returns != data.count(b"\r\n", start):
        return None  # a lone '\r' ends a line: the line reader numbers those
    # one scan: the separators and the line ends, in file order
    marks = np.flatnonzero((buffer == sep[0]) | (buffer == 10))
    ends = marks[buffer[marks] == 10]
    if not data.endswith(b"\n"):  # the last line has no newline
        ends = np.append(ends, buffer.size)
        marks = np.append(marks, buffer.size)
    starts = np.concatenate(([0], ends[:-1] + 1))
    lengths = ends - starts
    if returns:
        filled = lengths > 0
        lengths[filled] -= buffer[ends[filled] - 1] == 13
    blank = lengths == 0
    rows = np.flatnonzero(~blank)
    if rows.size == 0 or lengths.max() > field_limit:
        return None
    # Each row's cells: its separators and its end fall in a group of ``width`` marks of
    # which the last is the row's end (a blank line's newline left out).
    if blank.any():
        marks = np.setdiff1d(marks, ends[blank], assume_unique=True)
    if marks.size != rows.size * width or not np.array_equal(marks[width - 1 :: width], ends[rows]):
        return None
    return rows.astype(np.int64)


def parse_rows(
    data: bytes,
    separator: str,
    width: int,
    columns: Sequence[tuple[int, ColumnSpec]],
    n_rows: int,
    start: int = 0,
) -> dict[int, np.ndarray] | None:
    """The read columns of a plain data section (:func:`row_lines`), or None.

    Parameters
    ----------
    data : bytes
        The plain data section.
    separator : str
        The cell separator.
    width : int
        The number of cells of every row.
    columns : sequence of (int, ColumnSpec)
        The 0-based position of each column read and its declaration.
    n_rows : int
        The number of rows :func:`row_lines` found.
    start : int, default 0
        The section's first byte in ``data``.

    Returns
    -------
    dict of int to ndarray, or None
        Each column's values by position, as :func:`column_values` gives them;
        None where a cell is not what its column needs (the line reader names it).
    """
    import pandas as pd

    begin = start
    while begin < len(data) and data[begin] in b"\r\n":  # blank lines before the first row
        begin += 1
    end = data.find(b"\n", begin)  # the first row's line, not a copy of the rest
    first = data[begin : end if end >= 0 else len(data)].rstrip(b"\r").decode().split(separator)
    used = [position for position, _ in columns]
    dtypes: dict[int, object] = {}
    for position, column in columns:
        if column.kind in ("number", "integer"):
            dtypes[position] = np.float64
        elif column.kind in ("text", "choice") or not _number(first[position]):
            dtypes[position] = object  # text: one cell not a number makes the column text
    stream = io.BytesIO(data)  # the bytes themselves, read from the section's start
    stream.seek(start)
    try:
        frame = pd.read_csv(
            stream,
            sep=separator,
            header=None,
            names=list(range(width)),
            # every column read: no column selection
            usecols=used if len(used) < width else None,
            dtype=dtypes,  # type: ignore[arg-type]
            keep_default_na=False,
            na_values=[""],
            skip_blank_lines=True,
            low_memory=False,
            engine="c",
        )
    except (ValueError, pd.errors.ParserError):
        return None  # a cell pandas cannot read as its column's dtype
    if len(frame) != n_rows:
        return None
    out: dict[int, np.ndarray] = {}
    for position, column in columns:
        values = column_values(column, frame[position])
        if values is None:
            return None
        out[position] = values
    return out


def _number(cell: str) -> bool:
    """Whether a filled cell reads as a number, as :func:`infer_written` reads it."""
    if not cell:
        return True  # an empty cell says nothing of its column
    try:
        np.array([cell], dtype=np.float64)
    except ValueError:
        return False
    return True


def column_values(column: ColumnSpec, series: object) -> np.ndarray | None:
    """One column's checked values, as the line reader reads its cells, or None.

    Numbers are float64, integers int64, text and choices ``object`` (an empty
    cell ``""``), an ``"any"`` column numbers where every filled cell is one
    (:func:`softbend.column_values.infer_written`); None where a cell is not
    what the column needs (empty where it may not be, not finite, below
    ``low``, not whole, not one of the choices) or pandas read it otherwise.
    """
    import pandas as pd

    assert isinstance(series, pd.Series)
    kind = column.kind
    if kind in ("number", "integer"):
        values = series.to_numpy(dtype=np.float64)
        finite = np.isfinite(values)
        if not finite.all() and (not column.missing or kind == "integer"):
            return None
        if column.missing and np.any(~finite & ~np.isnan(values)):
            return None
        with np.errstate(invalid="ignore"):
            if column.low is not None and np.any(values < column.low):
                return None
        if kind == "number":
            return values
        if not np.all((values == np.round(values)) & (np.abs(values) <= MAX_INTEGER)):
            return None
        return values.astype(np.int64)
    if kind in ("text", "choice"):
        empty = series.isna().to_numpy()
        if empty.any() and not column.missing:
            return None
        cells = series.to_numpy(dtype=object).copy()
        cells[empty] = ""
        if kind == "choice" and not np.all(np.isin(cells[~empty], list(column.choices))):
            return None
        return cells
    if series.dtype == np.int64:
        ints = series.to_numpy()
        if np.all(np.abs(ints) <= MAX_INTEGER):
            return ints.astype(np.int64)
        return ints.astype(np.float64)
    if series.dtype == np.float64:
        return series.to_numpy(dtype=np.float64)
    if series.dtype != object and not pd.api.types.is_string_dtype(series.dtype):
        return None  # read as booleans or another type: the line reader reads the text
    cells = series.to_numpy(dtype=object)
    filled = next((c for c in cells if isinstance(c, str)), None)
    if filled is not None:
        try:
            np.array([filled], dtype=np.float64)  # infer_written's test of a cell
        except ValueError:  # a text column: the cells as written, an empty one NaN
            return cells
    return infer_written(["" if not isinstance(c, str) else c for c in cells])
