"""Shared CLI plumbing: consoles, one-line errors, JSON output, progress bars."""

from __future__ import annotations

import logging
import os
import warnings
from collections.abc import Callable, Iterator
from contextlib import contextmanager
from pathlib import Path
from typing import Any

from rich.console import Console
from rich.logging import RichHandler
from rich.progress import (
    BarColumn,
    MofNCompleteColumn,
    Progress,
    TextColumn,
    TimeElapsedColumn,
    TimeRemainingColumn,
)
from rich.table import Table

from softbend._io import json_text
from softbend.errors import SoftbendError

__all__ = [
    "OutputError",
    "SoftbendError",
    "check_output_dir",
    "check_output_file",
    "configure_logging",
    "console",
    "err_console",
    "error_line",
    "file_kind",
    "os_error_message",
    "output_errors",
    "print_json",
    "print_table",
    "progress_bar",
    "warning_line",
]

console = Console()
err_console = Console(stderr=True)


def configure_logging(verbose: bool) -> None:
    """Send softbend's log records to stderr; INFO when verbose, WARNING otherwise."""
    logger = logging.getLogger("softbend")
    logger.handlers[:] = [RichHandler(console=err_console, show_path=False)]
    logger.setLevel(logging.INFO if verbose else logging.WARNING)


@contextmanager
def warnings_as_lines() -> Iterator[None]:
    """Within, every Python warning is one :func:`warning_line` (restored on exit).

    Scoped, not global: a command run in-process (tests, a notebook) leaves the
    caller's warning filters and display as they were.
    """
    with warnings.catch_warnings():  # the filters stay as the caller set them

        def show(message, category, filename, lineno, file=None, line=None) -> None:
            warning_line(f"{message} ({category.__name__})")

        warnings.showwarning = show
        yield


def error_line(message: str) -> None:
    """Print one error line to stderr (no traceback)."""
    text = " ".join(str(message).split())
    err_console.print(f"softbend: error: {text}", markup=False, highlight=False, soft_wrap=True)


def warning_line(message: str) -> None:
    """One ``softbend: warning: …`` line on stderr (the command goes on)."""
    text = " ".join(str(message).split())
    err_console.print(f"softbend: warning: {text}", markup=False, highlight=False, soft_wrap=True)


def print_json(payload: Any) -> None:
    """Print ``payload`` as JSON on stdout (NaN and inf become null)."""
    print(json_text(payload))


def print_table(title: str, columns: list[str], rows: list[list[Any]]) -> None:
    """Print a rich table; floats are shown with four significant digits."""
    table = Table(title=title)
    for column in columns:
        table.add_column(column, justify="right" if column != columns[0] else "left")
    for row in rows:
        table.add_row(*(f"{v:.4g}" if isinstance(v, float) else str(v) for v in row))
    console.print(table)


@contextmanager
def progress_bar(
    description: str, total: int, *, enabled: bool = True
) -> Iterator[Callable[..., None]]:
    """Yield ``advance(n=1, **fields)``, drawing a rich progress bar on stderr.

    Extra keyword fields (e.g. ``failed=3``) are shown after the bar. Off a
    terminal (a batch queue, a log file) a bar would draw nothing until the end,
    so a plain line with the count, the fields, the elapsed time and an estimate
    of the time left is written at every tenth of the total instead.
    """
    if enabled and not err_console.is_terminal:
        import time

        state = {"done": 0, "tenth": -1, "start": time.monotonic()}

        def advance_plain(n: int = 1, **fields: Any) -> None:
            state["done"] += n
            done = state["done"]
            tenth = 10 if total <= 0 else min(10, (10 * done) // total)
            if tenth <= state["tenth"]:
                return
            state["tenth"] = tenth
            elapsed = time.monotonic() - state["start"]
            eta = f", about {elapsed / done * (total - done):.0f} s left" if done else ""
            info = "  ".join(f"{k} {v}" for k, v in fields.items())
            err_console.print(
                f"{description}: {done}/{total}  {info}  {elapsed:.0f} s{eta}",
                highlight=False,
                soft_wrap=True,
            )

        yield advance_plain
        return
    columns = [
        TextColumn("[progress.description]{task.description}"),
        BarColumn(),
        MofNCompleteColumn(),
        TextColumn("{task.fields[info]}"),
        TimeElapsedColumn(),
        TextColumn("ETA"),
        TimeRemainingColumn(),
    ]
    with Progress(*columns, console=err_console, disable=not enabled, transient=False) as bar:
        task = bar.add_task(description, total=total, info="")

        def advance(n: int = 1, **fields: Any) -> None:
            info = "  ".join(f"{k} {v}" for k, v in fields.items())
            bar.update(task, advance=n, info=info)

        yield advance


@contextmanager
def phase_progress(*, enabled: bool = True) -> Iterator[Callable[[str, int, int], None]]:
    """Yield ``progress(phase, done, total)`` for jobs with several phases.

    On a terminal each phase gets a rich progress bar on stderr. Elsewhere (a
    batch queue, a CI log) a bar would draw nothing until the end, so a plain
    line is written to stderr when a phase starts, at every further tenth of
    it, and when it ends.
    """
    if not enabled:
        yield lambda phase, done, total: None
        return
    if err_console.is_terminal:
        columns = [
            TextColumn("{task.description}"),
            BarColumn(),
            MofNCompleteColumn(),
            TimeElapsedColumn(),
            TextColumn("ETA"),
            TimeRemainingColumn(),
        ]
        with Progress(*columns, console=err_console) as bar:
            tasks: dict[str, Any] = {}

            def draw(phase: str, done: int, total: int) -> None:
                if phase not in tasks:
                    tasks[phase] = bar.add_task(phase, total=total)
                bar.update(tasks[phase], completed=done, total=total)

            yield draw
        return
    import time

    last_tenth: dict[str, int] = {}
    started: dict[str, float] = {}

    def write(phase: str, done: int, total: int) -> None:
        tenth = 10 if total <= 0 else min(10, (10 * done) // total)
        if phase in last_tenth and tenth <= last_tenth[phase]:
            return
        started.setdefault(phase, time.monotonic())
        last_tenth[phase] = tenth
        elapsed = time.monotonic() - started[phase]
        err_console.print(f"{phase}: {done}/{total} ({elapsed:.0f} s)", highlight=False)

    yield write


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
