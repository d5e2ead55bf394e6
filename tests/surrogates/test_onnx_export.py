import json

import numpy as np
import onnx
import pytest
import xgboost as xgb
from onnx import TensorProto
from sklearn.exceptions import NotFittedError
from sklearn.linear_model import LinearRegression

from softbend.surrogates.families import MODEL_NAMES as BASE_KINDS
from softbend.surrogates.features import FEATURES
from softbend.surrogates.mlp import NormalizedMLPRegressor
from softbend.surrogates.onnx_export import DEFAULT_OPSET, onnx_predict, save_onnx, to_onnx
from softbend.surrogates.persistence import load_surrogate, save_surrogate
from softbend.surrogates.polynomial import PolynomialRegressor, monomial_powers

from .conftest import HIGH, LOW
from .conftest import smooth_angle as _angle
from .conftest import table1_inputs as _inputs


@pytest.fixture(scope="module")
def fitted():
    X = _inputs(300, 0)
    y = _angle(X)
    return {
        "plr": PolynomialRegressor(degree=4).fit(X, y),
        "mlp": NormalizedMLPRegressor(
            hidden_sizes=(8, 6), epochs=3, batch_size=64, seed=1, device="cpu"
        ).fit(X, y),
        "xgb": xgb.XGBRegressor(
            n_estimators=40, max_depth=6, tree_method="hist", random_state=0, n_jobs=1
        ).fit(X, y),
    }


def _assert_close(actual, expected):
    expected = np.asarray(expected, dtype=np.float64)
    assert actual.dtype == np.float64 and actual.shape == expected.shape
    assert np.all(np.abs(actual - expected) <= 1e-5 * np.maximum(1.0, np.abs(expected)))


@pytest.mark.parametrize("kind", BASE_KINDS)
def test_onnx_predicts_what_the_model_predicts(fitted, kind):
    model = fitted[kind]
    proto = to_onnx(model)
    onnx.checker.check_model(proto, full_check=True)
    X = _inputs(2000, 5)
    _assert_close(onnx_predict(proto, X), model.predict(X))
    _assert_close(onnx_predict(proto, LOW), model.predict(LOW[None, :]))
    _assert_close(onnx_predict(proto, HIGH[None, :]), model.predict(HIGH[None, :]))


@pytest.mark.parametrize("kind", BASE_KINDS)
def test_graph_signature_and_metadata(fitted, kind):
    proto = to_onnx(fitted[kind])
    (source,), (target,) = proto.graph.input, proto.graph.output
    assert source.name == "x" and target.name == "angle_deg"
    in_shape = [d.dim_value or d.dim_param for d in source.type.tensor_type.shape.dim]
    out_shape = [d.dim_value or d.dim_param for d in target.type.tensor_type.shape.dim]
    assert in_shape[1:] == [7] and len(out_shape) == 1
    dtype = TensorProto.FLOAT if kind == "xgb" else TensorProto.DOUBLE
    assert source.type.tensor_type.elem_type == target.type.tensor_type.elem_type == dtype
    props = {p.key: p.value for p in proto.metadata_props}
    assert props["kind"] == kind
    assert json.loads(props["features"]) == list(FEATURES)
    assert json.loads(props["units"])["pressure_mpa"] == "MPa"
    assert json.loads(props["units"])["angle_deg"] == "deg"


@pytest.mark.parametrize("opset", [13, DEFAULT_OPSET, 18, 21])
def test_polynomial_graph_for_old_and_new_reduce_prod(fitted, opset):
    model = fitted["plr"]
    proto = to_onnx(model, opset=opset)
    assert [op.version for op in proto.opset_import if op.domain == ""] == [opset]
    X = _inputs(300, 6)
    _assert_close(onnx_predict(proto, X), model.predict(X))


def _hand_polynomial(coef_by_powers, x_mean=None, x_scale=None, y_mean=0.0, y_scale=1.0):
    model = PolynomialRegressor(degree=2)
    model.powers_ = monomial_powers(7, 2)
    rows = {tuple(p): i for i, p in enumerate(model.powers_.tolist())}
    model.coef_ = np.zeros(len(rows))
    for powers, value in coef_by_powers.items():
        model.coef_[rows[powers]] = value
    model.x_mean_ = np.zeros(7) if x_mean is None else x_mean
    model.x_scale_ = np.ones(7) if x_scale is None else x_scale
    model.y_mean_, model.y_scale_, model.n_features_in_ = y_mean, y_scale, 7
    return model


def test_polynomial_graph_matches_a_closed_form():
    # y = 2 + 3 z0 - z1 z6 + 0.5 z2^2 with z = (x - 1) / 2, rescaled by 4 and shifted by 10.
    model = _hand_polynomial(
        {
            (0,) * 7: 2.0,
            (1, 0, 0, 0, 0, 0, 0): 3.0,
            (0, 1, 0, 0, 0, 0, 1): -1.0,
            (0, 0, 2, 0, 0, 0, 0): 0.5,
        },
        x_mean=np.ones(7),
        x_scale=np.full(7, 2.0),
        y_mean=10.0,
        y_scale=4.0,
    )
    X = np.random.default_rng(7).normal(size=(50, 7)) * 3.0
    z = (X - 1.0) / 2.0
    expected = 10.0 + 4.0 * (2.0 + 3.0 * z[:, 0] - z[:, 1] * z[:, 6] + 0.5 * z[:, 2] ** 2)
    np.testing.assert_allclose(onnx_predict(to_onnx(model), X), expected, rtol=1e-13, atol=1e-12)
    np.testing.assert_allclose(model.predict(X), expected, rtol=1e-13, atol=1e-12)


def test_polynomial_graph_handles_zero_inputs_exactly(fitted):
    # At x = x_mean_ every z is 0: only the constant monomial (0**0 = 1) survives.
    model = fitted["plr"]
    at_mean = model.x_mean_[None, :]
    expected = model.y_mean_ + model.y_scale_ * model.coef_[0]
    assert onnx_predict(to_onnx(model), at_mean)[0] == expected
    # A zero in some columns only: 0**k = 0 for k > 0 and 0**0 = 1 inside each product.
    X = np.repeat(_inputs(1, 8), 7, axis=0)
    X[np.arange(7), np.arange(7)] = model.x_mean_
    _assert_close(onnx_predict(to_onnx(model), X), model.predict(X))
    constant = _hand_polynomial({(0,) * 7: 1.5, (0, 0, 0, 0, 0, 0, 2): 1.0})
    np.testing.assert_array_equal(onnx_predict(to_onnx(constant), np.zeros((3, 7))), 1.5)


def test_mlp_graph_matches_the_numpy_formula(fitted):
    model = fitted["mlp"]
    X = _inputs(100, 9)
    z = (X - model.x_mean_) / model.x_scale_
    (W1, W2, W3), (b1, b2, b3) = model.coefs_, model.intercepts_
    y = model.y_mean_ + model.y_scale_ * (np.tanh(np.tanh(z @ W1 + b1) @ W2 + b2) @ W3 + b3)[:, 0]
    np.testing.assert_allclose(onnx_predict(to_onnx(model), X), y, rtol=1e-12, atol=1e-12)


def test_loaded_model_exports_the_same_graph(fitted, tmp_path):
    model = fitted["plr"]
    loaded = load_surrogate(save_surrogate(model, tmp_path / "m.json")).model
    a, b = to_onnx(model), to_onnx(loaded)
    assert [t.raw_data for t in a.graph.initializer] == [t.raw_data for t in b.graph.initializer]


@pytest.mark.parametrize("kind", BASE_KINDS)
def test_save_onnx_writes_a_loadable_file(fitted, tmp_path, kind):
    path = save_onnx(fitted[kind], tmp_path / "out" / f"{kind}.onnx")
    onnx.checker.check_model(onnx.load(path))
    X = _inputs(20, 10)
    expected = onnx_predict(to_onnx(fitted[kind]), X)
    np.testing.assert_array_equal(onnx_predict(path, X), expected)
    np.testing.assert_array_equal(onnx_predict(str(path), X), expected)
    np.testing.assert_array_equal(onnx_predict(path.read_bytes(), X), expected)
    assert sorted(p.name for p in path.parent.iterdir()) == [f"{kind}.onnx"]


def test_bad_inputs_are_refused(fitted, tmp_path):
    model = fitted["plr"]
    proto = to_onnx(model)
    with pytest.raises(ValueError, match="must have 7 columns"):
        onnx_predict(proto, np.ones((4, 6)))
    with pytest.raises(ValueError, match="must be finite"):
        onnx_predict(proto, np.full((2, 7), np.nan))
    with pytest.raises(ValueError, match=r"onnx\.ModelProto, bytes or a path"):
        onnx_predict(12, np.ones((2, 7)))
    with pytest.raises(FileNotFoundError):
        onnx_predict(tmp_path / "absent.onnx", np.ones((2, 7)))
    for opset in (12, "17", True, 10**6):
        with pytest.raises(ValueError, match="opset: must be None or an integer"):
            to_onnx(model, opset=opset)
    with pytest.raises(ValueError, match=r"opset: must be .*\[13, "):
        to_onnx(fitted["xgb"], opset=99)
    with pytest.raises(ValueError, match="model: must be one of"):
        to_onnx(LinearRegression().fit(np.ones((3, 7)), np.ones(3)))
    with pytest.raises(NotFittedError):
        to_onnx(PolynomialRegressor())
    with pytest.raises(NotFittedError):
        to_onnx(xgb.XGBRegressor())


def test_xgboost_fitted_on_a_dataframe_exports():
    import pandas as pd

    X = _inputs(150, 14)
    frame = pd.DataFrame(X, columns=list(FEATURES))
    model = xgb.XGBRegressor(n_estimators=10, max_depth=4, n_jobs=1).fit(frame, _angle(X))
    _assert_close(onnx_predict(to_onnx(model), X), model.predict(frame))
    assert model.get_booster().feature_names == list(FEATURES)  # the model is left alone
