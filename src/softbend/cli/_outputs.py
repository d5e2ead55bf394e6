"""Outputs of the commands: refused before any work if unwritable, OS errors as one line."""

from __future__ import annotations

import functools
import os
from collections.abc import Callable, Iterator
from contextlib import contextmanager
from contextvars import ContextVar
from pathlib import Path
from typing import Any

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
    "running_as",
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
    "model": {"softbend model"},
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


def _is_softbend_model(path: Path) -> bool:
    """Whether a JSON file is a surrogate softbend saved (the format its loader accepts)."""
    import json

    from softbend.surrogates.persistence import FORMAT

    try:
        with open(path, encoding="utf-8") as handle:
            document = json.load(handle)
    except (OSError, ValueError):
        return False
    return isinstance(document, dict) and document.get("format") == FORMAT


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
    :data:`_REPLACEABLE`: an export never replaces a database, a saved model only
    replaces a model softbend saved); a file whose
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
        if found == "text" and kind == "model" and _is_softbend_model(path):
            found = "softbend model"
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
    path: Path, option: str, command: str | None = None, *, inputs: tuple[Path, ...] = ()
) -> None:
    """Refuse, before any work, an output folder that replacing it as a whole would lose from.

    The one rule of :mod:`softbend._outdir` for every command that writes a folder:
    an existing ``path`` is replaced only when it is empty or holds nothing but an
    earlier result of the same command (every entry listed in its manifest). Refused
    with one line: the current folder or one above it; a folder with other entries
    (naming them); a folder that holds one of the command's inputs. The inputs are
    ``inputs`` and every file or folder named by an option or argument of the running
    command (so an ``--actuator`` read from inside ``--out`` is refused too).
    """
    from softbend._outdir import check_replaceable, replaceable_target
    from softbend.errors import InputError

    try:
        target = replaceable_target(path)
    except InputError as exc:
        raise ValueError(f"The '{option}' {exc.detail}") from None
    for name, source in (*_named_inputs(option), *((None, Path(p)) for p in inputs)):
        if not Path(source).exists():  # (a missing input is reported by its reader)
            continue
        found = Path(os.path.realpath(source))
        if found == target or target in found.parents:
            given = f"the '{name}' {source}" if name else f"the input {source}"
            raise ValueError(
                f"The '{option}' {path} holds {given}, and the folder is replaced as a whole "
                "by the new results; move the input or choose another folder."
            )
    try:
        check_replaceable(path, command)
    except InputError as exc:
        raise ValueError(f"The '{option}' {exc.detail}") from None


#: The command line's running command: its parameters' labels (``--actuator``, ``DB``) and
#: values, set by :func:`running_as` for the paths :func:`check_replaceable_dir` refuses.
_ARGUMENTS: ContextVar[tuple[tuple[str, object], ...]] = ContextVar("arguments", default=())


def running_as(command: str, callback: Callable[..., Any]) -> Callable[..., Any]:
    """``callback``, a command's function, run as the command ``command`` (``"fem run"``).

    While it runs, output folders are written as that command's
    (:func:`softbend._outdir.running`) and its arguments are known to
    :func:`check_replaceable_dir`, which refuses an input read from inside ``--out``.
    """
    from softbend._outdir import running

    labels = _labels(callback)

    @functools.wraps(callback)
    def run(*args: Any, **kwargs: Any) -> Any:
        arguments = tuple((labels.get(k, k), v) for k, v in kwargs.items())
        token = _ARGUMENTS.set(arguments)
        try:
            with running(command):
                return callback(*args, **kwargs)
        finally:
            _ARGUMENTS.reset(token)

    return run


def _labels(callback: Callable[..., Any]) -> dict[str, str]:
    """Each parameter of a command's function as a user types it: ``--actuator``, or ``DB``."""
    import inspect
    import typing

    try:
        hints = typing.get_type_hints(callback, include_extras=True)
    except Exception:  # an annotation that does not resolve: the defaults still name options
        hints = {}
    labels = {}
    for name, parameter in inspect.signature(callback).parameters.items():
        found = [parameter.default, *getattr(hints.get(name), "__metadata__", ())]
        decls = [d for info in found for d in (getattr(info, "param_decls", None) or ())]
        long = [d for d in decls if isinstance(d, str) and d.startswith("--")]
        labels[name] = long[0] if long else f"--{name.replace('_', '-')}"
        if any(type(info).__name__ == "ArgumentInfo" for info in found):
            labels[name] = name.upper()
    return labels


def _named_inputs(option: str) -> list[tuple[str, Path]]:
    """Every existing path an option or argument of the running command names, but ``option``."""
    found = []
    for label, value in _ARGUMENTS.get():
        if label == option:
            continue
        values = value if isinstance(value, list | tuple) else [value]
        for item in values:
            if isinstance(item, str | os.PathLike) and str(item) and _exists(item):
                found.append((label, Path(item)))
    return found


def _exists(item: str | os.PathLike[str]) -> bool:
    try:
        return os.path.lexists(item)
    except (OSError, ValueError):  # a name too long, a NUL byte: not a path
        return False


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
