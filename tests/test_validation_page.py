"""``make docs`` after a fresh ``make run`` leaves docs/validation.md as it was.

The page is tracked and generated from a run's ``summary.json``; two runs of the same code on
the same machine differ in their dates and wall time only, so the page leaves those off: it
changes when a figure or the run's setting does, and a rerun does not dirty the tree.
"""

from __future__ import annotations

import copy
import importlib.util
import sys
from pathlib import Path

ROOT = Path(__file__).resolve().parents[1]


def _load(name: str):
    spec = importlib.util.spec_from_file_location(name, ROOT / "docs" / f"{name}.py")
    module = importlib.util.module_from_spec(spec)
    sys.modules[name] = module
    spec.loader.exec_module(module)
    return module


gen_validation = _load("gen_validation")

#: A run's summary as ``softbend reproduce`` writes it (the figures the page reads).
RUN = {
    "paper_a": {},
    "paper_b": {"r2": 0.84181, "f_value": 68146.3, "mape_pct": 133.55},
    "paper_b_fem_data": {"r2": 0.83593, "f_value": 37817.9, "mape_pct": 48.93},
    "transfer": {"best": "refined", "summary": {"refined": {"rmse_deg": 7.6, "mape_pct": 7.05}}},
    "control": {"rig": [{"controller": "bang-bang", "reference": "square:90:4", "mape_pct": 7.17}]},
    "design": {"specifications": []},
    "reduced_settings": [],
    "provenance": {
        "command": "softbend reproduce --out results/reproduce",
        "softbend": "0.1.0",
        "seed": 0,
        "started (UTC)": "2026-11-26 13:25:58",
        "finished (UTC)": "2026-11-26 13:32:44",
        "wall time": "406 s",
    },
    "seconds": 406.0,
}


def _rerun(**changes: object) -> dict:
    """The same run again: other dates and wall time, and ``changes`` to its figures."""
    again = copy.deepcopy(RUN)
    again["provenance"].update(
        {"started (UTC)": "2026-11-28 02:00:01", "finished (UTC)": "2026-11-28 02:07:30"}
    )
    again["provenance"]["wall time"] = "449 s"
    again["seconds"] = 449.3
    for section, figures in changes.items():
        again[section] = {**again[section], **figures}
    return again


def test_a_rerun_makes_the_same_page():
    page = gen_validation.page_text(gen_validation.check_summary(copy.deepcopy(RUN)))
    assert gen_validation.page_text(_rerun()) == page
    assert "2026-11-26" not in page and "406 s" not in page
    assert "| seed | 0 |" in page and "| 0.84181 |" in page  # the setting and the figures stay
    assert page.rstrip().endswith(gen_validation.NOTE)


def test_a_changed_figure_changes_the_page():
    page = gen_validation.page_text(RUN)
    assert gen_validation.page_text(_rerun(paper_b={"r2": 0.84182})) != page


def test_the_tracked_page_has_no_run_s_dates():
    tracked = (ROOT / "docs" / "validation.md").read_text(encoding="utf-8")
    for key in gen_validation.VOLATILE:
        assert f"| {key} |" not in tracked, key
    assert tracked.rstrip().endswith(gen_validation.NOTE)
