"""The report's transfer-learning section, drawn from the pipeline's results."""

from __future__ import annotations

import pytest

from softbend.reports import transfer_section
from softbend.reports.html import Report

from .conftest import figures_of, only_section

#: Strategies without a network or a Gaussian process to train.
FAST = ("fem-only", "analytical", "scale-offset", "pressure-scale")


@pytest.fixture(scope="module")
def section(tmp_path_factory):
    out = tmp_path_factory.mktemp("transfer_section")
    report = Report("test")
    summary = transfer_section.add_section(report, out, 0, strategies=FAST)
    return out, report, summary


def test_the_section_is_labelled_synthetic_with_its_figures(section):
    out, report, _ = section
    title, html = only_section(report)
    assert "transfer learning" in title
    assert "SYNTHETIC" in html
    assert figures_of(html) == [
        "transfer/virtual_lab.png",
        "transfer/fig7_actuators.png",
        "transfer/fig6_loss_curves.png",
        "transfer/learning_curve.png",
    ]
    assert all((out / src).stat().st_size > 1000 for src in figures_of(html))


def test_the_table_has_every_strategy_and_paper_b_beside(section):
    _, report, summary = section
    _, html = only_section(report)
    for name, row in summary["summary"].items():
        assert f"<td>{name}</td><td>{row['rmse_deg']:.4g}</td>" in html
    assert "paper B refined MLP (real rig)" in html
    assert str(transfer_section.PAPER_B_REFINED["rmse_deg"]) in html
    assert f"Best: {summary['best']}" in html
    assert "pressure-scale and scaled-refined strategies go beyond paper B" in html
    assert set(summary["files"]) >= {"summary", "per_actuator", "json"}
