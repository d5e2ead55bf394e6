"""The browser check itself: it sees a report as a user does and catches a missing image."""

from __future__ import annotations

import matplotlib

matplotlib.use("Agg")
import matplotlib.pyplot as plt

from softbend.reports.html import Report

from .conftest import open_in_browser


def _report(tmp_path, *, remove_figure: bool):
    figure = tmp_path / "figs" / "curve.png"
    figure.parent.mkdir()
    fig, ax = plt.subplots(figsize=(3, 2))
    ax.plot([0, 1], [0, 1])
    fig.savefig(figure)
    plt.close(fig)
    report = Report("Check")
    report.section("One").figure(figure, "a curve", root=tmp_path)
    report.section("Two").table(["a"], [[1.0]])
    report.provenance = {"seed": 0}
    path = report.write(tmp_path / "index.html")
    if remove_figure:
        figure.unlink()
    return path


def test_a_complete_report_loads_every_image_without_errors(tmp_path):
    seen = open_in_browser(_report(tmp_path, remove_figure=False), tmp_path / "shot.png")
    assert seen["images"] == ["figs/curve.png"] and seen["broken_images"] == []
    assert seen["console_errors"] == []
    assert seen["toc_targets"] == ["one", "two"]
    assert seen["section_ids"] == ["one", "two", "provenance"] and seen["tables"] == 1
    assert (tmp_path / "shot.png").stat().st_size > 5_000


def test_a_missing_image_is_seen(tmp_path):
    seen = open_in_browser(_report(tmp_path, remove_figure=True))
    assert seen["broken_images"] == ["figs/curve.png"]
    assert any("curve.png" in e for e in seen["console_errors"])
