import logging

import numpy as np
import pytest
import torch

from softbend.surrogates import batched, batched_epochs
from softbend.surrogates.batched import train_mlp_grid
from softbend.surrogates.batched_shuffle import MAX_ROWS, DeviceShuffle, hash32, model_keys

pytestmark = pytest.mark.usefixtures("one_torch_thread")


def _lowbias32(x: int) -> int:
    """The published lowbias32 finalizer in plain Python integers (the reference)."""
    x ^= x >> 16
    x = (x * 0x7FEB352D) & 0xFFFFFFFF
    x ^= x >> 15
    x = (x * 0x846CA68B) & 0xFFFFFFFF
    return x ^ (x >> 16)


def test_hash32_is_lowbias32_without_overflow():
    rng = np.random.default_rng(0)
    values = np.concatenate([[0, 1, 2**31, 2**32 - 1], rng.integers(0, 2**32, 500)])
    ours = hash32(torch.tensor(values, dtype=torch.int64)).tolist()
    assert ours == [_lowbias32(int(v)) for v in values]
    assert _lowbias32(1) != 1 and all(0 <= h < 2**32 for h in ours)


def _tables():
    rng = np.random.default_rng(1)
    return [rng.choice(500, size=n, replace=False) for n in (300, 120, 299)]


def test_device_shuffle_permutes_each_models_own_rows_and_pads_last():
    train_idx = _tables()
    keys = model_keys(7, [(5, 5, 0), (5, 5, 1), (6, 5, 0)])
    shuffle = DeviceShuffle(train_idx, keys, n_cols=320, device="cpu")
    orders = []
    for epoch in range(3):
        rows = shuffle.rows(torch.tensor([epoch])).numpy()
        for m, idx in enumerate(train_idx):
            assert sorted(rows[m, : idx.size]) == sorted(idx)  # a permutation of its rows
            assert np.all(rows[m, idx.size :] == 0)  # padding after them, pointing at row 0
        orders.append(rows)
        # not the identity: a shuffle (the chance of a fixed order is nil)
        assert not np.array_equal(rows[0, :300], train_idx[0])
    assert not np.array_equal(orders[0], orders[1])  # every epoch its own order
    again = DeviceShuffle(train_idx, keys, n_cols=320, device="cpu").rows(torch.tensor([1]))
    np.testing.assert_array_equal(again.numpy(), orders[1])  # deterministic
    # a model's orders do not depend on the models beside it
    alone = DeviceShuffle(train_idx[2:], keys[2:], n_cols=299, device="cpu").rows(2).numpy()
    np.testing.assert_array_equal(alone[0], orders[2][2, :299])


def test_device_shuffle_positions_are_close_to_uniform():
    # row j's position over many epochs: each of n positions about equally often
    n, epochs = 8, 4000
    shuffle = DeviceShuffle([np.arange(n)], model_keys(0, [(1, 1, 0)]), n_cols=n, device="cpu")
    counts = np.zeros((n, n))
    for epoch in range(epochs):
        counts[np.arange(n), shuffle.rows(epoch).numpy()[0]] += 1
    expected = epochs / n
    chi2 = float(((counts - expected) ** 2 / expected).sum())
    assert chi2 < 100.0  # 49 degrees of freedom: the 1e-4 quantile is about 95


def test_model_keys_differ_per_model_and_seed():
    keys = model_keys(0, [(55, 55, 0), (55, 55, 1), (55, 56, 0)])
    assert len(set(keys.tolist())) == 3
    assert not np.array_equal(keys, model_keys(1, [(55, 55, 0), (55, 55, 1), (55, 56, 0)]))
    assert np.all((keys >= 0) & (keys < 2**32))


def test_too_many_rows_for_the_device_shuffle_is_one_clear_error():
    with pytest.raises(ValueError, match=r"at most 4194304 training rows.*shuffle='host'"):
        DeviceShuffle([np.arange(MAX_ROWS + 1)], np.array([1]), MAX_ROWS + 1, "cpu")


def _data(n=140, seed=0):
    rng = np.random.default_rng(seed)
    X = rng.uniform([100, 6, 2, 2, 5, 8, 0], [160, 10, 4, 4, 15, 12, 0.5], size=(n, 7))
    y = 40 * X[:, 6] * X[:, 0] / 100 / (X[:, 2] ** 0.5) + 0.3 * X[:, 4]
    rows = np.arange(n)
    return X, y, [(rows[:100], rows[100:]), (rows[40:], rows[:40])]


KW = dict(epochs=8, batch_size=32, learning_rate=5e-3, seed=2, device="cpu", dtype=torch.float64)


def test_device_shuffle_trains_each_model_as_if_alone():
    X, y, splits = _data()
    grid = train_mlp_grid(X, y, splits, [(5, 6), (7, 4)], shuffle="device", **KW)
    assert grid.shuffle == "device"
    for c, hidden in enumerate([(5, 6), (7, 4)]):
        for s, split in enumerate(splits):
            alone = train_mlp_grid(
                X, y, [splits[0]] * s + [split], [hidden], shuffle="device", **KW
            )
            a, b = grid.model(c, s), alone.model(0, s)
            for pa, pb in zip(a.coefs + a.intercepts, b.coefs + b.intercepts, strict=True):
                np.testing.assert_allclose(pa, pb, rtol=0, atol=1e-12)
    longer = {**KW, "epochs": 40}
    host = train_mlp_grid(X, y, splits, [(5, 6), (7, 4)], shuffle="host", **longer)
    device = train_mlp_grid(X, y, splits, [(5, 6), (7, 4)], shuffle="device", **longer)
    assert host.shuffle == "host"
    # another order of the rows: another model, but it learns as well
    assert not np.allclose(host.models[0].coefs[0], device.models[0].coefs[0], atol=1e-6)
    for a, b in zip(host.models, device.models, strict=True):
        assert a.loss_curve[-1] < 0.5 * a.loss_curve[0] and b.loss_curve[-1] < 0.5 * b.loss_curve[0]
        assert b.loss_curve[-1] == pytest.approx(a.loss_curve[-1], rel=0.5)


class _HostOrders:
    """The host's NumPy orders behind the device path's interface (the epoch is ignored)."""

    def __init__(self, batches, rngs):
        self.batches, self.rngs = batches, rngs

    def rows(self, epoch):
        return self.batches.rows(self.rngs)


def test_the_device_epoch_loop_with_the_host_orders_is_bitwise_todays_training(monkeypatch):
    # The GPU path's loop (epoch counter on the device, losses placed by index) fed
    # the NumPy orders trains exactly the models of the host loop: float64 and float32.
    X, y, splits = _data()
    for dtype in (torch.float64, torch.float32):
        kw = {**KW, "dtype": dtype}
        today = train_mlp_grid(X, y, splits, [(5, 6), (7, 4)], shuffle="host", **kw)

        def with_host_orders(net, batches, rngs, real_run=batched_epochs.run_epochs, **options):
            options["shuffle"] = _HostOrders(batches, rngs)
            options["cuda_graph"] = True  # ignored on the CPU: the same eager loop
            return real_run(net, batches, rngs, **options)

        monkeypatch.setattr(batched, "run_epochs", with_host_orders)
        device_loop = train_mlp_grid(X, y, splits, [(5, 6), (7, 4)], shuffle="host", **kw)
        monkeypatch.undo()
        for a, b in zip(today.models, device_loop.models, strict=True):
            for pa, pb in zip(a.coefs + a.intercepts, b.coefs + b.intercepts, strict=True):
                np.testing.assert_array_equal(pa, pb)
            np.testing.assert_array_equal(a.loss_curve, b.loss_curve)


def test_tf32_and_cuda_graph_change_nothing_on_the_cpu():
    X, y, splits = _data()
    plain = train_mlp_grid(X, y, splits, [(5, 6)], shuffle="device", **KW)
    flagged = train_mlp_grid(
        X, y, splits, [(5, 6)], shuffle="device", tf32=True, cuda_graph=True, **KW
    )
    assert flagged.tf32 is False  # recorded as not used: no CUDA
    for a, b in zip(plain.models, flagged.models, strict=True):
        for pa, pb in zip(a.coefs, b.coefs, strict=True):
            np.testing.assert_array_equal(pa, pb)


def test_a_failing_compile_falls_back_to_the_eager_step(monkeypatch, caplog):
    X, y, splits = _data()

    def broken_compile(fn, **_):
        def compiled(*args):
            raise RuntimeError("no compiler here")

        return compiled

    monkeypatch.setattr(batched.torch, "compile", broken_compile)
    eager = train_mlp_grid(X, y, splits, [(5, 6)], **KW)
    with caplog.at_level(logging.WARNING, logger="softbend.surrogates.batched"):
        fallback = train_mlp_grid(X, y, splits, [(5, 6)], compile_step=True, **KW)
    assert "torch.compile of the training step failed (no compiler here)" in caplog.text
    for a, b in zip(eager.models, fallback.models, strict=True):
        np.testing.assert_array_equal(a.coefs[0], b.coefs[0])


@pytest.mark.parametrize(
    "option, value, message",
    [
        ("shuffle", "gpu", "shuffle: must be"),
        ("tf32", "yes", "tf32: must be True or False"),
        ("compile_step", 1, "compile_step: must be True or False"),
        ("cuda_graph", "on", "cuda_graph: must be True, False or None"),
    ],
)
def test_bad_device_path_options_are_named(option, value, message):
    X, y, splits = _data(n=60)
    with pytest.raises(ValueError, match=message):
        train_mlp_grid(X, y, splits, [(3, 3)], epochs=1, **{option: value})


@pytest.mark.slow
def test_the_compiled_step_trains_the_same_models_on_the_cpu():
    pytest.importorskip("torch._inductor")
    X, y, splits = _data()
    eager = train_mlp_grid(X, y, splits, [(5, 6)], shuffle="device", **KW)
    compiled = train_mlp_grid(X, y, splits, [(5, 6)], shuffle="device", compile_step=True, **KW)
    for a, b in zip(eager.models, compiled.models, strict=True):
        for pa, pb in zip(a.coefs + a.intercepts, b.coefs + b.intercepts, strict=True):
            np.testing.assert_allclose(pa, pb, rtol=0, atol=1e-9)  # float64: fused rounding
