"""docs/ranges.md is what docs/gen_ranges.py writes from the declarations in the code."""

from __future__ import annotations

import importlib.util
from pathlib import Path

ROOT = Path(__file__).resolve().parents[1]


def _gen():
    spec = importlib.util.spec_from_file_location("gen_ranges", ROOT / "docs" / "gen_ranges.py")
    module = importlib.util.module_from_spec(spec)
    spec.loader.exec_module(module)
    return module


def test_the_page_lists_every_declaration_and_no_parameter_is_undeclared():
    text = _gen().render()
    assert "## Names that become paths" in text
    assert "`step_s`" in text and "`hidden_sizes`" in text and "`period`" in text
    undeclared = [line for line in text.splitlines() if "**not declared**" in line]
    assert not undeclared, "numeric parameters without a declared Range:\n" + "\n".join(undeclared)


def test_the_committed_page_is_current():
    page = ROOT / "docs" / "ranges.md"
    assert page.read_text(encoding="utf-8") == _gen().render(), (
        "docs/ranges.md is out of date: run `make docs` (python docs/gen_ranges.py)"
    )
