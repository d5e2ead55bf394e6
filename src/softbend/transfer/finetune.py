"""Training a fitted MLP further on a few measurements, many variants at once.

Transfer learning trains the same network again and again on small row sets:
one refit per held-out actuator, per learning-curve point, per ensemble
member. Each is a full-batch problem of ~100 rows, where PyTorch's per-call
overhead, not arithmetic, would set the time (about 1 ms per Adam step). So the
K variants are stacked along a leading axis and trained together: one batched
matrix product per layer, one (fused) Adam step for all. Each variant's loss is the
weighted mean over its own rows, and Adam acts element by element, so variant
k ends exactly where training it alone would (up to rounding).

Training stops on a held-out plateau when asked (:class:`EarlyStop`): beside
each variant trains a *shadow*, the same start on the variant's rows less a
seeded share of them, and the shadow's loss on the rows it does not see is
watched. When it has not fallen by ``min_delta`` (relative) for ``patience``
epochs, the variant is stopped and keeps its weights of the shadow's best
epoch; the epochs given are the cap. The variant itself trains on all its rows, so
a variant that never plateaus ends exactly where training without the stop
would, and the shadows ride in the same batched step (one training for every
fold). A stopped variant and its shadow leave the batch (the others' steps are
the same without them), and training ends when every variant has stopped.

On a GPU (``device="cuda"``, or ``"auto"`` where one is seen) the same code runs
with every tensor on the device, in float64 as on the CPU; the loss curve is
gathered there and copied to the host once, after the last epoch, so the epoch
loop never waits for the host.
"""

from __future__ import annotations

from dataclasses import dataclass
from typing import TYPE_CHECKING, Any

import numpy as np
from numpy.typing import ArrayLike

from softbend._progress import every, report
from softbend._validation import check_int, check_range
from softbend.errors import ConvergenceError, InputError
from softbend.limits import check_limit

if TYPE_CHECKING:
    from softbend.surrogates.mlp import NormalizedMLPRegressor

__all__ = [
    "FINE_TUNE_THREADS",
    "EarlyStop",
    "check_mlp",
    "fine_tune_many",
    "fine_tune_mlp",
    "held_out_rows",
    "row_weights",
]

#: Threads of the batched training (at most; fewer if PyTorch has fewer). The
#: stacked variants of a fold set make every step a batch of matrix products
#: large enough to be compute-bound, so two threads pay (``softbend transfer
#: loco`` on the shipped lab: docs/results.md gives the time with one and two).
#: A fixed number, not the machine's core count, so the rounding (and the
#: figures) are the same on every machine with two cores or more.
FINE_TUNE_THREADS = 2


@dataclass(frozen=True)
class EarlyStop:
    """When a batched refit stops before its cap: a plateau of a held-out loss.

    Parameters
    ----------
    patience : int
        Epochs without progress on the held-out rows before a variant stops, >= 1.
    min_delta : float
        Relative fall of the held-out loss that counts as progress, >= 0
        (1e-3: 0.1 % below the best so far).
    validation_share : float
        Share of each variant's rows its shadow does not train on, in (0, 1):
        a seeded draw of the rows (:func:`held_out_rows`).
    seed : int
        Seed of that draw.
    """

    patience: int
    min_delta: float = 1e-3
    validation_share: float = 0.2
    seed: int = 0

    def __post_init__(self) -> None:
        check_int(self.patience, "patience", low=1)
        check_range(self.min_delta, "min_delta", low=0.0, low_inclusive=True)
        check_range(self.validation_share, "validation_share", low=0.0, high=1.0)
        check_int(self.seed, "seed", low=0)


def held_out_rows(n_rows: int, share: float, seed: int) -> np.ndarray:
    """Which of ``n_rows`` rows the shadows of :class:`EarlyStop` hold out (boolean mask).

    One seeded uniform draw per row (stream ``(seed, 13)``), held out below
    ``share``: a row is held out in every variant that has it, whatever the
    batch, so a fold's stop does not depend on the other folds trained beside it.
    """
    return np.random.default_rng([seed, 13]).random(n_rows) < share


def check_mlp(base: object) -> NormalizedMLPRegressor:
    """``base`` if it is a fitted NormalizedMLPRegressor, else :class:`InputError` keyed base.

    The message names the surrogate families a user saves (``mlp``, ``plr``, ...).
    """
    from sklearn.utils.validation import check_is_fitted

    from softbend.surrogates.mlp import NormalizedMLPRegressor
    from softbend.surrogates.persistence import kind_of

    if not isinstance(base, NormalizedMLPRegressor):
        try:
            family = f"a {kind_of(base)} surrogate"
        except InputError:
            family = "a model of no saved family" if base is not None else "none"
        raise InputError(
            f"must be a fitted mlp surrogate: its weights are trained further; got {family}",
            key="base",
        )
    check_is_fitted(base)
    return base


def row_weights(row_sets: list[np.ndarray], n_rows: int) -> np.ndarray:
    """``(K, n_rows)`` counts of each row in each set (a bootstrap draw counts twice)."""
    return np.array([np.bincount(np.asarray(r), minlength=n_rows) for r in row_sets], dtype=float)


def fine_tune_many(
    base: NormalizedMLPRegressor | list[NormalizedMLPRegressor],
    X: ArrayLike,
    y: ArrayLike,
    weights: ArrayLike,
    *,
    epochs: int = 1000,
    learning_rate: float = 6e-4,
    device: str = "auto",
    stop: EarlyStop | None = None,
) -> list[NormalizedMLPRegressor]:
    """Train K copies of a fitted MLP further, full batch, each on its own weighted rows.

    Parameters
    ----------
    base : NormalizedMLPRegressor or list of them
        The starting point of every variant, or one per variant (K of the
        same architecture); each keeps its own standardization. Not modified.
    X : array_like of shape (n, d)
        Rows of :data:`softbend.design.FEATURES` (mm, deg, MPa), finite.
    y : array_like of shape (n,)
        Measured angle, degrees, finite.
    weights : array_like of shape (K, n)
        Non-negative weight of each row in each variant (0: not used; integer
        counts reproduce a draw with repeats); every variant needs a positive sum.
    epochs : int, default 1000
        Adam steps (full batch: one per epoch), >= 1.
    learning_rate : float, default 6e-4
        Adam step size, > 0.
    device : {"auto", "cpu", "cuda"}, default "auto"
        Where to train, as for :class:`~softbend.surrogates.mlp.NormalizedMLPRegressor`:
        "auto" is "cuda" when torch sees a GPU, else "cpu". Recorded as each
        model's ``device_``.
    stop : EarlyStop, optional
        Stop each variant on a plateau of its shadow's held-out loss (module
        docstring), ``epochs`` the cap; None trains every variant ``epochs``
        epochs. A variant with no row held out, or none left to its shadow,
        trains to the cap; a ``patience`` of ``epochs`` or more watches none.

    Returns
    -------
    list of NormalizedMLPRegressor
        K fitted models; each ``loss_curve_`` is its training MSE per epoch in
        the base's standardized units, as for any fitted MLP (times
        ``y_scale_**2``: deg², paper B Fig. 6's unit). Each model's ``epochs``
        is the steps it kept: a variant stopped early keeps its weights of its
        shadow's best epoch, and its curve ends with their loss (``epochs + 1``
        values: the start's, then one per step); one trained to the cap has
        the cap and a curve of that many values, as without a stop.
    """
    from softbend._torch import require_torch
    from softbend.surrogates.mlp import NormalizedMLPRegressor

    torch = require_torch("refining the MLP surrogate")
    from softbend.surrogates.mlp_core import resolve_device

    device = resolve_device(device)
    starts = [check_mlp(b) for b in (base if isinstance(base, list) else [base])]
    first = starts[0]
    epochs = check_int(epochs, "epochs", low=1)
    check_limit("epochs", epochs, "epochs")
    learning_rate = check_range(learning_rate, "learning_rate", low=0.0)
    X = np.asarray(X, dtype=np.float64)
    y = np.asarray(y, dtype=np.float64).ravel()
    w = np.asarray(weights, dtype=np.float64)
    d = first.n_features_in_
    if X.ndim != 2 or X.shape[1] != d or X.shape[0] != y.size or y.size == 0:
        raise InputError(
            f"must have shape (n, {d}) and y shape (n,), n >= 1; got {X.shape} and {y.shape}",
            key="X",
        )
    if not (np.isfinite(X).all() and np.isfinite(y).all()):
        raise InputError("must be finite (no NaN or inf), and so must y", key="X")
    if w.ndim != 2 or w.shape[1] != y.size:
        raise InputError(f"must have shape (K, {y.size}); got {w.shape}", key="weights")
    if not np.isfinite(w).all() or (w < 0).any() or (w.sum(axis=1) <= 0).any():
        raise InputError("must be finite, >= 0, with a positive sum per variant", key="weights")
    k = w.shape[0]
    if len(starts) == 1:
        starts = starts * k
    shapes = {tuple(c.shape for c in m.coefs_) for m in starts}
    if len(starts) != k or len(shapes) != 1:
        raise InputError(
            f"must be one MLP or {k} MLPs of one architecture; got {len(starts)} with layer "
            f"shapes {sorted(shapes)}",
            key="base",
        )
    # The shadows of the watched variants ride after the K variants (module docstring).
    watched = np.zeros(0, dtype=int)
    if stop is not None and stop.patience < epochs:  # else no variant could stop: none watched
        held = held_out_rows(y.size, stop.validation_share, stop.seed)
        shadow_w, check_w = w * ~held, w * held
        watched = np.flatnonzero((shadow_w.sum(axis=1) > 0) & (check_w.sum(axis=1) > 0))
        starts = starts + [starts[i] for i in watched]
        check_w = check_w[watched]
        w = np.vstack([w, shadow_w[watched]])
    m = watched.size
    x_mean = np.array([m.x_mean_ for m in starts])[:, None, :]
    x_scale = np.array([m.x_scale_ for m in starts])[:, None, :]
    y_mean = np.array([m.y_mean_ for m in starts])[:, None]
    y_scale = np.array([m.y_scale_ for m in starts])[:, None]

    threads = torch.get_num_threads()
    torch.set_num_threads(min(threads, FINE_TUNE_THREADS))
    try:
        on = {"dtype": torch.float64, "device": device}
        z = torch.as_tensor((X[None, :, :] - x_mean) / x_scale, **on)  # (K, n, d)
        t = torch.as_tensor((y[None, :] - y_mean) / y_scale, **on)  # (K, n)
        share = torch.as_tensor(w / w.sum(axis=1, keepdims=True), **on)

        def stacked(arrays: list[np.ndarray], bias: bool) -> Any:
            tiled = np.stack(arrays)[:, None, :] if bias else np.stack(arrays)
            return torch.tensor(tiled, **on, requires_grad=True)

        weights_ = [stacked([m.coefs_[i] for m in starts], False) for i in range(3)]
        biases = [stacked([m.intercepts_[i] for m in starts], True) for i in range(3)]
        # Fused Adam: one kernel for the update of all six tensors.
        optimizer = torch.optim.Adam([*weights_, *biases], lr=learning_rate, fused=True)
        curve_t = torch.empty((k, epochs), **on)
        watch = _Watch(torch, stop, check_w, watched, k, on) if m else None
        phase, stride = f"training {k} network{'s' * (k > 1)} (epochs)", every(epochs)
        # The rows of the stack still trained: all (None), or those a stop has not ended.
        active: Any = None
        active_k: Any = None  # the variants among them
        for epoch in range(epochs):
            if active is None:
                zz, tt, ss, ws, bs = z, t, share, weights_, biases
            else:  # the stopped variants and their shadows ride no longer
                zz, tt, ss = z[active], t[active], share[active]
                ws, bs = [p[active] for p in weights_], [b[active] for b in biases]
            a = torch.tanh(zz @ ws[0] + bs[0])
            a = torch.tanh(a @ ws[1] + bs[1])
            out = (a @ ws[2] + bs[2])[..., 0]
            per_variant = (((out - tt) ** 2) * ss).sum(dim=1)
            if watch is not None:
                seen = out.detach()
                if active is not None:
                    seen = seen.new_zeros(t.shape).index_copy_(0, active, seen)
                watch.see(epoch, seen, t, [*weights_, *biases])
            optimizer.zero_grad()
            per_variant.sum().backward()
            optimizer.step()
            if active is None:
                curve_t[:, epoch] = per_variant.detach()[:k]
            else:
                curve_t[active_k, epoch] = per_variant.detach()[: active_k.numel()]
            if (epoch + 1) % stride == 0 or epoch + 1 == epochs:
                report(phase, epoch + 1, epochs)
            if watch is not None and (epoch + 1) % _STOP_CHECK == 0:
                if m == k and watch.done():
                    report(phase, epochs, epochs)  # every variant stopped: the phase is over
                    break
                active = watch.active(k)
                if active is not None:
                    active_k = active[active < k]
        curve = curve_t.cpu().numpy()
        kept = np.full(k, epochs)
        params = [p.detach() for p in (*weights_, *biases)]
        if watch is not None:
            kept, params = watch.kept(epochs, params)
    finally:
        torch.set_num_threads(threads)
    coefs = [p[:k].cpu().numpy() for p in params[:3]]
    intercepts = [p[:k].cpu().numpy()[:, 0, :] for p in params[3:]]
    if not all(np.isfinite(a).all() for a in (*coefs, *intercepts)):
        raise ConvergenceError("the refit produced non-finite weights; lower the learning_rate")
    return [
        NormalizedMLPRegressor.from_arrays(
            x_mean=starts[i].x_mean_,
            x_scale=starts[i].x_scale_,
            y_mean=starts[i].y_mean_,
            y_scale=starts[i].y_scale_,
            coefs=[c[i].copy() for c in coefs],
            intercepts=[b[i].copy() for b in intercepts],
            loss_curve=(curve[i] if kept[i] == epochs else curve[i, : kept[i] + 1]).tolist(),
            fitted_device=device,
            epochs=max(int(kept[i]), 1),
            batch_size=max(int(np.count_nonzero(w[i])), 1),
            learning_rate=learning_rate,
            seed=0,
        )
        for i in range(k)
    ]


#: Epochs between two looks at whether every variant has stopped (a look waits for the device).
_STOP_CHECK = 25


class _Watch:
    """The held-out losses of the shadows, and each watched variant's weights at its shadow's
    best epoch (:class:`EarlyStop`); tensors only, so the epoch loop never waits for the host.
    """

    def __init__(
        self, torch: Any, stop: Any, check_w: np.ndarray, watched: np.ndarray, k: int, on: Any
    ) -> None:
        self.torch, self.k = torch, k
        self.patience, self.factor = int(stop.patience), 1.0 - float(stop.min_delta)
        self.share = torch.as_tensor(check_w / check_w.sum(axis=1, keepdims=True), **on)
        self.watched = torch.as_tensor(watched, dtype=torch.long, device=on["device"])
        m = watched.size
        self.best = torch.full((m,), float("inf"), **on)
        self.best_epoch = torch.zeros(m, dtype=torch.long, device=on["device"])
        self.stale = torch.zeros(m, dtype=torch.long, device=on["device"])
        self.running = torch.ones(m, dtype=torch.bool, device=on["device"])
        self.snaps: list[Any] | None = None

    def see(self, epoch: int, out: Any, t: Any, params: list[Any]) -> None:
        """Score the shadows on their held-out rows (weights after ``epoch`` steps)."""
        torch = self.torch
        with torch.no_grad():
            loss = (((out[self.k :] - t[self.k :]) ** 2) * self.share).sum(dim=1)
            better = self.running & (loss < self.best * self.factor)
            self.best = torch.where(better, loss, self.best)
            self.best_epoch = torch.where(better, epoch, self.best_epoch)
            self.stale = torch.where(better, 0, self.stale + 1)
            mine = [p[self.watched] for p in params]
            if self.snaps is None:
                self.snaps = [p.clone() for p in mine]
            else:
                self.snaps = [
                    torch.where(better[:, None, None], p, s)
                    for p, s in zip(mine, self.snaps, strict=True)
                ]
            self.running &= self.stale < self.patience

    def done(self) -> bool:
        """Whether every watched variant has stopped."""
        return not bool(self.running.any())

    def active(self, k: int) -> Any:
        """The rows of the stack (``k`` variants, then the shadows) still to train, in order;
        None while every one is. A stopped variant keeps its snapshot, so neither it nor its
        shadow needs another step; a variant no shadow watches trains to the cap."""
        torch = self.torch
        keep = torch.ones(k + self.watched.numel(), dtype=torch.bool, device=self.running.device)
        keep[self.watched[~self.running]] = False
        keep[k:] = self.running
        if bool(keep.all()):
            return None
        return torch.nonzero(keep).flatten()

    def kept(self, epochs: int, params: list[Any]) -> tuple[np.ndarray, list[Any]]:
        """Steps each variant keeps and the weights: a stopped one's at its shadow's best."""
        kept = np.full(self.k, epochs)
        stopped = ~self.running.cpu().numpy()
        rows = self.watched.cpu().numpy()[stopped]
        kept[rows] = self.best_epoch.cpu().numpy()[stopped]
        out = []
        for p, snap in zip(params, self.snaps or [], strict=True):
            p = p.clone()
            p[rows] = snap[self.torch.as_tensor(stopped, device=p.device)]
            out.append(p)
        return kept, out


def fine_tune_mlp(
    base: NormalizedMLPRegressor,
    X: ArrayLike,
    y: ArrayLike,
    *,
    epochs: int = 1000,
    learning_rate: float = 6e-4,
    device: str = "auto",
) -> NormalizedMLPRegressor:
    """Train every layer of a fitted MLP further on new rows (full batch), scaling kept.

    :func:`fine_tune_many` with one variant holding every row once. Paper B's
    batches of 1024 rows are larger than any set of measurements, so a batch
    is the whole set, as here. ``device`` as for :func:`fine_tune_many`.

    Returns
    -------
    NormalizedMLPRegressor
        A new fitted model (``loss_curve_`` in standardized units).
    """
    y = np.asarray(y, dtype=np.float64).ravel()
    return fine_tune_many(
        base,
        X,
        y,
        np.ones((1, y.size)),
        epochs=epochs,
        learning_rate=learning_rate,
        device=device,
    )[0]
