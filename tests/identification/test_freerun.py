"""The vectorised free run equals the step-by-step loop; pruning keeps the winner."""

from __future__ import annotations

import numpy as np
import pytest

from softbend.identification.freerun import _step_by_step, free_run
from softbend.identification.multi import MultiNARX
from softbend.identification.narx import _segments


def _plant(n_per: tuple[int, ...] = (230, 170, 300), seed: int = 0):
    """A nonlinear two-input, two-output plant; experiments of different lengths."""
    rng = np.random.default_rng(seed)
    n = sum(n_per)
    U = np.cumsum(rng.normal(scale=0.3, size=(n, 2)), axis=0) % 3.0
    Y = np.zeros((n, 2))
    groups = np.repeat(np.arange(len(n_per)), n_per)
    for t in range(1, n):
        if groups[t] != groups[t - 1]:
            continue
        Y[t, 0] = 0.7 * Y[t - 1, 0] + 0.3 * U[t, 0] ** 2 - 0.1 * Y[t - 1, 1]
        Y[t, 1] = 0.5 * Y[t - 1, 1] + 0.4 * np.tanh(Y[t - 1, 0]) + 0.2 * U[t, 1]
    return U, Y + 0.01 * rng.normal(size=Y.shape), groups


def _reference(model: MultiNARX, U, Y, groups) -> np.ndarray:
    """The model's free run by the step-by-step loop (one map call per output and step)."""
    segments = _segments(groups, len(U), model.max_lag)
    maps = [getattr(e, "_expansion", e.predict) for e in model.estimators_]
    Ys = _step_by_step(
        maps,
        model._inputs_standard(U, segments),
        (Y - model.y_mean_) / model.y_std_,
        (segments.starts, segments.lengths),
        (model.output_lags, model.input_lags),
        model._standard_bounds(),
    )
    return Ys * model.y_std_ + model.y_mean_


@pytest.mark.parametrize(
    ("family", "na", "nb", "params"),
    [
        ("arx", 3, 3, {}),
        ("poly2", 2, 2, {}),
        ("poly2", 1, 3, {}),
        ("gg-svr", 2, 2, {"C": 100.0, "epsilon": 0.05}),
        ("gg-svr", 2, 1, {"C": 10.0, "epsilon": 0.01, "shape": 2.0}),
        ("poly2-sim", 2, 3, {"filter": True, "tau_init": 2.0, "steps": 20, "seed": 1}),
        ("nn-sim", 2, 3, {"steps": 10, "pretrain": 20, "hidden": 4, "seed": 2}),
    ],
)
def test_the_vectorised_free_run_equals_the_step_by_step_one(family, na, nb, params):
    U, Y, groups = _plant()
    model = MultiNARX(family, output_lags=na, input_lags=nb, params=params, max_rows=300)
    model.fit(U, Y, groups)
    simulated = model.simulate(U, Y, groups)
    reference = _reference(model, U, Y, groups)
    np.testing.assert_allclose(simulated, reference, rtol=0, atol=1e-10)
    # the initial conditions are copied, every other sample is simulated
    np.testing.assert_allclose(simulated[: model.max_lag], Y[: model.max_lag], atol=1e-12)
    assert not np.allclose(simulated, Y)


def test_a_single_experiment_and_experiments_given_in_any_order():
    U, Y, groups = _plant((120, 400, 90))
    model = MultiNARX("poly2", output_lags=2, input_lags=2).fit(U, Y, groups)
    np.testing.assert_allclose(
        model.simulate(U, Y, groups), _reference(model, U, Y, groups), rtol=0, atol=1e-10
    )
    one = groups == 1
    np.testing.assert_allclose(
        model.simulate(U[one], Y[one]), model.simulate(U, Y, groups)[one], rtol=0, atol=1e-10
    )


def _linear_step(coef: np.ndarray):
    def step(phi: np.ndarray) -> np.ndarray:
        return phi @ coef

    return step


def test_non_finite_outputs_are_set_to_zero_or_clipped_as_step_by_step():
    """A step whose map gives NaN (or ±inf) is run as the reference loop runs it: NaN → 0,
    then every output clipped to its bounds."""
    rng = np.random.default_rng(4)
    Us, Ys = rng.normal(size=(60, 1)), rng.normal(size=(60, 2))
    segments = (np.array([0, 25]), np.array([25, 35]))
    coef = np.array([[0.5, 0.1], [0.2, 0.4], [-0.1, 0.2], [0.1, -0.3], [0.3, -0.2]])
    bounds = (np.array([-1.0, -2.0]), np.array([1.0, 2.0]))

    def blowing(phi: np.ndarray) -> np.ndarray:
        out = phi @ coef
        out[phi[:, 4] > 1.0, 0] = np.nan  # large inputs break output 0
        out[phi[:, 4] < -1.0, 1] = np.inf
        return out

    maps = [lambda phi, j=j: blowing(phi)[:, j] for j in range(2)]
    got = free_run(blowing, Us, Ys, segments, (2, 1), bounds)
    want = _step_by_step(maps, Us, Ys, segments, (2, 1), bounds)
    assert np.isfinite(got).all()
    np.testing.assert_allclose(got, want, rtol=0, atol=1e-12)
    assert (got[2:25, 1] == 2.0).any()  # an infinite output sits on its bound
    plain = free_run(_linear_step(coef), Us, Ys, segments, (2, 1), bounds)
    plain_ref = _step_by_step(
        [lambda phi, j=j: (phi @ coef)[:, j] for j in range(2)], Us, Ys, segments, (2, 1), bounds
    )
    np.testing.assert_allclose(plain, plain_ref, rtol=0, atol=1e-12)


def _arx_set(n_experiments: int = 6, n: int = 250):
    from softbend.identification.timeseries import Series, TimeSeriesSet

    rng = np.random.default_rng(5)
    experiments = []
    for i in range(n_experiments):
        u = rng.normal(size=n)
        y = np.zeros(n)
        for t in range(2, n):
            y[t] = 1.2 * y[t - 1] - 0.4 * y[t - 2] + 0.3 * u[t] + 0.1 * u[t - 1]
        experiments.append(Series(f"e{i}", np.arange(n) * 0.1, u, y + 0.002 * rng.normal(size=n)))
    return TimeSeriesSet(("u",), ("y",), tuple(experiments))


def test_pruning_keeps_the_candidate_that_wins_without_it(monkeypatch):
    from softbend.identification import selection as module
    from softbend.identification.selection import Candidate, select_model

    data = _arx_set()
    candidates = [
        Candidate("arx-2-2", "arx", 2, 2),
        Candidate("poly2-1-1", "poly2", 1, 1),
        *[
            Candidate(f"svr-{i}", "gg-svr", na, 1, {"C": C, "epsilon": 0.05, "shape": 2.0})
            for i, (na, C) in enumerate([(1, 1.0), (2, 10.0), (1, 100.0), (2, 0.5)])
        ],
    ]
    pruned = select_model(data, validate_on=["e5"], candidates=candidates, folds=3)
    monkeypatch.setattr(module, "prunable", lambda candidate: False)
    full = select_model(data, validate_on=["e5"], candidates=candidates, folds=3)
    assert pruned.best == full.best == "arx-2-2"
    table = pruned.table.set_index("candidate")
    assert (table["pruned_after_folds"] > 0).sum() >= 2  # the kernel candidates cannot win
    assert (full.table["pruned_after_folds"] == 0).all()
    for name, row in table.iterrows():
        if row["pruned_after_folds"]:
            assert np.isnan(row["cv_freerun_nrmse"]) and np.isnan(row["validation_freerun_nrmse"])
            # the bound that pruned it is at least the winner's CV free-run NRMSE ...
            bound = row["cv_onestep_nrmse"] * row["pruned_after_folds"] / 3
            assert bound >= table.loc["arx-2-2", "cv_freerun_nrmse"]
            # ... and the candidate run in full would not have won
            complete = full.table.set_index("candidate").loc[name, "cv_freerun_nrmse"]
            assert complete > table.loc["arx-2-2", "cv_freerun_nrmse"]
        else:
            assert np.isfinite(row["cv_freerun_nrmse"])
    # the baselines are never pruned
    assert table.loc[["arx-2-2", "poly2-1-1"], "pruned_after_folds"].eq(0).all()
