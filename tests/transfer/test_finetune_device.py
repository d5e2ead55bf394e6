"""The refits' device path: the same code on the CPU and on a GPU."""

from __future__ import annotations

import numpy as np
import pytest

from softbend.transfer.finetune import fine_tune_many, fine_tune_mlp, row_weights

torch = pytest.importorskip("torch")


@pytest.fixture
def base(random_mlp):
    return random_mlp


def _rows(base, n=40, seed=3):
    rng = np.random.default_rng(seed)
    X = base.x_mean_ + base.x_scale_ * rng.uniform(-1.0, 1.0, size=(n, base.n_features_in_))
    return X, base.predict(X) * 1.05 + 1.0


def test_cpu_is_the_auto_path_without_a_gpu(base, monkeypatch):
    monkeypatch.setattr(torch.cuda, "is_available", lambda: False)
    X, y = _rows(base)
    auto = fine_tune_mlp(base, X, y, epochs=30)
    cpu = fine_tune_mlp(base, X, y, epochs=30, device="cpu")
    assert auto.device_ == cpu.device_ == "cpu"
    for a, b in zip(auto.coefs_, cpu.coefs_, strict=True):
        np.testing.assert_array_equal(a, b)
    assert auto.loss_curve_ == cpu.loss_curve_
    # Refining on rows the base misses lowers the loss.
    assert cpu.loss_curve_[-1] < cpu.loss_curve_[0]


def test_unknown_device_is_one_line(base):
    X, y = _rows(base, n=5)
    with pytest.raises(ValueError, match=r"^device: must be one of 'auto', 'cpu', 'cuda'"):
        fine_tune_many(base, X, y, np.ones((1, y.size)), epochs=2, device="tpu")


def test_cuda_without_a_gpu_is_refused(base, monkeypatch):
    monkeypatch.setattr(torch.cuda, "is_available", lambda: False)
    X, y = _rows(base, n=5)
    with pytest.raises(ValueError, match="is_available"):
        fine_tune_mlp(base, X, y, epochs=2, device="cuda")


@pytest.mark.skipif(not torch.cuda.is_available(), reason="needs a CUDA GPU")
def test_gpu_refits_match_the_cpu(base):
    """float64 on both: the variants agree to rounding (1e-9 of the weights' scale)."""
    X, y = _rows(base)
    sets = [np.arange(0, 20), np.arange(10, 40), np.r_[0:40:2, 0:10]]
    weights = row_weights(sets, y.size)
    cpu = fine_tune_many(base, X, y, weights, epochs=200, device="cpu")
    gpu = fine_tune_many(base, X, y, weights, epochs=200, device="cuda")
    for c, g in zip(cpu, gpu, strict=True):
        assert g.device_ == "cuda"
        for a, b in zip(c.coefs_, g.coefs_, strict=True):
            np.testing.assert_allclose(b, a, rtol=0, atol=1e-9 * np.abs(a).max())
        np.testing.assert_allclose(g.loss_curve_, c.loss_curve_, rtol=1e-9)


def test_a_refit_reports_its_epochs_to_the_listener(base):
    from softbend._progress import listening

    X, y = _rows(base)
    heard = []
    with listening(lambda phase, done, total: heard.append((phase, done, total))):
        fine_tune_many(base, X, y, np.ones((2, y.size)), epochs=120, device="cpu")
    assert heard[-1] == ("training 2 networks (epochs)", 120, 120)
    assert [d for _, d, _ in heard] == sorted(d for _, d, _ in heard) and len(heard) <= 61
