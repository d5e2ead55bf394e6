import itertools

import numpy as np
import pytest

from softbend.surrogates.search import grid, grouped_splits, search


def test_grid_sizes_match_paper_b():
    assert [c["degree"] for c in grid("paper", "plr")] == list(range(2, 11))
    xgb = grid("paper", "xgb")
    assert len(xgb) == 200
    assert {c["max_depth"] for c in xgb} == set(range(1, 21))
    assert sorted({c["learning_rate"] for c in xgb}) == pytest.approx(
        [0.1 * k for k in range(1, 11)]
    )
    mlp = grid("paper", "mlp")
    assert len(mlp) == 121 and (63, 65) in [c["hidden_sizes"] for c in mlp]
    assert len(grid("quick", "plr")) < 9


@pytest.mark.parametrize(("name", "model"), [("huge", "plr"), ("quick", "svm")])
def test_unknown_grid_or_model(name, model):
    with pytest.raises(ValueError, match="must be one of"):
        grid(name, model)


def test_grouped_splits_never_split_a_design():
    groups = np.repeat([f"d{i}" for i in range(13)], 7)
    splits = grouped_splits(groups, 5, seed=1)
    assert len(splits) == 5
    seen = np.zeros(groups.size, dtype=int)
    for train, val in splits:
        assert not set(groups[train]) & set(groups[val])
        seen[val] += 1
    assert np.all(seen == 1)
    again = grouped_splits(groups, 5, seed=1)
    assert all(np.array_equal(a[1], b[1]) for a, b in zip(splits, again, strict=True))


def test_too_few_designs_for_the_folds():
    with pytest.raises(ValueError, match="folds"):
        grouped_splits(np.array(["a", "a", "b"]), 5)


def test_unknown_model_in_search(small_data):
    with pytest.raises(ValueError, match=r"'models'.*'plr', 'xgb', 'mlp'"):
        search(small_data, models=["plr", "gpr"])


#: Small configurations: the test data are 80 designs x 11 pressures.
SMALL_GRID = {
    "plr": [{"degree": 1}, {"degree": 2}, {"degree": 3}],
    "xgb": [{"max_depth": d, "learning_rate": 0.3} for d in (2, 3, 6, 8)],
    "mlp": [{"hidden_sizes": (8, 8)}, {"hidden_sizes": (16, 16)}],
}


@pytest.fixture(scope="module")
def searched(small_data):
    return search(
        small_data, models=["plr", "xgb", "mlp"], param_grid=SMALL_GRID, epochs=500, seed=0
    )


def test_search_reports_every_configuration(searched):
    cv = searched.cv_results
    assert list(cv["model"].value_counts().sort_index()) == [2, 3, 4]  # mlp, plr, xgb
    assert np.isfinite(cv["r2"]).all()
    assert (cv["status"] == "ok").all()
    assert set(searched.families) == {"plr", "xgb", "mlp"}
    summary = searched.summary()
    assert list(summary["model"]) == ["plr", "xgb", "mlp"]


def test_best_is_the_lowest_mean_fold_rmse(searched):
    cv = searched.cv_results
    for name, fam in searched.families.items():
        rows = cv[cv["model"] == name]
        best = rows.loc[rows["rmse_fold_mean"].idxmin()]
        assert fam.cv["rmse_fold_mean"] == best["rmse_fold_mean"]


def test_out_of_fold_predictions_come_from_models_that_never_saw_the_design(searched, small_data):
    from softbend.surrogates.polynomial import PolynomialRegressor

    fam = searched.families["plr"]
    splits = grouped_splits(small_data.groups, 5, seed=0)
    train, val = splits[2]
    model = PolynomialRegressor(**fam.params).fit(small_data.X[train], small_data.y[train])
    np.testing.assert_allclose(fam.oof_pred[val], model.predict(small_data.X[val]), rtol=1e-10)


def test_smooth_analytical_data_is_learned(searched):
    # The analytical model is smooth in every input: a curved polynomial beats the
    # linear one on unseen designs and explains almost all the variance.
    cv = searched.cv_results.set_index("params")
    assert cv.loc["degree=1", "rmse_fold_mean"] > 2 * cv.loc["degree=2", "rmse_fold_mean"]
    plr = searched.families["plr"]
    assert plr.params["degree"] >= 2 and plr.cv["r2"] > 0.98
    assert searched.families["xgb"].cv["r2"] > 0.95
    assert plr.timing["fast_path"] is True


def test_a_polynomial_too_large_for_memory_is_skipped_not_fatal(small_data):
    result = search(
        small_data,
        models=["plr"],
        param_grid={"plr": [{"degree": 2}, {"degree": 2, "max_memory_mb": 1e-3}]},
    )
    cv = result.cv_results
    assert cv["status"].iloc[0] == "ok"
    assert cv["status"].iloc[1].startswith("skipped") and "max_memory_mb" in cv["status"].iloc[1]
    assert result.families["plr"].params == {"degree": 2}


def test_search_settings_record_the_grid(searched):
    assert searched.settings["mlp_epochs"] == 500
    assert "own grid" in searched.settings["grid"]
    assert searched.settings["folds"] == 5


def test_refit_model_predicts_the_training_data(searched, small_data):
    for fam in searched.families.values():
        pred = fam.model.predict(small_data.X)
        assert np.all(np.isfinite(pred))
        assert np.corrcoef(pred, small_data.y)[0, 1] > 0.95


def test_halving_rungs_shrink_by_eta_and_end_at_the_full_epochs():
    from softbend.surrogates.search import halving_rungs

    assert halving_rungs(121, 1000, 3) == [(121, 37), (41, 111), (14, 333), (5, 1000)]
    assert halving_rungs(9, 90, 3) == [(9, 30), (3, 90)]
    assert halving_rungs(2, 50, 3) == [(2, 50)]  # too few to race
    for n, eta in ((121, 2), (40, 4), (7, 3)):
        rungs = halving_rungs(n, 1000, eta)
        assert rungs[0][0] == n and rungs[-1][1] == 1000
        assert all(a[0] > b[0] and a[1] < b[1] for a, b in itertools.pairwise(rungs))


def test_successive_halving_keeps_the_exhaustive_models_of_its_survivors(small_data):
    sizes = [{"hidden_sizes": (h, h)} for h in (2, 3, 4, 6, 8, 10, 12, 14, 16)]
    common = {"models": ["mlp"], "param_grid": {"mlp": sizes}, "epochs": 60, "seed": 1}
    exhaustive = search(small_data, **common)
    raced = search(small_data, **common, halving=3)
    cv_all, cv_raced = (r.cv_results.set_index("params") for r in (exhaustive, raced))
    survivors = cv_raced.index[cv_raced["status"] == "ok"]
    assert len(survivors) == 3
    stopped = cv_raced.loc[cv_raced["status"] != "ok", "status"]
    assert stopped.str.contains("stopped after 20 epochs").all()
    # A survivor trained the full epochs from the same start: the same model.
    for params in survivors:
        assert cv_raced.loc[params, "rmse_fold_mean"] == cv_all.loc[params, "rmse_fold_mean"]
    best = raced.families["mlp"]
    assert best.cv["rmse_fold_mean"] == cv_all.loc[survivors, "rmse_fold_mean"].min()
    assert raced.settings["mlp_halving"] == 3
    with pytest.raises(ValueError, match="'halving'"):
        search(small_data, **common, halving=1)


def test_random_folds_mix_the_designs(small_data):
    from softbend.surrogates.search import random_splits

    splits = random_splits(small_data.n_samples, 5, seed=0)
    train, val = splits[0]
    assert set(small_data.groups[train]) & set(small_data.groups[val])
    result = search(small_data, models=["plr"], param_grid=SMALL_GRID, cv="random")
    assert result.settings["cv"] == "random"
    with pytest.raises(ValueError, match="'cv'"):
        search(small_data, models=["plr"], cv="loo")
