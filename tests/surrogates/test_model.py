"""A trained surrogate as a bending model: sweeps, the campaign backend and the CLI."""

from __future__ import annotations

import pickle

import numpy as np
import pytest

from softbend.analytical import AnalyticalModel, tip_position_mm
from softbend.campaign import load_samples, run_campaign
from softbend.cli import main
from softbend.design import DesignSpace, sfrba_design
from softbend.models import BendingModel, default_pressures_mpa
from softbend.surrogates.features import training_data
from softbend.surrogates.model import SurrogateModel
from softbend.surrogates.persistence import save_surrogate
from softbend.surrogates.polynomial import PolynomialRegressor

from ..cli.conftest import one_error_line

DESIGN = sfrba_design(130, 8, 3, 3, 10, 10)  # inside the space the surrogate learned
GRID = default_pressures_mpa(0.15, 0.01)


@pytest.fixture(scope="module")
def analytical_campaign(tmp_path_factory):
    db = tmp_path_factory.mktemp("surrogate") / "analytical.duckdb"
    run_campaign(db, DesignSpace.sample(150, seed=4), pressures_mpa=GRID, workers=0)
    return db


@pytest.fixture(scope="module")
def saved(analytical_campaign, tmp_path_factory):
    data = training_data(load_samples(analytical_campaign))
    model = PolynomialRegressor(degree=4).fit(data.X, data.y)
    return save_surrogate(model, tmp_path_factory.mktemp("models") / "plr.json"), model


def test_a_surrogate_sweeps_what_it_predicts_with_the_arc_tip(saved):
    path, estimator = saved
    model = SurrogateModel.load(path)
    assert isinstance(model, BendingModel) and model.name == "surrogate"
    result = model.sweep(DESIGN, GRID)
    np.testing.assert_array_equal(result.angle_deg, estimator.predict(DESIGN.feature_rows(GRID)))
    tip_x, tip_z = tip_position_mm(DESIGN, result.angle_deg)
    np.testing.assert_array_equal(result.tip_x_mm, tip_x)
    np.testing.assert_array_equal(result.tip_z_mm, tip_z)
    assert result.converged.all() and str(path) in result.stats["source"]
    # It learned the analytical model: the sweeps agree within a couple of degrees.
    reference = AnalyticalModel().sweep(DESIGN, GRID)
    np.testing.assert_allclose(result.angle_deg, reference.angle_deg, atol=3.0)
    again = pickle.loads(pickle.dumps(model)).sweep(DESIGN, GRID)
    np.testing.assert_array_equal(again.angle_deg, result.angle_deg)


def test_a_non_finite_prediction_ends_the_sweep_there():
    class Broken:
        def predict(self, X):
            return np.where(X[:, -1] < 0.05, 10.0 * X[:, -1], np.nan)

    result = SurrogateModel(Broken(), source="broken").sweep(DESIGN, GRID)
    assert len(result.pressure_mpa) == 6 and not result.converged[-1]
    assert result.converged[:-1].all() and np.isnan(result.angle_deg[-1])


def test_bad_surrogates_and_grids_are_refused():
    with pytest.raises(ValueError, match="estimator: must be a fitted regressor"):
        SurrogateModel(object())
    model = SurrogateModel(PolynomialRegressor(degree=1), source="unfitted")
    with pytest.raises(ValueError, match=r"pressures_mpa: must be strictly increasing"):
        model.sweep(DESIGN, [0.1, 0.05])


def test_a_campaign_runs_on_a_saved_surrogate(saved, tmp_path, capsys):
    path, estimator = saved
    db = tmp_path / "s.duckdb"
    backend = SurrogateModel.load(path)
    run_campaign(db, DesignSpace.sample(3, seed=9), backend=backend, pressures_mpa=GRID)
    samples = load_samples(db)
    assert len(samples) == 3 * len(GRID)
    X = samples[["l_mm", "r_mm", "t_mm", "b_mm", "phi_deg", "lc_mm", "pressure_mpa"]].to_numpy()
    np.testing.assert_allclose(samples["angle_deg"], estimator.predict(X), rtol=1e-12)

    cli_db = tmp_path / "cli.duckdb"
    args = ["campaign", "run", str(cli_db), "--space", "lhs:2", "--pmax", "0.1", "--pstep", "0.05"]
    assert main([*args, "--backend", "surrogate", "--model", str(path), "--json"]) == 0
    capsys.readouterr()
    assert len(load_samples(cli_db)) == 6
    assert main([*args, "--backend", "surrogate"]) == 2
    assert "--model: must be given" in one_error_line(capsys)
    assert main([*args, "--model", str(path)]) == 2
    assert "--model" in one_error_line(capsys)
    assert main([*args, "--backend", "surrogate", "--model", str(tmp_path / "none.json")]) == 2
    assert "none.json" in one_error_line(capsys)
