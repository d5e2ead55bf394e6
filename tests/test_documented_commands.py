"""Every softbend command shown in the README and the docs names a real command and options.

The commands are read from the ```bash blocks (continuation lines joined, comments dropped);
each is resolved in the command tree of ``softbend`` and each ``--option`` must be one of that
command's. A renamed command or option breaks this test, not a reader's first try. A line
pasted twice into a continued command, or an option line left after a command has ended, breaks
it too: the shell would run it as a command of its own.
"""

from __future__ import annotations

import re
import shlex
from pathlib import Path

import pytest
import typer

from softbend.cli import app

from .doc_commands import broken_continuations, softbend_commands

ROOT = Path(__file__).resolve().parents[1]
PAGES = [ROOT / "README.md", *sorted((ROOT / "docs").glob("*.md"))]


def _commands(page: Path) -> list[tuple[str, int, str]]:
    """``(page name, line, command)`` of every ``softbend …`` line in its bash blocks."""
    return [(page.name, line, command) for line, command in softbend_commands(page)]


COMMANDS = [c for page in PAGES for c in _commands(page)]


def test_the_pages_show_commands():
    assert len([c for c in COMMANDS if c[0] == "README.md"]) >= 10
    assert len(COMMANDS) >= 40


def _problem(command: str) -> str | None:
    """Why ``command`` is not a real softbend command with real options, or None."""
    words = shlex.split(command.replace("…", "x"))
    if words[0] != "softbend":
        return f"not a softbend command: {command}"
    group = typer.main.get_command(app)
    path = ["softbend"]
    rest = words[1:]
    while hasattr(group, "commands") and rest and not rest[0].startswith("-"):
        sub = group.commands.get(rest[0])
        if sub is None:
            return f"no command '{' '.join([*path, rest[0]])}'"
        group, path, rest = sub, [*path, rest[0]], rest[1:]
    known = {"--help"} | {name for p in group.params for name in (*p.opts, *p.secondary_opts)}
    for word in rest:
        if word.startswith("--") or re.fullmatch(r"-[a-zA-Z]", word):
            option = word.split("=", 1)[0]
            if option not in known:
                return f"'{' '.join(path)}' has no option {option}"
    return None


def test_a_renamed_command_or_option_is_caught():
    assert _problem("softbend fem run --design 100,6,2,2,5,8 -o x") is None
    assert "no option --no-such" in _problem("softbend fem run --no-such 1")
    assert "no command 'softbend fem walk'" in _problem("softbend fem walk")


@pytest.mark.parametrize(("page", "line", "command"), COMMANDS, ids=lambda v: str(v)[:40])
def test_a_documented_command_exists_with_its_options(page, line, command):
    problem = _problem(command)
    assert problem is None, f"{page}:{line}: {problem}"


def test_a_line_pasted_twice_is_caught(tmp_path):
    page = tmp_path / "page.md"
    page.write_text(
        "```bash\n"
        "softbend identify arm.csv --inputs p1 \\\n"
        "    --outputs x --out m/          # the model\n"
        "    --outputs x --out m/          # the model\n"
        "softbend fem run --design 100,6,2,2,5,8 \\\n"
        "    --pmax 0.1 \\\n"
        "    --pmax 0.1 \\\n"
        "    -o fem/\n"
        "softbend predict m.json --pressures 0.1\n"
        "    --design 100,6,2,2,5,8\n"
        "MY_SPACE=(--space corners\n"
        "          --range l=60:100)\n"
        "```\n"
        "```text\n"
        "    --pmax 0.1\n"
        "    --pmax 0.1\n"
        "```\n"
    )
    assert [line for line, _ in broken_continuations(page)] == [4, 7, 10]


@pytest.mark.parametrize("page", PAGES, ids=lambda p: p.name)
def test_no_command_block_has_a_line_pasted_twice(page):
    assert broken_continuations(page) == [], f"{page.name}: a line that breaks a copy-paste"
