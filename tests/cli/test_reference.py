"""docs/cli-reference.md is the commands' own --help: regenerated, it must not change."""

from __future__ import annotations

from pathlib import Path

from softbend.cli.reference import command_paths, reference_markdown

PAGE = Path(__file__).resolve().parents[2] / "docs" / "cli-reference.md"


def test_the_reference_page_is_what_the_commands_say_today():
    fresh = reference_markdown()
    assert PAGE.read_text(encoding="utf-8") == fresh, (
        "docs/cli-reference.md is out of date: run `make docs` (python docs/gen_cli_reference.py)"
    )


def test_every_command_has_its_section():
    page = PAGE.read_text(encoding="utf-8")
    paths = command_paths()
    assert ("design", "find") in paths and ("identify",) in paths
    for path in paths:
        assert f"## {' '.join(('softbend', *path))}\n" in page
