"""Accuracy and speed of a surrogate: R², RMSE, MAPE, maximum error, inference time.

MAPE treats angles near 0° as paper B cannot: a percentage of a 0.01° angle is
meaningless, so readings with ``|θ|`` below a floor are left out of the MAPE and
counted (:func:`softbend.metrics.thresholded_mape`). The floor is by default
:func:`softbend.metrics.mape_floor` of the readings, max(5°, 5 % of the largest
``|θ|``); paper B's own figures (§4.1) are compared under its definition,
:data:`PAPER_B_MAPE_FLOOR_DEG` (1°: the 0 MPa readings left out,
:func:`mape_floor_deg`). When no reading reaches the floor the MAPE is undefined
(NaN here; null with a reason in JSON, a dash in tables). The other metrics use
every reading.
"""

from __future__ import annotations

import time
from collections.abc import Callable
from typing import TYPE_CHECKING, Any

import numpy as np
from numpy.typing import ArrayLike

from softbend.metrics import mape_floor, r2, rmse, thresholded_mape
from softbend.surrogates.protocol import Surrogate

if TYPE_CHECKING:
    from softbend.actuators import Actuator

#: Paper B's MAPE, as softbend compares with its §4.1 figures: every reading but the 0 MPa
#: ones (``|θ| >= 1°``), degrees.
PAPER_B_MAPE_FLOOR_DEG = 1.0
#: Former name of :data:`PAPER_B_MAPE_FLOOR_DEG`.
MAPE_THRESHOLD_DEG = PAPER_B_MAPE_FLOOR_DEG


def mape_floor_deg(y: ArrayLike, actuator: Actuator | None = None) -> float:
    """The MAPE floor of a table's angles ``y`` (degrees) for ``actuator``.

    An actuator with a fixed floor keeps it (its
    :attr:`~softbend.actuators.Actuator.mape_floor_deg`: paper B's,
    :data:`PAPER_B_MAPE_FLOOR_DEG`, so that its figures stay comparable with paper
    B §4.1, MLP 0.89 %, XGBoost 0.8 %); None is paper B's actuator (a campaign of
    it). Any other actuator gets :func:`softbend.metrics.mape_floor`: max(5°, 5 %
    of the largest ``|y|``).
    """
    from softbend.actuators import SFRBA

    fixed = (actuator or SFRBA).mape_floor_deg
    return mape_floor(y) if fixed is None else float(fixed)


def mape_text(floor_deg: float) -> str:
    """The column title of a MAPE over the readings at or above ``floor_deg``."""
    return f"MAPE % (|θ| ≥ {floor_deg:.3g}°)"


def accuracy(
    y_true: ArrayLike, y_pred: ArrayLike, *, mape_threshold_deg: float | None = None
) -> dict[str, float]:
    """Accuracy of predicted bending angles.

    Parameters
    ----------
    y_true, y_pred : array_like, shape (n,)
        Observed and predicted angles, degrees.
    mape_threshold_deg : float, optional
        The MAPE floor: smallest ``|y_true|`` in the MAPE, degrees (default
        :func:`softbend.metrics.mape_floor` of ``y_true``, max(5°, 5 % of its
        largest ``|θ|``)). Score folds of one data set with one floor.

    Returns
    -------
    dict
        ``r2``, ``rmse_deg``, ``mape_pct`` (NaN when no reading reaches the
        floor), ``max_abs_error_deg``, ``n``, ``n_mape_excluded`` (readings
        below the floor), ``n_mape_used`` and ``mape_floor_deg``.
    """
    y_true = np.asarray(y_true, dtype=float).ravel()
    y_pred = np.asarray(y_pred, dtype=float).ravel()
    floor = mape_floor(y_true) if mape_threshold_deg is None else float(mape_threshold_deg)
    mape, excluded = thresholded_mape(y_true, y_pred, threshold=floor)
    return {
        "r2": r2(y_true, y_pred),
        "rmse_deg": rmse(y_true, y_pred),
        "mape_pct": mape,
        "max_abs_error_deg": float(np.max(np.abs(y_pred - y_true))),
        "n": int(y_true.size),
        "n_mape_excluded": excluded,
        "n_mape_used": int(y_true.size - excluded),
        "mape_floor_deg": floor,
    }


def _median_time(call: Callable[[], Any], *, repeats: int, number: int) -> float:
    """Median over ``repeats`` of the mean time of ``number`` calls, s."""
    times = []
    for _ in range(repeats):
        start = time.perf_counter()
        for _ in range(number):
            call()
        times.append((time.perf_counter() - start) / number)
    return float(np.median(times))


def inference_time(
    model: Surrogate, X: ArrayLike, *, batch: int = 10_000, repeats: int = 5, seed: int = 0
) -> dict[str, float]:
    """Inference time of a fitted surrogate for one sample and for a batch.

    The single-sample figure uses the model's fast path ``predictor()`` when it
    has one (what a control loop calls), else ``predict`` on one row; both are
    reported when they differ.

    Parameters
    ----------
    model : fitted estimator
        Anything with ``predict(X)``; optionally ``predictor()``.
    X : array_like, shape (n, 7)
        Inputs to draw samples from (rows are resampled to fill the batch).
    batch : int
        Batch size for the batch figure (default 10 000).
    repeats : int
        Timing repeats; the median is reported.
    seed : int
        Seed of the row resampling.

    Returns
    -------
    dict
        ``single_us`` (fast path or predict), ``single_predict_us`` (``predict``
        on one row) and ``batch_ms`` (``predict`` on ``batch`` rows), plus
        ``batch`` and ``fast_path`` (bool).
    """
    X = np.asarray(X, dtype=float)
    rng = np.random.default_rng(seed)
    rows = X[rng.integers(0, X.shape[0], size=batch)]
    one = np.ascontiguousarray(rows[:1])
    sample = one[0].copy()
    predict_one = _median_time(lambda: model.predict(one), repeats=repeats, number=20)
    fast = getattr(model, "predictor", None)
    if callable(fast):
        f = fast()
        f(sample)  # warm up
        single = _median_time(lambda: f(sample), repeats=repeats, number=2000)
    else:
        single = predict_one
    model.predict(rows[:100])  # warm up
    batch_s = _median_time(lambda: model.predict(rows), repeats=repeats, number=1)
    return {
        "single_us": 1e6 * single,
        "single_predict_us": 1e6 * predict_one,
        "batch_ms": 1e3 * batch_s,
        "batch": int(batch),
        "fast_path": callable(fast),
    }
