"""train_surrogates: what it writes and returns; the figures are drawn by reports."""

from __future__ import annotations

import json

import pandas as pd
import pytest

from softbend.campaign import load_samples, run_campaign
from softbend.design import DesignSpace
from softbend.models import default_pressures_mpa
from softbend.reports.surrogate_figures import training_figures
from softbend.surrogates.persistence import load_surrogate
from softbend.surrogates.workflow import PAPER_B_FIG5, train_surrogates


@pytest.fixture(scope="module")
def samples(tmp_path_factory):
    db = tmp_path_factory.mktemp("workflow") / "c.duckdb"
    run_campaign(db, DesignSpace.sample(30, seed=5), pressures_mpa=default_pressures_mpa(0.1, 0.01))
    return load_samples(db)


def test_the_workflow_saves_models_and_tables_and_draws_nothing(samples, tmp_path):
    result, summary = train_surrogates(samples, tmp_path, models=["plr"], export_onnx=True)
    assert set(result.families) == {"plr"}
    assert summary["best_by_mape"] == "plr"
    assert not list(tmp_path.rglob("*.png"))
    saved = load_surrogate(summary["files"]["plr_model"])
    assert saved.metadata["n_designs"] == 30 and saved.metadata["n_samples"] == len(samples)
    assert saved.metadata["cv"]["mape_pct"] == pytest.approx(summary["models"]["plr"]["mape_pct"])
    assert summary["models"]["plr"]["paper_b"] == PAPER_B_FIG5["plr"]
    assert summary["models"]["plr"]["onnx_max_abs_diff_deg"] < 1e-9
    table = pd.read_csv(summary["files"]["summary"])
    assert list(table["model"]) == ["plr"] and table["paper_b_mape_pct"].iloc[0] == 1.8
    cv = pd.read_csv(summary["files"]["cv_results"])
    assert len(cv) == 3  # degrees 2, 4, 6 of the quick grid
    json.dumps(summary)  # the summary is JSON-friendly

    files = training_figures(result, tmp_path / "figures")
    assert set(files) == {"fig5"}  # no MLP, no loss curve
    assert (tmp_path / "figures" / "fig5_parity_errors.png").stat().st_size > 10_000


def test_a_missing_database_is_a_clear_error(tmp_path):
    with pytest.raises(FileNotFoundError, match=r"nope\.duckdb"):
        train_surrogates(tmp_path / "nope.duckdb", tmp_path / "out")
