"""How well a fitted NARX model runs free and predicts one step ahead on whole experiments.

Each figure is an NRMSE: the mean over outputs of RMSE / range (the ranges
given, the training outputs' in :func:`~softbend.identification.selection.select_model`),
pooled over every sample after each experiment's initial conditions.
"""

from __future__ import annotations

import numpy as np

from softbend.identification.multi import MultiNARX, nrmse
from softbend.identification.timeseries import TimeSeriesSet

__all__ = ["free_run_error", "one_step_error"]


def free_run_error(
    model: MultiNARX, data: TimeSeriesSet, ranges: np.ndarray
) -> tuple[float, float, np.ndarray]:
    """``(free-run NRMSE, one-step NRMSE, simulated outputs)`` of ``model`` on ``data``.

    Each NRMSE is the mean over outputs of RMSE / range (``ranges``), pooled over
    every sample after each experiment's initial conditions.
    """
    step = one_step_error(model, data, ranges)
    free, simulated = _free_run_only(model, data, ranges)
    return free, step, simulated


def one_step_error(model: MultiNARX, data: TimeSeriesSet, ranges: np.ndarray) -> float:
    """The one-step NRMSE of ``model`` on ``data`` (as :func:`free_run_error`'s)."""
    U, Y, groups = data.stacked()
    scored = _scored(data, model.max_lag)
    one_step = model.predict_one_step(U, Y, groups)
    return float(np.mean(nrmse(Y[scored], one_step[scored], ranges)))


def _free_run_only(
    model: MultiNARX, data: TimeSeriesSet, ranges: np.ndarray
) -> tuple[float, np.ndarray]:
    U, Y, groups = data.stacked()
    scored = _scored(data, model.max_lag)
    simulated = model.simulate(U, Y, groups)
    return float(np.mean(nrmse(Y[scored], simulated[scored], ranges))), simulated


def _scored(data: TimeSeriesSet, lag: int) -> np.ndarray:
    """Every sample after each experiment's ``lag`` initial conditions."""
    scored = np.ones(sum(e.n_samples for e in data.experiments), dtype=bool)
    start = 0
    for e in data.experiments:
        scored[start : start + lag] = False
        start += e.n_samples
    return scored
