import numpy as np
import pytest
import torch

from softbend.errors import ConvergenceError
from softbend.surrogates.batched import _BatchedMLP, estimate_pass_bytes, train_mlp_grid
from softbend.surrogates.mlp import NormalizedMLPRegressor
from softbend.surrogates.mlp_core import init_parameters, mlp_forward, model_rng, standardization


@pytest.fixture(autouse=True, scope="module")
def _one_torch_thread():
    # these networks are tiny: OpenMP threads only add synchronization, and on a loaded
    # 2-core machine their spinning slows training by orders of magnitude
    before = torch.get_num_threads()
    torch.set_num_threads(1)
    yield
    torch.set_num_threads(before)


CONFIGS = [(5, 7), (8, 4), (6, 6)]


def _smooth_data(n=120, d=7, seed=0):
    rng = np.random.default_rng(seed)
    X = rng.uniform([100, 6, 2, 2, 5, 8, 0], [160, 10, 4, 4, 15, 12, 0.5], size=(n, d))
    y = 40 * X[:, 6] * X[:, 0] / 100 / (X[:, 2] ** 0.5) + 0.3 * X[:, 4]
    return X, y


def _uneven_splits(n):
    rows = np.arange(n)
    # training sets of 96 and 70 rows: with batch 32 the second model's epoch ends a step
    # early and both have partial last batches
    return [(rows[:96], rows[96:]), (rows[50:], rows[:50])]


def _assert_same_models(a, b, atol):
    for ma, mb in zip(a.models, b.models, strict=True):
        assert ma.hidden_sizes == mb.hidden_sizes and ma.split_index == mb.split_index
        for pa, pb in zip(ma.coefs + ma.intercepts, mb.coefs + mb.intercepts, strict=True):
            np.testing.assert_allclose(pa, pb, rtol=0, atol=atol)
        np.testing.assert_allclose(ma.loss_curve, mb.loss_curve, rtol=0, atol=atol)
        np.testing.assert_allclose(ma.val_pred_deg, mb.val_pred_deg, rtol=0, atol=atol * 1e3)


# --- the key equivalence: batched == each model alone -----------------------------------


@pytest.mark.parametrize("dtype, atol", [(torch.float64, 1e-10), (torch.float32, 1e-4)])
def test_batched_grid_equals_each_model_trained_alone(dtype, atol):
    X, y = _smooth_data()
    splits = _uneven_splits(len(y))
    kwargs = dict(epochs=6, batch_size=32, learning_rate=5e-3, seed=3, device="cpu", dtype=dtype)
    grid = train_mlp_grid(X, y, splits, CONFIGS, **kwargs)
    assert len(grid.models) == 6 and grid.n_passes == 1
    for c, hidden in enumerate(CONFIGS):
        for s, split in enumerate(splits):
            batched = grid.model(c, s)
            assert batched.hidden_sizes == hidden and batched.n_train == split[0].size
            # the split index is part of the model's RNG stream: train it alone (M = 1)
            # under the same split index by padding the split list in front
            alone = train_mlp_grid(
                X, y, [splits[0]] * s + [split], [hidden], max_models_per_pass=1, **kwargs
            ).model(0, s)
            for pa, pb in zip(
                batched.coefs + batched.intercepts, alone.coefs + alone.intercepts, strict=True
            ):
                np.testing.assert_allclose(pa, pb, rtol=0, atol=atol)
            np.testing.assert_allclose(batched.loss_curve, alone.loss_curve, atol=atol)
            np.testing.assert_allclose(batched.val_pred_deg, alone.val_pred_deg, atol=atol * 1e3)


def test_the_largest_configuration_is_bitwise_the_same_beside_a_smaller_one():
    # the quick grid of reproduce trains (63, 65) alone because of this: a smaller
    # configuration beside it neither pads it nor shares its random stream
    X, y = _smooth_data()
    splits = _uneven_splits(len(y))
    kwargs = dict(epochs=5, batch_size=32, learning_rate=5e-3, seed=1, device="cpu")
    both = train_mlp_grid(X, y, splits, [(5, 4), (8, 7)], **kwargs)
    alone = train_mlp_grid(X, y, splits, [(8, 7)], **kwargs)
    for s in range(len(splits)):
        a, b = both.model(1, s), alone.model(0, s)
        for pa, pb in zip(a.coefs + a.intercepts, b.coefs + b.intercepts, strict=True):
            np.testing.assert_array_equal(pa, pb)
        np.testing.assert_array_equal(a.loss_curve, b.loss_curve)
        np.testing.assert_array_equal(a.val_pred_deg, b.val_pred_deg)


def test_models_differ_between_configs_and_splits_and_learn():
    X, y = _smooth_data()
    grid = train_mlp_grid(
        X, y, _uneven_splits(len(y)), CONFIGS, epochs=30, batch_size=32, learning_rate=5e-3
    )
    firsts = {m.coefs[0][0, 0] for m in grid.models}
    assert len(firsts) == len(grid.models)
    for m in grid.models:
        assert m.loss_curve.shape == (30,)
        assert m.loss_curve[-1] < 0.5 * m.loss_curve[0]
        assert np.isfinite(m.train_loss) and m.train_loss < m.loss_curve[0]


def test_chunking_into_passes_gives_identical_results():
    X, y = _smooth_data()
    splits = _uneven_splits(len(y))
    kwargs = dict(epochs=4, batch_size=32, learning_rate=5e-3, seed=1, device="cpu")
    whole = train_mlp_grid(X, y, splits, CONFIGS, **kwargs)
    for per_pass in (1, 4):
        chunked = train_mlp_grid(X, y, splits, CONFIGS, max_models_per_pass=per_pass, **kwargs)
        assert chunked.n_passes == -(-6 // per_pass)
        _assert_same_models(whole, chunked, atol=0.0)


def test_standardization_uses_each_models_own_training_rows():
    X, y = _smooth_data()
    splits = _uneven_splits(len(y))
    grid = train_mlp_grid(X, y, splits, [(4, 4)], epochs=1, batch_size=64)
    for s, (train, _) in enumerate(splits):
        m = grid.model(0, s)
        np.testing.assert_allclose(m.x_mean, X[train].mean(axis=0), rtol=1e-14)
        np.testing.assert_allclose(m.x_scale, X[train].std(axis=0), rtol=1e-14)
        assert m.y_mean == pytest.approx(y[train].mean(), rel=1e-14)
        assert m.y_scale == pytest.approx(y[train].std(), rel=1e-14)


def test_constant_column_gets_unit_scale():
    X = np.column_stack([np.linspace(0, 1, 20), np.full(20, 0.1)])
    _, scale = standardization(X)
    assert scale[1] == 1.0 and scale[0] == pytest.approx(X[:, 0].std())


# --- Adam, masks, inactive models --------------------------------------------------------


def test_adam_steps_match_torch_optim_adam_for_a_single_model():
    X, y = _smooth_data(n=50)
    h1, h2, seed, lr = 6, 5, 11, 1e-2
    coefs, intercepts = init_parameters(model_rng(seed, h1, h2, 0), X.shape[1], h1, h2)
    net = torch.nn.Sequential(
        torch.nn.Linear(7, h1), torch.nn.Tanh(), torch.nn.Linear(h1, h2), torch.nn.Tanh()
    )
    net.append(torch.nn.Linear(h2, 1))
    net = net.double()
    with torch.no_grad():
        for layer, W, b in zip(net[::2], coefs, intercepts, strict=True):
            layer.weight.copy_(torch.from_numpy(W.T.copy()))
            layer.bias.copy_(torch.from_numpy(b))
    optimizer = torch.optim.Adam(net.parameters(), lr=lr, betas=(0.9, 0.999), eps=1e-8)
    Z = torch.from_numpy((X - X.mean(0)) / X.std(0))
    target = torch.from_numpy((y - y.mean()) / y.std())
    losses = []
    for _ in range(3):
        optimizer.zero_grad()
        loss = torch.mean((net(Z)[:, 0] - target) ** 2)
        loss.backward()
        optimizer.step()
        losses.append(loss.item())

    rows = np.arange(len(y))
    ours = train_mlp_grid(
        X,
        y,
        [(rows, rows[:0])],
        [(h1, h2)],
        epochs=3,
        batch_size=64,  # one full batch per epoch: one Adam step
        learning_rate=lr,
        seed=seed,
        dtype=torch.float64,
    ).models[0]
    for layer, W, b in zip(net[::2], ours.coefs, ours.intercepts, strict=True):
        np.testing.assert_allclose(W, layer.weight.detach().numpy().T, rtol=0, atol=1e-12)
        np.testing.assert_allclose(b, layer.bias.detach().numpy(), rtol=0, atol=1e-12)
    np.testing.assert_allclose(ours.loss_curve, losses, rtol=1e-12)


def _two_padded_models(seed=0):
    rng = np.random.default_rng(seed)
    sizes = [(3, 5), (6, 2)]
    coefs, intercepts = [], []
    for h1, h2 in sizes:
        c, b = init_parameters(rng, 4, h1, h2)
        coefs.append(c)
        intercepts.append(b)
    return _BatchedMLP(coefs, intercepts, 6, 5, device="cpu", dtype=torch.float64)


def _padding(net):
    """Per parameter, 1 where a model's weight or bias belongs to a padded hidden unit."""
    sizes = [(3, 5), (6, 2)]
    pads = [torch.ones_like(p) for p in net.params]
    for m, (h1, h2) in enumerate(sizes):
        pads[0][m, :, :h1] = 0
        pads[1][m, :, :h1] = 0
        pads[2][m, :h1, :h2] = 0
        pads[3][m, :, :h2] = 0
        pads[4][m, :h2, :] = 0
        pads[5][m] = 0
    return pads


def test_padded_hidden_units_stay_zero_and_change_nothing():
    gen = torch.Generator().manual_seed(0)
    net = _two_padded_models()
    pads = _padding(net)
    for _ in range(3):
        Z = torch.randn((2, 9, 4), generator=gen, dtype=torch.float64)
        target = torch.randn((2, 9), generator=gen, dtype=torch.float64)
        weight = torch.ones((2, 9), dtype=torch.float64)
        count = torch.full((2,), 9.0, dtype=torch.float64)
        grads, _ = net.gradients(Z, target, weight, count)
        for g, pad in zip(grads, pads, strict=True):
            assert torch.all(g[pad == 1] == 0)  # padding receives exactly zero gradient
        net.adam_step(grads, torch.tensor([True, True]), 0.1)
        for p, pad in zip(net.params, pads, strict=True):
            assert torch.all(p[pad == 1] == 0)  # ... so Adam leaves it at zero
    # each padded model computes what the same model alone (unpadded) computes
    for m, (h1, h2) in enumerate([(3, 5), (6, 2)]):
        alone = _BatchedMLP(
            [
                [
                    W[m].clone().numpy()
                    for W in (net.params[0][:, :, :h1], net.params[2][:, :h1, :h2])
                ]
                + [net.params[4][m, :h2].numpy()]
            ],
            [
                [
                    net.params[1][m, 0, :h1].numpy(),
                    net.params[3][m, 0, :h2].numpy(),
                    net.params[5][m, 0].numpy(),
                ]
            ],
            h1,
            h2,
            device="cpu",
            dtype=torch.float64,
        )
        np.testing.assert_allclose(
            alone.forward(Z[m : m + 1])[2][0], net.forward(Z)[2][m], rtol=0, atol=1e-14
        )


def test_inactive_model_is_not_updated_by_adam():
    net = _two_padded_models()
    gen = torch.Generator().manual_seed(1)
    Z = torch.randn((2, 9, 4), generator=gen, dtype=torch.float64)
    target = torch.randn((2, 9), generator=gen, dtype=torch.float64)
    grads, _ = net.gradients(Z, target, torch.ones((2, 9), dtype=torch.float64), torch.ones(2))
    net.adam_step(grads, torch.tensor([True, True]), 0.01)  # nonzero moments for both
    before = [p.clone() for p in net.params]
    net.adam_step([torch.zeros_like(g) for g in grads], torch.tensor([True, False]), 0.01)
    assert net.steps.tolist() == [2.0, 1.0]
    for p, p0 in zip(net.params, before, strict=True):
        assert torch.equal(p[1], p0[1])  # inactive: untouched although Adam's momentum is not 0
    assert any(not torch.equal(p[0], p0[0]) for p, p0 in zip(net.params, before, strict=True))


def test_the_in_place_adam_step_of_all_active_models_is_bitwise_the_selecting_one():
    nets = [_two_padded_models(seed=3), _two_padded_models(seed=3)]
    gen = torch.Generator().manual_seed(2)
    for _ in range(3):
        Z = torch.randn((2, 9, 4), generator=gen, dtype=torch.float64)
        target = torch.randn((2, 9), generator=gen, dtype=torch.float64)
        weight, count = torch.ones((2, 9), dtype=torch.float64), torch.full((2,), 9.0)
        for net, in_place in zip(nets, (False, True), strict=True):
            grads, _ = net.gradients(Z, target, weight, count)
            net.adam_step(grads, torch.tensor([True, True]), 0.05, all_active=in_place)
    a, b = nets
    for tensors_a, tensors_b in ((a.params, b.params), (a.exp_avg, b.exp_avg)):
        for x, y in zip(tensors_a, tensors_b, strict=True):
            assert torch.equal(x, y)
    assert not torch.equal(a.params[0], _two_padded_models(seed=3).params[0])  # it moved


def test_short_training_set_ends_its_epoch_without_extra_updates():
    X, y = _smooth_data()
    rows = np.arange(len(y))
    # 20 training rows (1 step per epoch) beside 120 rows (4 steps per epoch)
    splits = [(rows, rows[:0]), (rows[:20], rows[20:])]
    kwargs = dict(epochs=5, batch_size=32, learning_rate=1e-2, seed=0, dtype=torch.float64)
    grid = train_mlp_grid(X, y, splits, [(4, 3)], **kwargs)
    small_alone = train_mlp_grid(X, y, splits, [(4, 3)], max_models_per_pass=1, **kwargs)
    _assert_same_models(grid, small_alone, atol=1e-12)
    # and the small model is the result of exactly 5 Adam steps on full batches of 20 rows
    five = train_mlp_grid(X, y, [splits[1]] * 2, [(4, 3)], **{**kwargs, "batch_size": 20})
    for a, b in zip(grid.model(0, 1).coefs, five.model(0, 1).coefs, strict=True):
        np.testing.assert_allclose(a, b, atol=1e-12)


# --- results ------------------------------------------------------------------------------


def test_validation_predictions_and_estimator_from_result():
    X, y = _smooth_data()
    splits = _uneven_splits(len(y))
    grid = train_mlp_grid(X, y, splits, CONFIGS[:2], epochs=3, batch_size=32)
    for c in range(2):
        for s, (_, val) in enumerate(splits):
            m = grid.model(c, s)
            np.testing.assert_array_equal(m.val_index, val)
            assert m.val_pred_deg.dtype == np.float64 and m.val_pred_deg.shape == val.shape
            estimator = NormalizedMLPRegressor.from_grid(grid, c, s)
            assert isinstance(estimator, NormalizedMLPRegressor)
            assert estimator.hidden_sizes == CONFIGS[c] and estimator.epochs == 3
            np.testing.assert_array_equal(estimator.predict(X[val]), m.val_pred_deg)
            np.testing.assert_array_equal(m.predict(X[val]), m.val_pred_deg)
            assert estimator.loss_curve_ == m.loss_curve.tolist()


def test_forward_is_the_contract_formula():
    rng = np.random.default_rng(0)
    coefs, intercepts = init_parameters(rng, 3, 4, 2)
    X = rng.normal(size=(5, 3))
    x_mean, x_scale = np.array([1.0, 2.0, 3.0]), np.array([2.0, 0.5, 1.0])
    expected = []
    for x in X:
        z = (x - x_mean) / x_scale
        a1 = [
            np.tanh(sum(z[i] * coefs[0][i, j] for i in range(3)) + intercepts[0][j])
            for j in range(4)
        ]
        a2 = [
            np.tanh(sum(a1[i] * coefs[1][i, j] for i in range(4)) + intercepts[1][j])
            for j in range(2)
        ]
        expected.append(
            10.0 + 3.0 * (sum(a2[i] * coefs[2][i, 0] for i in range(2)) + intercepts[2][0])
        )
    got = mlp_forward(X, x_mean, x_scale, 10.0, 3.0, coefs, intercepts)
    np.testing.assert_allclose(got, expected, rtol=1e-13)


def test_progress_reports_every_epoch_of_every_pass():
    X, y = _smooth_data(n=40)
    calls = []
    rows = np.arange(40)
    train_mlp_grid(
        X,
        y,
        [(rows, rows[:0])],
        [(3, 3), (4, 4)],
        epochs=3,
        batch_size=16,
        max_models_per_pass=1,
        progress=lambda done, total: calls.append((done, total)),
    )
    assert calls == [(k, 6) for k in range(1, 7)]


def test_divergence_raises_convergence_error():
    X, y = _smooth_data(n=40)
    rows = np.arange(40)
    with pytest.raises(ConvergenceError, match="non-finite"):
        train_mlp_grid(X, y, [(rows, rows[:0])], [(3, 3)], epochs=2, learning_rate=1e300)


# --- memory guard and bad input -----------------------------------------------------------


def test_memory_estimate_grows_with_models_and_guard_names_the_remedy():
    small = estimate_pass_bytes(10, 7, 65, 65, 1024, 24000)
    assert estimate_pass_bytes(20, 7, 65, 65, 1024, 24000) > 1.9 * small
    assert estimate_pass_bytes(10, 7, 65, 65, 1024, 24000, itemsize=8) > small
    X, y = _smooth_data()
    budget_mb = estimate_pass_bytes(2, 7, 8, 7, 32, 96) / 1024**2
    with pytest.raises(ValueError, match=r"max_models_per_pass: .*set it to 2 or fewer"):
        train_mlp_grid(
            X, y, _uneven_splits(len(y)), CONFIGS, epochs=1, batch_size=32, max_memory_mb=budget_mb
        )
    result = train_mlp_grid(
        X,
        y,
        _uneven_splits(len(y)),
        CONFIGS,
        epochs=1,
        batch_size=32,
        max_memory_mb=budget_mb,
        max_models_per_pass=2,
    )
    assert result.n_passes == 3


@pytest.mark.parametrize(
    "kwargs, match",
    [
        ({"hidden_sizes": [(0, 5)]}, "hidden_sizes: must be a pair"),
        ({"hidden_sizes": [(5,)]}, "hidden_sizes: must be a pair"),
        ({"hidden_sizes": []}, "hidden_sizes: must be a non-empty"),
        ({"batch_size": 0}, r"batch_size: must be an integer in \[1, inf\)"),
        ({"epochs": 2.5}, "epochs: must be"),
        ({"learning_rate": -1.0}, "learning_rate: must be"),
        ({"seed": -1}, "seed: must be"),
        ({"device": "tpu"}, "device: must be one of 'auto', 'cpu', 'cuda'"),
        ({"dtype": torch.float16}, "dtype: must be"),
        ({"max_models_per_pass": 0}, "max_models_per_pass: must be"),
        ({"progress": 3}, "progress: must be"),
        ({"splits": []}, "splits: must be a non-empty list"),
        ({"splits": [(np.arange(3), np.array([200]))]}, "val indices of split 0"),
        ({"splits": [(np.array([], dtype=int), np.arange(3))]}, "split 0 with no training row"),
        ({"splits": [(np.array([0.5]), np.arange(3))]}, "train indices of split 0"),
    ],
)
def test_bad_arguments_raise_one_clear_value_error(kwargs, match):
    X, y = _smooth_data(n=30)
    rows = np.arange(30)
    args = {"splits": [(rows, rows[:0])], "hidden_sizes": [(3, 3)], "epochs": 1, **kwargs}
    with pytest.raises(ValueError, match=match):
        train_mlp_grid(X, y, **args)


def test_bad_data_raises():
    X, y = _smooth_data(n=30)
    rows = np.arange(30)
    split = [(rows, rows[:0])]
    X_nan = X.copy()
    X_nan[4, 2] = np.nan
    with pytest.raises(ValueError, match="X: must be finite"):
        train_mlp_grid(X_nan, y, split, [(3, 3)], epochs=1)
    with pytest.raises(ValueError, match=r"y: must have shape \(30,\)"):
        train_mlp_grid(X, y[:-1], split, [(3, 3)], epochs=1)
    with pytest.raises(ValueError, match="X: must be a non-empty 2-D"):
        train_mlp_grid(X[:, 0], y, split, [(3, 3)], epochs=1)


def test_cuda_is_refused_clearly_without_a_gpu_and_matches_cpu_with_one():
    X, y = _smooth_data(n=60)
    rows = np.arange(60)
    args = (X, y, [(rows[:40], rows[40:])], [(5, 4)])
    if not torch.cuda.is_available():
        with pytest.raises(
            ValueError, match="device: must be 'auto' or 'cpu' without a usable GPU"
        ):
            train_mlp_grid(*args, epochs=1, device="cuda")
        pytest.skip("CUDA not available: GPU equivalence not checked")
    # the device shuffle draws the same orders on both; the GPU path graphs its epochs
    kwargs = dict(epochs=5, batch_size=16, dtype=torch.float64, shuffle="device")
    cpu = train_mlp_grid(*args, device="cpu", **kwargs)
    gpu = train_mlp_grid(*args, device="cuda", **kwargs)
    assert gpu.device == "cuda" and gpu.shuffle == "device"
    _assert_same_models(cpu, gpu, atol=1e-9)
    host_cpu = train_mlp_grid(*args, device="cpu", **{**kwargs, "shuffle": "host"})
    host_gpu = train_mlp_grid(*args, device="cuda", **{**kwargs, "shuffle": "host"})
    _assert_same_models(host_cpu, host_gpu, atol=1e-9)
    compiled = train_mlp_grid(*args, device="cuda", compile_step=True, **kwargs)
    _assert_same_models(cpu, compiled, atol=1e-9)
