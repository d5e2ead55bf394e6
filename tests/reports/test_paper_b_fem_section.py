"""The report's Fig. 2 section: the fit and the FEM sweep, drawn from the pipeline's results."""

from __future__ import annotations

import pytest

from softbend.design import parse_sfrba
from softbend.fem import FEMOptions
from softbend.reports import paper_b_fem
from softbend.reports.html import Report

from .conftest import figures_of, only_section


@pytest.fixture(scope="module")
def section(tmp_path_factory):
    out = tmp_path_factory.mktemp("fem_section")
    report = Report("test")
    summary = paper_b_fem.add_section(report, out, options=FEMOptions(maxh_mm=6.0), pmax_mpa=0.02)
    return out, report, summary


def test_the_section_shows_the_fit_and_the_sweep(section):
    out, report, _ = section
    title, html = only_section(report)
    assert "Fig. 2" in title
    assert figures_of(html) == [
        "paper_b_fem/dragon_skin_30_fit.png",
        "paper_b_fem/fem_angle_pressure.png",
        "paper_b_fem/fem_shapes.png",
    ]
    assert all((out / src).stat().st_size > 1000 for src in figures_of(html))
    assert html.count("<table>") == 2
    assert "yeoh" in html and "neo-hookean" in html
    assert f"Design ({parse_sfrba(paper_b_fem.FIG2_DESIGN)}) swept from 0 to 0.02 MPa" in html


def test_the_angle_table_holds_the_summary_angles(section):
    _, report, summary = section
    _, html = only_section(report)
    fem = summary["fem_angles_deg"]
    assert set(fem) == {"0", "0.02"} and fem["0.02"] > fem["0"] > 0.0
    # One row per pressure of the summary, FEM and analytical (four significant digits).
    for pressure, angle in fem.items():
        analytical = summary["analytical_angles_deg"][pressure]
        row = f"<td>{float(pressure):.4g}</td><td>{angle:.4g}</td><td>{analytical:.4g}</td>"
        assert row in html


def test_seconds_cover_the_drawing(section):
    _, _, summary = section
    assert summary["seconds"] >= summary["fem_wall_time_s"] > 0
    assert next(iter(summary)) == "seconds"
