"""Every command's ``--help``: an example, plain text, only commands that exist.

The walk goes through the click tree behind the typer app, so a command added
later is checked without being listed here.
"""

from __future__ import annotations

import re
import shlex

import pytest
import typer.main

from softbend.cli import app, main


def _commands() -> list[tuple[str, ...]]:
    root = typer.main.get_command(app)
    found: list[tuple[str, ...]] = []

    def walk(command: object, path: tuple[str, ...]) -> None:
        found.append(path)
        subcommands = getattr(command, "commands", None)
        if subcommands:
            for name, sub in sorted(subcommands.items()):
                if not sub.hidden:
                    walk(sub, (*path, name))

    walk(root, ())
    return found


COMMANDS = _commands()
LEAVES = [
    path
    for path in COMMANDS
    if path and not any(p[: len(path)] == path and len(p) > len(path) for p in COMMANDS)
]


def _help(capsys, path: tuple[str, ...]) -> str:
    assert main([*path, "--help"]) == 0
    return capsys.readouterr().out


def test_the_walk_finds_the_commands():
    assert ("control", "simulate") in COMMANDS and ("train",) in COMMANDS
    assert len(LEAVES) >= 20


@pytest.mark.parametrize("path", LEAVES, ids=lambda p: " ".join(p))
def test_every_command_shows_an_example(capsys, path):
    text = _help(capsys, path)
    assert re.search(r"^\s*Example", text, re.MULTILINE), text
    # The example runs this very command.
    assert f"softbend {' '.join(path)}" in text, text


@pytest.mark.parametrize("path", COMMANDS, ids=lambda p: " ".join(p) or "softbend")
def test_help_is_plain_text(capsys, path):
    text = _help(capsys, path)
    for markup in ("``", "`", ":func:", ":class:", ":mod:", ":meth:", ":data:", ".. "):
        assert markup not in text, (markup, text)


@pytest.mark.parametrize("path", COMMANDS, ids=lambda p: " ".join(p) or "softbend")
def test_help_names_only_commands_that_exist(capsys, path):
    text = _help(capsys, path)
    groups = {p[0] for p in COMMANDS if p}
    for match in re.finditer(r"softbend ((?:[a-z][a-z0-9-]* ?){1,2})", text):
        words = match.group(1).split()
        if not words or words[0] not in groups:
            assert words and words[0] in groups, (match.group(0), text)
            continue
        is_group = any(p[:1] == (words[0],) and len(p) == 2 for p in COMMANDS)
        if len(words) == 2 and is_group:
            # A group and a word after it: the word is one of its subcommands.
            assert (words[0], words[1]) in COMMANDS, (match.group(0), text)


@pytest.mark.parametrize(
    "path", [p for p in COMMANDS if len(p) <= 1], ids=lambda p: " ".join(p) or "softbend"
)
def test_command_summaries_are_not_cut_short(capsys, path):
    text = _help(capsys, path)
    for line in text.splitlines():
        stripped = line.rstrip()
        assert not re.search(r"\b(Fig|et al|e\.g|i\.e|Eq|Sec|vs)\.$", stripped), (line, text)


def _click_command(path: tuple[str, ...]):
    command = typer.main.get_command(app)
    for name in path:
        command = command.commands[name]
    return command


def _option_names(path: tuple[str, ...]) -> set[str]:
    return {
        name
        for param in _click_command(path).params
        for name in (*param.opts, *param.secondary_opts)
        if name.startswith("-")
    }


GROUPS = [p for p in COMMANDS if len(p) <= 1 and p not in LEAVES]


@pytest.mark.parametrize("path", GROUPS, ids=lambda p: " ".join(p) or "softbend")
def test_group_listings_show_whole_summaries_on_80_columns(capsys, monkeypatch, path):
    monkeypatch.setenv("COLUMNS", "80")
    text = _help(capsys, path)
    listing = text.split("Commands:", 1)[1]
    for line in listing.splitlines():
        assert not line.rstrip().endswith("..."), (line, text)


#: Names given up for one name per notion: the pressure list is --pressures, the
#: pressure grid --pmax and --pstep, parallel work --workers.
RETIRED = ("--pressure", "--step", "--jobs")


@pytest.mark.parametrize("path", LEAVES, ids=lambda p: " ".join(p))
def test_one_name_per_notion(path):
    names = _option_names(path)
    assert not names & set(RETIRED), names & set(RETIRED)
    # Every output path is --out, with its short form.
    assert ("--out" in names) == ("-o" in names), names
    # A pressure grid is its top and its step, both in MPa.
    assert ("--pmax" in names) == ("--pstep" in names), names


def _example_lines(text: str, path: tuple[str, ...]) -> list[str]:
    """The example command lines of a help text, continuation lines joined."""
    lines, current = [], ""
    for raw in text.split("Example", 1)[1].splitlines():
        line = raw.strip()
        if current:
            current += " " + line.rstrip("\\").strip()
        elif line.startswith(f"softbend {' '.join(path)}"):
            current = line.rstrip("\\").strip()
        else:
            continue
        if not line.endswith("\\"):
            lines.append(current)
            current = ""
    return lines


@pytest.mark.parametrize("path", LEAVES, ids=lambda p: " ".join(p))
def test_examples_give_only_options_the_command_has(capsys, path):
    text = _help(capsys, path)
    examples = _example_lines(text, path)
    assert examples, text
    names = _option_names(path)
    for example in examples:
        for word in shlex.split(example):  # a quoted value is one word
            option = word.split("=", 1)[0]
            if option.startswith("-"):
                assert option in names, (option, example)
