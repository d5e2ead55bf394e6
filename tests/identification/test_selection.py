"""select_model: chosen by held-out free-run error, baselines always beside."""

from __future__ import annotations

import numpy as np
import pytest

from softbend.identification.arm import arm_experiments
from softbend.identification.selection import Candidate, default_candidates, select_model
from softbend.identification.timeseries import Series, TimeSeriesSet

FEW = [
    Candidate("arx-1-1", "arx", 1, 1),
    Candidate("arx-2-2", "arx", 2, 2),
    Candidate("poly2-1-1", "poly2", 1, 1),
    Candidate("paper-a", "gg-svr", 2, 2, {"C": 100.0, "epsilon": 0.1}),
    Candidate("svr-1", "gg-svr", 1, 1, {"C": 10.0, "epsilon": 0.01, "shape": 2.0}),
    Candidate("svr-2", "gg-svr", 2, 1, {"C": 100.0, "epsilon": 0.03, "shape": 2.0}),
]


def _linear_set(n_experiments: int = 5, n: int = 300) -> TimeSeriesSet:
    rng = np.random.default_rng(3)
    experiments = []
    for i in range(n_experiments):
        u = rng.normal(size=n)
        y = np.zeros(n)
        for t in range(1, n):
            y[t] = 0.8 * y[t - 1] + 0.3 * u[t]
        y += 0.001 * rng.normal(size=n)
        experiments.append(Series(f"e{i}", np.arange(n) * 0.1, u, y))
    return TimeSeriesSet(("u",), ("y",), tuple(experiments))


@pytest.fixture(scope="module")
def arm():
    return arm_experiments(n_train=5, n_validate=2, duration_s=25.0, seed=1)


def test_on_the_nonlinear_arm_the_selected_model_beats_the_linear_arx(arm):
    validation = [n for n in arm.names if n.startswith("val")]
    selection = select_model(arm, validate_on=validation, candidates=FEW, folds=3)
    best = selection.row(selection.best)
    linear = selection.best_of("arx")
    assert best["validation_freerun_nrmse"] <= linear["validation_freerun_nrmse"]
    assert best["cv_freerun_nrmse"] == selection.table["cv_freerun_nrmse"].min()
    assert set(selection.validation_outputs) == set(validation)
    assert selection.holdout_outputs is selection.validation_outputs
    # successive halving: of the two raced kernel candidates one goes on, one stops
    rungs = dict(zip(selection.table["candidate"], selection.table["rung"], strict=True))
    assert sorted([rungs["svr-1"], rungs["svr-2"]]) == ["final", "first"]
    assert rungs["paper-a"] == "all"
    assert "below the best linear ARX" in selection.verdict() or best["family"] == "arx"


def test_a_linear_plant_chooses_a_linear_model_and_says_so():
    data = _linear_set()
    selection = select_model(data, candidates=FEW[:3], folds=2)
    assert selection.best in ("arx-1-1", "arx-2-2")
    assert selection.verdict().startswith("A linear ARX model is the best")
    assert set(selection.cv_outputs) == set(data.names)  # every experiment run free once


def test_the_choice_is_by_free_run_never_one_step():
    data = _linear_set()
    selection = select_model(data, candidates=FEW[:3], folds=2)
    table = selection.table
    assert table.iloc[0]["candidate"] == selection.best
    assert list(table["cv_freerun_nrmse"]) == sorted(table["cv_freerun_nrmse"])


def test_nothing_to_hold_out_and_unknown_names_are_one_line():
    data = _linear_set(n_experiments=2)
    with pytest.raises(ValueError, match="at least 2 training experiments"):
        select_model(data, validate_on=["e0"], candidates=FEW[:1])
    with pytest.raises(ValueError, match=r"Unknown validation experiment.*e0, e1"):
        select_model(data, validate_on=["e9"], candidates=FEW[:1])


def test_the_default_candidates_hold_every_baseline_and_a_seeded_search():
    a, b = default_candidates(0), default_candidates(0)
    assert a == b and default_candidates(1) != a
    names = {c.name for c in a}
    assert {"arx-1-1", "arx-3-3", "poly2-2-2", "paper-a"} <= names
    paper = next(c for c in a if c.name == "paper-a")
    assert paper.params == {"C": 100.0, "epsilon": 0.1} and (
        paper.output_lags,
        paper.input_lags,
    ) == (2, 2)
