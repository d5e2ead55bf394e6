"""The report's Figs. 4 and 5 on FEM data, drawn from the pipeline's results."""

from __future__ import annotations

import pytest

from softbend.reports import paper_b_fem_data
from softbend.reports.html import Report

from ..stand_ins import stand_in_fem_dataset
from .conftest import figures_of, only_section

#: The surrogate search under both protocols takes most of a minute on two cores.
pytestmark = pytest.mark.slow


@pytest.fixture(scope="module")
def section(tmp_path_factory):
    dataset = stand_in_fem_dataset(tmp_path_factory.mktemp("dataset"))
    out = tmp_path_factory.mktemp("fem_data_section")
    report = Report("test")
    summary = paper_b_fem_data.add_section(report, out, 0, dataset=dataset, models=["plr"])
    return out, report, summary


def test_the_section_shows_fig4_and_fig5_and_the_dataset(section):
    out, report, summary = section
    title, html = only_section(report)
    assert "Figs. 4 and 5" in title
    assert figures_of(html) == [
        "paper_b_fem/fig4a_correlation_fem.png",
        "paper_b_fem/fig4b_loadings_fem.png",
        "paper_b_fem/fig4c_parity_fem.png",
        "paper_b_fem/surrogates/fig5_parity_errors.png",
    ]
    assert all((out / src).stat().st_size > 1000 for src in figures_of(html))
    assert "stand-in for the test" in html
    assert f"{summary['designs_done']} / {paper_b_fem_data.TABLE1_DESIGNS}" in html
    # 15 of 972 designs: the section says the campaign is not complete.
    assert "not complete yet" in html


def test_the_surrogate_table_has_both_protocols(section):
    _, report, summary = section
    _, html = only_section(report)
    grouped, shuffled = summary["surrogates_grouped"]["plr"], summary["surrogates_random"]["plr"]
    assert shuffled["rmse_deg"] < grouped["rmse_deg"]
    assert "R², random CV" in html and "paper B (random CV)" in html
    assert f"<td>{grouped['r2']:.4g}</td>" in html and f"<td>{shuffled['r2']:.4g}</td>" in html
    assert html.count("<table>") == 4  # dataset, loadings, fit, surrogates
