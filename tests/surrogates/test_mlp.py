import pickle

import numpy as np
import pytest
import torch
from sklearn.base import clone
from sklearn.exceptions import NotFittedError
from sklearn.metrics import r2_score
from sklearn.utils.estimator_checks import parametrize_with_checks

from softbend.surrogates.batched import train_mlp_grid
from softbend.surrogates.features import FEATURES
from softbend.surrogates.mlp import NormalizedMLPRegressor


@pytest.fixture(autouse=True, scope="module")
def _one_torch_thread():
    # these networks are tiny: OpenMP threads only add synchronization, and on a loaded
    # 2-core machine their spinning slows training by orders of magnitude
    before = torch.get_num_threads()
    torch.set_num_threads(1)
    yield
    torch.set_num_threads(before)


@parametrize_with_checks(
    [NormalizedMLPRegressor(hidden_sizes=(8, 8), epochs=60, batch_size=16, learning_rate=1e-2)]
)
def test_sklearn_estimator_contract(estimator, check):
    check(estimator)


def _actuator_like(n, seed):
    """A smooth 7-input stand-in for the bending angle over paper B's design space, degrees."""
    rng = np.random.default_rng(seed)
    low = [100, 6, 2, 2, 5, 8, 0.0]
    high = [160, 10, 4, 4, 15, 12, 0.5]
    X = rng.uniform(low, high, size=(n, 7))
    length, r, t, b, phi, lc, p = X.T
    y = 300 * p * (length / 130) * (r / 8) ** 1.5 / (t**0.7 * b**0.4) * np.cos(np.radians(phi))
    y *= 1 - 0.02 * (lc - 10)
    return X, y


def test_learns_a_smooth_seven_input_function():
    X, y = _actuator_like(3000, seed=0)
    model = NormalizedMLPRegressor(
        hidden_sizes=(32, 32), epochs=150, batch_size=128, learning_rate=3e-3, seed=0
    ).fit(X[:2500], y[:2500])
    assert r2_score(y[2500:], model.predict(X[2500:])) > 0.99
    assert model.loss_curve_[-1] < 0.02 * model.loss_curve_[0]
    assert model.device_ == "cpu" and model.n_features_in_ == 7
    assert [c.shape for c in model.coefs_] == [(7, 32), (32, 32), (32, 1)]
    assert [b.shape for b in model.intercepts_] == [(32,), (32,), (1,)]
    assert all(c.dtype == np.float64 for c in model.coefs_ + model.intercepts_)


@pytest.fixture(scope="module")
def fitted():
    X, y = _actuator_like(300, seed=1)
    return NormalizedMLPRegressor(hidden_sizes=(65, 65), epochs=5, batch_size=64).fit(X, y), X


def test_predictor_equals_predict(fitted):
    model, X = fitted
    f = model.predictor()
    batch = model.predict(X)
    single = np.array([f(x) for x in X])
    assert all(isinstance(f(x), float) for x in X[:3])
    np.testing.assert_allclose(single, batch, rtol=1e-12, atol=1e-12)
    assert f(list(X[0])) == f(X[0])


def test_predict_is_the_standardized_forward_pass(fitted):
    model, X = fitted
    z = (X - model.x_mean_) / model.x_scale_
    a = np.tanh(z @ model.coefs_[0] + model.intercepts_[0])
    a = np.tanh(a @ model.coefs_[1] + model.intercepts_[1])
    expected = model.y_mean_ + model.y_scale_ * (a @ model.coefs_[2] + model.intercepts_[2])[:, 0]
    np.testing.assert_array_equal(model.predict(X), expected)
    np.testing.assert_allclose(model.x_mean_, X.mean(axis=0), rtol=1e-14)


def test_fit_is_train_mlp_grid_with_one_config_and_one_split(fitted):
    model, X = fitted
    _, y = _actuator_like(300, seed=1)
    rows = np.arange(300)
    grid = train_mlp_grid(X, y, [(rows, rows[:0])], [(65, 65)], epochs=5, batch_size=64)
    rebuilt = NormalizedMLPRegressor.from_grid(grid, 0, 0)
    for a, b in zip(
        model.coefs_ + model.intercepts_, rebuilt.coefs_ + rebuilt.intercepts_, strict=True
    ):
        np.testing.assert_array_equal(a, b)
    assert rebuilt.get_params() == model.get_params() | {"device": "auto"}


def test_same_seed_same_weights_whatever_torch_global_rng(fitted):
    X, y = _actuator_like(200, seed=2)
    params = dict(hidden_sizes=(10, 6), epochs=4, batch_size=32, seed=5, device="cpu")
    torch.manual_seed(0)
    a = NormalizedMLPRegressor(**params).fit(X, y)
    torch.manual_seed(123)
    torch.rand(10)
    b = NormalizedMLPRegressor(**params).fit(X, y)
    for pa, pb in zip(a.coefs_ + a.intercepts_, b.coefs_ + b.intercepts_, strict=True):
        np.testing.assert_array_equal(pa, pb)
    assert a.loss_curve_ == b.loss_curve_
    c = NormalizedMLPRegressor(**{**params, "seed": 6}).fit(X, y)
    assert not np.array_equal(a.coefs_[0], c.coefs_[0])


def test_pickle_and_from_arrays_round_trip(fitted):
    model, X = fitted
    again = pickle.loads(pickle.dumps(model))
    np.testing.assert_array_equal(again.predict(X), model.predict(X))
    rebuilt = NormalizedMLPRegressor.from_arrays(
        x_mean=model.x_mean_,
        x_scale=model.x_scale_,
        y_mean=model.y_mean_,
        y_scale=model.y_scale_,
        coefs=model.coefs_,
        intercepts=model.intercepts_,
        loss_curve=model.loss_curve_,
        epochs=5,
    )
    assert rebuilt.hidden_sizes == (65, 65) and rebuilt.epochs == 5
    np.testing.assert_array_equal(rebuilt.predict(X), model.predict(X))
    assert rebuilt.predictor()(X[0]) == model.predictor()(X[0])


def test_from_arrays_rejects_inconsistent_shapes(fitted):
    model, _ = fitted
    good = dict(
        x_mean=model.x_mean_,
        x_scale=model.x_scale_,
        y_mean=model.y_mean_,
        y_scale=model.y_scale_,
        coefs=model.coefs_,
        intercepts=model.intercepts_,
    )
    with pytest.raises(ValueError, match="must have shapes"):
        NormalizedMLPRegressor.from_arrays(**{**good, "coefs": model.coefs_[:2]})
    with pytest.raises(ValueError, match="must have shapes"):
        NormalizedMLPRegressor.from_arrays(**{**good, "x_mean": model.x_mean_[:3]})
    with pytest.raises(ValueError, match="must be > 0"):
        NormalizedMLPRegressor.from_arrays(**{**good, "y_scale": 0.0})


@pytest.mark.parametrize(
    "params, match",
    [
        ({"hidden_sizes": (0, 60)}, "hidden_sizes: must be a pair"),
        ({"hidden_sizes": (60, 60, 60)}, "hidden_sizes: must be"),
        ({"batch_size": 0}, r"batch_size: must be an integer in \[1"),
        ({"epochs": 0}, "epochs: must be"),
        ({"learning_rate": 0.0}, "learning_rate: must be"),
        ({"seed": -3}, "seed: must be"),
        ({"device": "gpu"}, "device: must be one of"),
    ],
)
def test_bad_parameters_raise_at_fit(params, match):
    X, y = _actuator_like(20, seed=0)
    model = NormalizedMLPRegressor(**params)  # constructors store, fit validates
    with pytest.raises(ValueError, match=match):
        model.fit(X, y)


def test_bad_data_raises_clearly(fitted):
    model, X = fitted
    X_nan = X[:5].copy()
    X_nan[2, 6] = np.nan
    with pytest.raises(ValueError, match=r"X: must be finite \(no NaN or inf\) in fit"):
        clone(model).fit(X_nan, np.ones(5))
    with pytest.raises(ValueError, match="'pressure_mpa' of row 2"):
        model.predict(X_nan)
    with pytest.raises(ValueError, match=r"y: must be finite"):
        clone(model).fit(X[:5], [1.0, np.inf, 0.0, 0.0, 0.0])
    with pytest.raises(ValueError, match="X has 6 features, but NormalizedMLPRegressor is"):
        model.predict(X[:, :6])
    f = model.predictor()
    with pytest.raises(ValueError, match=r"x: must have shape"):
        f(X[0, :6])
    with pytest.raises(ValueError, match="x: must be finite"):
        f(np.where(np.arange(7) == 3, np.inf, X[0]))
    with pytest.raises(NotFittedError):
        NormalizedMLPRegressor().predictor()
    assert len(FEATURES) == 7


def test_device_auto_resolves_and_cuda_is_checked():
    X, y = _actuator_like(40, seed=0)
    model = NormalizedMLPRegressor(hidden_sizes=(4, 4), epochs=1, device="auto").fit(X, y)
    assert model.device_ == ("cuda" if torch.cuda.is_available() else "cpu")
    if not torch.cuda.is_available():
        with pytest.raises(
            ValueError, match="device: must be 'auto' or 'cpu' without a usable GPU"
        ):
            NormalizedMLPRegressor(epochs=1, device="cuda").fit(X, y)
        pytest.skip("CUDA not available")
    gpu = NormalizedMLPRegressor(hidden_sizes=(4, 4), epochs=3, device="cuda").fit(X, y)
    cpu = NormalizedMLPRegressor(hidden_sizes=(4, 4), epochs=3, device="cpu").fit(X, y)
    assert gpu.device_ == "cuda"
    np.testing.assert_allclose(gpu.predict(X), cpu.predict(X), rtol=1e-4, atol=1e-4)
