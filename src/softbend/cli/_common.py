"""Shared CLI plumbing: consoles, one-line errors, JSON output, progress bars, outputs.

Gathered here for the command modules (``from softbend.cli import _common``);
each part lives in its own module: :mod:`~softbend.cli._console` (consoles,
one-line errors, JSON, tables), :mod:`~softbend.cli._progress` (progress on
stderr) and :mod:`~softbend.cli._outputs` (outputs checked before any work, OS
errors as one line). :func:`parse_assignments` reads a repeated ``--set NAME=VALUE``;
:data:`DESIGN_HELP` is the help of every ``--design`` option.
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
from softbend.cli._progress import library_progress, phase_progress, progress_bar
from softbend.errors import SoftbendError, keyed

__all__ = [
    "DESIGN_HELP",
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
    "library_progress",
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

#: The help of every ``--design`` option: one actuator's parameters and their units.
DESIGN_HELP = "Actuator l,r,t,b,phi,lc (mm, mm, mm, mm, deg, mm)."


def parse_assignments(texts: Sequence[str]) -> dict[str, str]:
    """The ``NAME=VALUE`` texts of a repeated ``--set`` as names and value texts.

    :func:`softbend.parameters.parse_assignments`, its errors keyed ``settings``
    (the key the command line names ``--set``).
    """
    from softbend.parameters import parse_assignments as parse

    with keyed("settings"):
        return parse(texts)
