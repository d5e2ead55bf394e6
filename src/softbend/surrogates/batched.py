"""Train many normalized MLPs at once in one batched tensor program (paper B §4.1 grid).

A hyperparameter grid with cross-validation is M = (number of configurations) x
(number of folds) small, independent networks. :func:`train_mlp_grid` stacks them:
the weights of all M models live in padded tensors of shape (M, d, H1max),
(M, H1max, H2max) and (M, H2max, 1), every forward and backward product is one
``torch.baddbmm``/``torch.bmm`` over the model axis, and hidden units beyond a
model's own size have zero weights and biases, so their activation is exactly 0,
they contribute nothing to the output, receive exactly zero gradient and stay at
zero.

Each model is exactly what it would be if trained alone (the tests check this):

* its inputs and target are standardized with the mean and standard deviation of
  ITS OWN training rows;
* it has its own random stream, derived from ``(seed, h1, h2, split index)`` and
  not from its position in the batch, which draws the initial weights (the
  ``torch.nn.Linear`` default U(-1/sqrt(fan_in), 1/sqrt(fan_in)) with the model's
  true fan_in) and, every epoch, the permutation of its own training rows;
* the optimizer is Adam written as batched tensor operations (betas 0.9/0.999,
  eps 1e-8, bias correction; the update of :class:`torch.optim.Adam`) with a
  per-model step count and a per-model *active* mask: folds differ in size, and
  a model whose epoch has run out of mini-batches is not touched (Adam with a
  zero gradient would still move it);
* the loss of a partial last mini-batch is the mean over that model's true rows.

Gradients are computed by hand (three layers, closed form), not by autograd:
that keeps memory at one set of activations. The
network, its gradients and Adam are :class:`~softbend.surrogates.batched_net.BatchedMLP`;
the memory a pass needs is :mod:`~softbend.surrogates.batched_memory`'s, and the
arguments are checked by :mod:`~softbend.surrogates.batched_checks`. The
random streams come from NumPy (``numpy.random.SeedSequence``), so results do
not depend on torch's global RNG state, and CPU runs with the same seed give
identical weights.

On a CUDA device the epoch loop is kept on the device: the row orders are drawn
there (``shuffle="device"``, :mod:`~softbend.surrogates.batched_shuffle`: the same
orders on CPU and GPU, not NumPy's), every epoch after the first replays one
captured CUDA graph, and TF32 products (``tf32=True``) and a compiled step
(``compile_step=True``) are options. The CPU keeps NumPy's orders by default.
"""

from __future__ import annotations

import logging
import math
import time
from collections.abc import Callable, Iterator, Sequence
from contextlib import contextmanager
from dataclasses import dataclass, field
from typing import TYPE_CHECKING, Any

import numpy as np
from numpy.typing import ArrayLike

from softbend._torch import require_torch
from softbend._validation import check_choice, check_int, check_range, must_be
from softbend.errors import ConvergenceError, InputError
from softbend.limits import check_limit
from softbend.surrogates.batched_checks import (
    check_data,
    check_dtype,
    check_hidden_sizes,
    check_splits,
)
from softbend.surrogates.batched_epochs import (
    MiniBatches,
    StepFunction,
    final_train_loss,
    run_epochs,
)
from softbend.surrogates.batched_memory import estimate_pass_bytes, models_per_pass
from softbend.surrogates.batched_net import BatchedMLP
from softbend.surrogates.batched_shuffle import DeviceShuffle, model_keys
from softbend.surrogates.mlp_core import (
    init_parameters,
    mlp_forward,
    model_rng,
    resolve_device,
    standardization,
)

if TYPE_CHECKING:
    import torch
else:
    torch = require_torch("the MLP surrogate (softbend.surrogates)")

logger = logging.getLogger(__name__)

__all__ = [
    "GridTrainingResult",
    "TrainedMLP",
    "estimate_pass_bytes",
    "tf32_matmul",
    "train_mlp_grid",
]

#: The batched network, under the name this module gave it before it had its own module.
_BatchedMLP = BatchedMLP

_OWNER = "train_mlp_grid"


# --- results ----------------------------------------------------------------------------


@dataclass(frozen=True)
class TrainedMLP:
    """One trained (configuration, split) model of :func:`train_mlp_grid`.

    Attributes
    ----------
    hidden_sizes : tuple of int
        (h1, h2).
    config_index, split_index : int
        Position of the configuration in ``hidden_sizes`` and of the split in ``splits``.
    x_mean, x_scale : ndarray of shape (d,)
        Input standardization from the model's training rows, input units.
    y_mean, y_scale : float
        Target standardization, degrees.
    coefs, intercepts : list of ndarray
        Float64 weights (d, h1), (h1, h2), (h2, 1) and biases (h1,), (h2,), (1,).
    loss_curve : ndarray of shape (epochs,)
        Training MSE per epoch in standardized units: the squared errors of the
        epoch's mini-batches (each training row once, before the update that used
        it), averaged over the training rows.
    train_loss : float
        MSE of the final parameters on all the model's training rows, standardized units.
    n_train : int
        Training rows.
    val_index : ndarray of int
        Validation rows (indices into X), possibly empty.
    val_pred_deg : ndarray of float64
        Predictions for ``val_index``, degrees (NumPy float64 forward pass).
    """

    hidden_sizes: tuple[int, int]
    config_index: int
    split_index: int
    x_mean: np.ndarray
    x_scale: np.ndarray
    y_mean: float
    y_scale: float
    coefs: list[np.ndarray]
    intercepts: list[np.ndarray]
    loss_curve: np.ndarray
    train_loss: float
    n_train: int
    val_index: np.ndarray
    val_pred_deg: np.ndarray

    def predict(self, X: ArrayLike) -> np.ndarray:
        """Bending angle for inputs ``X`` (n, d), degrees (NumPy float64)."""
        return mlp_forward(
            np.asarray(X, dtype=np.float64),
            self.x_mean,
            self.x_scale,
            self.y_mean,
            self.y_scale,
            self.coefs,
            self.intercepts,
        )


@dataclass(frozen=True)
class GridTrainingResult:
    """Everything :func:`train_mlp_grid` trained.

    Attributes
    ----------
    models : tuple of TrainedMLP
        Configuration-major: ``models[c * n_splits + s]`` is configuration ``c`` on split ``s``.
    hidden_sizes : tuple of (int, int)
        The configurations, in order.
    n_splits : int
        Number of splits.
    epochs, batch_size : int
        Training length and mini-batch rows.
    learning_rate : float
        Adam step size.
    seed : int
        Seed of the random streams.
    device : str
        Where the models were trained ("cpu" or "cuda").
    dtype : str
        Training precision ("float32" or "float64").
    n_passes : int
        Number of batched passes the models were split into.
    elapsed_s : float
        Wall-clock time of the training passes, s.
    shuffle : str
        Where the row orders were drawn ("host" or "device").
    tf32 : bool
        Whether TF32 matrix products were allowed (CUDA only).
    """

    models: tuple[TrainedMLP, ...]
    hidden_sizes: tuple[tuple[int, int], ...]
    n_splits: int
    epochs: int
    batch_size: int
    learning_rate: float
    seed: int
    device: str
    dtype: str
    n_passes: int
    elapsed_s: float = field(default=0.0, compare=False)
    shuffle: str = "host"
    tf32: bool = False

    def model(self, config_index: int, split_index: int) -> TrainedMLP:
        """The model of configuration ``config_index`` trained on split ``split_index``."""
        return self.models[config_index * self.n_splits + split_index]


# --- training ---------------------------------------------------------------------------


@dataclass
class _Job:
    config_index: int
    split_index: int
    h1: int
    h2: int
    train_idx: np.ndarray
    val_idx: np.ndarray


@dataclass(frozen=True)
class _PassSettings:
    """The training settings every pass of one :func:`train_mlp_grid` call shares."""

    h1_max: int
    h2_max: int
    epochs: int
    batch_size: int
    learning_rate: float
    seed: int
    device: str
    dtype: torch.dtype
    shuffle: str = "host"
    cuda_graph: bool = False
    compile_step: bool = False


@contextmanager
def _cpu_settings(num_threads: int | None) -> Iterator[None]:
    """Torch intra-op threads (if given) and flush-to-zero of subnormal floats while training.

    Squared gradients in Adam's second moment can fall into the subnormal range,
    where x86 arithmetic is slower (measured: 200 epochs of one 63x65 model on
    22 000 rows, 4.5 s without, 3.6 s with flush-to-zero). Both settings are
    restored afterwards (flush-to-zero is switched off again).
    """
    threads_before = torch.get_num_threads()
    if num_threads is not None:
        torch.set_num_threads(num_threads)
    flushed = torch.set_flush_denormal(True)
    try:
        yield
    finally:
        if flushed:
            torch.set_flush_denormal(False)
        torch.set_num_threads(threads_before)


@contextmanager
def tf32_matmul(device: str, tf32: bool) -> Iterator[None]:
    """TF32 matrix products on a CUDA device inside the block, if ``tf32`` (restored after).

    TF32 rounds the inputs of float32 matrix products to 10 mantissa bits on the
    GPU's tensor cores (accumulation stays float32). It has no effect on the CPU.
    """
    if not (tf32 and device == "cuda"):
        yield
        return
    before = torch.get_float32_matmul_precision()
    torch.set_float32_matmul_precision("high")
    try:
        yield
    finally:
        torch.set_float32_matmul_precision(before)


def train_mlp_grid(
    X: ArrayLike,
    y: ArrayLike,
    splits: Sequence[tuple[ArrayLike, ArrayLike]],
    hidden_sizes: Sequence[tuple[int, int]],
    *,
    epochs: int = 1000,
    batch_size: int = 1024,
    learning_rate: float = 6e-4,
    seed: int = 0,
    device: str = "auto",
    dtype: torch.dtype = torch.float32,
    progress: Callable[[int, int], object] | None = None,
    max_models_per_pass: int | None = None,
    max_memory_mb: float | None = None,
    num_threads: int | None = None,
    shuffle: str = "auto",
    tf32: bool = False,
    cuda_graph: bool | None = None,
    compile_step: bool = False,
) -> GridTrainingResult:
    """Train every (configuration, split) MLP of a grid at once (paper B §4.1).

    Parameters
    ----------
    X : array_like of shape (n_samples, d)
        Inputs (for softbend's surrogates the columns of
        :data:`softbend.surrogates.features.FEATURES`), finite.
    y : array_like of shape (n_samples,)
        Bending angle, degrees, finite.
    splits : sequence of (train_idx, val_idx)
        Integer row indices of each split (CV fold); ``val_idx`` may be empty
        (a refit on all rows).
    hidden_sizes : sequence of (int, int)
        The configurations (h1, h2), each >= 1.
    epochs : int, default 1000
        Passes over each model's training rows, >= 1.
    batch_size : int, default 1024
        Rows per mini-batch, >= 1.
    learning_rate : float, default 6e-4
        Adam step size, > 0.
    seed : int, default 0
        Seed of the per-model random streams, >= 0.
    device : {"auto", "cpu", "cuda"}, default "auto"
        Where to train; "auto" is "cuda" when available.
    dtype : torch.float32 or torch.float64, default torch.float32
        Training precision. Standardization and the returned parameters are float64.
    progress : callable, optional
        Called as ``progress(done, total)`` after every epoch of every pass
        (``total = epochs * n_passes``).
    max_models_per_pass : int, optional
        Train at most this many models at a time (None: all at once). The results
        do not depend on it.
    max_memory_mb : float, optional
        Memory a pass may use, MB; default 80 % of the memory available on the device.
    num_threads : int, optional
        torch intra-op CPU threads while training (restored afterwards); None keeps
        torch's setting. One thread avoids OpenMP oversubscription for small grids
        or on a loaded machine.
    shuffle : {"auto", "host", "device"}, default "auto"
        Where each epoch's row orders are drawn: "host" with each model's NumPy
        stream (the orders of every earlier version of softbend), "device" from
        counter-based keys on the training device
        (:mod:`~softbend.surrogates.batched_shuffle`: no host work or copy inside
        the epoch loop; the same orders on CPU and GPU, other than the host's).
        "auto" is "device" on a CUDA device and "host" on the CPU.
    tf32 : bool, default False
        Allow TF32 tensor-core matrix products on a CUDA device (float32 only;
        no effect on the CPU). Faster, with inputs of each product rounded to
        10 mantissa bits.
    cuda_graph : bool, optional
        Capture one epoch as a CUDA graph and replay it (needs the device shuffle).
        None: on when the device is CUDA and the shuffle is "device".
    compile_step : bool, default False
        Compile the mini-batch update (forward, backward, Adam) with
        ``torch.compile``, which fuses its element-wise work into fewer kernels.
        Compiling takes seconds once per process and shape (7 s on an H200, where
        it did not make the paper grid faster); if it fails, training goes on
        uncompiled (logged).

    Returns
    -------
    GridTrainingResult
        Per (configuration, split): parameters, loss curve, final training loss and
        validation predictions in degrees.

    Raises
    ------
    ValueError
        On a bad argument (naming it), or if a pass would not fit in memory (with the
        largest ``max_models_per_pass`` that would).
    ConvergenceError
        If a model's parameters became non-finite.
    """
    X, y = check_data(X, y)
    split_list = check_splits(splits, X.shape[0])
    configs = check_hidden_sizes(hidden_sizes)
    epochs = check_int(epochs, "epochs", low=1)
    check_limit("epochs", epochs, f"The 'epochs' of {_OWNER}")
    batch_size = check_int(batch_size, "batch_size", low=1)
    learning_rate = check_range(learning_rate, "learning_rate", low=0.0, high=math.inf)
    seed = check_int(seed, "seed", low=0)
    device = resolve_device(device)
    dtype = check_dtype(dtype)
    if progress is not None and not callable(progress):
        raise InputError(f"must be a callable or None; got {progress!r}", key="progress")
    if max_models_per_pass is not None:
        max_models_per_pass = check_int(max_models_per_pass, "max_models_per_pass", low=1)
    if max_memory_mb is not None:
        max_memory_mb = check_range(max_memory_mb, "max_memory_mb", low=0.0)
    if num_threads is not None:
        num_threads = check_int(num_threads, "num_threads", low=1)
    check_choice(shuffle, "shuffle", ("auto", "host", "device"))
    if shuffle == "auto":
        shuffle = "device" if device == "cuda" else "host"
    for name, flag in (("tf32", tf32), ("compile_step", compile_step)):
        if not isinstance(flag, bool):
            raise InputError(must_be("True or False", flag), key=name)
    if cuda_graph is None:
        cuda_graph = device == "cuda" and shuffle == "device"
    elif not isinstance(cuda_graph, bool):
        raise InputError(must_be("True, False or None", cuda_graph), key="cuda_graph")

    jobs = [
        _Job(c, s, h1, h2, train, val)
        for c, (h1, h2) in enumerate(configs)
        for s, (train, val) in enumerate(split_list)
    ]
    settings = _PassSettings(
        h1_max=max(h1 for h1, _ in configs),
        h2_max=max(h2 for _, h2 in configs),
        epochs=epochs,
        batch_size=batch_size,
        learning_rate=learning_rate,
        seed=seed,
        device=device,
        dtype=dtype,
        shuffle=shuffle,
        cuda_graph=cuda_graph,
        compile_step=compile_step,
    )
    per_pass = models_per_pass(
        len(jobs),
        X.shape[1],
        settings.h1_max,
        settings.h2_max,
        batch_size,
        max(job.train_idx.size for job in jobs),
        device=device,
        dtype=dtype,
        max_models_per_pass=max_models_per_pass,
        max_memory_mb=max_memory_mb,
    )
    X_dev = torch.tensor(X, dtype=torch.float64, device=device)
    y_dev = torch.tensor(y, dtype=torch.float64, device=device)
    start = time.perf_counter()
    with _cpu_settings(num_threads), tf32_matmul(device, tf32):
        trained = _train_in_passes(jobs, X, y, X_dev, y_dev, per_pass, settings, progress)
    elapsed = time.perf_counter() - start
    return GridTrainingResult(
        models=tuple(trained),
        hidden_sizes=tuple(configs),
        n_splits=len(split_list),
        epochs=epochs,
        batch_size=batch_size,
        learning_rate=learning_rate,
        seed=seed,
        device=device,
        dtype=str(dtype).removeprefix("torch."),
        n_passes=math.ceil(len(jobs) / per_pass),
        elapsed_s=elapsed,
        shuffle=shuffle,
        tf32=tf32 and device == "cuda",
    )


def _train_in_passes(
    jobs: list[_Job],
    X: np.ndarray,
    y: np.ndarray,
    X_dev: torch.Tensor,
    y_dev: torch.Tensor,
    per_pass: int,
    settings: _PassSettings,
    progress: Callable[[int, int], object] | None,
) -> list[TrainedMLP]:
    """Train ``jobs`` ``per_pass`` at a time, calling ``progress`` after every epoch."""
    n_passes = math.ceil(len(jobs) / per_pass)
    epochs = settings.epochs
    trained: list[TrainedMLP] = []
    for p in range(n_passes):
        chunk = jobs[p * per_pass : (p + 1) * per_pass]
        logger.debug(
            "%s: pass %d/%d, %d models on %s", _OWNER, p + 1, n_passes, len(chunk), settings.device
        )

        def report(epoch: int, pass_index: int = p) -> None:
            if progress is not None:
                progress(pass_index * epochs + epoch, n_passes * epochs)

        trained += _train_pass(chunk, X, y, X_dev, y_dev, settings, report)
    return trained


def _train_pass(
    jobs: list[_Job],
    X: np.ndarray,
    y: np.ndarray,
    X_dev: torch.Tensor,
    y_dev: torch.Tensor,
    settings: _PassSettings,
    report: Callable[[int], None],
) -> list[TrainedMLP]:
    """Train one group of models together and collect their results."""
    rngs = [model_rng(settings.seed, job.h1, job.h2, job.split_index) for job in jobs]
    net, x_stats, y_stats = _init_models(jobs, rngs, X, y, settings)
    batches = MiniBatches.build(
        [job.train_idx for job in jobs],
        x_stats,
        y_stats,
        X_dev,
        y_dev,
        batch_size=settings.batch_size,
        device=settings.device,
        dtype=settings.dtype,
    )
    shuffle = None
    if settings.shuffle == "device":
        keys = model_keys(settings.seed, [(job.h1, job.h2, job.split_index) for job in jobs])
        train_idx = [job.train_idx for job in jobs]
        shuffle = DeviceShuffle(train_idx, keys, batches.order.shape[1], settings.device)
    with torch.no_grad():
        losses = run_epochs(
            net,
            batches,
            rngs,
            epochs=settings.epochs,
            learning_rate=settings.learning_rate,
            report=report,
            shuffle=shuffle,
            step=_step_function(net, settings.compile_step),
            cuda_graph=settings.cuda_graph,
        )
        final_loss = final_train_loss(net, batches)
        _check_finite(net, jobs)

    train_loss = final_loss.cpu().numpy()
    loss_curves = losses.cpu().numpy()
    results = []
    for m, job in enumerate(jobs):
        coef, intercept = net.extract(m, job.h1, job.h2)
        (xm, xs), (ym, ys) = x_stats[m], y_stats[m]
        val_pred = mlp_forward(X[job.val_idx], xm, xs, ym, ys, coef, intercept)
        results.append(
            TrainedMLP(
                hidden_sizes=(job.h1, job.h2),
                config_index=job.config_index,
                split_index=job.split_index,
                x_mean=xm,
                x_scale=xs,
                y_mean=ym,
                y_scale=ys,
                coefs=coef,
                intercepts=intercept,
                loss_curve=loss_curves[:, m].copy(),
                train_loss=float(train_loss[m]),
                n_train=int(job.train_idx.size),
                val_index=job.val_idx,
                val_pred_deg=val_pred,
            )
        )
    return results


def _step_function(net: BatchedMLP, compile_step: bool) -> StepFunction:
    """``net.train_step``, compiled with ``torch.compile`` if asked (eager if that fails)."""
    if not compile_step:
        return net.train_step
    compiled = torch.compile(net.train_step, fullgraph=True, dynamic=False)
    state = {"step": compiled}

    def step(*args: Any) -> torch.Tensor:
        try:
            return state["step"](*args)
        except Exception as error:  # any compiler failure: train uncompiled
            if state["step"] is net.train_step:
                raise
            logger.warning("torch.compile of the training step failed (%s); running eagerly", error)
            state["step"] = net.train_step
            return net.train_step(*args)

    return step


def _init_models(
    jobs: list[_Job],
    rngs: list[np.random.Generator],
    X: np.ndarray,
    y: np.ndarray,
    settings: _PassSettings,
) -> tuple[BatchedMLP, list[tuple[np.ndarray, np.ndarray]], list[tuple[float, float]]]:
    """The batched network with each model's initial weights, and each model's standardization.

    Each model draws its weights from its own stream and is standardized with the
    mean and standard deviation of its own training rows.
    """
    d = X.shape[1]
    coefs, intercepts, x_stats, y_stats = [], [], [], []
    for job, rng in zip(jobs, rngs, strict=True):
        c, b = init_parameters(rng, d, job.h1, job.h2)
        coefs.append(c)
        intercepts.append(b)
        x_stats.append(standardization(X[job.train_idx]))
        y_mean, y_scale = standardization(y[job.train_idx])
        y_stats.append((float(y_mean), float(y_scale)))
    net = BatchedMLP(
        coefs,
        intercepts,
        settings.h1_max,
        settings.h2_max,
        device=settings.device,
        dtype=settings.dtype,
    )
    return net, x_stats, y_stats


def _check_finite(net: BatchedMLP, jobs: list[_Job]) -> None:
    """Raise :class:`ConvergenceError` naming the models whose parameters are not finite."""
    finite = torch.ones(len(jobs), dtype=torch.bool, device=net.params[0].device)
    for param in net.params:
        finite &= torch.isfinite(param).flatten(1).all(dim=1)
    bad = np.flatnonzero(~finite.cpu().numpy())
    if bad.size:
        which = ", ".join(
            f"hidden_sizes={(jobs[m].h1, jobs[m].h2)} split={jobs[m].split_index}" for m in bad[:5]
        )
        raise ConvergenceError(
            f"Adam produced non-finite MLP weights for {bad.size} model(s) ({which}); "
            "lower 'learning_rate' or check the scaling of X and y."
        )
