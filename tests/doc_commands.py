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
