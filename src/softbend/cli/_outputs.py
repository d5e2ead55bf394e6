"""Outputs of the commands: refused before any work if unwritable, OS errors as one line."""

from __future__ import annotations

import os
from collections.abc import Iterator
from contextlib import contextmanager
from pathlib import Path

from softbend.errors import SoftbendError

__all__ = [
    "OutputError",
    "as_written",
    "check_output_dir",
    "check_output_file",
    "check_replaceable_dir",
    "file_kind",
    "os_error_message",
    "output_errors",
]


class OutputError(SoftbendError, OSError):
    """An output could not be written (no space left, no permission, …); one line on the CLI."""


#: Kinds of file recognised by their first bytes, and where those bytes are.
_MAGIC: tuple[tuple[str, int, bytes], ...] = (
    ("DuckDB database", 8, b"DUCK"),
    ("Parquet", 0, b"PAR1"),
    ("PNG", 0, b"\x89PNG"),
    ("SQLite database", 0, b"SQLite format 3\x00"),
    ("zip", 0, b"PK\x03\x04"),
)

#: What each kind of output may replace: an empty file or a file of the same kind.
_REPLACEABLE: dict[str, set[str]] = {
    "duckdb": {"DuckDB database"},
    "parquet": {"Parquet"},
    "png": {"PNG"},
    "csv": {"text"},
    "json": {"text"},
    "text": {"text"},
}


def file_kind(path: Path) -> str:
    """What an existing file holds, from its first bytes: a name of :data:`_MAGIC`, text, …

    ``"empty"`` for an empty file, ``"text"`` for UTF-8 text, ``"binary"`` otherwise.
    """
    with open(path, "rb") as handle:
        head = handle.read(4096)
    if not head:
        return "empty"
    for kind, offset, magic in _MAGIC:
        if head[offset : offset + len(magic)] == magic:
            return kind
    if b"\x00" in head:
        return "binary"
    try:
        head.decode("utf-8")
    except UnicodeDecodeError as exc:
        if exc.start < len(head) - 3:  # not just a character cut at 4096 bytes
            return "binary"
    return "text"


def _same(a: Path, b: Path) -> bool:
    try:
        return os.path.samefile(a, b)
    except OSError:  # one of them does not exist
        return False


def _writable_parent(path: Path, option: str) -> None:
    parent = path.parent if str(path.parent) else Path(".")
    existing = parent
    while not existing.exists():
        existing = existing.parent
    if not existing.is_dir():
        raise ValueError(f"The '{option}' {path} cannot be created: {existing} is a file.")
    if not os.access(existing, os.W_OK | os.X_OK):
        raise ValueError(f"The '{option}' {path} cannot be written: {existing} is read-only.")


def check_output_file(
    path: Path, option: str, *, inputs: tuple[Path, ...] = (), kind: str | None = None
) -> None:
    """Refuse, before any work, an output file that cannot or must not be written.

    Refused: a folder; one of the command's ``inputs`` (the same file under any
    name); an existing file of another kind than ``kind`` (a key of
    :data:`_REPLACEABLE`: an export never replaces a database); a file whose
    folder cannot be created or written.
    """
    path = Path(path)
    if path.is_dir():
        raise ValueError(f"The '{option}' must name a file; {path} is a folder.")
    for source in inputs:
        if _same(path, Path(source)):
            raise ValueError(f"The '{option}' {path} is also an input; choose another file.")
    if kind is not None and path.is_file():
        found = file_kind(path)
        if found != "empty" and found not in _REPLACEABLE[kind]:
            raise ValueError(
                f"The '{option}' must be a new file or a {kind} file to replace. "
                f"Got {path}, an existing {found} file, instead."
            )
    _writable_parent(path, option)


def check_output_dir(
    path: Path, option: str, *, inputs: tuple[Path, ...] = (), files: tuple[str, ...] = ()
) -> None:
    """Refuse, before any work, an output folder that cannot or must not be written.

    Refused: an existing file; one of the command's ``inputs`` (a folder of
    input files); a folder whose ``files`` (names the command writes into it)
    include a folder or one of the ``inputs``; a folder that cannot be created
    or written.
    """
    path = Path(path)
    if path.exists() and not path.is_dir():
        raise ValueError(f"The '{option}' must name a folder; {path} is a file.")
    for source in inputs:
        if _same(path, Path(source)):
            raise ValueError(f"The '{option}' {path} is also an input; choose another folder.")
    for name in files:
        target = path / name
        if target.is_dir():
            raise ValueError(
                f"The '{option}' {path} holds a folder {name} where a file is written; "
                "remove it or choose another folder."
            )
        for source in inputs:
            if _same(target, Path(source)):
                raise ValueError(
                    f"The '{option}' {path} would overwrite the input {source} with its "
                    f"{name}; choose another folder."
                )
    _writable_parent(path / "x", option)


def check_replaceable_dir(
    path: Path,
    option: str,
    command: str,
    *,
    inputs: tuple[Path, ...] = (),
    files: tuple[str, ...] | None = None,
    marker: str | None = None,
) -> None:
    """Refuse an existing output folder that replacing it as a whole would lose data from.

    A command that builds its folder beside ``path`` and swaps it in (``staged_dir``)
    deletes whatever the old folder held. Refused, before any work: a folder that
    holds one of the command's ``inputs``; a folder with entries other than
    ``files`` (the names the command writes); a non-empty folder without
    ``marker`` (a file every earlier result of the command has).
    """
    path = Path(path)
    if not path.is_dir():
        return
    folder = Path(os.path.abspath(path))
    for source in inputs:  # (a missing input is reported by its reader)
        if Path(source).exists() and folder in Path(os.path.abspath(source)).parents:
            raise ValueError(
                f"The '{option}' {path} holds the input {source}, and the folder is replaced "
                "as a whole by the new results; choose another folder."
            )
    entries = sorted(p.name for p in path.iterdir())
    others = [name for name in entries if files is not None and name not in files]
    if marker is not None and entries and marker not in entries:
        others = others or entries
    if others:
        shown = ", ".join(others[:3]) + (f" and {len(others) - 3} more" if len(others) > 3 else "")
        raise ValueError(
            f"The '{option}' {path} is replaced as a whole by the results of '{command}', but "
            f"it holds other files ({shown}); choose a new or empty folder, or one of its "
            "earlier results."
        )


def _concerns(exc: OSError, path: Path) -> bool:
    """Whether an OS error names ``path``, a file inside it or a temporary file beside it."""
    names = [n for n in (exc.filename, exc.filename2) if n is not None]
    if not names:  # a write or flush: the error names no file
        return True
    target = Path(os.path.abspath(path))
    for name in names:
        if isinstance(name, int):  # a file descriptor
            return True
        found = Path(os.path.abspath(os.fsdecode(name)))
        if found == target or target in found.parents:
            return True
        if found.parent == target.parent and found.name.startswith(f".{target.name}."):
            return True
    return False


def os_error_message(exc: OSError) -> str:
    """An OS error as ``reason: path`` (no ``[Errno N]``); a message-only error as it is."""
    if exc.errno is None or not exc.strerror:
        return str(exc)
    names = [os.fsdecode(n) for n in (exc.filename, exc.filename2) if isinstance(n, str | bytes)]
    return f"{exc.strerror}: {' -> '.join(names)}" if names else exc.strerror


@contextmanager
def output_errors(path: Path, option: str) -> Iterator[None]:
    """Turn an OS error while writing ``path`` (the value of ``option``) into one line.

    A full disk, a read-only folder or a file where a folder is needed become an
    :class:`OutputError` naming the option and the path. OS errors about other
    files (the inputs), and errors raised on purpose with a message only, pass
    unchanged.
    """
    try:
        yield
    except OutputError:
        raise
    except OSError as exc:
        if exc.errno is None or not _concerns(exc, Path(path)):
            raise
        reason = exc.strerror or str(exc)
        names = [
            os.fsdecode(n) for n in (exc.filename, exc.filename2) if isinstance(n, str | bytes)
        ]
        detail = f" ({names[-1]})" if names and names[-1] != str(path) else ""
        raise OutputError(f"The '{option}' {path} could not be written: {reason}{detail}.") from exc


@contextmanager
def as_written(staged: Path, final: Path) -> Iterator[None]:
    """An OS error about a file under ``staged`` names the file it becomes under ``final``.

    Outputs are written beside their place first (a staging folder, a temporary
    file) and moved there when complete; an error while writing them is about
    the output, and :func:`output_errors` says so with the final name.
    """
    try:
        yield
    except OSError as exc:
        name = exc.filename
        if exc.errno is None or not isinstance(name, str | bytes):
            raise
        found = Path(os.path.abspath(os.fsdecode(name)))
        root = Path(os.path.abspath(staged))
        if found != root and root not in found.parents:
            raise
        renamed = Path(final) / found.relative_to(root) if found != root else Path(final)
        raise OSError(exc.errno, exc.strerror, str(renamed)) from exc
