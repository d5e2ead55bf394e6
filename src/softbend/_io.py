"""Atomic file writes, and the one reader of softbend's commented CSV files.

Writes: a finished file is either the old one or the complete new one. The new
file gets the permissions a plain ``open(path, "w")`` would give it: those of the
file it replaces, or ``0o666`` less the process umask for a new file (a temporary
file from :func:`tempfile.mkstemp` alone would be ``0o600``).

Reads: :func:`read_header_csv` walks a CSV file whose ``# key: value`` comments
before the column header carry metadata, within the limits of
:mod:`softbend.limits`; :mod:`softbend.tables` reads every CSV format of the
project through it.
"""

from __future__ import annotations

import json
import math
import os
import stat
import tempfile
from collections.abc import Iterator
from contextlib import contextmanager
from pathlib import Path
from typing import IO, Any, Literal, NamedTuple

__all__ = [
    "CSVLine",
    "atomic_file",
    "atomic_files",
    "json_safe",
    "json_text",
    "new_file_mode",
    "read_header_csv",
    "read_input_bytes",
    "read_input_text",
    "write_bytes_atomic",
    "write_text_atomic",
]


def _umask() -> int:
    """The process umask, read without changing it where the system allows."""
    try:
        with open("/proc/self/status", encoding="ascii") as status:
            for line in status:
                if line.startswith("Umask:"):
                    return int(line.split()[1], 8)
    except (OSError, ValueError):
        pass
    mask = os.umask(0o022)  # elsewhere: set and restore at once
    os.umask(mask)
    return mask


def new_file_mode(path: str | os.PathLike[str]) -> int:
    """Permission bits a plain ``open(path, "w")`` leaves ``path`` with."""
    try:
        return stat.S_IMODE(os.stat(path).st_mode) & 0o777
    except FileNotFoundError:
        return 0o666 & ~_umask()


@contextmanager
def atomic_file(path: str | os.PathLike[str], mode: str = "w") -> Iterator[IO]:
    """Yield a handle on a temporary file that replaces ``path`` when the block ends.

    ``mode`` is ``"w"`` (UTF-8 text) or ``"wb"``. The temporary file lies in the
    folder of ``path`` (created if missing), so the final :func:`os.replace` is
    atomic; if the block raises, it is removed and ``path`` is left as it was.
    """
    if mode not in ("w", "wb"):
        raise ValueError(f"The 'mode' of atomic_file must be one of 'w', 'wb'. Got {mode!r}.")
    path = Path(path)
    path.parent.mkdir(parents=True, exist_ok=True)
    permissions = new_file_mode(path)
    fd, tmp = tempfile.mkstemp(dir=path.parent, prefix=f".{path.name}.", suffix=".tmp")
    try:
        encoding = None if "b" in mode else "utf-8"
        with os.fdopen(fd, mode, encoding=encoding) as handle:
            os.chmod(tmp, permissions)
            yield handle
        os.replace(tmp, path)
    except BaseException:
        Path(tmp).unlink(missing_ok=True)
        raise


@contextmanager
def atomic_files(*targets: str | os.PathLike[str]) -> Iterator[list[Path]]:
    """Yield one temporary sibling per target; all replace their targets when the block ends.

    The outputs of one command are then all new or all old: if the block raises,
    every temporary is removed and every target is left as it was. A temporary
    keeps its target's suffix (a figure's format follows it) and the moved file
    gets the permissions a plain write would give it. A temporary the block did
    not create (an optional output it skipped) leaves its target alone.
    """
    paths = [Path(t) for t in targets]
    token = f"{os.getpid()}-{os.urandom(4).hex()}"
    temps = [p.parent / f".{p.name}.{token}.tmp{p.suffix}" for p in paths]
    for path in paths:
        path.parent.mkdir(parents=True, exist_ok=True)
    try:
        yield temps
        written = [(t, p) for t, p in zip(temps, paths, strict=True) if t.exists()]
        for temp, path in written:
            os.chmod(temp, new_file_mode(path))
        for temp, path in written:
            os.replace(temp, path)
    finally:
        for temp in temps:
            temp.unlink(missing_ok=True)


def read_input_text(
    path: str | os.PathLike[str],
    what: str,
    *,
    encoding: str = "utf-8",
    error: type[Exception] | None = None,
) -> str:
    """The text of an input file, after the ``file_mib`` limit, decoded strictly.

    Parameters
    ----------
    path : path
        The file (its existence is the caller's to check and name).
    what : str
        The file as messages name it, e.g. ``"The rig config rig.toml"``.
    encoding : str, default "utf-8"
        ``"utf-8-sig"`` for CSV files that may start with a byte-order mark.
    error : exception type, optional
        Raised for bytes that are not text; default
        :class:`~softbend.errors.DatasetError`.
    """
    from softbend.errors import DatasetError
    from softbend.limits import check_file_size

    check_file_size(path, what)
    try:
        return Path(path).read_text(encoding=encoding)
    except UnicodeDecodeError as exc:
        raise (error or DatasetError)(
            f"{what} is not UTF-8 text (undecodable byte at offset {exc.start})."
        ) from None


def read_input_bytes(path: str | os.PathLike[str], what: str) -> bytes:
    """The bytes of an input file, after the ``file_mib`` limit (:func:`read_input_text`'s
    check; the caller decodes what it needs).

    Parameters
    ----------
    path : path
        The file (its existence is the caller's to check and name).
    what : str
        The file as messages name it.
    """
    from softbend.limits import check_file_size

    check_file_size(path, what)
    return Path(path).read_bytes()


class CSVLine(NamedTuple):
    """One line of a commented CSV file that carries something (see :func:`read_header_csv`).

    Attributes
    ----------
    number : int
        The line's number as an editor shows it, from 1 (comments and blank
        lines counted).
    kind : {"meta", "header", "row"}
        A ``# key: value`` comment before the column header, the column header
        (the first line that is neither blank nor a comment) or a data row.
    cells : tuple of str
        The header's or the row's cells, each stripped of surrounding
        whitespace; empty for ``"meta"``.
    key, value : str
        The comment split at its first colon, both sides stripped; empty for
        ``"header"`` and ``"row"``.
    """

    number: int
    kind: Literal["meta", "header", "row"]
    cells: tuple[str, ...] = ()
    key: str = ""
    value: str = ""


def read_header_csv(
    path: str | os.PathLike[str], *, separator: str = ",", max_rows: int | None = None
) -> Iterator[CSVLine]:
    """The lines of a CSV file with ``# key: value`` comments before its header, in order.

    The file is read as UTF-8 (a byte-order mark is dropped) after the
    ``file_mib`` limit, and refused before any row is parsed when it has more
    data rows than the ``csv_rows`` limit (:mod:`softbend.limits`). Lines end at
    ``\\n``, ``\\r\\n`` or ``\\r`` (as the :mod:`csv` module reads them) and are
    numbered from 1. Blank lines are skipped; a line whose first non-blank
    character is ``#`` is a comment: before the column header, one with a colon
    and a non-empty key is yielded as ``"meta"``, every other comment is
    skipped. The first other line is the column header; the rest are rows.
    The caller checks the columns, the cells and the metadata: the lines come
    one by one, so the first problem in the file is the one reported. A file
    of :data:`~softbend._progress.READ_REPORT_BYTES` or more reports the
    percent of its lines read (:func:`softbend._progress.report`), the first
    report before the file is read.

    Parameters
    ----------
    path : path
        The file (its existence is the caller's to check and name).
    separator : str, default ","
        The cell separator.
    max_rows : int, optional
        The most data rows, in place of the ``csv_rows`` limit (a simulation
        table of millions of rows).

    Yields
    ------
    CSVLine
        The metadata comments, the header and the rows, in file order.

    Raises
    ------
    DatasetError
        Bytes that are not UTF-8, or a line the :mod:`csv` module cannot read
        (``"<path>:<n>: not a CSV row (<reason>)"``, the file and line as keywords).
    LimitError
        A file over the ``file_mib`` or ``csv_rows`` limit (or ``max_rows``).
    """
    import csv

    from softbend._progress import every, read_phase, report
    from softbend.errors import DatasetError
    from softbend.limits import check_limit, limit

    phase = read_phase(path)
    if phase is not None:  # before a byte is read: a large file shows at once
        report(phase, 0, 100)
    text = read_input_text(path, str(path), encoding="utf-8-sig")
    lines = text.replace("\r\n", "\n").replace("\r", "\n").split("\n")
    del text
    bound = limit("csv_rows") if max_rows is None else max_rows
    if len(lines) > bound:  # may be over: count the data rows (cheap)
        n_rows = max(
            sum(1 for line in lines if line.strip() and not line.lstrip().startswith("#")) - 1, 0
        )
        if max_rows is None:
            check_limit("csv_rows", n_rows, str(path))
        elif n_rows > max_rows:
            raise DatasetError(
                f"has {n_rows} data rows; at most {max_rows} are read", file=str(path)
            )
    field_limit = csv.field_size_limit()
    in_header = True
    stride = every(len(lines))
    for number, line in enumerate(lines, start=1):
        if phase is not None and number % stride == 0:
            report(phase, 100 * number // len(lines), 100)
        stripped = line.strip()
        if not stripped:
            continue
        if stripped.startswith("#"):
            key, sep, value = stripped[1:].partition(":")
            key = key.strip()
            if in_header and sep and key:
                yield CSVLine(number, "meta", key=key, value=value.strip())
            continue
        if '"' in line or "\0" in line or len(line) > field_limit:  # what csv must read
            try:
                cells = tuple(map(str.strip, next(csv.reader([line], delimiter=separator))))
            except csv.Error as exc:
                raise DatasetError(f"not a CSV row ({exc})", file=str(path), line=number) from None
        else:  # what csv reads from a line without quotes, faster
            cells = tuple(map(str.strip, line.split(separator)))
        yield CSVLine(number, "header" if in_header else "row", cells)
        in_header = False
    if phase is not None:
        report(phase, 100, 100)


def write_text_atomic(path: str | os.PathLike[str], text: str) -> Path:
    """Write ``text`` to ``path`` through a temporary file in the same folder and a rename."""
    with atomic_file(path, "w") as handle:
        handle.write(text)
    return Path(path)


def write_bytes_atomic(path: str | os.PathLike[str], data: bytes) -> Path:
    """Write ``data`` to ``path`` through a temporary file in the same folder and a rename."""
    with atomic_file(path, "wb") as handle:
        handle.write(data)
    return Path(path)


def json_safe(value: Any) -> Any:
    """``value`` with NumPy arrays and numbers as Python ones and NaN or inf as None.

    Dictionary keys become strings. What strict JSON readers (``jq``, JavaScript,
    most libraries other than Python's) accept: they refuse a bare ``NaN``.
    """
    if isinstance(value, dict):
        return {str(k): json_safe(v) for k, v in value.items()}
    if isinstance(value, list | tuple):
        return [json_safe(v) for v in value]
    if isinstance(value, float):
        return float(value) if math.isfinite(value) else None
    if not isinstance(value, str | bytes) and callable(getattr(value, "tolist", None)):
        return json_safe(value.tolist())  # NumPy arrays and scalars
    return value


def json_text(payload: Any, *, indent: int | None = 2, sort_keys: bool = False) -> str:
    """``payload`` as strict JSON text: :func:`json_safe`, other objects as ``str``."""
    return json.dumps(
        json_safe(payload), indent=indent, sort_keys=sort_keys, allow_nan=False, default=str
    )
