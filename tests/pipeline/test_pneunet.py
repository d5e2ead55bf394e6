"""The PneuNet section's pipeline and drawing: reference, mesh, main effects, a checked design."""

from __future__ import annotations

import json

import numpy as np
import pytest

import softbend._torch  # noqa: F401  (PyTorch before NGSolve)
from softbend.actuators import PNEUNET
from softbend.fem.pneunet.description import cavity_volume_mm3
from softbend.pipeline import pneunet as pipeline
from softbend.reports import pneunet_section
from softbend.reports.html import Report

from .conftest import Phases, pictures


@pytest.fixture(scope="module")
def ran(tmp_path_factory):
    out = tmp_path_factory.mktemp("pneunet")
    phases = Phases()
    section = pipeline.run_pneunet(out, progress=phases, mesh_sizes_mm=(3.0,), verify=1)
    return out, section, phases


def test_the_reference_bends_through_the_working_range_with_its_walls_pressing(ran):
    _, s, _ = ran
    p, a, v = s.step_pressure_mpa, s.step_angle_deg, s.step_volume_mm3
    force, pressure = s.step_contact_force_n, s.step_contact_pressure_kpa
    assert p[0] == 0.0 and np.all(np.diff(p) > 0)
    assert np.all(np.diff(a) > 0) and np.all(np.diff(v) > 0)  # more pressure: more bend, volume
    # at 0 kPa the cavity is the drawn one (gravity barely deforms it)
    assert v[0] == pytest.approx(cavity_volume_mm3(s.design), rel=0.01)
    assert s.sweep.stats["stop_reason"] == "reached the last pressure"
    assert p[-1] == pytest.approx(0.05) and a[-1] - a[0] >= 90.0  # the working range
    # the walls touch at 6-7 kPa (the contact-free sweep's stop) and press harder after
    assert len(force) == len(pressure) == len(p)
    first = int(np.flatnonzero(pressure > 0)[0])
    assert 0.006 <= p[first] <= 0.008
    assert np.all(force[:first] == 0) and pressure[-1] > pressure[first] > 0
    summary = s.summary
    assert summary["contact"] == "on" and summary["last_angle_deg"] == a[-1]
    assert summary["largest_contact_pressure_kpa"] == pytest.approx(pressure.max())


def test_the_mesh_study_and_the_main_effects_cover_the_design_space(ran):
    _, s, _ = ran
    assert [r.maxh_mm for r in s.mesh] == [3.0]
    assert len(s.mesh[0].angles_deg) == len(pipeline.MESH_PRESSURES_MPA)
    assert all(np.isfinite(s.mesh[0].angles_deg))  # past the touch, in contact
    names = [p.name for p in PNEUNET.parameters]
    assert list(s.effects.effects.index) == names
    assert len(s.effects.effects.columns) == 3
    assert len(s.designs) >= 200  # the shipped dataset
    # a thicker base stiffens the bending side: less angle at the same pressure
    assert s.effects.effects.loc["base_mm"].iloc[0] < 0


def test_the_best_design_on_the_surrogate_is_within_the_tolerance_on_the_fem(ran):
    _, s, _ = ran
    best = s.summary["best"]
    assert best is not None and best["fem_meets"] is True
    assert abs(best["fem_angle_deg"] - pipeline.TARGET_ANGLE_DEG) <= 3.0
    assert s.summary["designs_searched"] == s.search.n_designs > 100_000
    # the rounds: the last met, each earlier one refined the surrogate it searched on
    rounds = s.summary["refinements"]
    assert rounds["met"] and rounds["rounds"] == len(s.rounds) <= pipeline.REFINE_ROUNDS + 1
    assert s.model.path == s.rounds[-1].model
    assert 0.5 < s.training["r2"] <= 1.0


def test_progress_finishes_and_the_summary_is_strict_json(ran):
    out, s, phases = ran
    assert phases.all_finished()
    json.loads(json.dumps(s.summary), parse_constant=lambda name: pytest.fail(name))
    assert (out / "pneunet" / "surrogate" / "models" / f"{pipeline.SURROGATE}.json").is_file()
    assert not pictures(out / "pneunet" / "surrogate" / "models")


def test_the_section_draws_every_part_and_states_the_missing_comparison(ran, monkeypatch):
    out, s, _ = ran
    monkeypatch.setattr(pipeline, "run_pneunet", lambda *args, **kwargs: s)
    report = Report("t")
    summary = pneunet_section.add_section(report, out)
    html = report.render()
    assert "the PneuNet" in html and "Published curve: not compared" in html
    assert "mean contact pressure (kPa)" in html and "frictionless penalty contact" in html
    for name in ("reference_curves.png", "main_effects.png", "design/curves.png"):
        assert (out / "pneunet" / name).is_file(), name
        assert f"pneunet/{name}" in html
    assert summary["best"] == s.summary["best"] and summary["seconds"] >= 0
