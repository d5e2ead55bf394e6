"""The CLI's consoles: one-line errors and warnings, JSON and tables on stdout, logging."""

from __future__ import annotations

import logging
import warnings
from collections.abc import Iterator
from contextlib import contextmanager
from typing import Any

from rich.console import Console
from rich.logging import RichHandler
from rich.table import Table

from softbend._io import json_text

__all__ = [
    "configure_logging",
    "console",
    "err_console",
    "error_line",
    "print_json",
    "print_table",
    "warning_line",
    "warnings_as_lines",
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
