import tracemalloc
import warnings

import numpy as np
import pytest
from scipy.spatial.distance import cdist
from sklearn.exceptions import ConvergenceWarning, NotFittedError
from sklearn.metrics import r2_score
from sklearn.svm import SVR
from sklearn.utils.estimator_checks import parametrize_with_checks

from softbend.identification.kernels import (
    ShapeClippedWarning,
    estimate_gg_shape,
    estimate_kernel_shape,
    generalized_gaussian_kernel,
    gg_normalization,
)
from softbend.identification.svr import GeneralizedGaussianSVR, _merge_duplicates

# Random inputs are often lighter-tailed than Gaussian: the shape estimate is clipped to 2
# with a warning. The tests about that warning check for it explicitly.
pytestmark = pytest.mark.filterwarnings(
    "ignore::softbend.identification.kernels.ShapeClippedWarning"
)


@parametrize_with_checks([GeneralizedGaussianSVR()])
def test_sklearn_estimator_contract(estimator, check):
    check(estimator)


def _nonlinear_problem(n_samples=250, n_features=3, seed=0):
    rng = np.random.default_rng(seed)
    X = rng.normal(size=(n_samples, n_features))
    y = np.sin(2.0 * X[:, 0]) + 0.5 * X[:, 1] * X[:, 2] + 0.05 * rng.normal(size=n_samples)
    return X, y


# --- reductions to the Gaussian (RBF) SVR -----------------------------------------------
# LIBSVM stops within `tol` of the optimum, and the estimator presents the rows to it in a
# canonical (sorted) order, so two exact formulations agree only to about `tol` at the
# default setting; a tight tolerance shows they solve the same problem.


@pytest.mark.parametrize("sigma", [0.5, 1.0, 2.0])
@pytest.mark.parametrize("C", [0.3, 3.0, 100.0])
def test_gaussian_shape_without_normalization_is_the_rbf_svr(sigma, C):
    X, y = _nonlinear_problem()
    X_test, _ = _nonlinear_problem(n_samples=100, seed=1)
    ours = GeneralizedGaussianSVR(
        sigma=sigma, shape=2.0, normalize=False, C=C, epsilon=0.1, tol=1e-9
    ).fit(X, y)
    rbf = SVR(kernel="rbf", gamma=1.0 / (2.0 * sigma**2), C=C, epsilon=0.1, tol=1e-9).fit(X, y)
    assert np.max(np.abs(ours.predict(X_test) - rbf.predict(X_test))) < 1e-6
    assert ours.n_support_ == rbf.support_.size


@pytest.mark.parametrize("sigma", [0.5, 1.0])
@pytest.mark.parametrize("C", [0.3, 3.0, 30.0])
def test_normalized_kernel_is_the_rbf_svr_with_penalty_times_c(sigma, C):
    # Dual of the eps-SVR with Gram matrix cK and box |beta| <= C:
    #   min 1/2 c beta'K beta + eps |beta|_1 - y'beta,  sum(beta) = 0.
    # With alpha = c beta this is (1/c) [1/2 alpha'K alpha + eps |alpha|_1 - y'alpha] over
    # |alpha| <= cC: the same minimizer, f = sum beta_i cK_i + b = sum alpha_i K_i + b,
    # and the same intercept (the KKT conditions on free vectors are unchanged).
    # LIBSVM caches kernel rows in single precision (Qfloat = float), and cK and K round
    # differently there, so the two agree to float32 level rather than to 1e-12.
    float32_level = 50 * np.finfo(np.float32).eps  # 6e-6
    X, y = _nonlinear_problem()
    X_test, _ = _nonlinear_problem(n_samples=100, seed=1)
    c = gg_normalization(sigma, 2.0)
    gram = generalized_gaussian_kernel(X, sigma=sigma, shape=2.0, normalize=False)
    gram_test = generalized_gaussian_kernel(X_test, X, sigma=sigma, shape=2.0, normalize=False)
    scaled_kernel = SVR(kernel="precomputed", C=C, tol=1e-9).fit(c * gram, y)
    scaled_penalty = SVR(kernel="precomputed", C=c * C, tol=1e-9).fit(gram, y)
    np.testing.assert_allclose(
        scaled_kernel.predict(c * gram_test), scaled_penalty.predict(gram_test), atol=float32_level
    )

    ours = GeneralizedGaussianSVR(sigma=sigma, shape=2.0, normalize=True, C=C, tol=1e-9).fit(X, y)
    rbf = SVR(kernel="rbf", gamma=1.0 / (2.0 * sigma**2), C=c * C, tol=1e-9).fit(X, y)
    assert ours.kernel_scale_ == pytest.approx(c, rel=1e-15)
    assert np.max(np.abs(ours.predict(X_test) - rbf.predict(X_test))) < float32_level


# --- prediction paths -------------------------------------------------------------------


@pytest.mark.parametrize("shape", [2.0, 1.0, 1.3])
def test_predict_is_the_kernel_expansion_and_the_predictor_matches_it(shape):
    X, y = _nonlinear_problem()
    X_test, _ = _nonlinear_problem(n_samples=60, seed=3)
    model = GeneralizedGaussianSVR(shape=shape, sigma=0.9).fit(X, y)
    expansion = (
        generalized_gaussian_kernel(X_test, model.support_vectors_, sigma=0.9, shape=shape)
        @ model.dual_coef_
        + model.intercept_
    )
    batch = model.predict(X_test)
    np.testing.assert_allclose(batch, expansion, rtol=0, atol=1e-12)
    predict_one = model.predictor()
    one_by_one = np.array([predict_one(row) for row in X_test])
    np.testing.assert_allclose(one_by_one, batch, rtol=0, atol=1e-12)
    assert isinstance(predict_one(X_test[0].tolist()), float)


def test_smooth_function_is_learned_with_r2_above_0_99():
    rng = np.random.default_rng(4)
    X = rng.uniform(-2.0, 2.0, size=(600, 2))
    X_test = rng.uniform(-1.8, 1.8, size=(300, 2))

    def f(x):
        return np.sin(1.5 * x[:, 0]) * np.cos(x[:, 1]) + 0.3 * x[:, 1] ** 2

    X_mean, X_std = X.mean(axis=0), X.std(axis=0)
    with warnings.catch_warnings():
        warnings.simplefilter("ignore", ShapeClippedWarning)  # uniform inputs: kurtosis 1.8
        model = GeneralizedGaussianSVR(epsilon=0.01).fit((X - X_mean) / X_std, f(X))
    assert model.sigma_ == pytest.approx(1.0, rel=1e-12)
    assert r2_score(f(X_test), model.predict((X_test - X_mean) / X_std)) > 0.99


# --- kernel hyperparameters -------------------------------------------------------------


def test_missing_sigma_and_shape_are_estimated_from_the_training_inputs():
    rng = np.random.default_rng(8)
    X = rng.laplace(size=(400, 3))
    y = np.tanh(X[:, 0]) + 0.1 * X[:, 1]
    estimate = estimate_kernel_shape(X)  # the kernel's argument x - z, the default
    model = GeneralizedGaussianSVR().fit(X, y)
    assert (model.sigma_, model.shape_) == (
        pytest.approx(estimate.sigma),
        pytest.approx(estimate.shape),
    )
    assert model.shape_estimate_.moments_of == "differences"
    assert model.shape_estimate_.kurtosis == pytest.approx(estimate.kurtosis, rel=1e-12)
    assert 0.9 < model.shape_ < 1.6  # Laplacian inputs: heavier tails than Gaussian

    # The earlier reading (pooled standardized components) stays reachable.
    sigma, shape = estimate_gg_shape(X)
    components = GeneralizedGaussianSVR(moments_of="components").fit(X, y)
    assert (components.sigma_, components.shape_) == (pytest.approx(sigma), pytest.approx(shape))
    assert components.sigma_ == pytest.approx(model.sigma_, rel=1e-12)  # σ: same in every reading

    partly = GeneralizedGaussianSVR(sigma=0.4).fit(X, y)
    assert partly.sigma_ == 0.4
    assert partly.shape_ == pytest.approx(estimate.shape)
    assert GeneralizedGaussianSVR(sigma=0.4).get_params()["sigma"] == 0.4  # unchanged
    assert GeneralizedGaussianSVR(sigma=0.4, shape=1.0).fit(X, y).shape_estimate_ is None


def test_clipped_estimate_warns_but_an_explicit_shape_does_not():
    rng = np.random.default_rng(9)
    X = rng.uniform(size=(200, 2))
    y = X.sum(axis=1)
    with pytest.warns(ShapeClippedWarning):
        model = GeneralizedGaussianSVR().fit(X, y)
    assert model.shape_ == 2.0
    with warnings.catch_warnings():
        warnings.simplefilter("error", ShapeClippedWarning)
        GeneralizedGaussianSVR(shape=1.5).fit(X, y)


def test_fit_does_not_depend_on_sample_order_and_weights_count_as_copies():
    X, y = _nonlinear_problem(n_samples=120)
    order = np.random.default_rng(5).permutation(len(y))
    base = GeneralizedGaussianSVR(shape=1.5).fit(X, y)
    permuted = GeneralizedGaussianSVR(shape=1.5).fit(X[order], y[order])
    np.testing.assert_array_equal(base.predict(X), permuted.predict(X))

    counts = np.random.default_rng(6).integers(0, 3, size=len(y))
    weighted = GeneralizedGaussianSVR().fit(X, y, sample_weight=counts)
    copies = GeneralizedGaussianSVR().fit(np.repeat(X, counts, axis=0), np.repeat(y, counts))
    np.testing.assert_allclose(weighted.predict(X), copies.predict(X), rtol=1e-12, atol=1e-12)


# --- bad input --------------------------------------------------------------------------


@pytest.mark.parametrize(
    ("params", "field"),
    [
        ({"sigma": 0.0}, "sigma"),
        ({"sigma": -1.0}, "sigma"),
        ({"shape": 2.5}, "shape"),
        ({"shape": 0.0}, "shape"),
        ({"C": 0.0}, "C"),
        ({"epsilon": -0.1}, "epsilon"),
        ({"tol": 0.0}, "tol"),
        ({"cache_size": -5.0}, "cache_size"),
        ({"max_iter": 0}, "max_iter"),
        ({"max_iter": 2.5}, "max_iter"),
        ({"normalize": "yes"}, "normalize"),
    ],
)
def test_bad_hyperparameters_raise_naming_the_field(params, field):
    X, y = _nonlinear_problem(n_samples=30)
    with pytest.raises(ValueError, match=rf"^{field}: must be") as info:
        GeneralizedGaussianSVR(**params).fit(X, y)
    assert info.value.key == field


def test_non_finite_data_raise_naming_the_array():
    X, y = _nonlinear_problem(n_samples=30)
    X_bad = X.copy()
    X_bad[4, 0] = np.nan
    with pytest.raises(ValueError, match="X contains NaN"):
        GeneralizedGaussianSVR().fit(X_bad, y)
    y_bad = y.copy()
    y_bad[2] = np.inf
    with pytest.raises(ValueError, match="y contains infinity"):
        GeneralizedGaussianSVR().fit(X, y_bad)
    model = GeneralizedGaussianSVR().fit(X, y)
    with pytest.raises(ValueError, match="X contains NaN"):
        model.predict(X_bad)


def test_too_few_distinct_samples_to_estimate_the_kernel():
    X = np.repeat(np.eye(3), 5, axis=0)
    y = np.repeat([0.0, 1.0, 2.0], 5)
    with pytest.raises(
        ValueError, match=r"^X: must contain at least 4 distinct samples.*n_samples = 3"
    ):
        GeneralizedGaussianSVR().fit(X, y)
    # With the kernel given, nothing has to be estimated.
    model = GeneralizedGaussianSVR(sigma=1.0, shape=2.0, epsilon=0.0).fit(X, y)
    np.testing.assert_allclose(model.predict(np.eye(3)), [0.0, 1.0, 2.0], atol=0.01)


@pytest.mark.parametrize(("sigma", "fast"), [(0.9, True), (0.05, False)])
def test_the_predictor_rbf_path_agrees_near_and_far_from_the_data(sigma, fast):
    # The factored RBF path serves points near the support vectors of a model whose
    # support is compact in kernel widths; far points, and a narrow kernel, take
    # the direct sum. Both agree with predict.
    X, y = _nonlinear_problem()
    model = GeneralizedGaussianSVR(shape=2.0, sigma=sigma).fit(X, y)
    assert model._fast is fast
    rng = np.random.default_rng(5)
    near = rng.normal(size=(40, 3))
    far = 12.0 * sigma * rng.normal(size=(10, 3)) + 40.0  # rate·|x − m|² in the thousands
    predict_one = model.predictor()
    for rows in (near, far):
        one_by_one = np.array([predict_one(row) for row in rows])
        np.testing.assert_allclose(one_by_one, model.predict(rows), rtol=0, atol=1e-12)
    np.testing.assert_allclose(predict_one(far[0]), model.intercept_, atol=1e-12)


def test_the_predictor_checks_shape_finiteness_and_fitting():
    with pytest.raises(NotFittedError, match="before 'predictor'"):
        GeneralizedGaussianSVR().predictor()
    X, y = _nonlinear_problem(n_samples=30)
    model = GeneralizedGaussianSVR(shape=2.0).fit(X, y)
    predict_one = model.predictor()
    with pytest.raises(ValueError, match=r"^x: must have shape \(3,\)"):
        predict_one(np.zeros(4))
    with pytest.raises(ValueError, match="must be finite"):
        predict_one(np.array([0.0, np.inf, 0.0]))
    with pytest.raises(ValueError, match="must be finite"):
        predict_one(np.array([0.0, np.nan, 0.0]))


def test_the_predictor_keeps_the_fit_it_was_made_from():
    X, y = _nonlinear_problem(n_samples=60)
    model = GeneralizedGaussianSVR(shape=1.3, sigma=0.9).fit(X, y)
    predict_one = model.predictor()
    before = [predict_one(row) for row in X[:5]]
    model.fit(X, -y)
    np.testing.assert_array_equal([predict_one(row) for row in X[:5]], before)
    assert not hasattr(model, "predict_one")


def test_prediction_uses_the_same_kernel_as_a_direct_distance_computation():
    X, y = _nonlinear_problem(n_samples=80)
    model = GeneralizedGaussianSVR(sigma=1.2, shape=0.7, normalize=False).fit(X, y)
    distance = cdist(X[:5], model.support_vectors_)
    expected = np.exp(-((model._rate**0.5 * distance) ** 0.7)) @ model.dual_coef_ + model.intercept_
    np.testing.assert_allclose(model.predict(X[:5]), expected, rtol=1e-12, atol=1e-12)


# --- solvers without a dense Gram matrix ------------------------------------------------


def _dense_reference(X, y, *, sigma, shape, C, epsilon, tol, sample_weight=None):
    """The formulation the estimator replaces: LIBSVM on the full precomputed Gram matrix."""
    X_fit, y_fit, w_fit = _merge_duplicates(
        X, y, np.ones(len(y)) if sample_weight is None else sample_weight
    )
    gram = generalized_gaussian_kernel(X_fit, sigma=sigma, shape=shape)
    svr = SVR(kernel="precomputed", C=C, epsilon=epsilon, tol=tol)
    svr.fit(gram, y_fit, sample_weight=None if np.all(w_fit == 1.0) else w_fit)
    return lambda X_new: svr.predict(
        generalized_gaussian_kernel(X_new, X_fit, sigma=sigma, shape=shape)
    ), svr.support_.size


@pytest.mark.parametrize("shape", [0.6, 1.0, 1.5])
@pytest.mark.parametrize(("C", "max_working_set"), [(100.0, 4096), (100.0, 16), (0.5, 16)])
def test_active_set_solver_equals_the_dense_gram_formulation(shape, C, max_working_set):
    # max_working_set=16 forces many rounds, support vectors outside the working set and
    # the auxiliary variable that keeps sum(alpha) = 0; C=0.5 puts many of them at the bound.
    X, y = _nonlinear_problem(n_samples=300)
    X_test, _ = _nonlinear_problem(n_samples=80, seed=1)
    tol = 1e-6
    reference, n_support = _dense_reference(X, y, sigma=0.9, shape=shape, C=C, epsilon=0.1, tol=tol)
    model = GeneralizedGaussianSVR(
        sigma=0.9, shape=shape, C=C, epsilon=0.1, tol=tol, max_working_set=max_working_set
    ).fit(X, y)
    if max_working_set < 4096:
        assert model.n_support_ > max_working_set  # the over-capacity path ran
    np.testing.assert_allclose(model.predict(X_test), reference(X_test), rtol=0, atol=1e-4)
    assert abs(model.n_support_ - n_support) <= 0.02 * n_support + 1


def test_active_set_solver_with_weights_equals_the_dense_formulation():
    X, y = _nonlinear_problem(n_samples=200)
    weights = np.random.default_rng(3).uniform(0.2, 3.0, size=200)
    reference, _ = _dense_reference(
        X, y, sigma=1.1, shape=1.2, C=2.0, epsilon=0.05, tol=1e-6, sample_weight=weights
    )
    model = GeneralizedGaussianSVR(
        sigma=1.1, shape=1.2, C=2.0, epsilon=0.05, tol=1e-6, max_working_set=32
    ).fit(X, y, sample_weight=weights)
    np.testing.assert_allclose(model.predict(X), reference(X), rtol=0, atol=1e-4)


@pytest.mark.parametrize("shape", [2.0, 1.5])
def test_fit_never_holds_an_n_by_n_matrix(shape):
    # 8 000 rows: a dense float64 Gram matrix would take 512 MB. NumPy's allocations are
    # traced (the active-set solver's column cache reserves cache_size MB); LIBSVM's own
    # (its kernel cache, cache_size MB) are not, and are bounded anyway.
    rng = np.random.default_rng(0)
    X = rng.normal(size=(8_000, 3))
    y = np.sin(X[:, 0]) + 0.5 * X[:, 1] + 0.05 * rng.normal(size=8_000)
    model = GeneralizedGaussianSVR(sigma=1.0, shape=shape, epsilon=0.1, cache_size=50.0)
    tracemalloc.start()
    try:
        model.fit(X, y)
        peak = tracemalloc.get_traced_memory()[1]
    finally:
        tracemalloc.stop()
    assert peak < 100 * 2**20
    assert r2_score(y, model.predict(X)) > 0.95


def test_gaussian_shape_runs_libsvm_rbf_and_other_shapes_the_active_set(monkeypatch):
    import softbend.identification.svr as svr_module

    X, y = _nonlinear_problem(n_samples=60)

    def refuse(*args, **kwargs):
        raise AssertionError("the active-set solver must not run at shape 2")

    monkeypatch.setattr(svr_module, "_solve_active_set", refuse)
    GeneralizedGaussianSVR(shape=2.0).fit(X, y)
    with pytest.raises(AssertionError, match="must not run"):
        GeneralizedGaussianSVR(shape=1.5).fit(X, y)


def test_active_set_solver_that_runs_out_of_rounds_warns(monkeypatch):
    import softbend.identification.svr as svr_module

    monkeypatch.setattr(svr_module, "_MAX_ROUNDS", 1)
    monkeypatch.setattr(svr_module, "_ROUNDS_PER_CHUNK", 0)
    X, y = _nonlinear_problem(n_samples=800)
    with pytest.warns(ConvergenceWarning, match="stopped after 1 rounds"):
        GeneralizedGaussianSVR(sigma=1.0, shape=1.5, max_working_set=16).fit(X, y)


def test_prediction_in_row_blocks_equals_one_block(monkeypatch):
    import softbend.identification.svr as svr_module

    X, y = _nonlinear_problem(n_samples=200)
    model = GeneralizedGaussianSVR(sigma=1.0, shape=1.3).fit(X, y)
    whole = model.predict(X)
    monkeypatch.setattr(svr_module, "_BLOCK_BYTES", 8 * model.n_support_ * 7)  # 7 rows a block
    np.testing.assert_allclose(model.predict(X), whole, rtol=0, atol=1e-13)


@pytest.mark.parametrize(
    ("params", "match"),
    [
        ({"max_working_set": 4}, r"^max_working_set: must be an integer in \[8, inf\)"),
        ({"max_working_set": 100.5}, "^max_working_set: must be"),
        ({"moments_of": "pairs"}, "^moments_of: must be one of"),
    ],
)
def test_bad_solver_and_estimation_settings_raise_naming_the_field(params, match):
    X, y = _nonlinear_problem(n_samples=30)
    with pytest.raises(ValueError, match=match):
        GeneralizedGaussianSVR(**params).fit(X, y)


def test_no_support_vector_is_the_intercept_everywhere(tmp_path):
    """ε wider than the data (every sample in the tube): a constant model, no NaN centre."""
    from softbend.identification.narx import NARXRegressor
    from softbend.identification.persistence import load_narx, save_narx

    X, y = _nonlinear_problem(n_samples=40)
    with warnings.catch_warnings():
        warnings.simplefilter("error", RuntimeWarning)  # the mean of no support vector
        model = GeneralizedGaussianSVR(epsilon=10.0).fit(X, y)
        assert model.n_support_ == 0
        predict_one = model.predictor()
        for row in (X[0], 100.0 * X[1]):
            assert predict_one(row) == pytest.approx(model.intercept_)
        np.testing.assert_allclose(model.predict(X[:3]), model.intercept_)
        narx = NARXRegressor(estimator=GeneralizedGaussianSVR(epsilon=10.0)).fit(X[:, :1], y)
        loaded, _ = load_narx(save_narx(narx, tmp_path / "m.json"))
        simulated = loaded.simulate(X[:, :1], y)
    assert np.isfinite(simulated).all()
