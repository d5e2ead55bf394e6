import itertools
import math
import tracemalloc

import numpy as np
import pytest
from sklearn.exceptions import NotFittedError
from sklearn.linear_model import LinearRegression, Ridge
from sklearn.pipeline import make_pipeline
from sklearn.preprocessing import PolynomialFeatures, StandardScaler
from sklearn.utils.estimator_checks import parametrize_with_checks

from softbend.surrogates.polynomial import (
    PolynomialRegressor,
    monomial_powers,
    n_terms,
    system_memory_mb,
)

from .conftest import table1_inputs as _design_samples


def _monomials(Z, powers):
    return np.prod(Z[:, None, :] ** powers[None, :, :], axis=2)


def _contract_predict(model, X):
    """The prediction formula of the surrogate contract, from the fitted attributes alone."""
    Z = (X - model.x_mean_) / model.x_scale_
    return model.y_mean_ + model.y_scale_ * _monomials(Z, model.powers_) @ model.coef_


@parametrize_with_checks([PolynomialRegressor()])
def test_sklearn_estimator_contract(estimator, check):
    check(estimator)


# --- monomials ----------------------------------------------------------------------------


@pytest.mark.parametrize(
    ("n_features", "degree", "expected"),
    [(7, 0, 1), (7, 1, 8), (7, 2, 36), (7, 4, 330), (7, 6, 1716), (7, 9, 11440), (7, 10, 19448),
     (1, 5, 6), (3, 3, 20)],
)  # fmt: skip
def test_n_terms_closed_form(n_features, degree, expected):
    assert n_terms(n_features, degree) == expected
    assert n_terms(n_features, degree) == math.comb(n_features + degree, degree)


@pytest.mark.parametrize(("n_features", "degree"), [(1, 4), (3, 3), (7, 2), (7, 4)])
def test_monomial_powers_are_graded_lex_like_polynomial_features(n_features, degree):
    powers = monomial_powers(n_features, degree)
    assert powers.dtype == np.int64
    assert powers.shape == (n_terms(n_features, degree), n_features)
    assert not powers[0].any()
    totals = powers.sum(axis=1)
    assert totals.max() == degree
    assert np.all(np.diff(totals) >= 0)
    assert np.unique(powers, axis=0).shape[0] == powers.shape[0]
    reference = PolynomialFeatures(degree).fit(np.zeros((1, n_features))).powers_
    np.testing.assert_array_equal(powers, reference)


@pytest.mark.parametrize(
    ("n_features", "degree"), [(0, 2), (-1, 2), (2.0, 2), (True, 2), (3, -1), (3, 1.5)]
)
def test_n_terms_rejects_bad_input(n_features, degree):
    with pytest.raises(ValueError, match=r"must be an integer in \[-?\d+, inf\)"):
        n_terms(n_features, degree)


# --- fit: closed-form cases and equivalences ------------------------------------------------


def test_recovers_a_degree_3_polynomial_in_7_variables_exactly():
    X = _design_samples(600, seed=1)
    rng = np.random.default_rng(2)
    powers = monomial_powers(7, 3)
    mean, std = X.mean(axis=0), X.std(axis=0)
    true_coef = rng.normal(size=powers.shape[0])
    y = _monomials((X - mean) / std, powers) @ true_coef
    model = PolynomialRegressor(degree=3, alpha=0.0).fit(X, y)

    assert model.solver_ == "cholesky"
    np.testing.assert_allclose(model.x_mean_, mean, rtol=1e-12)
    np.testing.assert_allclose(model.x_scale_, std, rtol=1e-12)
    recovered = model.y_scale_ * model.coef_
    recovered[0] += model.y_mean_
    np.testing.assert_allclose(recovered, true_coef, rtol=0, atol=1e-8)
    X_new = _design_samples(200, seed=3)
    y_new = _monomials((X_new - mean) / std, powers) @ true_coef
    np.testing.assert_allclose(model.predict(X_new), y_new, rtol=0, atol=1e-8)


def test_default_ridge_barely_changes_a_well_posed_fit():
    X = _design_samples(400, seed=4)
    y = 3.0 + X[:, 0] * X[:, 6] - 2.0 * X[:, 1] ** 2
    exact = PolynomialRegressor(degree=2, alpha=0.0).fit(X, y)
    ridge = PolynomialRegressor(degree=2).fit(X, y)
    np.testing.assert_allclose(ridge.predict(X), exact.predict(X), rtol=1e-6)
    heavy = PolynomialRegressor(degree=2, alpha=1.0).fit(X, y)
    assert np.linalg.norm(heavy.coef_[1:]) < np.linalg.norm(exact.coef_[1:])


def test_degree_1_is_linear_regression():
    X = _design_samples(300, seed=5)
    y = np.sin(X[:, 6] * 3.0) * X[:, 0] + X[:, 1] * X[:, 2]
    ours = PolynomialRegressor(degree=1, alpha=0.0).fit(X, y)
    linear = LinearRegression().fit(X, y)
    np.testing.assert_allclose(ours.predict(X), linear.predict(X), rtol=1e-10)
    slopes = ours.y_scale_ * ours.coef_[1:] / ours.x_scale_
    np.testing.assert_allclose(slopes, linear.coef_, rtol=1e-9)


@pytest.mark.parametrize("alpha", [0.0, 1e-3])
def test_streaming_is_exact(alpha):
    X = _design_samples(1000, seed=6)
    y = np.exp(X[:, 6]) * X[:, 0] / X[:, 1]
    small = PolynomialRegressor(degree=3, alpha=alpha, chunk_rows=7).fit(X, y)
    large = PolynomialRegressor(degree=3, alpha=alpha, chunk_rows=100000).fit(X, y)
    np.testing.assert_allclose(small.coef_, large.coef_, rtol=1e-9, atol=1e-12)
    X_new = _design_samples(50, seed=7)
    np.testing.assert_allclose(small.predict(X_new), large.predict(X_new), rtol=1e-10)


@pytest.mark.parametrize("degree", [2, 3])
def test_equals_polynomial_features_with_linear_regression(degree):
    rng = np.random.default_rng(8)
    X = rng.normal(size=(80, 3)) * [2.0, 0.5, 10.0] + [1.0, -3.0, 50.0]
    y = np.cos(X[:, 0]) + X[:, 1] * X[:, 2] + 0.1 * rng.normal(size=80)
    ours = PolynomialRegressor(degree=degree, alpha=0.0).fit(X, y)
    reference = make_pipeline(
        StandardScaler(), PolynomialFeatures(degree), LinearRegression(fit_intercept=False)
    ).fit(X, y)
    X_new = rng.normal(size=(30, 3)) * [2.0, 0.5, 10.0] + [1.0, -3.0, 50.0]
    np.testing.assert_allclose(ours.predict(X_new), reference.predict(X_new), rtol=1e-9)


@pytest.mark.parametrize("alpha", [1e-3, 0.1, 2.0])
def test_ridge_penalty_equals_sklearn_ridge_in_standardized_units(alpha):
    # (ΦᵀΦ + α n I′)c = Φᵀ y_std with an unpenalized constant is sklearn's Ridge with an
    # intercept, penalty α·n, on the standardized inputs' monomials (Ridge is homogeneous in y).
    rng = np.random.default_rng(9)
    X = rng.normal(size=(60, 4))
    y = X[:, 0] ** 2 - X[:, 1] * X[:, 3] + 0.3 * rng.normal(size=60)
    ours = PolynomialRegressor(degree=2, alpha=alpha).fit(X, y)
    reference = make_pipeline(
        StandardScaler(),
        PolynomialFeatures(2, include_bias=False),
        Ridge(alpha=alpha * X.shape[0], solver="cholesky"),
    ).fit(X, y)
    np.testing.assert_allclose(ours.predict(X), reference.predict(X), rtol=1e-9)
    np.testing.assert_allclose(ours.y_scale_ * ours.coef_[1:], reference[-1].coef_, rtol=1e-8)


def test_contract_formula_reproduces_predict_and_survives_attribute_transfer():
    X = _design_samples(500, seed=10)
    y = 20.0 * X[:, 6] * X[:, 0] / (X[:, 1] * X[:, 2]) + X[:, 4]
    model = PolynomialRegressor(degree=4, chunk_rows=64).fit(X, y)
    X_new = _design_samples(40, seed=11)
    expected = model.predict(X_new)
    assert expected.dtype == np.float64
    np.testing.assert_allclose(_contract_predict(model, X_new), expected, rtol=1e-10)

    # A model rebuilt from the contract's attributes only (what persistence does).
    clone = PolynomialRegressor(degree=4, chunk_rows=5)
    for name in ("x_mean_", "x_scale_", "y_mean_", "y_scale_", "powers_", "coef_"):
        setattr(clone, name, np.array(getattr(model, name)).copy())
    clone.y_mean_, clone.y_scale_ = float(model.y_mean_), float(model.y_scale_)
    clone.n_features_in_ = model.n_features_in_
    np.testing.assert_allclose(clone.predict(X_new), expected, rtol=1e-12)


def test_fits_the_sfrba_like_response_better_with_higher_degree():
    X = _design_samples(3000, seed=12)
    y = 40.0 * X[:, 6] * X[:, 0] / (X[:, 1] * X[:, 2] * (1.0 + 0.05 * X[:, 4]))
    X_test = _design_samples(500, seed=13)
    y_test = 40.0 * X_test[:, 6] * X_test[:, 0] / (X_test[:, 1] * X_test[:, 2])
    y_test /= 1.0 + 0.05 * X_test[:, 4]
    errors = [
        np.sqrt(np.mean((PolynomialRegressor(degree=k).fit(X, y).predict(X_test) - y_test) ** 2))
        for k in (1, 2, 4)
    ]
    assert errors[0] > errors[1] > errors[2]


# --- collinear grid designs -----------------------------------------------------------------


@pytest.mark.parametrize(("alpha", "solver"), [(0.0, "eigh"), (1e-8, "cholesky")])
def test_three_level_grid_degree_4_interpolates_arbitrary_data(alpha, solver):
    # On a 3 x 3 grid the monomials x^a y^b with a, b <= 2 (all of total degree <= 4) span
    # every function of the 9 points: degree 4 interpolates, though z^3, z^4 are collinear.
    X = np.array(list(itertools.product([100.0, 130.0, 160.0], [0.0, 0.25, 0.5])))
    y = np.random.default_rng(14).normal(size=9)
    model = PolynomialRegressor(degree=4, alpha=alpha).fit(X, y)
    assert model.solver_ == solver
    assert model.rank_ == (9 if solver == "eigh" else 15)
    assert np.all(np.isfinite(model.coef_))
    np.testing.assert_allclose(model.predict(X), y, rtol=0, atol=1e-6)
    X_off = np.array([[115.0, 0.1], [145.0, 0.4], [160.0, 0.3]])
    off = model.predict(X_off)
    assert np.all(np.isfinite(off))
    assert np.all(np.abs(off) < 10.0 * np.abs(y).max())


@pytest.mark.parametrize("alpha", [0.0, 1e-8])
def test_three_level_grid_in_7_parameters_degree_4(alpha):
    levels = [(100.0, 130.0, 160.0), (6.0, 8.0, 10.0), (2.0, 3.0, 4.0), (2.0, 3.0, 4.0),
              (5.0, 10.0, 15.0), (8.0, 10.0, 12.0), (0.0, 0.25, 0.5)]  # fmt: skip
    X = np.array(list(itertools.product(*levels)))
    Z = (X - X.mean(axis=0)) / X.std(axis=0)
    # Representable on the grid: every exponent <= 2, total degree <= 4.
    y = 5.0 + 3.0 * Z[:, 6] * Z[:, 0] - 2.0 * Z[:, 1] ** 2 * Z[:, 2] ** 2 + Z[:, 3] * Z[:, 4] ** 2
    model = PolynomialRegressor(degree=4, alpha=alpha).fit(X, y)
    assert model.rank_ <= n_terms(7, 4)
    if alpha == 0.0:
        # Per parameter z^3 = c z and z^4 = c z^2 on three levels: rank drops.
        assert model.solver_ == "eigh"
        assert model.rank_ < n_terms(7, 4)
    np.testing.assert_allclose(model.predict(X), y, rtol=0, atol=1e-6)
    X_off = _design_samples(100, seed=15)
    assert np.all(np.isfinite(model.predict(X_off)))


# --- predictor ------------------------------------------------------------------------------


@pytest.mark.parametrize("degree", [1, 2, 4, 6])
def test_predictor_equals_predict(degree):
    X = _design_samples(2000, seed=16)
    y = 30.0 * X[:, 6] * X[:, 0] / X[:, 1] - X[:, 5] ** 2
    model = PolynomialRegressor(degree=degree).fit(X, y)
    predict_one = model.predictor()
    X_new = _design_samples(25, seed=17)
    one_by_one = np.array([predict_one(x) for x in X_new])
    assert all(isinstance(predict_one(x), float) for x in X_new[:3])
    np.testing.assert_allclose(one_by_one, model.predict(X_new), rtol=1e-11, atol=1e-9)
    assert predict_one(list(X_new[0])) == pytest.approx(one_by_one[0], rel=1e-14)


def test_predictor_keeps_its_model_after_refit():
    X = _design_samples(200, seed=18)
    model = PolynomialRegressor(degree=2).fit(X, X[:, 0])
    predict_one = model.predictor()
    before = predict_one(X[0])
    model.fit(X, -X[:, 1])
    assert predict_one(X[0]) == before
    assert before == pytest.approx(X[0, 0], rel=1e-8)


def test_predictor_rejects_a_wrong_shape_and_needs_a_fit():
    with pytest.raises(NotFittedError):
        PolynomialRegressor().predictor()
    X = _design_samples(100, seed=19)
    predict_one = PolynomialRegressor().fit(X, X[:, 6]).predictor()
    with pytest.raises(ValueError, match=r"must have shape \(7,\)"):
        predict_one(np.zeros(6))
    with pytest.raises(ValueError, match=r"must have shape \(7,\)"):
        predict_one(np.zeros((1, 7)))


# --- memory limit ---------------------------------------------------------------------------


def test_memory_estimate_matches_the_brief():
    assert 8 * n_terms(7, 9) ** 2 / 1e9 == pytest.approx(1.047, abs=1e-3)
    assert 8 * n_terms(7, 10) ** 2 / 1e9 == pytest.approx(3.026, abs=1e-3)
    assert system_memory_mb(7, 9, 8192) < 2048.0 < system_memory_mb(7, 10, 8192)
    assert system_memory_mb(7, 4, 1) == pytest.approx(8.0 * 330 * 331 / 1e6)


def test_degree_10_is_refused_before_allocating():
    X = _design_samples(100, seed=20)
    y = X[:, 6]
    tracemalloc.start()
    try:
        with pytest.raises(ValueError) as info:
            PolynomialRegressor(degree=10).fit(X, y)
        _, peak = tracemalloc.get_traced_memory()
    finally:
        tracemalloc.stop()
    assert peak < 20e6
    message = str(info.value)
    for part in ("degree: must fit", "got 10", "19448 terms", "3026 MB", "max_memory_mb=2048",
                 "largest degree that fits is 9"):  # fmt: skip
        assert part in message, message
    assert "\n" not in message


def test_memory_limit_names_the_largest_degree_that_fits():
    X = _design_samples(50, seed=21)
    limit = system_memory_mb(7, 3, 50) + 0.01
    PolynomialRegressor(degree=3, max_memory_mb=limit).fit(X, X[:, 0])
    with pytest.raises(ValueError, match="largest degree that fits is 3"):
        PolynomialRegressor(degree=5, max_memory_mb=limit).fit(X, X[:, 0])
    with pytest.raises(ValueError, match="no degree fits"):
        PolynomialRegressor(degree=2, max_memory_mb=1e-6).fit(X, X[:, 0])


# --- bad input ------------------------------------------------------------------------------


@pytest.mark.parametrize(
    ("params", "name"),
    [
        ({"degree": 0}, "degree"),
        ({"degree": -2}, "degree"),
        ({"degree": 2.5}, "degree"),
        ({"degree": True}, "degree"),
        ({"alpha": -1e-3}, "alpha"),
        ({"alpha": float("nan")}, "alpha"),
        ({"alpha": "big"}, "alpha"),
        ({"chunk_rows": 0}, "chunk_rows"),
        ({"max_memory_mb": 0.0}, "max_memory_mb"),
        ({"max_memory_mb": -5.0}, "max_memory_mb"),
    ],
)
def test_bad_hyperparameters_raise_one_clear_error(params, name):
    X = _design_samples(30, seed=22)
    with pytest.raises(ValueError, match=f"{name}: must be"):
        PolynomialRegressor(**params).fit(X, X[:, 0])


def test_bad_data_raises():
    X = _design_samples(30, seed=23)
    y = X[:, 0].copy()
    model = PolynomialRegressor().fit(X, y)
    with pytest.raises(
        ValueError, match="X has 6 features, but PolynomialRegressor is expecting 7"
    ):
        model.predict(X[:, :6])
    X_nan = X.copy()
    X_nan[4, 2] = np.nan
    with pytest.raises(ValueError, match=r"X: must be finite.*row 4"):
        PolynomialRegressor().fit(X_nan, y)
    with pytest.raises(ValueError, match=r"X: must be finite"):
        model.predict(X_nan)
    y_inf = y.copy()
    y_inf[3] = np.inf
    with pytest.raises(ValueError, match=r"y: must be finite"):
        PolynomialRegressor().fit(X, y_inf)
    with pytest.raises(NotFittedError):
        PolynomialRegressor().predict(X)


def test_incomplete_exponent_table_is_rejected():
    X = _design_samples(30, seed=24)
    model = PolynomialRegressor(degree=2).fit(X, X[:, 0])
    model.powers_ = model.powers_[1:]  # constant term missing
    model.coef_ = model.coef_[1:]
    with pytest.raises(ValueError, match="powers_: must be a 2-D table"):
        model.predict(X)
