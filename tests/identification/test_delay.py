"""Input delays of the simulation-error families: the shift, its search, reload, bad input."""

from __future__ import annotations

import numpy as np
import pytest

from softbend.errors import InputError, SchemaError
from softbend.identification import simmaps
from softbend.identification.multi import MultiNARX, load_multi_narx, save_multi_narx

DEAD = (2, 0)  # samples of dead time of each input of the plant


def _dead_time_plant(n_exp: int = 4, n: int = 300, seed: int = 0):
    """Two held random inputs, the first seen 2 samples late, the second at once, into a
    first-order output with a quadratic drive."""
    rng = np.random.default_rng(seed)
    U, Y, groups = [], [], []
    for e in range(n_exp):
        u = np.repeat(rng.uniform(-1.0, 1.0, (n // 10, 2)), 10, axis=0)
        late = simmaps.delay_inputs(u, [0], [n], DEAD)
        y = np.zeros((n, 1))
        for t in range(1, n):
            drive = late[t, 0] + 0.3 * late[t, 0] ** 2 + 0.5 * late[t, 1]
            y[t] = 0.6 * y[t - 1] + 0.4 * drive
        U.append(u)
        Y.append(y + rng.normal(0.0, 1e-3, y.shape))
        groups += [e] * n
    return np.vstack(U), np.vstack(Y), np.array(groups)


def test_a_delay_shifts_each_input_and_holds_the_first_sample_in_each_experiment():
    U = np.column_stack([np.arange(10.0), 100 + np.arange(10.0)])
    out = simmaps.delay_inputs(U, [0, 6], [6, 4], [2, 0])
    np.testing.assert_array_equal(out[:, 0], [0, 0, 0, 1, 2, 3, 6, 6, 6, 7])
    np.testing.assert_array_equal(out[:, 1], U[:, 1])
    # a delay longer than an experiment holds its first sample throughout
    np.testing.assert_array_equal(simmaps.delay_inputs(U, [0], [10], [20, 0])[:, 0], 0.0)


def test_delay_and_filter_commute_from_rest():
    rng = np.random.default_rng(1)
    U = rng.normal(size=(80, 2))
    starts, lengths, tau = [0, 50], [50, 30], np.array([2.0, 0.5])
    a = simmaps.filter_inputs(
        simmaps.delay_inputs(U, starts, lengths, [3, 1]), starts, lengths, tau
    )
    b = simmaps.delay_inputs(
        simmaps.filter_inputs(U, starts, lengths, tau), starts, lengths, [3, 1]
    )
    np.testing.assert_allclose(a, b, atol=1e-14)


@pytest.fixture(scope="module")
def plant():
    return _dead_time_plant()


@pytest.fixture(scope="module")
def searched(plant):
    U, Y, groups = plant
    params = {"delay": None, "steps": 0}
    return MultiNARX("poly2-sim", output_lags=1, input_lags=1, params=params).fit(U, Y, groups)


def test_the_search_finds_each_inputs_dead_time(searched, plant):
    U, Y, groups = plant
    assert searched.input_delay_.tolist() == list(DEAD)
    assert "input delay = 2, 0 samples" in searched.describe()
    blind = MultiNARX("poly2-sim", output_lags=1, input_lags=1, params={"steps": 0})
    blind.fit(U, Y, groups)
    assert blind.input_delay_ is None

    def error(model):
        return np.sqrt(np.mean((model.simulate(U, Y, groups) - Y) ** 2))

    assert error(searched) < 0.2 * error(blind)


def test_a_given_delay_is_used_for_every_input(plant):
    U, Y, groups = plant
    params = {"delay": 1, "steps": 0}
    model = MultiNARX("arx-sim", output_lags=1, input_lags=1, params=params).fit(U, Y, groups)
    assert model.input_delay_.tolist() == [1, 1]


def test_a_saved_delayed_model_reloads_bit_for_bit(searched, plant, tmp_path):
    U, Y, groups = plant
    model, _ = load_multi_narx(save_multi_narx(searched, tmp_path / "model.json"))
    assert model.input_delay_.tolist() == list(DEAD)
    assert np.array_equal(model.simulate(U, Y, groups), searched.simulate(U, Y, groups))
    data = searched.to_dict()
    data["input_delay"] = [2.5, 0]
    with pytest.raises(SchemaError, match="input_delay"):
        MultiNARX.from_dict(data)
    del data["input_delay"]  # a model saved before delays existed loads without one
    assert MultiNARX.from_dict(data).input_delay_ is None


@pytest.mark.parametrize("delay", [-1, 51, 1.5, True, "2"])
def test_a_bad_delay_is_refused_naming_it(delay):
    with pytest.raises(InputError) as caught:
        MultiNARX("poly2-sim", params={"delay": delay})
    assert caught.value.key == "delay"
    assert "integer in [0, 50]" in str(caught.value)


def test_the_candidates_with_delays_search_them_after_the_model_without():
    from softbend.identification.selection import default_candidates

    assert all("delay" not in c.params for c in default_candidates(3, n_kernel=0, delays=False))
    names = [c.name for c in default_candidates(3, n_kernel=0)]  # searched by default
    plain, delayed = names.index("poly2-sim-2-3-filter"), names.index("poly2-sim-2-3-filter-delay")
    assert plain < delayed  # a tie (no delay found) keeps the model without
    params = default_candidates(3, n_kernel=0, delays=True)[delayed].params
    assert params == {"filter": True, "delay": None, "seed": 3}
