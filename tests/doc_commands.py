"""The ``softbend …`` commands a page of documentation shows in its bash blocks."""

from __future__ import annotations

from pathlib import Path


def softbend_commands(page: Path) -> list[tuple[int, str]]:
    """``(line, command)`` of every ``softbend …`` command in the ```bash blocks of ``page``.

    Continuation lines (``\\``) are joined and comments dropped; ``line`` is the first line.
    """
    out = []
    inside = False
    pending = ""
    start = 0
    for number, line in enumerate(page.read_text(encoding="utf-8").splitlines(), start=1):
        if line.startswith("```"):
            inside = line.strip() == "```bash" if not inside else False
            continue
        if not inside:
            continue
        text = line.split(" #", 1)[0].rstrip() if not line.lstrip().startswith("#") else ""
        if pending:
            pending += " " + text.strip().rstrip("\\").strip()
        elif text.strip().startswith("softbend "):
            pending, start = text.strip().rstrip("\\").strip(), number
        if pending and not text.rstrip().endswith("\\"):
            out.append((start, pending))
            pending = ""
    return out


def _code(line: str) -> str:
    """``line`` without its comment (a ``#`` after a space, or a whole-line comment)."""
    return "" if line.lstrip().startswith("#") else line.split(" #", 1)[0].rstrip()


def broken_continuations(page: Path) -> list[tuple[int, str]]:
    """``(line, text)`` of every line of a ```bash block that breaks a copy-paste of a command.

    Two defects: a line repeating the line before it where that one is continued (ends with
    ``\\``) or where both are option lines (indented, starting with ``-``), as a line pasted
    twice; and an option line after a ``softbend …`` command has ended (the previous line has
    no ``\\``), which the shell would run as a command of its own.
    """
    found = []
    inside = False
    previous = ""
    in_command = False  # the previous line belongs to a softbend command
    for number, line in enumerate(page.read_text(encoding="utf-8").splitlines(), start=1):
        if line.startswith("```"):
            inside = line.strip() == "```bash" if not inside else False
            previous, in_command = "", False
            continue
        if not inside:
            continue
        code = _code(line)
        continued = _code(previous).endswith("\\")
        option = line[:1].isspace() and code.strip().startswith("-")
        if line.strip() and line.strip() == previous.strip():
            if continued or (option and previous[:1].isspace()):
                found.append((number, line.strip()))
        elif option and in_command and not continued:
            found.append((number, line.strip()))
        if code.strip().startswith("softbend "):
            in_command = True
        elif not continued and not option:
            in_command = False
        previous = line
    return found
