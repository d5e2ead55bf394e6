"""The command-line reference, generated from the commands themselves.

:func:`reference_markdown` walks the command tree behind ``softbend`` and puts
every command's ``--help`` (at 80 columns, plain text) into one Markdown page,
``docs/cli-reference.md`` (``make docs`` writes it). A test compares the page
with a fresh rendering, so a renamed option or a changed help text cannot go
unnoticed in the documentation.
"""

from __future__ import annotations

import contextlib
import io
import os
from collections.abc import Iterator

__all__ = ["command_paths", "reference_markdown"]

_HEADER = """# Command-line reference

Generated from the commands themselves by `make docs` (`python docs/gen_cli_reference.py`);
do not edit by hand. Every command's `--help`, as `softbend … --help` prints it on an
80-column terminal. The guide to the commands is [cli.md](cli.md).
"""


def command_paths() -> list[tuple[str, ...]]:
    """Every command and group under ``softbend`` (the root as ``()``), depth first, sorted."""
    import typer.main

    from softbend.cli import app

    found: list[tuple[str, ...]] = []

    def walk(command: object, path: tuple[str, ...]) -> None:
        found.append(path)
        for name, sub in sorted((getattr(command, "commands", None) or {}).items()):
            if not sub.hidden:
                walk(sub, (*path, name))

    walk(typer.main.get_command(app), ())
    return found


@contextlib.contextmanager
def _terminal(columns: int) -> Iterator[None]:
    """A plain terminal of ``columns`` columns for the duration of the block."""
    saved = {k: os.environ.get(k) for k in ("COLUMNS", "NO_COLOR", "TERM")}
    os.environ.update({"COLUMNS": str(columns), "NO_COLOR": "1", "TERM": "dumb"})
    try:
        yield
    finally:
        for key, value in saved.items():
            if value is None:
                os.environ.pop(key, None)
            else:
                os.environ[key] = value


def reference_markdown(columns: int = 80) -> str:
    """The whole reference page: one section per command with its ``--help`` verbatim."""
    from softbend.cli import main

    parts = [_HEADER]
    with _terminal(columns):
        for path in command_paths():
            out = io.StringIO()
            with contextlib.redirect_stdout(out):
                main([*path, "--help"])
            title = " ".join(("softbend", *path))
            parts.append(f"## {title}\n\n```text\n{out.getvalue().rstrip()}\n```\n")
    return "\n".join(parts)
