"""The report's control section, drawn from the pipeline's results."""

from __future__ import annotations

import pytest

from softbend.control.study import PAPER_B_CONTROL
from softbend.reports import control_section
from softbend.reports.html import Report

from .conftest import figures_of, only_section


@pytest.fixture(scope="module")
def section(tmp_path_factory):
    out = tmp_path_factory.mktemp("control_section")
    report = Report("test")
    summary = control_section.add_section(report, out, 0, duration_s=1.5, refine_epochs=20)
    return out, report, summary


def test_the_section_shows_the_rig_and_the_mismatch(section):
    out, report, summary = section
    title, html = only_section(report)
    assert "closed-loop control" in title
    assert "SIMULATED rig" in html and control_section.CONTROL_DESIGN in html
    assert "1.5 s per run, seed 0" in html
    assert figures_of(html) == [
        "control/fig9_square.png",
        "control/fig9_triangle.png",
        "control/lab_square.png",
    ]
    assert all((out / src).stat().st_size > 1000 for src in figures_of(html))
    assert summary["files"] == {
        "square": str(out / "control" / "fig9_square.png"),
        "triangle": str(out / "control" / "fig9_triangle.png"),
        "lab": str(out / "control" / "lab_square.png"),
    }
    assert list(summary) == ["seconds", "rig", "lab_fem_mlp", "lab_refined_mlp", "files"]


def test_the_tables_put_paper_b_beside_the_runs(section):
    _, report, summary = section
    _, html = only_section(report)
    assert html.count("<table>") == 2
    assert "paper B bang-bang (its rig)" in html
    assert f"<td>{PAPER_B_CONTROL['square']['mape_pct']:.4g}</td>" in html
    for row in summary["rig"]:
        assert f"<td>{row['controller']}</td>" in html
