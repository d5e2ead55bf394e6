"""The free run of a NARX model, every experiment stepped together, per-step work hoisted.

A free run is a recursion in time: the outputs at t feed the regressor at t+1,
so the steps cannot be batched, but everything that does not depend on the
simulated outputs can be done once before the loop. :func:`free_run` lays the
experiments out as one array of regressors ``(steps, experiments, d)``, the
experiments ordered longest first, so the experiments still running at a step
are a leading slice of it (no index arrays per step); the input part of every
regressor and the initial conditions are written before the loop, and each
step only evaluates the maps on its slice, clips the outputs to the free run's
bounds and writes them into the ``na`` later regressors that read them.

Non-finite outputs are handled once: a map of finite regressors with finite
parameters gives finite outputs, so the loop clips without looking for NaN; a
run that ends with a NaN anywhere is run again with every step's NaN set to 0
before the clip (what the step-by-step loop always did), so the result is the
same in both cases. :func:`_step_by_step` is that loop as it was, kept as the
reference the tests and the benchmark compare against.
"""

from __future__ import annotations

from collections.abc import Callable, Sequence

import numpy as np

__all__ = ["free_run"]

#: One step of the maps: regressor rows (r, d) → outputs (r, m), a new array.
StepMap = Callable[[np.ndarray], np.ndarray]


def free_run(
    step: StepMap,
    Us: np.ndarray,
    Ys: np.ndarray,
    segments: tuple[np.ndarray, np.ndarray],
    lags: tuple[int, int],
    bounds: tuple[np.ndarray, np.ndarray],
) -> np.ndarray:
    """Run the maps free over every experiment (standardized units).

    Parameters
    ----------
    step : callable
        ``step(Phi)``: the outputs (r, m) of the regressor rows ``Phi`` (r, d), a new array.
    Us : ndarray, shape (n, k)
        Inputs (standardized, filtered if the model filters them), experiments concatenated.
    Ys : ndarray, shape (n, m)
        Outputs whose first ``max(na, nb − 1)`` samples of each experiment are the
        initial conditions (the rest is not read).
    segments : (starts, lengths)
        First row and length of each experiment, each at least ``max_lag + 1`` long.
    lags : (na, nb)
        Output and input lags of the regressor ``[y(t−1) … y(t−na), u(t) … u(t−nb+1)]``.
    bounds : (low, high)
        Each output's bounds (m,); every simulated output is clipped to them.

    Returns
    -------
    ndarray, shape (n, m)
        The initial conditions copied, every other sample simulated.
    """
    out = _run(step, Us, Ys, segments, lags, bounds, safe=False)
    if np.isnan(out).any():
        out = _run(step, Us, Ys, segments, lags, bounds, safe=True)
    return out


def _run(
    step: StepMap,
    Us: np.ndarray,
    Ys: np.ndarray,
    segments: tuple[np.ndarray, np.ndarray],
    lags: tuple[int, int],
    bounds: tuple[np.ndarray, np.ndarray],
    *,
    safe: bool,
) -> np.ndarray:
    starts, lengths = (np.asarray(s, dtype=np.int64) for s in segments)
    na, nb = lags
    lag = max(na, nb - 1)
    low, high = bounds
    m = Ys.shape[1]
    result = np.array(Ys, dtype=np.float64, copy=True)
    if starts.size == 0:
        return result
    order = np.argsort(-lengths, kind="stable")
    steps = int(lengths.max())
    d = na * m + nb * Us.shape[1]
    phi = np.zeros((steps, order.size, d))
    for column, e in enumerate(order):
        t = starts[e] + np.arange(lag, lengths[e])
        blocks = [Ys[t - q] for q in range(1, na + 1)] + [Us[t - q] for q in range(nb)]
        phi[lag : lengths[e], column] = np.hstack(blocks)
    running = (lengths[order][None, :] > np.arange(steps)[:, None]).sum(axis=1).tolist()
    simulated = np.zeros((steps, order.size, m))
    with np.errstate(all="ignore"):
        for s in range(lag, steps):
            r = running[s]
            new = step(phi[s, :r])
            if safe:
                new = np.nan_to_num(new, nan=0.0)
            np.minimum(new, high, out=new)
            np.maximum(new, low, out=new)
            simulated[s, :r] = new
            for q in range(1, min(na, steps - 1 - s) + 1):
                phi[s + q, :r, (q - 1) * m : q * m] = new
    for column, e in enumerate(order):
        result[starts[e] + lag : starts[e] + lengths[e]] = simulated[lag : lengths[e], column]
    return result


def _step_by_step(
    maps: Sequence[Callable[[np.ndarray], np.ndarray]],
    Us: np.ndarray,
    Ys: np.ndarray,
    segments: tuple[np.ndarray, np.ndarray],
    lags: tuple[int, int],
    bounds: tuple[np.ndarray, np.ndarray],
) -> np.ndarray:
    """The free run as it was computed before :func:`free_run`: index arrays, regressors
    and NaN handling rebuilt at every step, one map call per output (the reference)."""
    starts, lengths = (np.asarray(s, dtype=np.int64) for s in segments)
    na, nb = lags
    lag = max(na, nb - 1)
    low, high = bounds
    Ys = np.array(Ys, dtype=np.float64, copy=True)
    for step in range(lag, int(lengths.max(initial=0))):
        t = starts[lengths > step] + step
        Phi = np.hstack([Ys[t - k] for k in range(1, na + 1)] + [Us[t - k] for k in range(nb)])
        with np.errstate(all="ignore"):
            new = np.column_stack([f(Phi) for f in maps])
        Ys[t] = np.clip(np.nan_to_num(new, nan=0.0), low, high)
    return Ys
