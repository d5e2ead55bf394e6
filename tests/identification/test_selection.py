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
    with pytest.raises(
        ValueError, match=r"^validate_on: must name experiments of the data \(e0, e1"
    ):
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


def _no_fit(monkeypatch):
    """Make any model fit fail the test: a check must come before the first one."""
    from softbend.identification.multi import MultiNARX

    def fit(self, *args, **kwargs):
        raise AssertionError("a model was fitted before the input was checked")

    monkeypatch.setattr(MultiNARX, "fit", fit)


@pytest.mark.parametrize(
    ("kwargs", "match"),
    [
        ({"seed": -1}, r"^seed: must be an integer in \[0, 4294967295\]; "
                       r"got -1$"),
        ({"folds": 1}, r"^folds: must be an integer in \[2, 1000\]; got 1$"),
        ({"folds": 10**20}, r"^folds: must be an integer in \[2, 1000\]"),
        ({"validate_on": ["e0", "e0"]},
         r"^validate_on: must name each experiment once; got 'e0' more than"),
    ],
)  # fmt: skip
def test_bad_settings_are_refused_before_any_fit(monkeypatch, kwargs, match):
    data = _linear_set(n_experiments=4, n=40)
    _no_fit(monkeypatch)
    with pytest.raises(ValueError, match=match):
        select_model(data, candidates=FEW[:1], **kwargs)


def test_default_candidates_refuses_a_negative_seed():
    with pytest.raises(ValueError, match=r"^seed: must be an integer in"):
        default_candidates(-1)


def _with_output(values_of) -> TimeSeriesSet:
    rng = np.random.default_rng(0)
    experiments = [
        Series(f"e{i}", np.arange(30.0), rng.normal(size=30), values_of(i, rng)) for i in range(3)
    ]
    return TimeSeriesSet(("u",), ("y",), tuple(experiments))


@pytest.mark.parametrize(
    ("values_of", "match"),
    [
        (lambda i, rng: np.full(30, 3.0), r"output column 'y' is constant .*every sample 3\.0"),
        (lambda i, rng: 1e301 * rng.normal(size=30), r"output column 'y' of experiment 'e0'"),
    ],
    ids=["constant", "1e301"],
)
def test_a_constant_or_overflowing_output_is_refused_before_any_fit(monkeypatch, values_of, match):
    from softbend.errors import DatasetError

    _no_fit(monkeypatch)
    with pytest.raises(DatasetError, match=match):
        select_model(_with_output(values_of), candidates=FEW, folds=2)


def test_folds_too_short_for_the_kernel_candidates_are_refused_before_any_fit(monkeypatch):
    from softbend.errors import DatasetError

    data = _with_output(lambda i, rng: rng.normal(size=30))
    short = TimeSeriesSet(("u",), ("y",), tuple(e.__class__(e.name, e.time[:4], e.inputs[:4],
                          e.outputs[:4]) for e in data.experiments))  # fmt: skip
    _no_fit(monkeypatch)
    with pytest.raises(DatasetError, match=r"need at least 4 regressor rows.*give 2 \(lags up"):
        select_model(short, candidates=FEW, folds=2)


def test_figures_that_are_not_finite_fail_the_selection(monkeypatch):
    from softbend.errors import ConvergenceError
    from softbend.identification import selection as module

    real = module._free_run_only

    def broken(model, data, ranges):
        free, simulated = real(model, data, ranges)
        return (np.nan if model.family == "poly2" else free), simulated

    monkeypatch.setattr(module, "_free_run_only", broken)
    with pytest.raises(ConvergenceError, match=r"cv_freerun_nrmse of candidate poly2-1-1 is nan"):
        select_model(_linear_set(n_experiments=3, n=60), candidates=FEW[:3], folds=2)


def test_the_verdict_has_no_nan_when_the_linear_model_is_exact():
    from softbend.identification.selection import Selection

    selection = select_model(_linear_set(n_experiments=3, n=60), candidates=FEW[:3], folds=2)
    table = selection.table.copy()
    table["validation_freerun_nrmse"] = [0.0 if f == "arx" else 0.5 for f in table["family"]]
    table.loc[table["family"] == "poly2", "cv_freerun_nrmse"] = 0.0
    best = table.loc[table["family"] == "poly2", "candidate"].iloc[0]
    table = table.sort_values("cv_freerun_nrmse").reset_index(drop=True)
    fake = Selection(**{**selection.__dict__, "table": table, "best": best, "validation": ("x",)})
    verdict = fake.verdict()
    assert "nan" not in verdict and "against 0 for the best linear ARX" in verdict
