"""The epochs of one batched training pass: mini-batch tables, Adam steps, final loss.

:class:`MiniBatches` holds the row tables of M models that each train on their
own rows: model m's rows fill the first ``n_m`` columns of an (M, n_steps * B)
table, the rest is padding with weight 0. :func:`run_epochs` trains a
:class:`~softbend.surrogates.batched_net.BatchedMLP` on them; every epoch each
model visits its rows in the order its own random stream draws (on the host, or
on the device from counter-based keys), and a model whose epoch has run out of
mini-batches is not updated; on a CUDA device the epochs can replay one captured
CUDA graph. :func:`final_train_loss` is each model's MSE on all its rows afterwards.
"""

from __future__ import annotations

import logging
import math
from collections.abc import Callable
from dataclasses import dataclass
from typing import TYPE_CHECKING

import numpy as np

from softbend._torch import require_torch
from softbend.surrogates.batched_net import BatchedMLP
from softbend.surrogates.batched_shuffle import DeviceShuffle

if TYPE_CHECKING:
    import torch
else:
    torch = require_torch("the MLP surrogate (softbend.surrogates)")

logger = logging.getLogger(__name__)

__all__ = ["MiniBatches", "StepFunction", "final_train_loss", "run_epochs"]


@dataclass(frozen=True)
class MiniBatches:
    """The standardized mini-batches of one pass of M models, each over its own rows.

    The row table has shape (M, n_steps * batch_size): model m's rows fill its first
    ``n_train[m]`` columns. ``valid`` (M, columns) is 1 on those and 0 on padding;
    ``counts[s]`` (M,) is each model's rows in step s, clamped to >= 1, and
    ``actives[s]`` whether it has any (once a model's epoch is over, it is not updated).
    """

    X_dev: torch.Tensor
    y_dev: torch.Tensor
    x_mean: torch.Tensor
    x_scale: torch.Tensor
    y_mean: torch.Tensor
    y_scale: torch.Tensor
    valid: torch.Tensor
    counts: torch.Tensor
    actives: torch.Tensor
    n_train: torch.Tensor
    n_steps: int
    batch_size: int
    device: str
    dtype: torch.dtype
    order: np.ndarray
    train_idx: list[np.ndarray]

    @classmethod
    def build(
        cls,
        train_idx: list[np.ndarray],
        x_stats: list[tuple[np.ndarray, np.ndarray]],
        y_stats: list[tuple[float, float]],
        X_dev: torch.Tensor,
        y_dev: torch.Tensor,
        *,
        batch_size: int,
        device: str,
        dtype: torch.dtype,
    ) -> MiniBatches:
        """The tables of models training on ``train_idx`` (rows of ``X_dev``), one per model.

        Parameters
        ----------
        train_idx : list of ndarray of int
            Each model's training rows.
        x_stats, y_stats : list
            Each model's input (mean, scale) arrays and target (mean, scale).
        X_dev, y_dev : torch.Tensor
            All inputs and targets, float64, on ``device``.
        batch_size : int
            Rows per mini-batch.
        device : str
            "cpu" or "cuda".
        dtype : torch.dtype
            Training precision of the batches.
        """
        B = batch_size
        x_mean = torch.tensor(np.stack([s[0] for s in x_stats])[:, None, :], device=device)
        x_scale = torch.tensor(np.stack([s[1] for s in x_stats])[:, None, :], device=device)
        y_mean = torch.tensor([[s[0]] for s in y_stats], dtype=torch.float64, device=device)
        y_scale = torch.tensor([[s[1]] for s in y_stats], dtype=torch.float64, device=device)

        n_train = np.array([idx.size for idx in train_idx])
        n_steps = math.ceil(n_train.max() / B)
        n_cols = n_steps * B
        valid = torch.tensor(
            np.arange(n_cols)[None, :] < n_train[:, None], dtype=dtype, device=device
        )
        # rows of step s for model m: min(B, n_m - s*B), 0 once the model's epoch is over
        counts_np = np.clip(n_train[None, :] - B * np.arange(n_steps)[:, None], 0, B)
        counts = torch.tensor(counts_np, dtype=dtype, device=device)
        actives = torch.tensor(counts_np > 0, device=device)
        return cls(
            X_dev=X_dev,
            y_dev=y_dev,
            x_mean=x_mean,
            x_scale=x_scale,
            y_mean=y_mean,
            y_scale=y_scale,
            valid=valid,
            counts=counts.clamp(min=1.0),
            actives=actives,
            n_train=torch.tensor(n_train, dtype=torch.float64, device=device),
            n_steps=n_steps,
            batch_size=B,
            device=device,
            dtype=dtype,
            order=np.zeros((len(train_idx), n_cols), dtype=np.int64),
            train_idx=list(train_idx),
        )

    def rows(self, rngs: list[np.random.Generator] | None = None) -> torch.Tensor:
        """The row table: each model's training rows, shuffled by its stream if ``rngs``."""
        for m, idx in enumerate(self.train_idx):
            if rngs is None:
                self.order[m, : idx.size] = idx
            else:
                self.order[m, : idx.size] = idx[rngs[m].permutation(idx.size)]
        return torch.from_numpy(self.order).to(self.device)

    def step(
        self, rows_all: torch.Tensor, s: int
    ) -> tuple[torch.Tensor, torch.Tensor, torch.Tensor]:
        """Standardized inputs (M, B, d), target (M, B) and row weights (M, B) of step ``s``."""
        cols = slice(s * self.batch_size, (s + 1) * self.batch_size)
        rows = rows_all[:, cols]
        # index_select gathers the same values as X_dev[rows], with less indexing overhead
        flat = rows.reshape(-1)
        X = self.X_dev.index_select(0, flat).view(*rows.shape, -1)
        y = self.y_dev.index_select(0, flat).view(rows.shape)
        Z = ((X - self.x_mean) / self.x_scale).to(self.dtype)
        target = ((y - self.y_mean) / self.y_scale).to(self.dtype)
        return Z, target, self.valid[:, cols]


#: A step function: (Z, target, weight, count, active, lr, all_active) -> SSE (M,).
StepFunction = Callable[..., torch.Tensor]


def run_epochs(
    net: BatchedMLP,
    batches: MiniBatches,
    rngs: list[np.random.Generator],
    *,
    epochs: int,
    learning_rate: float,
    report: Callable[[int], None],
    shuffle: DeviceShuffle | None = None,
    step: StepFunction | None = None,
    cuda_graph: bool = False,
) -> torch.Tensor:
    """Train ``epochs`` epochs; the training MSE of each, (epochs, M), standardized units.

    Every epoch each model visits its own training rows once, in the order its own
    stream draws; the loss of an epoch sums the squared errors of its mini-batches
    (before the update that used them) over the model's training rows.

    Parameters
    ----------
    shuffle : DeviceShuffle, optional
        Draw the row orders on the device (no host work inside the epoch loop);
        None: each model's NumPy stream in ``rngs`` draws them on the host.
    step : callable, optional
        The mini-batch update, ``net.train_step`` or a compiled version of it.
    cuda_graph : bool, default False
        With ``shuffle`` on a CUDA device: run the first epoch as usual, capture the
        second as one CUDA graph and replay it for every further epoch (one launch
        per epoch instead of thousands). If the capture fails, training goes on
        without it (logged).
    """
    step = step if step is not None else net.train_step
    n_models = len(batches.train_idx)
    device = batches.device
    losses = torch.zeros((epochs, n_models), dtype=torch.float64, device=device)
    all_active = batches.actives.all(dim=1).tolist()  # per step: no model's epoch is over

    def epoch_sse(rows_all: torch.Tensor) -> torch.Tensor:
        sse_epoch = torch.zeros(n_models, dtype=torch.float64, device=device)
        for s in range(batches.n_steps):
            Z, target, valid = batches.step(rows_all, s)
            count, active = batches.counts[s], batches.actives[s]
            sse = step(Z, target, valid, count, active, learning_rate, all_active[s])
            sse_epoch += sse.to(torch.float64)
        return sse_epoch

    if shuffle is None:
        for epoch in range(epochs):
            losses[epoch] = epoch_sse(batches.rows(rngs)) / batches.n_train
            report(epoch + 1)
        return losses

    # The epoch number lives on the device, so that one captured epoch replays as any.
    epoch_now = torch.zeros(1, dtype=torch.int64, device=device)

    def one_epoch() -> None:
        sse_epoch = epoch_sse(shuffle.rows(epoch_now))
        losses.index_copy_(0, epoch_now, (sse_epoch / batches.n_train)[None, :])
        epoch_now.add_(1)

    if not (cuda_graph and device == "cuda"):
        for epoch in range(epochs):
            one_epoch()
            report(epoch + 1)
        return losses
    _run_graphed(one_epoch, epochs, report)
    return losses


def _run_graphed(one_epoch: Callable[[], None], epochs: int, report: Callable[[int], None]) -> None:
    """Run ``one_epoch`` ``epochs`` times: once eagerly, then as replays of a CUDA graph.

    The eager first epoch (on a side stream, as graph capture wants) creates the
    library handles, workspaces and compiled kernels the capture needs; capturing
    records the second epoch without running it. The host waits for every replay
    so that ``report`` tells the truth (the wait costs microseconds per epoch).
    """
    side = torch.cuda.Stream()
    side.wait_stream(torch.cuda.current_stream())
    with torch.cuda.stream(side):
        one_epoch()
    torch.cuda.current_stream().wait_stream(side)
    torch.cuda.synchronize()
    report(1)
    if epochs == 1:
        return
    graph = torch.cuda.CUDAGraph()
    try:
        with torch.cuda.graph(graph):
            one_epoch()
    except RuntimeError as error:  # capture recorded nothing that ran: go on eagerly
        logger.warning("CUDA graph capture failed (%s); training on without it", error)
        torch.cuda.synchronize()
        for epoch in range(1, epochs):
            one_epoch()
            report(epoch + 1)
        return
    for epoch in range(1, epochs):
        graph.replay()
        torch.cuda.current_stream().synchronize()
        report(epoch + 1)


def final_train_loss(net: BatchedMLP, batches: MiniBatches) -> torch.Tensor:
    """MSE of every model on all its training rows in their natural order, standardized units."""
    rows_all = batches.rows()
    sse_final = torch.zeros(len(batches.train_idx), dtype=torch.float64, device=batches.device)
    for s in range(batches.n_steps):
        Z, target, valid = batches.step(rows_all, s)
        out = net.forward(Z)[2]
        residual = (out - target) * valid
        sse_final += (residual * residual).sum(dim=1).to(torch.float64)
    return sse_final / batches.n_train
