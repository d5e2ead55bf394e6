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
from softbend.surrogates.workflow import (
    PAPER_B_FIG5,
    best_family,
    small_data_advice,
    train_surrogates,
)


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


class _Scored:
    def __init__(self, **cv):
        self.cv = cv


def test_the_best_family_follows_the_metric_asked_for():
    # The newcomer's case: XGBoost's MAPE is lower, its RMSE nearly three times the polynomial's.
    families = {
        "plr": _Scored(rmse_deg=5.4, mape_pct=12.0, r2=0.99),
        "xgb": _Scored(rmse_deg=14.5, mape_pct=9.0, r2=0.95),
        "mlp": _Scored(rmse_deg=6.0, mape_pct=float("nan"), r2=0.995),
    }
    assert best_family(families) == "plr"  # RMSE by default
    assert best_family(families, "mape") == "xgb"  # an undefined MAPE is no candidate
    assert best_family(families, "r2") == "mlp"
    assert best_family({"mlp": families["mlp"]}, "mape") is None
    with pytest.raises(ValueError, match=r"^select_by: .*got .mae."):
        best_family(families, "mae")


def test_small_tables_get_the_small_grid_and_one_line_of_advice(samples, tmp_path):
    lines = []
    result, summary = train_surrogates(
        samples, tmp_path, models=["plr"], grid_name=None, export_onnx=False, advise=lines.append
    )
    assert result.settings["grid"] == "small" and len(lines) == 1
    assert lines[0].startswith("30 designs: fewer than 100") and summary["advice"] == lines[0]
    assert summary["best"] == "plr" and summary["selected_by"] == "rmse"
    # paper B's actuator keeps paper B's MAPE (only the 0 MPa readings left out)
    plr = summary["models"]["plr"]
    assert summary["mape_floor_deg"] == plr["mape_floor_deg"] == 1.0
    assert plr["n_mape_used"] == int((abs(result.data.y) >= 1.0).sum()) < result.data.n_samples
    assert small_data_advice(100, None) is None
    assert "--grid quick was asked for" in small_data_advice(99, "quick")
    # without the MLP, no word of its grid
    assert "grid" not in small_data_advice(99, None, mlp=False)


def test_saving_the_models_is_a_phase_after_the_last_refit(samples, tmp_path):
    from softbend.surrogates.workflow import SAVING_PHASE

    heard: list[tuple[str, int, int]] = []
    _, summary = train_surrogates(
        samples,
        tmp_path,
        models=["plr"],
        folds=2,
        export_onnx=False,
        interpolation=False,
        progress=lambda phase, done, total: heard.append((phase, done, total)),
    )
    saving = [(done, total) for phase, done, total in heard if phase == SAVING_PHASE]
    assert saving == [(0, 1), (1, 1)]
    first = next(i for i, call in enumerate(heard) if call[0] == SAVING_PHASE)
    assert heard[first - 1][0].startswith("plr: refit on all designs")
    assert all(call[0] == SAVING_PHASE for call in heard[first:])
    saved = load_surrogate(summary["files"]["plr_model"]).metadata
    assert saved["n_designs"] == 30 and saved["support"] and saved["training_ranges"]
