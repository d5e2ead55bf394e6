"""The Surrogate protocol, the models as BendingModels, and the package's exports."""

from __future__ import annotations

import importlib
import subprocess
import sys

import numpy as np
import pytest

import softbend.surrogates as surrogates
from softbend.analytical import AnalyticalModel
from softbend.models import BendingModel
from softbend.surrogates import FastSurrogate, Surrogate
from softbend.surrogates.corrected import (
    AffineCorrected,
    GPCorrected,
    MeanEnsemble,
    PressureScaled,
    gp_kernel,
)
from softbend.surrogates.model import SurrogateModel
from softbend.surrogates.persistence import load_surrogate, save_surrogate
from softbend.surrogates.polynomial import PolynomialRegressor

from .conftest import smooth_angle, table1_inputs

pytestmark = pytest.mark.filterwarnings("ignore::sklearn.exceptions.ConvergenceWarning")


@pytest.fixture(scope="module")
def data():
    X = table1_inputs(200, 0)
    return X, smooth_angle(X)


@pytest.fixture(scope="module")
def plr(data):
    return PolynomialRegressor(degree=2).fit(*data)


def _check(model, X, *, fast):
    assert isinstance(model, Surrogate)
    assert isinstance(model, FastSurrogate) is fast
    assert model.n_features_in_ == 7
    angles = np.asarray(model.predict(X))
    assert angles.shape == (len(X),) and np.isfinite(angles).all()
    if fast:
        assert model.predictor()(X[0]) == pytest.approx(angles[0], rel=1e-9)


def test_the_polynomial_and_the_mlp_are_fast_surrogates_as_fitted_and_as_loaded(
    data, plr, tmp_path, one_torch_thread
):
    from softbend.surrogates.mlp import NormalizedMLPRegressor

    X, y = data
    mlp = NormalizedMLPRegressor(hidden_sizes=(6, 5), epochs=3, seed=0, device="cpu").fit(X, y)
    for model in (plr, mlp):
        _check(model, X, fast=True)
        path = save_surrogate(model, tmp_path / f"{type(model).__name__}.json")
        _check(load_surrogate(path).model, X, fast=True)


def test_xgboost_as_persisted_and_loaded_is_a_surrogate_without_a_fast_path(data, tmp_path):
    xgb = pytest.importorskip("xgboost")
    X, y = data
    model = xgb.XGBRegressor(n_estimators=5, max_depth=3, n_jobs=1).fit(X, y)
    loaded = load_surrogate(save_surrogate(model, tmp_path / "xgb.json")).model
    _check(loaded, X, fast=False)


def test_the_corrected_models_are_surrogates_without_a_fast_path(data, plr, tmp_path):
    X, y = data
    theta = plr.predict(X[:30])
    Z = np.column_stack([X[:30], theta])
    mean, scale = Z.mean(axis=0), Z.std(axis=0)
    other = PolynomialRegressor(degree=1).fit(X, y)
    models = [
        AffineCorrected(plr, 1.1, -2.0, 0.5),
        PressureScaled(plr, 1.2, 0.5),
        MeanEnsemble([plr, other], 0.25),
        GPCorrected(plr, mean, scale, gp_kernel(8).theta, (Z - mean) / scale, y[:30] - theta),
    ]
    for model in models:
        _check(model, X, fast=False)
        path = save_surrogate(model, tmp_path / f"{type(model).__name__}.json")
        _check(load_surrogate(path).model, X, fast=False)


def test_an_unfitted_estimator_is_no_surrogate():
    assert not isinstance(PolynomialRegressor(), Surrogate)
    assert not isinstance(object(), Surrogate)


def test_the_surrogate_and_the_analytical_model_are_bending_models(plr):
    assert isinstance(SurrogateModel(plr), BendingModel)
    assert isinstance(surrogates.SurrogateModel(plr), BendingModel)
    assert isinstance(AnalyticalModel(), BendingModel)


def test_every_exported_name_is_the_object_of_its_module():
    assert surrogates.__all__ == sorted(surrogates.__all__)
    assert set(surrogates.__all__) <= set(dir(surrogates))
    for name in surrogates.__all__:
        if name in ("NormalizedMLPRegressor", "train_mlp_grid"):
            pytest.importorskip("torch")
        if name in ("to_onnx", "save_onnx", "onnx_predict"):
            pytest.importorskip("onnx")
        value = getattr(surrogates, name)
        module = importlib.import_module(f"softbend.surrogates.{surrogates._EXPORTS[name]}")
        assert value is getattr(module, name), name
        assert name in getattr(module, "__all__", [name]), f"{name} not in its module's __all__"
    with pytest.raises(AttributeError, match="no attribute 'nope'"):
        _ = surrogates.nope


def test_importing_the_package_and_its_registry_stays_light():
    code = (
        "import sys, softbend.surrogates as s; s.FAMILIES; s.Surrogate; s.MODEL_NAMES; "
        "import softbend.surrogates.search; "
        "print(sorted(m for m in ('torch', 'xgboost', 'onnx') if m in sys.modules))"
    )
    out = subprocess.run([sys.executable, "-c", code], capture_output=True, text=True, check=True)
    assert out.stdout.strip() == "[]"
