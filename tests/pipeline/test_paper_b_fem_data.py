"""Figs. 4 and 5 on a FEM dataset: read, regression, surrogates under both protocols."""

from __future__ import annotations

import json

import pytest

from softbend.pipeline.paper_b_fem_data import run_fem_data

from ..stand_ins import stand_in_fem_dataset
from .conftest import Phases, pictures

#: The surrogate search under both protocols takes most of a minute on two cores.
pytestmark = pytest.mark.slow


@pytest.fixture(scope="module")
def fem_data(tmp_path_factory):
    dataset = stand_in_fem_dataset(tmp_path_factory.mktemp("dataset"))
    out = tmp_path_factory.mktemp("paper_b_fem_data")
    phases = Phases()
    # The polynomial only: the three families are run by tests/reports/test_reproduce.py.
    return out, run_fem_data(out, 0, phases, dataset=dataset, models=["plr"]), phases


def test_reads_the_whole_dataset(fem_data):
    _, result, _ = fem_data
    s = result.summary
    assert s["designs_done"] == len(result.done) == 15
    assert s["samples"] == len(result.samples) >= s["converged_samples"] == len(result.converged)
    assert sum(s["stops"].values()) == 15
    assert len(s["samples_sha256"]) == 64
    assert result.provenance["command"] == "stand-in for the test"


def test_pressure_drives_the_angle_and_a_thick_top_wall_opposes_it(fem_data):
    _, result, _ = fem_data
    s = result.summary
    assert s["loadings"]["pressure_mpa"] > 0.5 and s["loadings"]["t_mm"] < 0.0
    assert 0.0 < s["r2"] < 1.0 and s["f_value"] > 0
    corr = result.correlation
    assert corr.loc["pressure_mpa", "angle_deg"] > 0.5
    assert corr.loc["angle_deg", "angle_deg"] == pytest.approx(1.0)


def test_both_protocols_score_the_same_families_and_models_are_saved(fem_data):
    out, result, phases = fem_data
    grouped, shuffled = result.summary["surrogates_grouped"], result.summary["surrogates_random"]
    assert set(grouped) == set(shuffled) == {"plr"}
    # The same configuration under both protocols (no second grid search).
    assert {k: v["params"] for k, v in grouped.items()} == {
        k: v["params"] for k, v in shuffled.items()
    }
    # Samples shuffled across designs are easier than unseen designs for the polynomial.
    assert shuffled["plr"]["rmse_deg"] < grouped["plr"]["rmse_deg"]
    assert 0.0 < grouped["plr"]["r2"] < shuffled["plr"]["r2"] <= 1.0
    models = out / "paper_b_fem" / "surrogates" / "models"
    assert sorted(p.name for p in models.iterdir()) == ["plr.json", "plr.onnx"]
    assert list(result.search.families) == ["plr"]
    assert pictures(out) == []
    assert phases.all_finished()
    json.dumps(result.summary)
