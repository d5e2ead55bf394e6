import warnings

import numpy as np
import pytest
from sklearn.base import BaseEstimator, RegressorMixin, clone
from sklearn.exceptions import NotFittedError
from sklearn.linear_model import LinearRegression
from sklearn.svm import SVR
from sklearn.utils import estimator_checks

from softbend.errors import DatasetError
from softbend.identification.narx import NARXRegressor, lagged_matrix
from softbend.metrics import nrmse, r2, rmse

# ----------------------------------------------------------------------------- systems


def hold_input(n, seed, low=-1.0, high=1.0):
    """Random-hold (piecewise constant) input, holds of 3 to 14 samples."""
    rng = np.random.default_rng(seed)
    u = np.empty(n)
    i = 0
    while i < n:
        hold = int(rng.integers(3, 15))
        u[i : i + hold] = rng.uniform(low, high)
        i += hold
    return u


def linear_arx(u):
    y = np.zeros(u.size)
    for t in range(2, u.size):
        y[t] = 0.6 * y[t - 1] - 0.1 * y[t - 2] + 0.5 * u[t] + 0.2 * u[t - 1]
    return y


def nonlinear_step(y1, y2, u0, u1):
    """Stable NARX map: |∂f/∂y(t−1)| + |∂f/∂y(t−2)| ≤ 0.5 + 0.3 < 1."""
    return 0.5 * y1 + 0.3 * np.tanh(u0) * y2 + 0.5 * u1**2 + 0.4 * u0


def nonlinear_narx(u, y0=(0.0, 0.0)):
    y = np.zeros(u.size)
    y[:2] = y0
    for t in range(2, u.size):
        y[t] = nonlinear_step(y[t - 1], y[t - 2], u[t], u[t - 1])
    return y


def experiments(seeds, n, system=nonlinear_narx):
    us = [hold_input(n, seed) for seed in seeds]
    ys = [system(u) for u in us]
    groups = np.repeat(np.arange(len(seeds)), n)
    return np.concatenate(us), np.concatenate(ys), groups


class TrueNARX(RegressorMixin, BaseEstimator):
    """The exact map of ``nonlinear_narx`` on unscaled rows [y1, y2, u0, u1]."""

    def fit(self, X, y):
        self.fitted_ = True
        return self

    def predict(self, X):
        X = np.asarray(X)
        return nonlinear_step(X[:, 0], X[:, 1], X[:, 2], X[:, 3])


class TrueNARXWithPredictOne(TrueNARX):
    def fit(self, X, y):
        self.batch_calls_ = 0
        self.single_calls_ = 0
        return super().fit(X, y)

    def predict(self, X):
        self.batch_calls_ += 1
        return super().predict(X)

    def predictor(self):
        def predict_one(x):
            self.single_calls_ += 1
            return float(nonlinear_step(x[0], x[1], x[2], x[3]))

        return predict_one


class BlowsUpAboveThreshold(RegressorMixin, BaseEstimator):
    """y(t) = 0.5 y(t−1) + u(t), but non-finite whenever u(t) > 5."""

    def fit(self, X, y):
        self.fitted_ = True
        return self

    def predict(self, X):
        X = np.asarray(X)
        out = 0.5 * X[:, 0] + X[:, 2]
        return np.where(X[:, 2] > 5.0, np.inf, out)


# ------------------------------------------------------------------------- lag matrix

X_TINY = np.array([10.0, 11, 12, 13, 14, 20, 21, 22])
Y_TINY = np.array([0.0, 1, 2, 3, 4, 5, 6, 7])
G_TINY = np.array(["a"] * 5 + ["b"] * 3)


def test_lagged_matrix_rows_by_hand_respect_the_experiment_boundary():
    Phi, target, index = lagged_matrix(X_TINY, Y_TINY, G_TINY)
    # Rows t = 2, 3, 4 of "a" and t = 7 of "b"; [y(t-1), y(t-2), u(t), u(t-1)].
    expected = np.array(
        [
            [1.0, 0.0, 12.0, 11.0],
            [2.0, 1.0, 13.0, 12.0],
            [3.0, 2.0, 14.0, 13.0],
            [6.0, 5.0, 22.0, 21.0],
        ]
    )
    np.testing.assert_array_equal(Phi, expected)
    np.testing.assert_array_equal(target, [2.0, 3.0, 4.0, 7.0])
    np.testing.assert_array_equal(index, [2, 3, 4, 7])
    assert len(index) == (5 - 2) + (3 - 2)


def test_lagged_matrix_without_current_input_and_without_groups():
    Phi, target, index = lagged_matrix(X_TINY, Y_TINY, include_current_input=False)
    # Without groups the series is one experiment: rows t = 2 … 7.
    np.testing.assert_array_equal(index, np.arange(2, 8))
    np.testing.assert_array_equal(Phi[0], [1.0, 0.0, 11.0, 10.0])
    np.testing.assert_array_equal(Phi[3], [4.0, 3.0, 14.0, 13.0])  # t = 5 reaches into "a"
    np.testing.assert_array_equal(target, Y_TINY[2:])


def test_lagged_matrix_orders_several_inputs_input_by_input():
    X = np.column_stack([X_TINY, -X_TINY])
    Phi, _, index = lagged_matrix(X, Y_TINY, G_TINY, output_lags=1, input_lags=3)
    # max_lag = max(1, 3 - 1) = 2; columns y(t-1), u0(t..t-2), u1(t..t-2).
    np.testing.assert_array_equal(index, [2, 3, 4, 7])
    np.testing.assert_array_equal(Phi[0], [1.0, 12.0, 11.0, 10.0, -12.0, -11.0, -10.0])
    np.testing.assert_array_equal(Phi[3], [6.0, 22.0, 21.0, 20.0, -22.0, -21.0, -20.0])


def test_a_reused_label_starts_a_new_experiment():
    groups = [0, 0, 0, 1, 1, 1, 0, 0, 0]
    _, _, index = lagged_matrix(np.arange(9.0), np.arange(9.0), groups)
    np.testing.assert_array_equal(index, [2, 5, 8])


@pytest.mark.parametrize(
    ("na", "nb", "current", "max_lag", "names"),
    [
        (2, 2, True, 2, ("y(t-1)", "y(t-2)", "u(t)", "u(t-1)")),
        (1, 1, True, 1, ("y(t-1)", "u(t)")),
        (1, 3, True, 2, ("y(t-1)", "u(t)", "u(t-1)", "u(t-2)")),
        (2, 3, False, 3, ("y(t-1)", "y(t-2)", "u(t-1)", "u(t-2)", "u(t-3)")),
        (3, 1, False, 3, ("y(t-1)", "y(t-2)", "y(t-3)", "u(t-1)")),
    ],
)
def test_max_lag_and_regressor_names(na, nb, current, max_lag, names):
    u, y, groups = experiments([1, 2], 40, linear_arx)
    model = NARXRegressor(
        estimator=LinearRegression(),
        output_lags=na,
        input_lags=nb,
        include_current_input=current,
    ).fit(u, y, groups=groups)
    assert model.max_lag_ == max_lag
    assert model.regressor_names_ == names
    assert model.n_train_rows_ == 2 * (40 - max_lag)
    assert model.n_experiments_ == 2
    mask = model.warmup_mask(80, groups=groups)
    assert mask.sum() == 2 * max_lag
    assert mask[:max_lag].all() and mask[40 : 40 + max_lag].all()


# ---------------------------------------------------------------------- linear ARX


def test_linear_arx_coefficients_are_recovered_exactly():
    u, y, groups = experiments([11, 12, 13], 300, linear_arx)
    model = NARXRegressor(estimator=LinearRegression(), scale=False).fit(u, y, groups=groups)
    np.testing.assert_allclose(model.estimator_.coef_, [0.6, -0.1, 0.5, 0.2], atol=1e-8)
    assert abs(model.estimator_.intercept_) < 1e-8


def test_rows_across_experiments_would_spoil_the_linear_fit():
    # The same data without groups contains rows that straddle the boundaries,
    # where the second experiment restarts from rest: the fit is no longer exact.
    u, y, _ = experiments([11, 12, 13], 300, linear_arx)
    model = NARXRegressor(estimator=LinearRegression(), scale=False).fit(u, y)
    assert np.max(np.abs(model.estimator_.coef_ - [0.6, -0.1, 0.5, 0.2])) > 1e-4


def test_linear_arx_is_recovered_with_scaling_through_its_predictions():
    u, y, groups = experiments([11, 12, 13], 300, linear_arx)
    model = NARXRegressor(estimator=LinearRegression()).fit(3.0 * u + 1.0, y, groups=groups)
    u_test = hold_input(250, 77)
    y_test = linear_arx(u_test)
    scale = np.ptp(y_test)
    one_step = model.predict_one_step(3.0 * u_test + 1.0, y_test)
    np.testing.assert_allclose(one_step, y_test, atol=1e-8 * scale)
    free_run = model.simulate(3.0 * u_test + 1.0, y_test)
    np.testing.assert_allclose(free_run, y_test, atol=1e-8 * scale)


# ---------------------------------------------------------------- exact simulation


def test_simulating_the_true_map_reproduces_the_noiseless_output():
    u, y, groups = experiments([21, 22, 23], 200)
    model = NARXRegressor(estimator=TrueNARX(), scale=False).fit(u, y, groups=groups)
    np.testing.assert_allclose(model.simulate(u, y, groups=groups), y, rtol=1e-12, atol=1e-12)
    np.testing.assert_allclose(
        model.predict_one_step(u, y, groups=groups), y, rtol=1e-12, atol=1e-12
    )


def test_lockstep_simulation_of_unequal_experiments_equals_separate_runs():
    lengths = [120, 45, 200]
    us = [hold_input(n, 30 + k) for k, n in enumerate(lengths)]
    ys = [nonlinear_narx(u, y0=(0.2 * k, -0.1 * k)) for k, u in enumerate(us)]
    groups = np.concatenate([np.full(n, f"run{k}") for k, n in enumerate(lengths)])
    u, y = np.concatenate(us), np.concatenate(ys)
    model = NARXRegressor(estimator=SVR(C=100.0, epsilon=0.01)).fit(u, y, groups=groups)
    together = model.simulate(u, y, groups=groups)
    separate = np.concatenate([model.simulate(uk, yk) for uk, yk in zip(us, ys, strict=True)])
    np.testing.assert_allclose(together, separate, rtol=1e-12, atol=1e-12)
    # The initial conditions may also be given as rows (n_experiments, max_lag_).
    initial = np.array([yk[:2] for yk in ys])
    np.testing.assert_array_equal(model.simulate(u, initial, groups=groups), together)
    # Only the first max_lag_ samples of each experiment are read.
    y_nan = y.copy()
    y_nan[~model.warmup_mask(y.size, groups=groups)] = np.nan
    np.testing.assert_array_equal(model.simulate(u, y_nan, groups=groups), together)


def test_the_fast_path_is_used_for_a_single_experiment_and_agrees_with_predict():
    u, y, groups = experiments([41, 42], 150)
    model = NARXRegressor(estimator=TrueNARXWithPredictOne(), scale=False)
    model.fit(u, y, groups=groups)
    single = model.simulate(u[:150], y[:150])
    assert model.estimator_.single_calls_ == 150 - 2
    assert model.estimator_.batch_calls_ == 0
    both = model.simulate(u, y, groups=groups)
    assert model.estimator_.batch_calls_ == 150 - 2
    np.testing.assert_allclose(single, both[:150], rtol=1e-12, atol=1e-12)
    np.testing.assert_allclose(both, y, rtol=1e-12, atol=1e-12)


def test_one_step_returns_measured_initial_conditions():
    u, y, groups = experiments([51, 52], 80)
    model = NARXRegressor(estimator=SVR()).fit(u, y, groups=groups)
    for prediction in (model.predict_one_step(u, y, groups=groups), model.simulate(u, y)):
        np.testing.assert_array_equal(prediction[:2], y[:2])
    np.testing.assert_array_equal(model.predict_one_step(u, y, groups=groups)[80:82], y[80:82])


# ------------------------------------------------------------- nonlinear NARX + SVR


@pytest.fixture(scope="module")
def nonlinear_fit():
    u, y, groups = experiments([1, 2, 3], 400)
    model = NARXRegressor(estimator=SVR(C=100.0, epsilon=0.05)).fit(u, y, groups=groups)
    u_test = hold_input(500, 99)
    y_test = nonlinear_narx(u_test)
    return model, u_test, y_test


def test_rbf_svr_recovers_a_nonlinear_narx_in_free_run(nonlinear_fit):
    model, u_test, y_test = nonlinear_fit
    keep = ~model.warmup_mask(y_test.size)
    free_run = model.simulate(u_test, y_test)
    assert nrmse(y_test[keep], free_run[keep]) < 0.05
    one_step = model.predict_one_step(u_test, y_test)
    assert rmse(y_test[keep], one_step[keep]) <= rmse(y_test[keep], free_run[keep])


def test_score_is_the_r2_of_the_free_run_simulation(nonlinear_fit):
    model, u_test, y_test = nonlinear_fit
    keep = ~model.warmup_mask(y_test.size)
    expected = r2(y_test[keep], model.simulate(u_test, y_test)[keep])
    assert model.score(u_test, y_test) == pytest.approx(expected, rel=1e-12)
    assert 0.99 < expected < 1.0


def test_scaling_makes_the_model_invariant_to_the_output_unit():
    u, y, groups = experiments([5, 6], 300)
    u_test = hold_input(300, 7)
    y_test = nonlinear_narx(u_test)
    keep = slice(2, None)

    def free_run_nrmse(factor, scale):
        svr = SVR(C=100.0, epsilon=0.1, gamma=0.5)
        model = NARXRegressor(estimator=svr, scale=scale)
        model.fit(u, factor * y, groups=groups)
        simulated = model.simulate(u_test, factor * y_test)
        return nrmse(factor * y_test[keep], simulated[keep])

    assert free_run_nrmse(1000.0, True) == pytest.approx(free_run_nrmse(1.0, True), abs=1e-6)
    # Without scaling ε = 0.1 is read in the unit of y and the kernel sees
    # unscaled regressors, so the unit changes the model.
    assert abs(free_run_nrmse(1000.0, False) - free_run_nrmse(1.0, False)) > 1e-3


@pytest.mark.filterwarnings("ignore:Sample kurtosis")  # uniform-ish inputs: shape clipped to 2
def test_default_estimator_is_the_generalized_gaussian_svr():
    svr = pytest.importorskip("softbend.identification.svr")
    u, y, groups = experiments([1, 2, 3], 300)
    model = NARXRegressor().fit(u, y, groups=groups)
    assert isinstance(model.estimator_, svr.GeneralizedGaussianSVR)
    assert model.estimator_.C == 100.0 and model.estimator_.epsilon == 0.1
    assert model.estimator is None
    u_test = hold_input(400, 99)
    y_test = nonlinear_narx(u_test)
    keep = ~model.warmup_mask(y_test.size)
    assert nrmse(y_test[keep], model.simulate(u_test, y_test)[keep]) < 0.05


def test_paper_sized_problem_six_experiments_of_512_samples():
    svr = pytest.importorskip("softbend.identification.svr")
    rng = np.random.default_rng(8)
    u, y, groups = experiments(range(60, 66), 512)
    y_noisy = y + 0.01 * np.ptp(y) * rng.normal(size=y.size)
    model = NARXRegressor().fit(u, y_noisy, groups=groups)
    assert isinstance(model.estimator_, svr.GeneralizedGaussianSVR)
    assert model.n_train_rows_ == 6 * 510
    u_test, y_test, g_test = experiments([70, 71], 512)
    keep = ~model.warmup_mask(y_test.size, groups=g_test)
    simulated = model.simulate(u_test, y_test, groups=g_test)
    assert nrmse(y_test[keep], simulated[keep]) < 0.05


# -------------------------------------------------------------------- several inputs

#: Input gains of ``multi_input_system``; opposite signs, so swapped columns show.
INPUT_GAINS = (0.3, -0.2, 0.15)


def multi_input_step(y1, u_past):
    """y(t) = 0.6 y(t−1) + Σ c_i u_i(t−1) + 0.1 u_0(t−1) u_last(t−1).

    ``u_past`` holds u(t−1), one column per input. With one input the product
    is 0.1 u(t−1)²; with two, y(t) = 0.6 y(t−1) + 0.3 u1 − 0.2 u2 + 0.1 u1 u2.
    ∂f/∂y(t−1) = 0.6 everywhere, so the system contracts with factor 0.6.
    """
    u_past = np.atleast_2d(u_past)
    gains = np.asarray(INPUT_GAINS[: u_past.shape[1]])
    return 0.6 * y1 + u_past @ gains + 0.1 * u_past[:, 0] * u_past[:, -1]


def multi_input_system(U):
    y = np.zeros(U.shape[0])
    for t in range(1, U.shape[0]):
        y[t] = multi_input_step(y[t - 1], U[t - 1 : t])[0]
    return y


def multi_inputs(n, seed, n_inputs):
    """Independent random-hold inputs, one column each (different seeds)."""
    return np.column_stack([hold_input(n, seed + 1000 * i) for i in range(n_inputs)])


class TrueMultiInputMap(RegressorMixin, BaseEstimator):
    """The exact map of ``multi_input_system`` on unscaled default-lag rows.

    Rows are [y(t−1), y(t−2), u0(t), u0(t−1), u1(t), u1(t−1), …]: the map reads
    y(t−1) and every u_i(t−1), ignoring the other columns.
    """

    def fit(self, X, y):
        self.n_inputs_ = (np.shape(X)[1] - 2) // 2
        self.single_calls_ = 0
        return self

    def predict(self, X):
        X = np.asarray(X)
        assert X.shape[1] == 2 + 2 * self.n_inputs_
        return multi_input_step(X[:, 0], X[:, 3::2])

    def predictor(self):
        def predict_one(x):
            self.single_calls_ += 1
            return float(self.predict(np.asarray(x)[None, :])[0])

        return predict_one


@pytest.mark.parametrize("n_inputs", [1, 2, 3])
def test_free_run_of_the_exact_map_with_several_inputs_reproduces_the_system(n_inputs):
    # The estimator is the true one-step map, so the free run must reproduce the
    # noiseless output up to rounding (1e-12): any misplaced input column or lag
    # would change it by O(1). One input is the case that always worked.
    lengths = [150, 60, 110]
    Us = [multi_inputs(n, 10 + k, n_inputs) for k, n in enumerate(lengths)]
    ys = [multi_input_system(U) for U in Us]
    groups = np.repeat(np.arange(len(lengths)), lengths)
    U, y = np.vstack(Us), np.concatenate(ys)
    model = NARXRegressor(estimator=TrueMultiInputMap(), scale=False).fit(U, y, groups=groups)
    assert model.n_inputs_ == n_inputs
    symbols = ["u"] if n_inputs == 1 else [f"u{i}" for i in range(n_inputs)]
    input_names = [name for s in symbols for name in (f"{s}(t)", f"{s}(t-1)")]
    expected_names = ("y(t-1)", "y(t-2)", *input_names)
    assert model.regressor_names_ == expected_names

    simulated = model.simulate(U, y, groups=groups)
    assert simulated.shape == (y.size,)
    np.testing.assert_allclose(simulated, y, rtol=1e-12, atol=1e-12)
    np.testing.assert_allclose(
        model.predict_one_step(U, y, groups=groups), y, rtol=1e-12, atol=1e-12
    )
    # A single experiment takes the predictor() path with the same rows (the
    # grouped run above also used it where the longest experiment ran alone).
    calls_before = model.estimator_.single_calls_
    single = model.simulate(Us[0], ys[0])
    assert model.estimator_.single_calls_ - calls_before == lengths[0] - model.max_lag_
    np.testing.assert_allclose(single, ys[0], rtol=1e-12, atol=1e-12)


def test_linear_two_input_arx_is_recovered_exactly_in_free_run_with_scaling():
    # Inputs in different units (kPa-like and unit-range) exercise the per-input
    # scaling. The data are noiseless and the regressor contains the true terms,
    # so least squares is exact and only rounding remains: 1e-8 of the range.
    def linear_system(U):
        y = np.zeros(U.shape[0])
        for t in range(1, U.shape[0]):
            y[t] = 0.6 * y[t - 1] + 0.3 * U[t - 1, 0] - 0.2 * U[t - 1, 1]
        return y

    def plant_inputs(n, seed):
        U = multi_inputs(n, seed, 2)
        return np.column_stack([40.0 * U[:, 0] + 50.0, U[:, 1]]), U

    Us = [plant_inputs(200, seed) for seed in (1, 2, 3)]
    U = np.vstack([measured for measured, _ in Us])
    y = np.concatenate([linear_system(raw) for _, raw in Us])
    groups = np.repeat([0, 1, 2], 200)
    model = NARXRegressor(
        estimator=LinearRegression(), output_lags=1, input_lags=1, include_current_input=False
    ).fit(U, y, groups=groups)
    U_test, raw_test = plant_inputs(300, 77)
    y_test = linear_system(raw_test)
    simulated = model.simulate(U_test, y_test)
    assert simulated.shape == y_test.shape
    np.testing.assert_allclose(simulated, y_test, atol=1e-8 * np.ptp(y_test))


@pytest.fixture(scope="module")
def two_input_svr_fit():
    Us = [multi_inputs(400, seed, 2) for seed in (1, 2, 3, 4)]
    U = np.vstack(Us)
    y = np.concatenate([multi_input_system(Uk) for Uk in Us])
    groups = np.repeat([0, 1, 2, 3], 400)
    model = NARXRegressor(
        estimator=SVR(C=100.0, epsilon=0.01),
        output_lags=1,
        input_lags=1,
        include_current_input=False,
    ).fit(U, y, groups=groups)
    return model


@pytest.mark.parametrize("seed", [5, 99])
def test_svr_narx_with_two_inputs_reproduces_the_system_in_free_run(two_input_svr_fit, seed):
    model = two_input_svr_fit
    U_test = multi_inputs(400, seed, 2)  # fresh inputs, not seen in fit
    y_test = multi_input_system(U_test)
    keep = ~model.warmup_mask(y_test.size)
    simulated = model.simulate(U_test, y_test)
    assert simulated.shape == (400,)
    one_step = model.predict_one_step(U_test, y_test)
    # The system contracts with ∂f/∂y(t−1) = 0.6, so a per-step model error δ
    # accumulates in free run to at most δ / (1 − 0.6) = 2.5 δ. The one-step
    # error on the measured trajectory estimates δ (the simulated states stay
    # within a few hundredths of it, and the SVR is smooth).
    free_error = np.max(np.abs(simulated[keep] - y_test[keep]))
    assert free_error <= 2.5 * np.max(np.abs(one_step[keep] - y_test[keep]))
    # In absolute terms: the ε-tube (0.01 std of y ≈ 0.25 % of the range) and
    # its 2.5-fold accumulation leave well under 2 % of the range, while a
    # model fed the inputs in the wrong columns is off by about 40 %.
    assert nrmse(y_test[keep], simulated[keep]) < 0.02
    swapped = model.simulate(U_test[:, ::-1], y_test)
    assert nrmse(y_test[keep], swapped[keep]) > 0.2


def test_a_wrong_number_of_input_columns_raises_one_clear_value_error():
    Us = [multi_inputs(60, seed, 2) for seed in (1, 2)]
    U = np.vstack(Us)
    y = np.concatenate([multi_input_system(Uk) for Uk in Us])
    groups = np.repeat([0, 1], 60)
    model = NARXRegressor(estimator=LinearRegression()).fit(U, y, groups=groups)
    # 1-D (read as one input), one column, three columns.
    wrong = [U[:, 0], U[:, :1], np.column_stack([U, U[:, 0]])]
    for method in ("simulate", "predict_one_step", "score"):
        for X in wrong:
            n_columns = 1 if X.ndim == 1 else X.shape[1]
            pattern = rf"^X: must have 2 input column\(s\) as in fit; got {n_columns}$"
            with pytest.raises(ValueError, match=pattern):
                getattr(model, method)(X, y, groups=groups)


# ------------------------------------------------------------------------ divergence


def test_a_diverging_experiment_stops_with_a_warning_and_nan_the_others_go_on():
    u_a = np.zeros(60)
    u_b = np.zeros(60)
    u_b[30:] = 10.0  # the model returns inf from sample 30 of "b" on
    u = np.concatenate([u_a, u_b, u_a])
    y = np.ones(u.size)
    groups = np.repeat(["a", "b", "c"], 60)
    model = NARXRegressor(estimator=BlowsUpAboveThreshold(), scale=False).fit(u, y, groups=groups)
    with pytest.warns(RuntimeWarning, match=r"experiment 'b' diverged at sample 30") as record:
        simulated = model.simulate(u, y, groups=groups)
    assert len(record) == 1
    assert np.isfinite(simulated[:90]).all()
    assert np.isnan(simulated[90:120]).all()
    assert np.isfinite(simulated[120:]).all()
    np.testing.assert_allclose(simulated[:60], 0.5 ** np.arange(-1, 59).clip(0))
    with pytest.warns(RuntimeWarning, match=r"diverged"):
        assert np.isnan(model.score(u, y, groups=groups))


def test_an_unstable_identified_model_overflows_without_raising():
    u = np.ones(1200)
    y = np.zeros(1200)
    y[1:] = 2.0 ** np.arange(1, 1200).clip(max=60)  # fit data only; growth factor 2
    model = NARXRegressor(estimator=LinearRegression(), output_lags=1, input_lags=1)
    model.fit(u[:60], y[:60])
    with warnings.catch_warnings(record=True) as record:
        warnings.simplefilter("always")
        simulated = model.simulate(u, y)
    messages = [str(w.message) for w in record]
    assert len(messages) == 1 and "diverged" in messages[0]
    assert np.isnan(simulated[-1])
    assert np.isfinite(simulated[:900]).all()


# ------------------------------------------------------------------------ validation


@pytest.mark.parametrize(
    ("params", "field"),
    [
        ({"output_lags": 0}, "output_lags"),
        ({"output_lags": 1.5}, "output_lags"),
        ({"output_lags": True}, "output_lags"),
        ({"output_lags": "2"}, "output_lags"),
        ({"input_lags": 0}, "input_lags"),
        ({"input_lags": 0, "include_current_input": False}, "input_lags"),
        ({"include_current_input": "yes"}, "include_current_input"),
        ({"scale": "no"}, "scale"),
        ({"estimator": object()}, "estimator"),
    ],
)
def test_bad_parameters_raise_in_fit_naming_the_field(params, field):
    model = NARXRegressor(estimator=LinearRegression())
    model.set_params(**params)
    with pytest.raises(ValueError, match=rf"^{field}: must be") as info:
        model.fit(np.arange(10.0), np.arange(10.0))
    assert info.value.key == field


@pytest.mark.parametrize(
    ("X", "y", "groups", "error", "pattern"),
    [
        ([1.0, np.nan, 2, 3, 4], np.zeros(5), None, DatasetError, "^X: must be finite"),
        (np.zeros(5), [1.0, 2, np.inf, 3, 4], None, DatasetError, "^y: must be finite"),
        (np.zeros(5), np.zeros(4), None, ValueError, "^y: .*\\(5\\); got 4"),
        (np.zeros(5), np.zeros((5, 2)), None, ValueError, "^y: .*one model per output"),
        (np.zeros((5, 1, 1)), np.zeros(5), None, ValueError, "^X: must be a non-empty array"),
        (np.zeros(0), np.zeros(0), None, ValueError, "^X: must be a non-empty array"),
        (np.zeros(5), np.zeros(5), [0, 0, 1, 1], ValueError, "^groups: .*per sample"),
        (
            np.zeros(5),
            np.zeros(5),
            [0, 0, 0, 1, 1],
            DatasetError,
            "^groups: .*max_lag \\+ 1 = 3.*experiment 1 with 2 samples",
        ),
    ],
)
def test_bad_data_raise_naming_the_field(X, y, groups, error, pattern):
    with pytest.raises(error, match=pattern):
        NARXRegressor(estimator=LinearRegression()).fit(X, y, groups=groups)


def test_bad_prediction_inputs_raise_naming_the_field():
    u, y, groups = experiments([1, 2], 50, linear_arx)
    with pytest.raises(NotFittedError):
        NARXRegressor().simulate(u, y)
    model = NARXRegressor(estimator=LinearRegression()).fit(u, y, groups=groups)
    with pytest.raises(ValueError, match=r"^X: must have 1 input"):
        model.simulate(np.column_stack([u, u]), y)
    with pytest.raises(ValueError, match=r"^y_init: .*\(2, 2\)"):
        model.simulate(u, np.zeros((3, 2)), groups=groups)
    y_bad = y.copy()
    y_bad[51] = np.nan  # second initial condition of experiment 1
    with pytest.raises(DatasetError, match=r"^y_init: must be finite"):
        model.simulate(u, y_bad, groups=groups)
    with pytest.raises(DatasetError, match=r"^y: must be finite"):
        model.predict_one_step(u, y_bad, groups=groups)
    with pytest.raises(DatasetError, match=r"^X: must be finite"):
        model.predict_one_step(np.full(u.size, np.nan), y)
    with pytest.raises(DatasetError, match=r"^groups: must label experiments"):
        model.score(u[:5], y[:5], groups=[0, 0, 0, 1, 1])
    with pytest.raises(DatasetError, match=r"^X: .*= 3 samples"):
        model.simulate(u[:2], y[:2])
    with pytest.raises(ValueError, match=r"^n_samples: must be an integer"):
        model.warmup_mask(10.0)


# ------------------------------------------------------------------- sklearn contract


@pytest.mark.parametrize(
    "check",
    [
        estimator_checks.check_estimator_cloneable,
        estimator_checks.check_estimator_repr,
        estimator_checks.check_no_attributes_set_in_init,
        estimator_checks.check_parameters_default_constructible,
        estimator_checks.check_get_params_invariance,
        estimator_checks.check_set_params,
        estimator_checks.check_dont_overwrite_parameters,
        estimator_checks.check_estimators_overwrite_params,
        estimator_checks.check_fit_check_is_fitted,
        estimator_checks.check_n_features_in,
    ],
    ids=lambda check: check.__name__,
)
def test_scikit_learn_api_checks(check):
    check("NARXRegressor", NARXRegressor(estimator=LinearRegression()))


def test_the_estimator_parameter_is_cloned_not_fitted():
    inner = LinearRegression()
    u, y, groups = experiments([1, 2], 50, linear_arx)
    model = NARXRegressor(estimator=inner).fit(u, y, groups=groups)
    assert model.estimator is inner
    assert not hasattr(inner, "coef_")
    assert model.estimator_ is not inner
    copy = clone(model)
    assert copy.get_params()["output_lags"] == 2 and not hasattr(copy, "estimator_")
