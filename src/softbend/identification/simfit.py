"""NARX maps fitted by simulation (free-run) error, with optional first-order input filters.

A NARX model fitted one step ahead minimises the error of each step with the
measured past fed in; run free, its own errors feed back and accumulate, and
that is never what its fit saw. The families of
:data:`~softbend.identification.simmaps.SIM_FAMILIES` start from the one-step
least-squares fit and then minimise the free-run error itself, by
backpropagation through the run (PyTorch, float64, one thread, seeded):

- ``arx-sim``, ``poly2-sim``: the linear and degree-2 polynomial maps of
  :class:`~softbend.identification.multi.MultiNARX` (the same features), their
  coefficients refined;
- ``nn-sim``: per output, the linear ARX map plus one hidden layer of ``hidden``
  tanh units, ``y = φ·w + c + tanh(W φ + b)·v``; its start is a one-step fit
  (linear part by least squares, then ``pretrain`` Adam steps on the one-step
  error of at most 5000 rows), its run refined as the others.

Adam's step size ``lr`` defaults to the family's
:data:`~softbend.identification.simmaps.DEFAULT_LR`.

Each update of Adam runs ``batch`` windows of ``window`` samples free, all
together, each window started from the measured outputs of its first
``max_lag`` samples (multiple shooting); windows are drawn, seeded, anywhere in
the training experiments, so an update costs the same whatever the length of
the recording. There are at most ``steps`` updates, and fewer when they would
run more than ``epochs`` times as many samples as the training rows (a short
recording is not overfitted). Every 10 updates the free-run error of a fixed set of training
windows is measured; the parameters with the lowest (the start included) are
kept, and training stops after 5 checks without improvement. ``steps=0``
leaves the one-step fit.

With ``filter=True`` every input first passes a first-order low-pass of unit
gain, ``u_f(t) = a·u_f(t−1) + (1−a)·u(t)``, ``a = exp(−1/τ)``, started at rest
(``u_f = u`` at each experiment's first sample): the lag between a commanded
pressure and the chamber's. Its time constant τ (in samples, at most
:data:`~softbend.identification.simmaps.MAX_TAU_SAMPLES`) is estimated with the
map, from ``tau_init``; by
default (``tau_init=None``) from the time constant, one for all inputs,
whose one-step fit runs free best over the first 200 samples of each training
experiment (:data:`~softbend.identification.multi.TAU_GRID`, then a golden-section
search in log τ).

A fitted model is evaluated with NumPy alone
(:mod:`softbend.identification.simmaps`); PyTorch is needed only to fit.
"""

from __future__ import annotations

import math
from dataclasses import dataclass
from typing import Any

import numpy as np

from softbend.identification.simmaps import MAX_TAU_SAMPLES, NeuralMap

__all__ = ["Refined", "Start", "refine"]

_CHECK_EVERY = 10
_PATIENCE = 5
_MONITOR_WINDOWS = 64
_PRETRAIN_ROWS = 5000
_TAU_LR = 0.03


@dataclass
class Start:
    """The one-step fit a refinement starts from (standardized units).

    ``coef`` (p, m) and ``intercept`` (m,) of the polynomial (degree 1 or 2) or,
    for ``nn-sim``, of its linear part.
    """

    degree: int
    coef: np.ndarray
    intercept: np.ndarray


@dataclass
class Refined:
    """What :func:`refine` returns: the maps' parameters, the input time constants."""

    coef: np.ndarray
    intercept: np.ndarray
    neural: list[NeuralMap] | None
    tau: np.ndarray | None
    steps_run: int
    start_loss: float
    loss: float


def _features(torch: Any, phi: Any, degree: int, pairs: tuple[Any, Any]) -> Any:
    if degree == 1:
        return phi
    i, j = pairs
    return torch.cat([phi, phi[:, i] * phi[:, j]], dim=1)


class _Trainer:
    """Windows of the training data, the parameters, and one free run of a batch."""

    def __init__(
        self,
        torch: Any,
        family: str,
        settings: dict[str, Any],
        Us: np.ndarray,
        Ys: np.ndarray,
        starts: np.ndarray,
        lengths: np.ndarray,
        lags: tuple[int, int],
        bounds: tuple[np.ndarray, np.ndarray],
        start: Start,
        tau: np.ndarray | None,
    ) -> None:
        self.torch, self.family, self.settings = torch, family, settings
        self.na, self.nb = lags
        self.lag = max(self.na, self.nb - 1)
        f64 = torch.float64
        self.U = torch.tensor(Us, dtype=f64)
        self.Y = torch.tensor(Ys, dtype=f64)
        self.low = torch.tensor(bounds[0], dtype=f64)
        self.high = torch.tensor(bounds[1], dtype=f64)
        self.degree = start.degree
        d = self.na * Ys.shape[1] + self.nb * Us.shape[1]
        self.pairs = tuple(torch.tensor(x) for x in np.triu_indices(d))
        self.coef = torch.tensor(start.coef, dtype=f64, requires_grad=True)
        self.intercept = torch.tensor(start.intercept, dtype=f64, requires_grad=True)
        self.params = [self.coef, self.intercept]
        self.hidden = None
        if family == "nn-sim":
            m, h = Ys.shape[1], settings["hidden"]
            gen = torch.Generator().manual_seed(settings["seed"])
            W = torch.randn(d, m * h, generator=gen, dtype=f64) / math.sqrt(d)
            b = (torch.rand(m * h, generator=gen, dtype=f64) * 2 - 1) * 0.5
            v = torch.zeros(m, h, dtype=f64)
            self.hidden = [t.requires_grad_(True) for t in (W, b, v)]
            self.params += self.hidden
        self.theta = None
        if tau is not None:
            # τ = softplus(θ) samples, θ from τ_init (a τ of 0 starts just above it)
            t0 = np.maximum(tau, 1e-3)
            self.theta = torch.tensor(np.log(np.expm1(t0)), dtype=f64, requires_grad=True)
            self.params.append(self.theta)
        # windows: experiments long enough, starts drawn in proportion to their count
        self.length = int(min(settings["window"] + self.lag, lengths.max()))
        ok = lengths >= self.length
        self.win_starts = starts[ok]
        self.win_counts = lengths[ok] - self.length + 1
        self.exp_of_row = np.repeat(np.arange(len(starts)), lengths)
        self.exp_start = starts

    def draw(self, rng: np.random.Generator, count: int) -> np.ndarray:
        """Start rows of ``count`` windows (seeded)."""
        p = self.win_counts / self.win_counts.sum()
        which = rng.choice(len(self.win_starts), size=count, p=p)
        return self.win_starts[which] + (rng.random(count) * self.win_counts[which]).astype(int)

    def tau(self) -> Any:
        torch = self.torch
        return torch.clamp(torch.nn.functional.softplus(self.theta), max=MAX_TAU_SAMPLES)

    def _inputs(self, rows: Any, first: Any) -> Any:
        """Standardized inputs (filtered if so) at ``rows`` (B, L); ``first``: experiment starts."""
        torch = self.torch
        if self.theta is None:
            return self.U[rows]
        tau = self.tau()
        a = torch.exp(-1.0 / torch.clamp(tau, min=1e-3))
        taps = int(min(math.ceil(12.0 * float(tau.detach().max())) + 1, 12 * MAX_TAU_SAMPLES))
        j = torch.arange(taps + 1)
        # u_f(r) = Σ_{j<K} (1−a) a^j u(r−j) + a^K u(r−K), rows before the start held at u(start)
        index = torch.maximum(rows[:, :, None] - j, first[:, None, None])
        weights = (1 - a)[None, :] * a[None, :] ** j[:-1, None].to(a.dtype)
        weights = torch.cat([weights, a[None, :] ** taps], dim=0)  # (K+1, k)
        return torch.einsum("blkc,kc->blc", self.U[index], weights)

    def _map(self, phi: Any) -> Any:
        torch = self.torch
        y = _features(torch, phi, self.degree, self.pairs) @ self.coef + self.intercept
        if self.hidden is not None:
            W, b, v = self.hidden
            h = torch.tanh(phi @ W + b).reshape(phi.shape[0], *v.shape)
            y = y + (h * v).sum(dim=2)
        return y

    def run(self, window_starts: np.ndarray) -> Any:
        """Mean squared free-run error (standardized) of the windows starting at those rows."""
        torch = self.torch
        rows = torch.as_tensor(window_starts)[:, None] + torch.arange(self.length)
        first = torch.as_tensor(self.exp_start[self.exp_of_row[window_starts]])
        U = self._inputs(rows, first)
        Y = self.Y[rows]
        lag, L = self.lag, self.length
        history = [Y[:, lag - i] for i in range(1, self.na + 1)]
        block = torch.cat([U[:, lag - j : L - j] for j in range(self.nb)], dim=2)
        outputs = []
        for step in range(L - lag):
            y = self._map(torch.cat([*history, block[:, step]], dim=1))
            y = torch.clamp(y, self.low, self.high)
            outputs.append(y)
            history = [y, *history[:-1]]
        return ((torch.stack(outputs, dim=1) - Y[:, lag:]) ** 2).mean()

    def snapshot(self) -> list[Any]:
        return [p.detach().clone() for p in self.params]

    def restore(self, values: list[Any]) -> None:
        with self.torch.no_grad():
            for p, v in zip(self.params, values, strict=True):
                p.copy_(v)


def _pretrain(trainer: _Trainer, Phi: np.ndarray, target: np.ndarray, steps: int) -> None:
    """Adam on the one-step error of the neural part (at most 5000 rows)."""
    torch = trainer.torch
    rng = np.random.default_rng([trainer.settings["seed"], 1])
    if len(Phi) > _PRETRAIN_ROWS:
        keep = np.sort(rng.choice(len(Phi), _PRETRAIN_ROWS, replace=False))
        Phi, target = Phi[keep], target[keep]
    X = torch.tensor(Phi, dtype=torch.float64)
    T = torch.tensor(target, dtype=torch.float64)
    assert trainer.hidden is not None  # the neural map has its hidden layer
    optimizer = torch.optim.Adam([*trainer.hidden, trainer.coef, trainer.intercept], lr=0.01)
    for _ in range(steps):
        optimizer.zero_grad()
        loss = ((trainer._map(X) - T) ** 2).mean()
        loss.backward()
        optimizer.step()


def refine(
    family: str,
    settings: dict[str, Any],
    Us: np.ndarray,
    Ys: np.ndarray,
    segments: tuple[np.ndarray, np.ndarray],
    lags: tuple[int, int],
    bounds: tuple[np.ndarray, np.ndarray],
    start: Start,
    tau: np.ndarray | None = None,
    one_step: tuple[np.ndarray, np.ndarray] | None = None,
) -> Refined:
    """Refine a one-step fit by its free-run error over windows of the training data.

    Parameters
    ----------
    family : {"arx-sim", "poly2-sim", "nn-sim"}
    settings : dict
        :func:`~softbend.identification.simmaps.check_sim_params`'s settings.
    Us, Ys : ndarray
        Standardized, unfiltered inputs (n, k) and outputs (n, m).
    segments : (starts, lengths)
        The experiments' first rows and lengths.
    lags : (na, nb)
    bounds : (low, high)
        The free run's standardized bounds, each (m,).
    start : Start
        The one-step least-squares fit (on inputs filtered with ``tau``).
    tau : ndarray, shape (k,), optional
        The input filters' time constants to start from, in samples; None: no filter.
    one_step : (Phi, target), optional
        One-step regressor rows and targets (``nn-sim``'s pretraining).

    Returns
    -------
    Refined
    """
    from softbend._torch import require_torch

    torch = require_torch("fitting a NARX model by simulation error")
    threads = torch.get_num_threads()
    torch.set_num_threads(1)
    try:
        starts, lengths = (np.asarray(s, dtype=np.int64) for s in segments)
        trainer = _Trainer(
            torch, family, settings, Us, Ys, starts, lengths, lags, bounds, start, tau
        )
        return _refine(trainer, settings, int(lengths.sum()), one_step)
    finally:
        torch.set_num_threads(threads)


def _refine(
    trainer: _Trainer,
    settings: dict[str, Any],
    n_rows: int,
    one_step: tuple[np.ndarray, np.ndarray] | None,
) -> Refined:
    """:func:`refine` on a built trainer; ``n_rows``: the training rows, for the budget."""
    torch = trainer.torch
    torch.manual_seed(settings["seed"])
    if trainer.hidden is not None and one_step is not None:
        _pretrain(trainer, one_step[0], one_step[1], settings["pretrain"])
    rng = np.random.default_rng([settings["seed"], 2])
    monitor = trainer.draw(rng, max(_MONITOR_WINDOWS, settings["batch"]))
    with torch.no_grad():
        best_loss = start_loss = float(trainer.run(monitor))
    best, stale, steps_run = trainer.snapshot(), 0, 0
    groups: list[dict[str, Any]] = [
        {"params": [p for p in trainer.params if p is not trainer.theta]}
    ]
    if trainer.theta is not None:  # a time constant moves by samples, not by fractions
        groups.append({"params": [trainer.theta], "lr": _TAU_LR})
    optimizer = torch.optim.Adam(groups, lr=settings["lr"])
    # at most `epochs` passes over the training rows: a short recording gets fewer updates
    per_step = settings["batch"] * (trainer.length - trainer.lag)
    budget = min(settings["steps"], math.ceil(settings["epochs"] * n_rows / per_step))
    for step in range(1, budget + 1):
        optimizer.zero_grad()
        loss = trainer.run(trainer.draw(rng, settings["batch"]))
        if torch.isfinite(loss):
            loss.backward()
            optimizer.step()
        steps_run = step
        if step % _CHECK_EVERY and step != budget:
            continue
        with torch.no_grad():
            checked = float(trainer.run(monitor))
        if checked < best_loss:
            best_loss, best, stale = checked, trainer.snapshot(), 0
        else:
            stale += 1
            if stale >= _PATIENCE:
                break
    trainer.restore(best)
    neural = None
    if trainer.hidden is not None:
        W, b, v = (p.detach().numpy() for p in trainer.hidden)
        m, h = v.shape
        coef = trainer.coef.detach().numpy()
        icpt = trainer.intercept.detach().numpy()
        neural = [
            NeuralMap(
                coef[:, o].copy(),
                float(icpt[o]),
                W[:, o * h : (o + 1) * h].T.copy(),
                b[o * h : (o + 1) * h].copy(),
                v[o].copy(),
            )
            for o in range(m)
        ]
    tau_fitted = None if trainer.theta is None else trainer.tau().detach().numpy().copy()
    return Refined(
        coef=trainer.coef.detach().numpy().copy(),
        intercept=trainer.intercept.detach().numpy().copy(),
        neural=neural,
        tau=tau_fitted,
        steps_run=steps_run,
        start_loss=start_loss,
        loss=best_loss,
    )
