"""The report's summary table: softbend's figures beside the papers', never a bare nan."""

from __future__ import annotations

import math

from softbend.reports.html import Report
from softbend.reports.summary_section import add_summary, headline_rows

SUMMARY = {
    "paper_b": {"r2": 0.84181, "f_value": 68146.33, "mape_pct": 133.5},
    "paper_b_fem_data": {
        "r2": math.nan,
        "surrogates_random": {"mlp": {"r2": 0.99994, "mape_pct": 1.31}},
    },
    "transfer": {"best": "refined", "summary": {"refined": {"rmse_deg": 7.6, "mape_pct": 7.05}}},
    "control": {"rig": [{"controller": "bang-bang", "reference": "square:90:4", "mape_pct": 7.2}]},
}


def test_each_figure_sits_beside_the_paper_s_with_its_source():
    rows = {figure: (ours, paper) for figure, ours, paper, _ in headline_rows(SUMMARY)}
    ours, paper = rows["Paper B Fig. 7, refined MLP, leave one actuator out: mean RMSE "
                       "(synthetic virtual lab)"]  # fmt: skip
    assert ours == "7.60°" and paper == "7.935° (Sec. 4.3, Fig. 7)"
    ours, paper = rows["Paper B Fig. 4c, linear model on the analytical model, Table 1: F"]
    assert ours == "68146.3" and paper == "33935.8 (Sec. 3.3, Fig. 4c)"
    ours, _ = rows["Paper B Fig. 9, bang-bang on the simulated rig, square:90:4: MAPE"]
    assert ours == "7.20 %"


def test_a_figure_the_run_lacks_says_why_and_never_nan():
    rows = {figure: ours for figure, ours, _, _ in headline_rows(SUMMARY)}
    assert rows["Paper B Fig. 4c, linear model on the FEM dataset, Table 1: R²"].startswith(
        "undefined"
    )
    assert rows["Paper B Fig. 4c, linear model on the FEM dataset, Table 1: MAPE"] == (
        "not computed in this run"
    )
    assert not any("nan" in ours.lower() for ours in rows.values())


def test_the_summary_goes_first_and_links_to_the_sections():
    report = Report("r")
    report.section("Paper B — closed-loop control (Figs. 8 and 9)").text("...")
    add_summary(report, SUMMARY, reduced="fewer designs")
    html = report.render()
    assert report.sections[0].title.startswith("Summary")
    assert "REDUCED SETTINGS: this report was made with fewer designs" in html
    assert 'href="#paper-b-closed-loop-control-figs-8-and-9"' in html
    plain = Report("r")
    add_summary(plain, SUMMARY, reduced=None)
    assert "REDUCED" not in plain.render()


def test_the_validation_page_carries_the_run_s_provenance_and_every_row():
    from softbend.reports.summary_section import validation_markdown

    page = validation_markdown(
        {**SUMMARY, "provenance": {"machine": "Linux x86_64, 2 logical CPUs", "seed": 0}}
    )
    assert page.startswith("# Validation: softbend beside the papers")
    assert "| machine | Linux x86_64, 2 logical CPUs |" in page
    assert "| 7.60° | 7.935° (Sec. 4.3, Fig. 7) |" in page
    assert len([line for line in page.splitlines() if line.startswith("| Paper")]) == len(
        headline_rows(SUMMARY)
    ) - sum(figure.startswith("  ") for figure, *_ in headline_rows(SUMMARY))


def test_the_pneunet_rows_give_the_reference_the_mesh_change_and_the_fem_check_of_the_design():
    summary = {
        "pneunet": {
            "contact": "on",
            "last_pressure_mpa": 0.05,
            "last_angle_deg": 170.304,
            "mesh_sizes_mm": [3.0, 2.5, 2.0],
            "mesh_pressure_mpa": 0.012,
            "mesh_change_deg": 1.032,
            "target": "90° ± 3° at 0.03 MPa",
            "best": {"angle_deg": 90.0, "fem_angle_deg": None},  # a quick run: not swept
        }
    }
    rows = {figure: ours for figure, ours, _, _ in headline_rows(summary)}
    assert rows["PneuNet reference (walls in contact): angle at 50 kPa"] == "170.30°"
    assert rows["PneuNet reference: angle at 12 kPa, change from 3 mm to 2 mm elements"] == "1.03°"
    checked = rows[
        "PneuNet design find, 90° ± 3° at 0.03 MPa: best design's angle, surrogate / FEM"
    ]
    assert checked == "90.00° / not computed in this run"
    summary["pneunet"]["contact"] = "off"  # a sweep to the first touch says so
    rows = {figure: ours for figure, ours, _, _ in headline_rows(summary)}
    assert "PneuNet reference (to the walls' touch): angle at 50 kPa" in rows
