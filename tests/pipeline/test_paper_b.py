"""Paper B pipeline: the campaign (resumed when present) and the surrogates trained on it."""

from __future__ import annotations

import numpy as np
import pandas as pd
import pytest

from softbend.pipeline.paper_b import run_campaign_section, train_campaign_surrogates

from ..stand_ins import small_space
from .conftest import Phases, pictures


@pytest.fixture(scope="module")
def campaign(tmp_path_factory):
    out = tmp_path_factory.mktemp("paper_b")
    phases = Phases()
    return out, run_campaign_section(out, space=small_space(), workers=0, progress=phases), phases


def test_campaign_sweeps_every_design_and_exports_the_samples(campaign):
    out, ran, phases = campaign
    s = ran.summary
    assert s["backend"] == "analytical"
    assert s["n_designs"] == s["done"] == s["run_now"] == 8 and s["failed"] == 0
    assert s["resumed_done"] == 0 and s["designs_per_s"] > 0
    assert ran.database == out / "paper_b" / "campaign.duckdb" and ran.database.is_file()
    exported = pd.read_parquet(ran.parquet)
    assert len(exported) == len(ran.samples) == s["n_samples"] > 8
    assert phases.all_finished()
    assert pictures(out) == []


def test_every_sweep_bends_more_with_pressure(campaign):
    _, ran, _ = campaign
    for design_id, rows in ran.samples[ran.samples["converged"]].groupby("design_id"):
        rows = rows.sort_values("pressure_mpa")
        assert rows["angle_deg"].iloc[0] == pytest.approx(0.0, abs=1e-9), design_id
        assert np.all(np.diff(rows["angle_deg"].to_numpy()) > 0), design_id


def test_thicker_top_wall_bends_less(campaign):
    # Same design but t: at the same pressure, t = 3 mm bends less than t = 2 mm.
    _, ran, _ = campaign
    s = ran.samples[ran.samples["converged"] & np.isclose(ran.samples["pressure_mpa"], 0.05)]
    thin = s[(s["t_mm"] == 2.0) & (s["l_mm"] == 100.0) & (s["b_mm"] == 2.0)]["angle_deg"]
    thick = s[(s["t_mm"] == 3.0) & (s["l_mm"] == 100.0) & (s["b_mm"] == 2.0)]["angle_deg"]
    assert len(thin) == len(thick) == 1
    assert float(thick.iloc[0]) < float(thin.iloc[0])


def test_a_second_run_resumes_and_runs_nothing(campaign):
    out, first, _ = campaign
    again = run_campaign_section(out, space=small_space(), workers=0)
    assert again.summary["run_now"] == 0 and again.summary["resumed_done"] == 8
    assert again.summary["designs_per_s"] is None
    assert len(again.samples) == len(first.samples)


def test_surrogates_fit_the_campaign_and_are_saved(campaign):
    # The polynomial only: the three families are run by tests/reports/test_reproduce.py.
    out, _, _ = campaign
    phases = Phases()
    trained = train_campaign_surrogates(out, seed=0, progress=phases, models=["plr"])
    models = trained.summary["models"]
    assert set(models) == {"plr"}
    assert all(0.5 < m["r2"] <= 1.0 and m["rmse_deg"] > 0 for m in models.values())
    assert trained.summary["best_by_mape"] in models
    folder = out / "paper_b" / "surrogates"
    assert sorted(p.name for p in (folder / "models").iterdir()) == ["plr.json", "plr.onnx"]
    assert trained.training["files"]["plr_model"] == str(folder / "models" / "plr.json")
    assert set(trained.search.families) == set(models)
    assert phases.all_finished()
    # each family's refit on all designs is a phase of its own; saving and the export,
    # after the last refit, are the last phase
    names = list(phases.last)
    assert names[-1] == "paper B: surrogates, save and export (stages)"
    assert names[-2] == "paper B: surrogates, plr: refit on all designs"
    assert pictures(folder) == []
