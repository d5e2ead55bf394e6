"""Train many normalized MLPs at once in one batched tensor program (paper B §4.1 grid).

A hyperparameter grid with cross-validation is M = (number of configurations) x
(number of folds) small, independent networks. :func:`train_mlp_grid` stacks them:
the weights of all M models live in padded tensors of shape (M, d, H1max),
(M, H1max, H2max) and (M, H2max, 1), every forward and backward product is one
``torch.baddbmm``/``torch.bmm`` over the model axis, and hidden units beyond a
model's own size are masked to zero after the tanh, so they neither contribute to
the output nor receive gradient (they stay exactly at their initial value).

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
that keeps memory at one set of activations and makes the masking explicit. The
random streams come from NumPy (``numpy.random.SeedSequence``), so results do
not depend on torch's global RNG state, and CPU runs with the same seed give
identical weights.
"""

from __future__ import annotations

import logging
import math
import os
import time
from collections.abc import Callable, Iterator, Sequence
from contextlib import contextmanager
from dataclasses import dataclass, field

import numpy as np
from numpy.typing import ArrayLike

from softbend._torch import require_torch
from softbend._validation import check_int, check_range
from softbend.errors import ConvergenceError
from softbend.surrogates.mlp_core import (
    check_hidden_pair,
    init_parameters,
    mlp_forward,
    model_rng,
    resolve_device,
    standardization,
)

torch = require_torch("the MLP surrogate (softbend.surrogates)")

logger = logging.getLogger(__name__)

__all__ = [
    "GridTrainingResult",
    "TrainedMLP",
    "estimate_pass_bytes",
    "train_mlp_grid",
]

_OWNER = "train_mlp_grid"
_BETA1 = 0.9
_BETA2 = 0.999
_EPS = 1e-8
_DTYPES = {"float32": torch.float32, "float64": torch.float64}


# --- validation ------------------------------------------------------------------------


def _check_dtype(dtype: object) -> torch.dtype:
    if dtype in (torch.float32, torch.float64):
        return dtype  # type: ignore[return-value]
    if isinstance(dtype, str) and dtype in _DTYPES:
        return _DTYPES[dtype]
    raise ValueError(
        f"The 'dtype' of {_OWNER} must be one of torch.float32, torch.float64. "
        f"Got {dtype!r} instead."
    )


def _check_data(X: ArrayLike, y: ArrayLike) -> tuple[np.ndarray, np.ndarray]:
    X = np.array(X, dtype=np.float64, copy=True)
    y = np.array(y, dtype=np.float64, copy=True)
    if X.ndim != 2 or X.shape[0] == 0 or X.shape[1] == 0:
        raise ValueError(
            f"The 'X' of {_OWNER} must be a non-empty 2-D array (n_samples, n_features). "
            f"Got shape {X.shape} instead."
        )
    if y.shape != (X.shape[0],):
        raise ValueError(
            f"The 'y' of {_OWNER} must have shape ({X.shape[0]},) to match X. "
            f"Got shape {y.shape} instead."
        )
    for name, array in (("X", X), ("y", y)):
        bad = ~np.isfinite(array)
        if bad.any():
            first = int(np.flatnonzero(bad.ravel())[0])
            raise ValueError(
                f"The '{name}' of {_OWNER} must be finite (no NaN or inf). "
                f"Got {array.ravel()[first]!r} at flat position {first}."
            )
    return X, y


def _check_splits(splits: object, n_samples: int) -> list[tuple[np.ndarray, np.ndarray]]:
    message = (
        f"The 'splits' of {_OWNER} must be a non-empty list of (train_idx, val_idx) pairs of "
        f"integer index arrays in [0, {n_samples}), train_idx non-empty."
    )
    try:
        pairs = list(splits)  # type: ignore[call-overload]
    except TypeError:
        raise ValueError(f"{message} Got {type(splits).__name__} instead.") from None
    if not pairs:
        raise ValueError(f"{message} Got an empty list instead.")
    checked = []
    for k, pair in enumerate(pairs):
        try:
            train, val = pair
        except (TypeError, ValueError):
            raise ValueError(f"{message} Split {k} is {pair!r}.") from None
        arrays = []
        for part, idx in (("train", train), ("val", val)):
            arr = np.asarray(idx)
            if arr.size == 0:
                arr = arr.astype(np.int64)
            if arr.ndim != 1 or arr.dtype.kind not in "iu":
                raise ValueError(
                    f"{message} The {part} indices of split {k} have dtype {arr.dtype} "
                    f"and shape {arr.shape}."
                )
            if arr.size and (arr.min() < 0 or arr.max() >= n_samples):
                raise ValueError(
                    f"{message} The {part} indices of split {k} span [{arr.min()}, {arr.max()}]."
                )
            arrays.append(arr.astype(np.int64))
        if arrays[0].size == 0:
            raise ValueError(f"{message} Split {k} has no training row.")
        checked.append((arrays[0], arrays[1]))
    return checked


# --- per-model pieces -------------------------------------------------------------------


# --- the batched network ----------------------------------------------------------------


class _BatchedMLP:
    """M padded two-hidden-layer tanh networks with hand-written backward pass and Adam.

    Parameters are tensors ``W[l]`` of shape (M, fan_in, fan_out) and biases
    ``b[l]`` of shape (M, 1, fan_out); ``mask1`` (M, 1, H1) and ``mask2`` (M, 1, H2)
    are 1 for a model's real hidden units and 0 for padding.
    """

    def __init__(
        self,
        coefs: Sequence[Sequence[np.ndarray]],
        intercepts: Sequence[Sequence[np.ndarray]],
        h1_max: int,
        h2_max: int,
        *,
        device: str,
        dtype: torch.dtype,
    ) -> None:
        n_models = len(coefs)
        d = coefs[0][0].shape[0]
        shapes = ((d, h1_max), (h1_max, h2_max), (h2_max, 1))
        W = [np.zeros((n_models, *s)) for s in shapes]
        b = [np.zeros((n_models, 1, s[1])) for s in shapes]
        mask1 = np.zeros((n_models, 1, h1_max))
        mask2 = np.zeros((n_models, 1, h2_max))
        for m in range(n_models):
            for layer in range(3):
                rows, cols = coefs[m][layer].shape
                W[layer][m, :rows, :cols] = coefs[m][layer]
                b[layer][m, 0, :cols] = intercepts[m][layer]
            mask1[m, 0, : coefs[m][0].shape[1]] = 1.0
            mask2[m, 0, : coefs[m][1].shape[1]] = 1.0

        def tensor(a: np.ndarray) -> torch.Tensor:
            return torch.tensor(a, dtype=dtype, device=device)

        self.params = [tensor(W[0]), tensor(b[0]), tensor(W[1]), tensor(b[1])]
        self.params += [tensor(W[2]), tensor(b[2])]
        self.mask1, self.mask2 = tensor(mask1), tensor(mask2)
        self.exp_avg = [torch.zeros_like(p) for p in self.params]
        self.exp_avg_sq = [torch.zeros_like(p) for p in self.params]
        self.steps = torch.zeros(n_models, dtype=torch.float64, device=device)

    def forward(self, Z: torch.Tensor) -> tuple[torch.Tensor, torch.Tensor, torch.Tensor]:
        """Hidden activations A1 (M, B, H1), A2 (M, B, H2) and output (M, B)."""
        W1, b1, W2, b2, W3, b3 = self.params
        A1 = torch.baddbmm(b1, Z, W1).tanh_().mul_(self.mask1)
        A2 = torch.baddbmm(b2, A1, W2).tanh_().mul_(self.mask2)
        out = torch.baddbmm(b3, A2, W3).squeeze(-1)
        return A1, A2, out

    def gradients(
        self, Z: torch.Tensor, target: torch.Tensor, weight: torch.Tensor, count: torch.Tensor
    ) -> tuple[list[torch.Tensor], torch.Tensor]:
        """Gradients of each model's mean squared error and its sum of squared errors.

        ``weight`` (M, B) is 1 for a real row and 0 for padding; ``count`` (M,) is the
        model's number of real rows (clamped to >= 1).
        """
        W2, W3 = self.params[2], self.params[4]
        A1, A2, out = self.forward(Z)
        residual = (out - target).mul_(weight)
        sse = (residual * residual).sum(dim=1)
        G = residual.mul_((2.0 / count).unsqueeze(1)).unsqueeze(-1)  # (M, B, 1)
        gW3 = torch.bmm(A2.transpose(1, 2), G)
        gb3 = G.sum(dim=1, keepdim=True)
        dP2 = G * (W3.transpose(1, 2) * self.mask2)  # (M, B, H2); zero on padded units
        dP2.mul_(torch.square(A2).neg_().add_(1.0))
        gW2 = torch.bmm(A1.transpose(1, 2), dP2)
        gb2 = dP2.sum(dim=1, keepdim=True)
        dP1 = torch.bmm(dP2, (W2 * self.mask1.transpose(1, 2)).transpose(1, 2))
        dP1.mul_(torch.square(A1).neg_().add_(1.0))
        gW1 = torch.bmm(Z.transpose(1, 2), dP1)
        gb1 = dP1.sum(dim=1, keepdim=True)
        return [gW1, gb1, gW2, gb2, gW3, gb3], sse

    def adam_step(self, grads: list[torch.Tensor], active: torch.Tensor, lr: float) -> None:
        """One Adam update (torch.optim.Adam's formula) of the active models only."""
        self.steps += active.to(torch.float64)
        steps = self.steps.clamp(min=1.0)
        step_size = lr / (1.0 - _BETA1**steps)
        bc2_sqrt = torch.sqrt(1.0 - _BETA2**steps)
        dtype = self.params[0].dtype
        keep = active.view(-1, 1, 1)
        step_size = step_size.to(dtype).view(-1, 1, 1)
        bc2_sqrt = bc2_sqrt.to(dtype).view(-1, 1, 1)
        for p, m, v, g in zip(self.params, self.exp_avg, self.exp_avg_sq, grads, strict=True):
            m_new = torch.lerp(m, g, 1.0 - _BETA1)
            v_new = (v * _BETA2).addcmul_(g, g, value=1.0 - _BETA2)
            denom = (v_new.sqrt() / bc2_sqrt).add_(_EPS)
            p_new = p - step_size * m_new / denom
            m.copy_(torch.where(keep, m_new, m))
            v.copy_(torch.where(keep, v_new, v))
            p.copy_(torch.where(keep, p_new, p))

    def extract(self, m: int, h1: int, h2: int) -> tuple[list[np.ndarray], list[np.ndarray]]:
        """Model ``m``'s parameters, unpadded, as float64 arrays (contract shapes)."""
        W1, b1, W2, b2, W3, b3 = (p[m].detach().to("cpu", torch.float64) for p in self.params)
        coefs = [W1[:, :h1].numpy().copy(), W2[:h1, :h2].numpy().copy()]
        coefs.append(W3[:h2, :].numpy().copy())
        intercepts = [b1[0, :h1].numpy().copy(), b2[0, :h2].numpy().copy()]
        intercepts.append(b3[0, :].numpy().copy())
        return coefs, intercepts


# --- memory -----------------------------------------------------------------------------


def estimate_pass_bytes(
    n_models: int,
    n_features: int,
    h1_max: int,
    h2_max: int,
    batch_size: int,
    n_rows_max: int,
    itemsize: int = 4,
) -> int:
    """Rough peak memory of one training pass of :func:`train_mlp_grid`, bytes.

    Counts parameters with their gradients, Adam moments and update temporaries,
    the activations and backward temporaries of one (M, B, ·) mini-batch, the
    gathered float64 inputs and the per-epoch (M, n_rows_max) row-index table,
    plus 25 % for allocator slack.

    Parameters
    ----------
    n_models : int
        Models trained at once (M).
    n_features : int
        Inputs per sample (d).
    h1_max, h2_max : int
        Padded hidden layer sizes.
    batch_size : int
        Rows per mini-batch (B).
    n_rows_max : int
        Largest training set of the models, rows.
    itemsize : int
        Bytes per training float (4 for float32, 8 for float64).

    Returns
    -------
    int
        Estimated bytes.
    """
    n_params = n_features * h1_max + h1_max + h1_max * h2_max + 2 * h2_max + 1
    params = 8 * n_models * n_params * itemsize
    rows = n_models * batch_size
    activations = rows * (4 * (h1_max + h2_max) + n_features + 4) * itemsize
    gathered = rows * (2 * n_features + 2) * 8
    n_cols = math.ceil(n_rows_max / batch_size) * batch_size
    index = n_models * n_cols * (2 * 8 + itemsize)
    return int(1.25 * (params + activations + gathered + index))


def _available_bytes(device: str) -> int:
    if device == "cuda":
        return int(torch.cuda.mem_get_info()[0])
    try:
        with open("/proc/meminfo", encoding="ascii") as handle:
            for line in handle:
                if line.startswith("MemAvailable:"):
                    return int(line.split()[1]) * 1024
    except OSError:
        pass
    return int(os.sysconf("SC_PAGE_SIZE") * os.sysconf("SC_AVPHYS_PAGES"))


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
    X, y = _check_data(X, y)
    split_list = _check_splits(splits, X.shape[0])
    try:
        configs = [check_hidden_pair(h, "hidden_sizes", _OWNER) for h in hidden_sizes]
    except TypeError:
        configs = []
    if not configs:
        raise ValueError(
            f"The 'hidden_sizes' of {_OWNER} must be a non-empty list of (h1, h2) pairs of "
            f"positive integers. Got {hidden_sizes!r} instead."
        )
    epochs = check_int(epochs, "epochs", _OWNER, low=1)
    batch_size = check_int(batch_size, "batch_size", _OWNER, low=1)
    learning_rate = check_range(learning_rate, "learning_rate", _OWNER, low=0.0, high=math.inf)
    seed = check_int(seed, "seed", _OWNER, low=0)
    device = resolve_device(device)
    dtype = _check_dtype(dtype)
    if progress is not None and not callable(progress):
        raise ValueError(
            f"The 'progress' of {_OWNER} must be a callable or None. Got {progress!r} instead."
        )
    if max_models_per_pass is not None:
        max_models_per_pass = check_int(max_models_per_pass, "max_models_per_pass", _OWNER, low=1)
    if max_memory_mb is not None:
        max_memory_mb = check_range(max_memory_mb, "max_memory_mb", _OWNER, low=0.0)
    if num_threads is not None:
        num_threads = check_int(num_threads, "num_threads", _OWNER, low=1)

    jobs = [
        _Job(c, s, h1, h2, train, val)
        for c, (h1, h2) in enumerate(configs)
        for s, (train, val) in enumerate(split_list)
    ]
    n_models = len(jobs)
    h1_max = max(h1 for h1, _ in configs)
    h2_max = max(h2 for _, h2 in configs)
    per_pass = n_models if max_models_per_pass is None else min(max_models_per_pass, n_models)
    itemsize = torch.empty((), dtype=dtype).element_size()
    n_rows_max = max(job.train_idx.size for job in jobs)
    budget = 0.8 * _available_bytes(device) if max_memory_mb is None else max_memory_mb * 1024.0**2

    def need(count: int) -> int:
        return estimate_pass_bytes(
            count, X.shape[1], h1_max, h2_max, batch_size, n_rows_max, itemsize
        )

    if need(per_pass) > budget:
        fitting = [k for k in range(per_pass, 0, -1) if need(k) <= budget][:1]
        hint = (
            f"set 'max_models_per_pass' of {_OWNER} to {fitting[0]} or fewer"
            if fitting
            else "even one model does not fit: lower 'batch_size'"
        )
        raise ValueError(
            f"Training {per_pass} MLPs at once needs about {need(per_pass) / 1024**2:.3g} MB "
            f"on {device}, more than the {budget / 1024**2:.3g} MB allowed; {hint} "
            f"(train fewer configurations at a time)."
        )

    X_dev = torch.tensor(X, dtype=torch.float64, device=device)
    y_dev = torch.tensor(y, dtype=torch.float64, device=device)
    n_passes = math.ceil(n_models / per_pass)
    trained: list[TrainedMLP] = []
    start = time.perf_counter()
    with _cpu_settings(num_threads):
        for p in range(n_passes):
            chunk = jobs[p * per_pass : (p + 1) * per_pass]
            logger.debug(
                "%s: pass %d/%d, %d models on %s", _OWNER, p + 1, n_passes, len(chunk), device
            )

            def report(epoch: int, pass_index: int = p) -> None:
                if progress is not None:
                    progress(pass_index * epochs + epoch, n_passes * epochs)

            trained += _train_pass(
                chunk,
                X,
                y,
                X_dev,
                y_dev,
                h1_max=h1_max,
                h2_max=h2_max,
                epochs=epochs,
                batch_size=batch_size,
                learning_rate=learning_rate,
                seed=seed,
                device=device,
                dtype=dtype,
                report=report,
            )
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
        n_passes=n_passes,
        elapsed_s=elapsed,
    )


def _train_pass(
    jobs: list[_Job],
    X: np.ndarray,
    y: np.ndarray,
    X_dev: torch.Tensor,
    y_dev: torch.Tensor,
    *,
    h1_max: int,
    h2_max: int,
    epochs: int,
    batch_size: int,
    learning_rate: float,
    seed: int,
    device: str,
    dtype: torch.dtype,
    report: Callable[[int], None],
) -> list[TrainedMLP]:
    """Train one group of models together and collect their results."""
    n_models, d, B = len(jobs), X.shape[1], batch_size
    rngs = [model_rng(seed, job.h1, job.h2, job.split_index) for job in jobs]
    coefs, intercepts, x_stats, y_stats = [], [], [], []
    for job, rng in zip(jobs, rngs, strict=True):
        c, b = init_parameters(rng, d, job.h1, job.h2)
        coefs.append(c)
        intercepts.append(b)
        x_stats.append(standardization(X[job.train_idx]))
        y_mean, y_scale = standardization(y[job.train_idx])
        y_stats.append((float(y_mean), float(y_scale)))
    net = _BatchedMLP(coefs, intercepts, h1_max, h2_max, device=device, dtype=dtype)

    x_mean = torch.tensor(np.stack([s[0] for s in x_stats])[:, None, :], device=device)
    x_scale = torch.tensor(np.stack([s[1] for s in x_stats])[:, None, :], device=device)
    y_mean = torch.tensor([[s[0]] for s in y_stats], dtype=torch.float64, device=device)
    y_scale = torch.tensor([[s[1]] for s in y_stats], dtype=torch.float64, device=device)

    n_train = np.array([job.train_idx.size for job in jobs])
    n_steps = math.ceil(n_train.max() / B)
    n_cols = n_steps * B
    valid = torch.tensor(np.arange(n_cols)[None, :] < n_train[:, None], dtype=dtype, device=device)
    # rows of step s for model m: min(B, n_m - s*B), 0 once the model's epoch is over
    counts_np = np.clip(n_train[None, :] - B * np.arange(n_steps)[:, None], 0, B)
    counts = torch.tensor(counts_np, dtype=dtype, device=device)
    actives = torch.tensor(counts_np > 0, device=device)
    counts = counts.clamp(min=1.0)
    losses = torch.zeros((epochs, n_models), dtype=torch.float64, device=device)
    n_train_dev = torch.tensor(n_train, dtype=torch.float64, device=device)

    def batch(rows: torch.Tensor) -> tuple[torch.Tensor, torch.Tensor]:
        Z = ((X_dev[rows] - x_mean) / x_scale).to(dtype)
        target = ((y_dev[rows] - y_mean) / y_scale).to(dtype)
        return Z, target

    order = np.zeros((n_models, n_cols), dtype=np.int64)
    with torch.no_grad():
        for epoch in range(epochs):
            for m, (job, rng) in enumerate(zip(jobs, rngs, strict=True)):
                order[m, : job.train_idx.size] = job.train_idx[rng.permutation(job.train_idx.size)]
            rows_all = torch.from_numpy(order).to(device)
            sse_epoch = torch.zeros(n_models, dtype=torch.float64, device=device)
            for s in range(n_steps):
                cols = slice(s * B, (s + 1) * B)
                Z, target = batch(rows_all[:, cols])
                grads, sse = net.gradients(Z, target, valid[:, cols], counts[s])
                net.adam_step(grads, actives[s], learning_rate)
                sse_epoch += sse.to(torch.float64)
            losses[epoch] = sse_epoch / n_train_dev
            report(epoch + 1)

        # final training loss of every model, on all its rows in their natural order
        for m, job in enumerate(jobs):
            order[m, : job.train_idx.size] = job.train_idx
        rows_all = torch.from_numpy(order).to(device)
        sse_final = torch.zeros(n_models, dtype=torch.float64, device=device)
        for s in range(n_steps):
            cols = slice(s * B, (s + 1) * B)
            Z, target = batch(rows_all[:, cols])
            out = net.forward(Z)[2]
            residual = (out - target) * valid[:, cols]
            sse_final += (residual * residual).sum(dim=1).to(torch.float64)
        finite = torch.ones(n_models, dtype=torch.bool, device=device)
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
    train_loss = (sse_final / n_train_dev).cpu().numpy()
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
