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


def print_json(payload: object) -> None:
    """Print ``payload`` as JSON on stdout (NaN and inf become null)."""
    print(json_text(payload))


#: Cells that stand for a missing value; they do not make a column textual.
_PLACEHOLDERS = frozenset({"", "-", "—", "n.s."})


def _is_number(text: str) -> bool:
    """True for a number as a table shows it (a unit sign such as % or ° may follow)."""
    try:
        float(text.rstrip("%°").strip())
    except ValueError:
        return False
    return True


def _numeric_column(cells: list[str]) -> bool:
    """True when every cell is a number or a placeholder, and one at least a number."""
    shown = [cell for cell in cells if cell.strip() not in _PLACEHOLDERS]
    return bool(shown) and all(_is_number(cell) for cell in shown)


def print_table(title: str, columns: list[str], rows: list[list[Any]]) -> None:
    """Print a rich table; floats are shown with four significant digits.

    Numeric columns are right-aligned, text columns left-aligned. Cells wrap (a
    word longer than its column folds onto the next line), so that nothing is
    cut short with an ellipsis on a narrow terminal (80 columns).
    """
    shown = [[f"{v:.4g}" if isinstance(v, float) else str(v) for v in row] for row in rows]
    table = Table(title=title)
    for index, column in enumerate(columns):
        cells = [row[index] for row in shown if index < len(row)]
        numeric = index > 0 and _numeric_column(cells)
        table.add_column(
            column, justify="right" if numeric else "left", overflow="fold", no_wrap=False
        )
    for row in shown:
        table.add_row(*row)
    console.print(table)
