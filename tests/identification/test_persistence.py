import json

import numpy as np
import pytest
from sklearn.linear_model import LinearRegression

from softbend.errors import SchemaError
from softbend.identification.narx import NARXRegressor
from softbend.identification.persistence import load_narx, save_narx
from softbend.identification.svr import GeneralizedGaussianSVR

pytestmark = pytest.mark.filterwarnings(
    "ignore::softbend.identification.kernels.ShapeClippedWarning"
)


def _system(seed):
    rng = np.random.default_rng(seed)
    u = np.repeat(rng.uniform(-1, 1, 40), 10)
    y = np.zeros_like(u)
    for t in range(2, u.size):
        y[t] = 0.7 * y[t - 1] - 0.1 * y[t - 2] + np.tanh(u[t]) + 0.2 * u[t - 1] ** 2
    return u[:, None], y


@pytest.mark.parametrize("shape", [None, 1.3])
def test_saved_model_reloads_bit_identically(tmp_path, shape):
    u, y = _system(0)
    model = NARXRegressor(estimator=GeneralizedGaussianSVR(shape=shape, epsilon=0.05))
    model.fit(u, y, groups=np.repeat([0, 1], u.shape[0] // 2))
    path = save_narx(model, tmp_path / "m.json", metadata={"output": "rho"})
    loaded, metadata = load_narx(path)
    u_test, y_test = _system(1)
    np.testing.assert_array_equal(model.simulate(u_test, y_test), loaded.simulate(u_test, y_test))
    np.testing.assert_array_equal(
        model.predict_one_step(u_test, y_test), loaded.predict_one_step(u_test, y_test)
    )
    assert metadata == {"output": "rho"}
    assert loaded.regressor_names_ == model.regressor_names_
    assert loaded.get_params()["output_lags"] == 2


def test_newer_schema_and_foreign_files_are_refused(tmp_path):
    u, y = _system(0)
    model = NARXRegressor().fit(u, y)
    path = save_narx(model, tmp_path / "m.json")
    data = json.loads(path.read_text())
    data["schema_version"] = 99
    path.write_text(json.dumps(data))
    with pytest.raises(SchemaError, match="schema version 99"):
        load_narx(path)
    path.write_text("{}")
    with pytest.raises(SchemaError, match="Not a saved softbend NARX model"):
        load_narx(path)
    path.write_text("not json")
    with pytest.raises(SchemaError, match="not valid JSON"):
        load_narx(path)
    with pytest.raises(FileNotFoundError):
        load_narx(tmp_path / "missing.json")


def test_only_gg_svr_models_can_be_saved(tmp_path):
    u, y = _system(0)
    model = NARXRegressor(estimator=LinearRegression()).fit(u, y)
    with pytest.raises(ValueError, match="GeneralizedGaussianSVR"):
        save_narx(model, tmp_path / "m.json")
