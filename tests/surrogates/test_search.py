import itertools

import numpy as np
import pandas as pd
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
    assert grid("quick", "mlp") == [{"hidden_sizes": (63, 65)}]  # paper B's pick


@pytest.mark.parametrize(
    ("name", "model", "match"),
    [
        ("huge", "plr", "grid: must be one of"),
        ("quick", "svm", r"model: Unknown surrogate family 'svm'; known: plr, xgb, mlp, table\."),
    ],
)
def test_unknown_grid_or_model(name, model, match):
    with pytest.raises(ValueError, match=match):
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


def test_grouped_splits_are_those_of_the_design_names():
    from sklearn.model_selection import GroupKFold

    rng = np.random.default_rng(3)
    groups = rng.choice([f"d{i:03d}" for i in range(40)], size=300)
    splitter = GroupKFold(n_splits=4, shuffle=True, random_state=2)
    by_name = [val for _, val in splitter.split(np.zeros((300, 1)), groups=groups)]
    ours = [val for _, val in grouped_splits(groups, 4, seed=2)]
    assert all(np.array_equal(a, b) for a, b in zip(by_name, ours, strict=True))


def test_too_few_designs_for_the_folds():
    with pytest.raises(ValueError, match="folds"):
        grouped_splits(np.array(["a", "a", "b"]), 5)


def test_unknown_model_in_search(small_data):
    with pytest.raises(
        ValueError, match=r"models: Unknown surrogate family 'gpr'; known: plr, xgb, mlp, table\."
    ):
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
    # One rung more than the default on paper B's grid: 8188 configuration-epochs, not 18 690.
    five = halving_rungs(121, 1000, 3, rungs=5)
    assert five == [(121, 12), (41, 37), (14, 111), (5, 333), (2, 1000)]
    assert sum(n * e for n, e in five) == 8188
    assert halving_rungs(9, 90, 3, rungs=1) == [(9, 90)]
    with pytest.raises(ValueError, match="rungs: must be"):
        halving_rungs(9, 90, 3, rungs=0)
    # Past the point where the first rung has an epoch or a race has two contenders.
    assert len(halving_rungs(121, 1000, 3, rungs=6)) == 6
    with pytest.raises(ValueError, match=r"rungs: must be at most 6 .* got 7"):
        halving_rungs(121, 1000, 3, rungs=7)
    with pytest.raises(ValueError, match="at most 2 for 9 configurations, 3 epochs"):
        halving_rungs(9, 3, 3, rungs=3)
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
    with pytest.raises(ValueError, match="halving: must be"):
        search(small_data, **common, halving=1)
    # Three rungs instead of two: only the best of the second rung's three go on.
    longer = search(small_data, **common, halving=3, halving_rungs=3)
    status = longer.cv_results["status"]
    assert (status == "ok").sum() == 1
    assert status.str.contains("stopped after 7 epochs").sum() == 6
    assert longer.settings["mlp_halving_rungs"] == 3
    with pytest.raises(ValueError, match=r"halving_rungs: needs 'halving'"):
        search(small_data, **common, halving_rungs=3)
    with pytest.raises(ValueError, match="halving_rungs: rungs: must be at most 3"):
        search(small_data, **common, halving=3, halving_rungs=4)


def test_random_folds_mix_the_designs(small_data):
    from softbend.surrogates.search import random_splits

    splits = random_splits(small_data.n_samples, 5, seed=0)
    train, val = splits[0]
    assert set(small_data.groups[train]) & set(small_data.groups[val])
    result = search(small_data, models=["plr"], param_grid=SMALL_GRID, cv="random")
    assert result.settings["cv"] == "random"
    with pytest.raises(ValueError, match="cv: must be one of"):
        search(small_data, models=["plr"], cv="loo")


#: A search small enough to run four times: every family, MLP halving in two rungs.
RESUME = {
    "models": ["plr", "xgb", "mlp"],
    "param_grid": {
        "plr": [{"degree": 1}, {"degree": 2}],
        "xgb": [{"max_depth": 2, "learning_rate": 0.3}, {"max_depth": 3, "learning_rate": 0.3}],
        "mlp": [{"hidden_sizes": (h, h + 1)} for h in (3, 4, 5, 6)],
    },
    "folds": 3,
    "seed": 1,
    "epochs": 8,
    "halving": 2,  # rungs: 4 configurations x 4 epochs, then 2 x 8
    "device": "cpu",
    "n_jobs": 1,
}


class _KilledError(Exception):
    """Stands for a kill: raised from the progress callback."""


def _stop_at(phase_start: str, done: int):
    def progress(phase, count, _total):
        if phase.startswith(phase_start) and count >= done:
            raise _KilledError(phase)

    return progress


def _assert_same_search(a, b):
    timing = ["fit_s_per_config"]
    pd.testing.assert_frame_equal(
        a.cv_results.drop(columns=timing), b.cv_results.drop(columns=timing)
    )
    assert a.settings == b.settings
    assert list(a.families) == list(b.families)
    for name, fam in a.families.items():
        other = b.families[name]
        assert fam.params == other.params and fam.cv == other.cv
        np.testing.assert_array_equal(fam.oof_pred, other.oof_pred)
        np.testing.assert_array_equal(fam.model.predict(a.data.X), other.model.predict(a.data.X))


def test_an_interrupted_search_resumes_from_its_finished_folds(small_data, tmp_path, monkeypatch):
    import softbend.surrogates.batched as batched
    import softbend.surrogates.search as search_module
    from softbend.surrogates.checkpoint import SearchCheckpoint

    reference = search(small_data, **RESUME)
    path = tmp_path / "search.jsonl"
    made: list[str] = []
    trainings: list[int] = []
    real_make, real_grid = search_module._make, batched.train_mlp_grid

    def counting_make(model, params, **kwargs):
        made.append(model)
        return real_make(model, params, **kwargs)

    def counting_grid(*args, **kwargs):
        trainings.append(kwargs["epochs"])
        return real_grid(*args, **kwargs)

    monkeypatch.setattr(search_module, "_make", counting_make)
    monkeypatch.setattr(batched, "train_mlp_grid", counting_grid)

    # Killed in the middle of XGBoost, after 2 of its 6 folds.
    with SearchCheckpoint(path) as checkpoint, pytest.raises(_KilledError):
        search(small_data, **RESUME, checkpoint=checkpoint, progress=_stop_at("xgb", 2))
    # Resumed, then killed in the MLP's second rung: the first rung's folds are saved.
    made.clear()
    said: list[str] = []
    with SearchCheckpoint(path, on_resume=said.append) as checkpoint, pytest.raises(_KilledError):
        search(small_data, **RESUME, checkpoint=checkpoint, progress=_stop_at("mlp", 5))
    assert len(said) == 1 and "8 configuration-folds" in said[0]  # 6 plr + 2 xgb
    assert made == ["plr"] + ["xgb"] * 5  # the refit of plr, 4 xgb folds and its refit
    assert trainings == [4, 8]
    # The last run trains only the second rung and the refits.
    made.clear()
    trainings.clear()
    with SearchCheckpoint(path) as checkpoint:
        resumed = search(small_data, **RESUME, checkpoint=checkpoint)
        assert checkpoint.n_records == 6 + 6 + 4 * 3 + 2 * 3
    assert made == ["plr", "xgb", "mlp"] and trainings == [8, 8]  # 2nd rung, MLP refit
    assert resumed.resumed == 6 + 6 + 4 * 3
    assert reference.resumed == 0
    _assert_same_search(resumed, reference)
    assert path.is_file()  # the caller removes it when the results are safe

    # Once more: everything comes from the checkpoint, nothing is trained but the refits.
    made.clear()
    trainings.clear()
    with SearchCheckpoint(path) as checkpoint:
        again = search(small_data, **RESUME, checkpoint=checkpoint)
    assert made == ["plr", "xgb", "mlp"] and trainings == [8]  # the MLP refit
    assert again.resumed == 6 + 6 + 4 * 3 + 2 * 3
    _assert_same_search(again, reference)


def test_a_checkpoint_of_other_settings_is_not_reused(small_data, tmp_path):
    from softbend.surrogates.checkpoint import SearchCheckpoint

    path = tmp_path / "search.jsonl"
    common = {"models": ["plr"], "param_grid": {"plr": [{"degree": 1}, {"degree": 2}]}}
    with SearchCheckpoint(path) as checkpoint:
        search(small_data, **common, folds=3, checkpoint=checkpoint)
    said: list[str] = []
    with SearchCheckpoint(path, on_discard=said.append) as checkpoint:
        result = search(small_data, **common, folds=4, checkpoint=checkpoint)
    assert result.resumed == 0 and result.settings["folds"] == 4
    assert len(said) == 1 and "folds" in said[0] and "splits" in said[0]


def test_scoring_without_refit_gives_the_same_cv_and_no_model(small_data):
    chosen = {"plr": [{"degree": 2}], "xgb": [{"max_depth": 3, "learning_rate": 0.3}]}
    kwargs = {"models": ["plr", "xgb"], "param_grid": chosen, "seed": 0, "cv": "random"}
    full = search(small_data, **kwargs)
    scored = search(small_data, refit=False, **kwargs)
    for name in chosen:
        assert scored.families[name].cv == full.families[name].cv
        np.testing.assert_array_equal(scored.families[name].oof_pred, full.families[name].oof_pred)
        assert scored.families[name].model is None and scored.families[name].fit_s == 0.0
        assert full.families[name].model is not None
    summary = scored.summary()
    assert summary["single_us"].isna().all() and (summary["mape_pct"] > 0).all()


def test_plr_patience_stops_raising_the_degree_once_the_cv_error_rises(small_data):
    """Degrees past the best are skipped; the ones fitted score as in the full search."""
    degrees = [{"degree": d} for d in (1, 2, 3, 4, 5)]
    common = {"models": ["plr"], "param_grid": {"plr": degrees}, "seed": 0, "refit": False}
    full = search(small_data, **common).cv_results.set_index("params")
    rmse = full["rmse_fold_mean"].to_numpy()
    best = int(np.argmin(rmse))
    assert 0 < best < len(degrees) - 2, "the test data must have an interior best degree"

    early = search(small_data, plr_patience=1, **common)
    table = early.cv_results.set_index("params")
    fitted = table[table["status"] == "ok"]
    # Fitted up to the first degree after the best that did not improve, then stopped.
    assert list(fitted.index) == list(full.index[: best + 2])
    assert fitted["rmse_fold_mean"].to_numpy() == pytest.approx(rmse[: best + 2], rel=1e-12)
    skipped = table[table["status"] != "ok"]
    assert len(skipped) == len(degrees) - best - 2
    assert skipped["status"].str.contains("patience 1").all()
    assert early.families["plr"].params == degrees[best]
    assert early.settings["plr_patience"] == 1

    # A patience longer than the grid changes nothing.
    same = search(small_data, plr_patience=len(degrees), **common).cv_results
    assert (same["status"] == "ok").all()


def test_plr_patience_judges_a_degree_by_its_best_ridge_strength(small_data):
    """With ridge strengths in the grid, a degree is stopped whole, never halfway."""
    configs = [{"degree": d, "alpha": a} for d in (1, 2, 3, 4, 5) for a in (1e-8, 1e-1)]
    common = {"models": ["plr"], "param_grid": {"plr": configs}, "seed": 0, "refit": False}
    full = search(small_data, **common).cv_results
    per_degree = full["rmse_fold_mean"].to_numpy().reshape(5, 2).min(axis=1)
    best = int(np.argmin(per_degree))
    assert 0 < best < 3, "the test data must have an interior best degree"
    table = search(small_data, plr_patience=1, **common).cv_results
    fitted = table[table["status"] == "ok"]
    assert list(fitted["params"]) == list(full["params"][: 2 * (best + 2)])
    assert table[table["status"] != "ok"]["status"].str.contains("degree").all()


@pytest.mark.parametrize("patience", [0, -1, 1.5, "2"])
def test_plr_patience_must_be_a_positive_integer(small_data, patience):
    with pytest.raises(ValueError, match="plr_patience: must be an integer"):
        search(small_data, models=["plr"], param_grid=SMALL_GRID, plr_patience=patience)


def test_tf32_is_recorded_checked_and_changes_nothing_on_the_cpu(small_data):
    kwargs = dict(models=["mlp"], param_grid={"mlp": [{"hidden_sizes": (4, 4)}]}, epochs=3)
    plain = search(small_data, device="cpu", **kwargs)
    tf32 = search(small_data, device="cpu", tf32=True, **kwargs)
    assert plain.settings["mlp_tf32"] is False and tf32.settings["mlp_tf32"] is True
    np.testing.assert_array_equal(plain.families["mlp"].oof_pred, tf32.families["mlp"].oof_pred)
    with pytest.raises(ValueError, match="tf32: must be True or False"):
        search(small_data, device="cpu", tf32="yes", **kwargs)


def test_the_small_grid_changes_the_mlp_and_the_polynomial_s_ridge():
    from softbend.surrogates.search import MLP_EPOCHS, SMALL_DATA_MLP_GRID

    assert grid("small", "xgb") == grid("quick", "xgb")
    # the polynomial: low degrees, each with ridge strengths from none to strong
    plr = grid("small", "plr")
    assert {c["degree"] for c in plr} == {1, 2, 3, 4} and min(c["alpha"] for c in plr) == 1e-8
    small = [c["hidden_sizes"] for c in grid("small", "mlp")]
    assert small == [c["hidden_sizes"] for c in SMALL_DATA_MLP_GRID]
    # smaller than paper B's pick, trained longer than the quick grid
    assert all(a * b < 63 * 65 for a, b in small) and MLP_EPOCHS["small"] > MLP_EPOCHS["quick"]


def test_search_records_the_mape_floor_of_the_data(searched, small_data):
    # a campaign of paper B's actuator: paper B's MAPE, only the 0 MPa readings left out
    assert searched.settings["mape_floor_deg"] == 1.0
    plr = searched.families["plr"].cv
    assert plr["mape_floor_deg"] == 1.0
    assert plr["n_mape_used"] == int((np.abs(small_data.y) >= 1.0).sum())
    floored = search(small_data, models=["plr"], param_grid=SMALL_GRID, mape_threshold_deg=30.0)
    cv = floored.families["plr"].cv
    assert cv["n_mape_used"] == int((np.abs(small_data.y) >= 30.0).sum()) < plr["n_mape_used"]
    assert cv["rmse_deg"] == plr["rmse_deg"]  # the floor is the MAPE's alone
    with pytest.raises(ValueError, match=r"^mape_threshold_deg: "):
        search(small_data, models=["plr"], mape_threshold_deg=-1.0)


def test_mlp_configurations_trained_together_share_one_learning_rate(small_data):
    rates = [{"hidden_sizes": (4, 4), "learning_rate": r} for r in (1e-3, 2e-3)]
    with pytest.raises(ValueError, match=r"^param_grid: must be one learning_rate"):
        search(small_data, models=["mlp"], param_grid={"mlp": rates}, epochs=2)
