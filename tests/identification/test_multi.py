"""MultiNARX: every output's regressor holds every output's lags; a joint free run; exact reload."""

from __future__ import annotations

import numpy as np
import pytest

from softbend.errors import SchemaError
from softbend.identification.multi import MultiNARX, load_multi_narx, save_multi_narx


def _coupled(U: np.ndarray, quadratic: bool = False) -> np.ndarray:
    """y1 follows u; y2 follows y1's past only: a single-output model of y2 cannot see it."""
    Y = np.zeros((len(U), 2))
    for t in range(1, len(U)):
        drive = U[t, 0] ** 2 if quadratic else U[t, 0]
        Y[t, 0] = 0.7 * Y[t - 1, 0] + 0.5 * drive
        Y[t, 1] = 0.6 * Y[t - 1, 1] + 0.4 * Y[t - 1, 0]
    return Y


@pytest.fixture(scope="module")
def data():
    U = np.random.default_rng(0).normal(size=(900, 1))
    return U, np.repeat(["a", "b", "c"], 300)


def test_arx_recovers_a_linear_coupled_plant_exactly(data):
    U, groups = data
    Y = _coupled(U)
    model = MultiNARX("arx", output_lags=1, input_lags=1).fit(U, Y, groups)
    simulated = model.simulate(U, Y, groups)
    np.testing.assert_allclose(simulated, Y, atol=1e-6)
    one_step = model.predict_one_step(U, Y, groups)
    assert np.isnan(one_step[0]).all() and np.isnan(one_step[300]).all()  # initial conditions
    np.testing.assert_allclose(one_step[1:300], Y[1:300], atol=1e-6)


def test_poly2_recovers_a_quadratic_plant_where_arx_cannot(data):
    U, groups = data
    Y = _coupled(U, quadratic=True)
    poly = MultiNARX("poly2", output_lags=1, input_lags=1).fit(U, Y, groups)
    arx = MultiNARX("arx", output_lags=1, input_lags=1).fit(U, Y, groups)
    poly_error = np.abs(poly.simulate(U, Y, groups) - Y).max()
    arx_error = np.abs(arx.simulate(U, Y, groups) - Y).max()
    assert poly_error < 1e-5 < 0.1 < arx_error


def test_the_kernel_map_runs_free_close_to_the_plant(data):
    U, groups = data
    Y = _coupled(U, quadratic=True)
    model = MultiNARX("gg-svr", output_lags=1, input_lags=1, params={"C": 100.0, "epsilon": 0.01})
    model.fit(U[:600], Y[:600], groups[:600])
    simulated = model.simulate(U[600:], Y[600:])
    assert np.sqrt(np.mean((simulated - Y[600:]) ** 2)) < 0.1 * np.ptp(Y)
    assert model.n_train_rows_ == 598


def test_a_diverging_model_saturates_at_the_widened_training_range():
    U = np.ones((200, 1))
    Y = np.cumsum(np.ones((200, 2)), axis=0)  # grows without bound
    model = MultiNARX("arx", output_lags=1, input_lags=1).fit(U[:50], Y[:50])
    simulated = model.simulate(U, Y)
    assert np.isfinite(simulated).all()
    assert simulated.max() <= model.y_high_.max() + 1e-9


@pytest.mark.parametrize("family", ["arx", "poly2", "gg-svr"])
def test_a_saved_model_reloads_and_simulates_bit_for_bit(data, tmp_path, family):
    U, groups = data
    Y = _coupled(U, quadratic=True)
    model = MultiNARX(
        family, output_lags=2, input_lags=2, params={"C": 10.0} if family == "gg-svr" else None
    )
    model.fit(U[:600], Y[:600], groups[:600])
    path = save_multi_narx(model, tmp_path / "m.json", metadata={"outputs": ["a", "b"]})
    again, metadata = load_multi_narx(path)
    assert metadata == {"outputs": ["a", "b"]}
    assert again.simulate(U[600:], Y[600:]).tobytes() == model.simulate(U[600:], Y[600:]).tobytes()


def test_bad_input_and_broken_files(data, tmp_path):
    U, _ = data
    with pytest.raises(ValueError, match=r"^family: must be one of 'arx', 'poly2', 'gg-svr'"):
        MultiNARX("lstm")
    with pytest.raises(ValueError, match=r"^output_lags: must be an integer"):
        MultiNARX(output_lags=0)
    with pytest.raises(ValueError, match=r"^Y: must be finite"):
        MultiNARX().fit(U, np.full((900, 2), np.nan))
    with pytest.raises(ValueError, match=r"at least max_lag \+ 1 = 3 samples"):
        MultiNARX().fit(U[:2], np.zeros((2, 1)))
    with pytest.raises(ValueError, match="not fitted"):
        MultiNARX().simulate(U, np.zeros((900, 1)))
    path = tmp_path / "m.json"
    path.write_text('{"format": "something else"}')
    with pytest.raises(SchemaError, match="not a saved softbend multi-output NARX") as info:
        load_multi_narx(path)
    assert str(info.value).startswith(f"{path}: format: must be")
