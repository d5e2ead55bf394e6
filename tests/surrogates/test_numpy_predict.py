"""A saved polynomial, GP correction or composite predicts with NumPy alone, as its estimator."""

from __future__ import annotations

import subprocess
import sys

import numpy as np
import pytest

from softbend.surrogates.corrected import (
    AffineCorrected,
    GPCorrected,
    MeanEnsemble,
    PressureScaled,
    gp_kernel,
)
from softbend.surrogates.gp_core import FixedGP
from softbend.surrogates.persistence import load_surrogate, save_surrogate
from softbend.surrogates.polynomial import PolynomialRegressor
from softbend.surrogates.predict import load_predictor

LOW = np.array([80, 4, 1.5, 1.5, 0, 5, 0.0])
HIGH = np.array([120, 8, 3, 3, 10, 10, 0.06])


def _rows(n: int, seed: int) -> np.ndarray:
    return LOW + (HIGH - LOW) * np.random.default_rng(seed).random((n, 7))


def _angle(X: np.ndarray) -> np.ndarray:
    """A smooth bending-like angle, degrees."""
    return 900 * X[:, 6] * (X[:, 0] / 100) / (X[:, 2] * X[:, 3]) + 0.5 * X[:, 4]


@pytest.fixture(scope="module")
def polynomial() -> PolynomialRegressor:
    X = _rows(400, 0)
    return PolynomialRegressor(degree=3, chunk_rows=64).fit(X, _angle(X))


def _gp(base) -> GPCorrected:
    X = _rows(40, 1)
    theta = base.predict(X)
    Z = np.column_stack([X, theta])
    mean, scale = Z.mean(axis=0), Z.std(axis=0)
    errors = 0.05 * theta + np.sin(X[:, 0])
    kernel = gp_kernel(8)
    kernel.theta = np.log(np.r_[4.0, np.linspace(0.5, 3.0, 8), 0.01])
    return GPCorrected(base, mean, scale, kernel.theta, (Z - mean) / scale, errors)


def test_saved_polynomial_predicts_bit_for_bit_without_its_estimator(polynomial, tmp_path):
    path = save_surrogate(polynomial, tmp_path / "plr.json")
    predictor, saved = load_predictor(path)
    assert saved.kind == "plr"
    assert not isinstance(predictor, PolynomialRegressor)  # the NumPy evaluation
    X = _rows(300, 2)  # more rows than one chunk
    np.testing.assert_array_equal(predictor.predict(X), polynomial.predict(X))


def test_fixed_gp_matches_scikit_learn_to_1e12(polynomial):
    model = _gp(polynomial)
    X = _rows(50, 3)
    z = model._inputs(X)[1]
    mean, std = FixedGP(model.kernel_theta_, model.inputs_, model.targets_).predict(z)
    ref_mean, ref_std = model.gp_.predict(z, return_std=True)  # scikit-learn's
    np.testing.assert_allclose(mean, ref_mean, rtol=1e-12, atol=1e-12 * np.abs(ref_mean).max())
    np.testing.assert_allclose(std, ref_std, rtol=1e-12, atol=1e-12 * ref_std.max())
    np.testing.assert_array_equal(model.kernel_theta_, model.gp_.kernel_.theta)


def test_fixed_gp_interpolates_without_noise():
    """Closed form: with a tiny noise the GP's mean goes through its training targets."""
    X = np.linspace(-2, 2, 9)[:, None]
    y = np.sin(X[:, 0])
    gp = FixedGP(np.log([1.0, 0.7, 1e-9]), X, y)
    mean, std = gp.predict(X)
    np.testing.assert_allclose(mean, y, atol=1e-5)
    assert np.all(std < 1e-3)
    far_mean, far_std = gp.predict(np.array([[50.0]]))
    np.testing.assert_allclose(far_mean, y.mean(), atol=1e-9)  # the prior's mean far away
    np.testing.assert_allclose(far_std, np.std(y) * np.sqrt(1 + 1e-9), rtol=1e-6)


def test_fixed_gp_refuses_a_matrix_that_is_not_positive_definite():
    X = np.zeros((3, 1))  # equal inputs, a variance drowning the jitter: a singular matrix
    with pytest.raises(np.linalg.LinAlgError):
        FixedGP(np.log([1e20, 1.0, 1e-300]), X, np.array([0.0, 1.0, 2.0]))


COMPOSITES = ["affine-corrected", "pressure-scaled", "gp-corrected", "ensemble"]


@pytest.mark.parametrize("kind", COMPOSITES)
def test_saved_composites_predict_as_loaded(polynomial, tmp_path, kind):
    model = {
        "affine-corrected": lambda: AffineCorrected(polynomial, 1.1, 2.0, 1.5),
        "pressure-scaled": lambda: PressureScaled(polynomial, 0.9, 1.5),
        "gp-corrected": lambda: _gp(polynomial),
        "ensemble": lambda: MeanEnsemble([polynomial, AffineCorrected(polynomial, 1, 1, 1)], 1),
    }[kind]()
    path = save_surrogate(model, tmp_path / f"{kind}.json")
    predictor, saved = load_predictor(path)
    assert saved.kind == kind
    loaded = load_surrogate(path).model
    X = _rows(20, 4)
    np.testing.assert_array_equal(predictor.predict(X), loaded.predict(X))
    np.testing.assert_allclose(predictor.predict(X), model.predict(X), rtol=1e-12)
    low, high = predictor.predict_interval(X, 0.9)
    ref_low, ref_high = loaded.predict_interval(X, 0.9)
    np.testing.assert_array_equal(low, ref_low)
    np.testing.assert_array_equal(high, ref_high)
    assert np.all(low < high)


def test_interval_half_width_is_the_gaussian_quantile(polynomial):
    """1.6448536269514722 standard deviations each side for 90 % (Gaussian)."""
    model = AffineCorrected(polynomial, 1.0, 0.0, 2.0)
    X = _rows(3, 5)
    low, high = model.predict_interval(X, 0.9)
    np.testing.assert_allclose((high - low) / 2, 2.0 * 1.6448536269514722, rtol=1e-14)


def test_gp_corrected_mlp_predicts_without_scikit_learn_or_scipy(tmp_path):
    """A GP correction of the shipped MLP is read and asked with NumPy alone."""
    code = f"""
import sys, numpy as np
from softbend.surrogates.persistence import load_surrogate, save_surrogate
from softbend.surrogates.corrected import GPCorrected
from softbend.surrogates.predict import predict_angles
from importlib.resources import files
shipped = str(files("softbend") / "data" / "transfer" / "table1_fem_mlp.json")
if sys.argv[1] == "save":
    base = load_surrogate(shipped).model
    X = np.array([[100, 6, 2, 2, 5, 8, p] for p in np.linspace(0.01, 0.06, 12)])
    theta = base.predict(X)
    Z = np.column_stack([X, theta])
    m, s = Z.mean(axis=0), Z.std(axis=0)
    s[s == 0] = 1.0
    model = GPCorrected(base, m, s, np.zeros(10), (Z - m) / s, 0.1 * theta)
    save_surrogate(model, {str(tmp_path / "gp.json")!r})
else:
    p = predict_angles({str(tmp_path / "gp.json")!r}, "100,6,2,2,5,8", [0.03])
    assert np.isfinite(p.angle_deg).all() and p.interval_deg is not None
    print(sorted({{m.split(".")[0] for m in sys.modules}} & {{"sklearn", "scipy", "torch"}}))
"""
    subprocess.run([sys.executable, "-c", code, "save"], check=True)
    done = subprocess.run(
        [sys.executable, "-c", code, "predict"], check=True, capture_output=True, text=True
    )
    assert done.stdout.strip() == "[]"


@pytest.fixture(scope="module")
def xgb():
    xgboost = pytest.importorskip("xgboost")
    X = _rows(500, 6)
    return xgboost.XGBRegressor(n_estimators=40, max_depth=5, random_state=0, n_jobs=1).fit(
        X, _angle(X)
    )


def test_saved_xgboost_predicts_bit_for_bit_without_xgboost(xgb, tmp_path):
    from softbend.surrogates.xgboost_core import BoosterTrees

    path = save_surrogate(xgb, tmp_path / "xgb.json")
    predictor, saved = load_predictor(path)
    assert saved.kind == "xgb" and isinstance(predictor, BoosterTrees)
    X = _rows(2000, 7)
    np.testing.assert_array_equal(predictor.predict(X), xgb.predict(X).astype(np.float64))
    X[::7, 2] = np.nan  # a missing input goes each split's default way, as in XGBoost
    np.testing.assert_array_equal(predictor.predict(X), xgb.predict(X).astype(np.float64))


def test_xgboost_other_than_plain_regression_is_left_to_xgboost(xgb):
    import json

    from softbend.surrogates.xgboost_core import booster_trees

    text = bytes(xgb.get_booster().save_raw("json")).decode()
    assert booster_trees(text, {"missing": None}, 7) is not None
    assert booster_trees(text, {"missing": 0.0}, 7) is None  # 0 would mean "missing"
    assert booster_trees(text, {}, 6) is None  # a split on an input the model lacks
    document = json.loads(text)
    document["learner"]["objective"]["name"] = "reg:logistic"  # not an identity link
    assert booster_trees(json.dumps(document), {}, 7) is None
    document = json.loads(text)
    document["learner"]["gradient_booster"]["model"]["trees"][0]["left_children"][0] = 0
    assert booster_trees(json.dumps(document), {}, 7) is None  # a cycle
    assert booster_trees("not json", {}, 7) is None
