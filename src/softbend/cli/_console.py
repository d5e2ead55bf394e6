"""The CLI's consoles: one-line errors and warnings, JSON and tables on stdout, logging.

On a terminal rich fits the output to the window. Off a terminal (a pipe, a log
file, a batch queue) nothing is wrapped inside a word: messages are never wrapped
(one line each, however long), and a table is drawn wide enough for the longest
word of every column (up to :data:`TABLE_WIDTH` columns to keep each row on one
line), at least ``COLUMNS`` wide when set.
"""

from __future__ import annotations

import logging
import math
import numbers
import re
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
    "missing",
    "print_json",
    "print_table",
    "warning_line",
    "warnings_as_lines",
]

#: Third-party warnings known to be noise for a user (matched by category and message
#: start), silenced in :func:`warnings_as_lines`; every other warning is shown.
NOISY_WARNINGS: tuple[tuple[type[Warning], str], ...] = (
    (UserWarning, "No artists with labels found to put in legend"),
    (UserWarning, "FigureCanvasAgg is non-interactive"),
)


def _console(*, stderr: bool = False) -> Console:
    """A console; off a terminal its messages never wrap (``soft_wrap``)."""
    probe = Console(stderr=stderr)
    if probe.is_terminal:
        return probe
    return Console(stderr=stderr, soft_wrap=True)


console = _console()
err_console = _console(stderr=True)


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
            warning_line(f"{message}{_source(category)}")

        warnings.showwarning = show
        for category, start in NOISY_WARNINGS:
            warnings.filterwarnings("ignore", message=re.escape(start), category=category)
        yield


def _source(category: type[Warning]) -> str:
    """Where a warning comes from, for a reader: nothing for softbend's own or a plain one."""
    package = category.__module__.split(".")[0]
    if package in ("softbend", "builtins"):
        return ""
    return f" (from {package})"


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


#: Off a terminal, a table may take up to this many columns to keep each row on one line.
TABLE_WIDTH = 160

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
    shown = [
        cell for cell in cells if cell.strip() not in _PLACEHOLDERS and not cell.startswith("— (")
    ]
    return bool(shown) and all(_is_number(cell) for cell in shown)


def missing(reason: str | None = None) -> str:
    """The cell of an undefined value: ``—``, with the reason when known (``— (no data)``)."""
    return f"— ({reason})" if reason else "—"


def _cell(value: Any) -> str:
    """A table cell: floats with four significant digits, an undefined value as ``—``."""
    if value is None:
        return missing()
    if isinstance(value, numbers.Real) and not isinstance(value, numbers.Integral):
        number = float(value)
        return missing() if math.isnan(number) else f"{number:.4g}"
    text = str(value)
    return missing() if text.strip() in ("", "nan", "NaN", "None") else text


def print_table(title: str, columns: list[str], rows: list[list[Any]]) -> None:
    """Print a rich table; floats are shown with four significant digits.

    Numeric columns are right-aligned, text columns left-aligned. A value that is
    None, NaN or empty is shown as ``—`` (:func:`missing`; a caller that knows why
    passes ``missing(reason)``). On a terminal, cells wrap at spaces (a word longer
    than its column folds onto the next line), so that nothing is cut short with an
    ellipsis on a narrow terminal (80 columns). Off a terminal the table is drawn
    wide enough for each column's longest word (see the module's docstring), so no
    word is broken.
    """
    shown = [[_cell(v) for v in row] for row in rows]
    table = Table(title=title)
    for index, column in enumerate(columns):
        cells = [row[index] for row in shown if index < len(row)]
        numeric = index > 0 and _numeric_column(cells)
        table.add_column(
            column, justify="right" if numeric else "left", overflow="fold", no_wrap=False
        )
    for row in shown:
        table.add_row(*row)
    if not console.soft_wrap:  # a terminal (or a console fitted to a width): fit the table
        console.print(table)
        return
    need = console.measure(table, options=console.options.update_width(100_000))
    # wide enough for the longest word of every column, for every cell on one line if
    # that takes at most TABLE_WIDTH columns; never narrower than the console (COLUMNS)
    width = max(console.width, need.minimum, min(need.maximum, TABLE_WIDTH))
    Console(file=console.file, width=width, soft_wrap=False).print(table)
