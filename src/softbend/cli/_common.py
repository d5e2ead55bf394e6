"""Shared CLI plumbing: consoles, one-line errors, JSON output, progress bars, outputs.

Gathered here for the command modules (``from softbend.cli import _common``);
each part lives in its own module: :mod:`~softbend.cli._console` (consoles,
one-line errors, JSON, tables), :mod:`~softbend.cli._progress` (progress on
stderr) and :mod:`~softbend.cli._outputs` (outputs checked before any work, OS
errors as one line). :func:`parse_assignments` reads repeated ``--set NAME=VALUE``.
"""

from __future__ import annotations

from collections.abc import Sequence

from softbend._io import json_text
from softbend.cli._console import (
    configure_logging,
    console,
    err_console,
    error_line,
    print_json,
    print_table,
    warning_line,
    warnings_as_lines,
)
from softbend.cli._outputs import (
    OutputError,
    as_written,
    check_output_dir,
    check_output_file,
    check_replaceable_dir,
    file_kind,
    os_error_message,
    output_errors,
)
from softbend.cli._progress import phase_progress, progress_bar
from softbend.errors import SoftbendError

__all__ = [
    "OutputError",
    "SoftbendError",
    "as_written",
    "check_output_dir",
    "check_output_file",
    "check_replaceable_dir",
    "configure_logging",
    "console",
    "err_console",
    "error_line",
    "file_kind",
    "json_text",
    "os_error_message",
    "output_errors",
    "parse_assignments",
    "phase_progress",
    "print_json",
    "print_table",
    "progress_bar",
    "warning_line",
    "warnings_as_lines",
]


def parse_assignments(texts: Sequence[str], option: str = "--set") -> dict[str, str]:
    """``NAME=VALUE`` texts (a repeated option) as a mapping of names to value texts.

    Raises
    ------
    ValueError
        For a text without ``=`` or with an empty name, or a name given twice.
    """
    values: dict[str, str] = {}
    for text in texts:
        name, sep, value = str(text).partition("=")
        name = name.strip()
        if not sep or not name:
            raise ValueError(
                f"The '{option}' must be NAME=VALUE (e.g. {option} epochs=500). "
                f"Got {text!r} instead."
            )
        if name in values:
            raise ValueError(f"The '{option}' names {name!r} twice; give each parameter once.")
        values[name] = value.strip()
    return values
