"""NARX maps fitted by free-run error, with input filters: recovery, start, reload, bad input."""

from __future__ import annotations

import subprocess
import sys
import textwrap

import numpy as np
import pytest

import softbend._torch  # noqa: F401  (PyTorch before anything that could load NGSolve)
from softbend.errors import InputError, SchemaError
from softbend.identification import simfit, simmaps
from softbend.identification.multi import MultiNARX, load_multi_narx, save_multi_narx
from softbend.identification.narx import _segments
from softbend.identification.selection import default_candidates

TAU = 3.0  # samples


def _lagged_plant(n_exp: int = 4, n: int = 300, seed: int = 0) -> tuple:
    """Held random pressures through a first-order lag (τ = 3 samples), a quadratic map, and a
    first-order output: a second-order plant that one output lag alone cannot follow."""
    rng = np.random.default_rng(seed)
    a = np.exp(-1.0 / TAU)
    U, Y, groups = [], [], []
    for e in range(n_exp):
        u = np.repeat(rng.uniform(-1.0, 1.0, n // 10), 10)[:, None]
        uf = np.empty_like(u)
        uf[0] = u[0]
        for t in range(1, n):
            uf[t] = a * uf[t - 1] + (1 - a) * u[t]
        drive = uf + 0.5 * uf**2
        y = np.empty_like(u)
        y[0] = drive[0]
        for t in range(1, n):
            y[t] = 0.5 * y[t - 1] + 0.5 * drive[t]
        y += rng.normal(0.0, 1e-3, y.shape)
        U.append(u)
        Y.append(y)
        groups += [e] * n
    return np.vstack(U), np.vstack(Y), np.array(groups)


def _free_run_rmse(model: MultiNARX, U, Y, groups) -> float:
    simulated = model.simulate(U, Y, groups)
    keep = np.ones(len(Y), bool)
    keep[np.flatnonzero(np.r_[True, groups[1:] != groups[:-1]])] = False
    return float(np.sqrt(np.mean((simulated[keep] - Y[keep]) ** 2)))


@pytest.fixture(scope="module")
def lagged():
    return _lagged_plant()


@pytest.fixture(scope="module")
def fitted(lagged):
    U, Y, groups = lagged
    params = {"filter": True, "steps": 150, "epochs": 1000, "window": 30, "batch": 32}
    params |= {"lr": 0.003, "hidden": 4, "pretrain": 50}
    return MultiNARX("nn-sim", output_lags=1, input_lags=1, params=params).fit(U, Y, groups)


def test_the_simulation_fit_recovers_the_input_lag_and_beats_the_one_step_fit(lagged):
    U, Y, groups = lagged
    params = {"filter": True, "epochs": 1000, "window": 30, "batch": 32, "steps": 60}
    refined = MultiNARX("poly2-sim", output_lags=1, input_lags=1, params=params)
    refined.fit(U, Y, groups)
    plain = MultiNARX("poly2", output_lags=1, input_lags=1).fit(U, Y, groups)
    assert refined.input_tau_[0] == pytest.approx(TAU, abs=0.3)
    # the noise is 1e-3: the filtered model runs free near it, the unfiltered one cannot
    assert _free_run_rmse(refined, U, Y, groups) < 2e-3 < 0.1 * _free_run_rmse(plain, U, Y, groups)
    # reported in seconds from the sampling interval (here 0.1 s)
    assert refined.input_time_constants_s(0.1)[0] == pytest.approx(0.1 * refined.input_tau_[0])
    assert "input tau = " in refined.describe()


def _second_order(n_exp: int = 4, n: int = 400, noise: float = 0.3) -> tuple:
    """A linear second-order plant measured with white output noise (an output-error model)."""
    rng = np.random.default_rng(1)
    U, Y, groups = [], [], []
    for e in range(n_exp):
        u = np.repeat(rng.uniform(-1.0, 1.0, n // 8), 8)
        x = np.zeros(n)
        for t in range(2, n):
            x[t] = 1.5 * x[t - 1] - 0.7 * x[t - 2] + 0.2 * u[t - 1]
        U.append(u[:, None])
        Y.append((x + rng.normal(0.0, noise * x.std(), n))[:, None])
        groups += [e] * n
    return np.vstack(U), np.vstack(Y), np.array(groups)


def test_the_simulation_fit_removes_the_one_step_fits_noise_bias():
    """Least squares one step ahead is biased by output noise; the free-run fit is not."""
    U, Y, groups = _second_order()
    clean = _second_order(noise=0.0)[1]
    params = {"epochs": 1000, "window": 60, "batch": 32, "steps": 300, "lr": 0.01}
    sim = MultiNARX("arx-sim", output_lags=2, input_lags=2, params=params).fit(U, Y, groups)
    arx = MultiNARX("arx", output_lags=2, input_lags=2).fit(U, Y, groups)

    def error(model: MultiNARX) -> float:  # free run against the noise-free output
        return float(np.sqrt(np.mean((model.simulate(U, Y, groups) - clean) ** 2)))

    assert error(sim) < 0.5 * error(arx)


@pytest.mark.parametrize(("family", "plain"), [("poly2-sim", "poly2"), ("arx-sim", "arx")])
def test_no_update_leaves_the_one_step_fit(lagged, family, plain):
    U, Y, groups = lagged
    sim = MultiNARX(family, output_lags=2, input_lags=2, params={"steps": 0}).fit(U, Y, groups)
    one_step = MultiNARX(plain, output_lags=2, input_lags=2).fit(U, Y, groups)
    assert np.array_equal(sim.simulate(U, Y, groups), one_step.simulate(U, Y, groups))
    assert sim.input_tau_ is None


def test_a_neural_map_without_updates_or_pretraining_is_the_linear_arx(lagged):
    U, Y, groups = lagged
    params = {"steps": 0, "pretrain": 0, "hidden": 3}
    nn = MultiNARX("nn-sim", output_lags=1, input_lags=2, params=params).fit(U, Y, groups)
    arx = MultiNARX("arx", output_lags=1, input_lags=2).fit(U, Y, groups)
    np.testing.assert_allclose(nn.simulate(U, Y, groups), arx.simulate(U, Y, groups), atol=1e-12)


def test_the_filter_is_a_unit_gain_first_order_lag_started_at_rest():
    U = np.r_[np.zeros(3), np.ones(40), 2.0 * np.ones(5)][:, None]
    out = simmaps.filter_inputs(U, [0, 43], [43, 5], np.array([2.0]))
    a = np.exp(-0.5)
    np.testing.assert_allclose(out[3:43, 0], 1 - a ** np.arange(1, 41), atol=1e-14)
    np.testing.assert_array_equal(out[43:], U[43:])  # the second experiment starts at rest
    np.testing.assert_array_equal(simmaps.filter_inputs(U, [0], [48], np.array([0.0])), U)


def test_a_saved_neural_model_reloads_bit_for_bit(fitted, lagged, tmp_path):
    U, Y, groups = lagged
    path = save_multi_narx(fitted, tmp_path / "model.json", {"inputs": ["p_kpa"]})
    model, metadata = load_multi_narx(path)
    assert metadata == {"inputs": ["p_kpa"]}
    assert model.family == "nn-sim" and np.array_equal(model.input_tau_, fitted.input_tau_)
    assert np.array_equal(model.simulate(U, Y, groups), fitted.simulate(U, Y, groups))
    assert np.array_equal(
        model.predict_one_step(U, Y, groups), fitted.predict_one_step(U, Y, groups), equal_nan=True
    )


def test_a_saved_neural_model_predicts_without_pytorch(fitted, lagged, tmp_path):
    U, Y, _groups = lagged
    path = save_multi_narx(fitted, tmp_path / "model.json")
    np.save(tmp_path / "u.npy", U[:300])
    np.save(tmp_path / "y.npy", Y[:300])
    code = textwrap.dedent(
        f"""
        import sys

        class NoTorch:  # any import of PyTorch fails
            def find_spec(self, name, path=None, target=None):
                if name.split(".")[0] == "torch":
                    raise ImportError("PyTorch is blocked here")

        sys.meta_path.insert(0, NoTorch())
        import numpy as np
        from softbend.identification.multi import load_multi_narx
        model, _ = load_multi_narx({str(path)!r})
        U, Y = np.load({str(tmp_path / "u.npy")!r}), np.load({str(tmp_path / "y.npy")!r})
        np.save({str(tmp_path / "out.npy")!r}, model.simulate(U, Y))
        assert "torch" not in sys.modules
        """
    )
    subprocess.run([sys.executable, "-c", code], check=True, timeout=120)
    expected = fitted.simulate(U[:300], Y[:300])
    assert np.array_equal(np.load(tmp_path / "out.npy"), expected)


def test_numpy_runs_free_what_the_training_ran(fitted, lagged):
    """The training's PyTorch free run of a whole experiment equals NumPy's simulate."""
    import torch

    U, Y, groups = lagged
    model = fitted
    Us, Ys = (U - model.u_mean_) / model.u_std_, (Y - model.y_mean_) / model.y_std_
    seg = _segments(groups, len(U), model.max_lag)
    settings = simmaps.check_sim_params({**model.params, "window": 299}, "nn-sim")
    bounds = ((model.y_low_ - model.y_mean_) / model.y_std_,
              (model.y_high_ - model.y_mean_) / model.y_std_)  # fmt: skip
    nmap = model.estimators_[0]
    start = simfit.Start(1, nmap.linear[:, None], np.array([nmap.intercept]))
    trainer = simfit._Trainer(
        torch, "nn-sim", settings, Us, Ys, seg.starts, seg.lengths, (1, 1), bounds, start,
        model.input_tau_,
    )  # fmt: skip
    with torch.no_grad():
        trainer.hidden[0].copy_(torch.tensor(nmap.weights.T))
        trainer.hidden[1].copy_(torch.tensor(nmap.biases))
        trainer.hidden[2].copy_(torch.tensor(nmap.out[None, :]))
        trainer.theta.copy_(torch.tensor(np.log(np.expm1(model.input_tau_))))
        loss = float(trainer.run(np.array([0, 300])))
    simulated = (model.simulate(U, Y, groups) - model.y_mean_) / model.y_std_
    rows = np.r_[1:300, 301:600]
    # the training reads the filter 12 τ back (a remainder of e**-12): not bit for bit
    assert loss == pytest.approx(float(np.mean((simulated[rows] - Ys[rows]) ** 2)), rel=1e-5)


def test_the_default_candidates_include_simulation_fits_with_and_without_filters():
    names = {c.name: c for c in default_candidates(3, n_kernel=0)}
    assert names["poly2-sim-2-3-filter"].params == {"filter": True, "seed": 3}
    assert names["nn-sim-2-3"].params == {"seed": 3}
    assert names["poly2-sim-2-3-filter"].build(10).family == "poly2-sim"


@pytest.mark.parametrize(
    ("family", "params", "key"),
    [
        ("poly2-sim", {"tau_init": -1.0}, "tau_init"),
        ("nn-sim", {"hidden": 0}, "hidden"),
        ("nn-sim", {"filter": "yes"}, "filter"),
        ("arx-sim", {"epoch": 3}, "params"),
        ("poly3-sim", {}, "family"),
    ],
)
def test_bad_settings_are_refused_with_one_clear_error(family, params, key):
    with pytest.raises(InputError) as caught:
        MultiNARX(family, params=params)
    assert caught.value.key == key


def test_a_broken_neural_map_is_refused_on_load(fitted):
    data = fitted.to_dict()
    data["maps"][0]["weights"] = data["maps"][0]["weights"][:-1]
    with pytest.raises(SchemaError, match=r"maps\.weights"):
        MultiNARX.from_dict(data)
    data = fitted.to_dict()
    data["input_tau"] = [-1.0]
    with pytest.raises(SchemaError, match="input_tau"):
        MultiNARX.from_dict(data)
