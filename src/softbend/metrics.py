r"""Error measures shared by every stage: materials fits, identified dynamic
models (paper A §4), the linear model of paper B Fig. 4 and the
surrogates (paper B §4.1).

Each function compares a measured signal ``y`` with a prediction ``y_hat`` of
the same length (a stress–stretch curve, a one-step-ahead or free-run
simulation of ρ or L, bending angles):

========================  =====================================================
``rmse``                  √(mean((y − ŷ)²)), in the unit of ``y``
``nrmse``                 RMSE / (max(y) − min(y)): normalized by the *range*
                          of the measurement, dimensionless (0.05 = 5 %)
``r2``                    1 − Σ(y − ŷ)² / Σ(y − ȳ)², the coefficient of
                          determination
``fit_percent``           100 · (1 − ‖y − ŷ‖ / ‖y − ȳ‖), the "fit" reported by
                          system-identification toolboxes (MATLAB ``compare``)
``thresholded_mape``      mean absolute percentage error over the samples with
                          \|y\| at least a threshold (bending angles near 0°
                          are left out and counted)
``mape_floor``            the default threshold of a bending angle's MAPE:
                          max(5°, 5 % of the largest \|θ\|)
========================  =====================================================

Rules that hold for all of them:

* ``y`` must be finite (it is a measurement; NaN there is a data error and
  raises :class:`~softbend.errors.DatasetError`).
* ``y_hat`` may contain NaN or ±inf, e.g. a free-run simulation that diverged.
  Nothing is dropped: the result is then NaN (or inf / −inf) so that a
  diverged model can never look good.
* If ``y`` is constant (max(y) = min(y)), the normalizers of ``nrmse``, ``r2``
  and ``fit_percent`` are zero and these three metrics are undefined: they
  return NaN, even for a perfect prediction. ``rmse`` stays defined.

Perfect prediction gives rmse = nrmse = 0, r2 = 1, fit = 100; predicting the
mean of ``y`` gives r2 = 0 and fit = 0.
"""

from __future__ import annotations

import math

import numpy as np
from numpy.typing import ArrayLike

from softbend._validation import check_finite_array, check_range
from softbend.errors import InputError

__all__ = [
    "MAPE_FLOOR_DEG",
    "MAPE_FLOOR_SHARE",
    "fit_percent",
    "mape_floor",
    "nrmse",
    "r2",
    "regression_metrics",
    "rmse",
    "thresholded_mape",
]


def _pair(y: ArrayLike, y_hat: ArrayLike) -> tuple[np.ndarray, np.ndarray]:
    """Validate a (measurement, prediction) pair and return two 1-D float arrays."""
    arrays = []
    for key, values in (("y", y), ("y_hat", y_hat)):
        try:
            array = np.asarray(values, dtype=float)
        except (TypeError, ValueError):
            raise InputError(
                f"must be a 1-D array of numbers; got {type(values).__name__}", key=key
            ) from None
        if array.ndim == 2 and array.shape[1] == 1:
            array = array[:, 0]
        if array.ndim != 1 or array.size == 0:
            raise InputError(
                f"must be a non-empty 1-D array (n_samples,); got shape {array.shape}", key=key
            )
        arrays.append(array)
    measured, predicted = arrays
    if measured.shape != predicted.shape:
        raise InputError(
            f"must have the length of 'y' ({measured.size}); got {predicted.size}", key="y_hat"
        )
    check_finite_array(measured, "y")
    return measured, predicted


def _sum_squared_error(measured: np.ndarray, predicted: np.ndarray) -> float:
    with np.errstate(over="ignore", invalid="ignore"):
        return float(np.sum((measured - predicted) ** 2))


def _is_constant(measured: np.ndarray) -> bool:
    return bool(np.ptp(measured) == 0.0)


def rmse(y: ArrayLike, y_hat: ArrayLike) -> float:
    """Root-mean-square error.

    Parameters
    ----------
    y : array-like, shape (n_samples,)
        Measured output (finite).
    y_hat : array-like, shape (n_samples,)
        Predicted output; NaN/inf allowed and propagated.

    Returns
    -------
    float
        √(mean((y − ŷ)²)) in the unit of ``y``; NaN if ``y_hat`` has NaN, inf if
        it has infinite values.
    """
    measured, predicted = _pair(y, y_hat)
    return math.sqrt(_sum_squared_error(measured, predicted) / measured.size)


def nrmse(y: ArrayLike, y_hat: ArrayLike) -> float:
    """RMSE normalized by the range of the measurement.

    Parameters
    ----------
    y, y_hat : array-like, shape (n_samples,)
        Measured (finite) and predicted output.

    Returns
    -------
    float
        RMSE / (max(y) − min(y)), dimensionless (multiply by 100 for percent).
        NaN if ``y`` is constant (zero range); NaN/inf propagate from ``y_hat``.

    Notes
    -----
    The range normalization (not the standard deviation or the mean) makes the
    number comparable between ρ (≈ 0.5 range) and L (mm) and between
    experiments with small and large excursions.
    """
    measured, predicted = _pair(y, y_hat)
    if _is_constant(measured):
        return math.nan
    error = math.sqrt(_sum_squared_error(measured, predicted) / measured.size)
    return error / float(np.ptp(measured))


def r2(y: ArrayLike, y_hat: ArrayLike) -> float:
    """Coefficient of determination.

    Parameters
    ----------
    y, y_hat : array-like, shape (n_samples,)
        Measured (finite) and predicted output.

    Returns
    -------
    float
        1 − Σ(y − ŷ)² / Σ(y − ȳ)²; 1 for a perfect prediction, 0 for predicting
        the mean, unbounded below. NaN if ``y`` is constant (unlike
        scikit-learn's ``r2_score``, which returns 1 or 0 there); NaN or −inf
        propagate from ``y_hat``.
    """
    measured, predicted = _pair(y, y_hat)
    if _is_constant(measured):
        return math.nan
    total = float(np.sum((measured - measured.mean()) ** 2))
    return 1.0 - _sum_squared_error(measured, predicted) / total


def fit_percent(y: ArrayLike, y_hat: ArrayLike) -> float:
    """Normalized fit of system-identification toolboxes, in percent.

    Parameters
    ----------
    y, y_hat : array-like, shape (n_samples,)
        Measured (finite) and predicted output.

    Returns
    -------
    float
        100 · (1 − ‖y − ŷ‖₂ / ‖y − ȳ‖₂); 100 for a perfect prediction, 0 for
        predicting the mean, unbounded below. Related to R² by
        fit = 100 · (1 − √(1 − R²)). NaN if ``y`` is constant; NaN or −inf
        propagate from ``y_hat``.
    """
    measured, predicted = _pair(y, y_hat)
    if _is_constant(measured):
        return math.nan
    total = float(np.sum((measured - measured.mean()) ** 2))
    return 100.0 * (1.0 - math.sqrt(_sum_squared_error(measured, predicted) / total))


def regression_metrics(y: ArrayLike, y_hat: ArrayLike) -> dict[str, float]:
    """All four measures at once.

    Parameters
    ----------
    y, y_hat : array-like, shape (n_samples,)
        Measured (finite) and predicted output. To score a NARX prediction,
        leave out the initial-condition samples first (see
        ``NARXRegressor.warmup_mask``).

    Returns
    -------
    dict
        ``{"rmse", "nrmse", "r2", "fit_percent"}`` as defined in this module.
    """
    measured, predicted = _pair(y, y_hat)
    return {
        "rmse": rmse(measured, predicted),
        "nrmse": nrmse(measured, predicted),
        "r2": r2(measured, predicted),
        "fit_percent": fit_percent(measured, predicted),
    }


def thresholded_mape(
    observed: ArrayLike,
    predicted: ArrayLike,
    *,
    threshold: float = 1.0,
) -> tuple[float, int]:
    """Mean absolute percentage error over the samples with ``|observed| >= threshold``.

    ``MAPE = 100 / m · Σ |predicted_i − observed_i| / |observed_i|`` over the
    ``m`` samples whose observed value is at least ``threshold`` in magnitude
    and non-zero. Bending angles at and near zero pressure are 0° or a fraction
    of a degree, where a percentage error is undefined or meaningless; they are
    left out and counted.

    Parameters
    ----------
    observed, predicted : array_like
        Same-shaped arrays, in the same unit (degrees for bending angles).
    threshold : float, default 1.0
        Smallest ``|observed|`` included, in the unit of ``observed``; ≥ 0.
        With 0 only exact zeros are left out.

    Returns
    -------
    mape_pct : float
        MAPE in percent; NaN if no sample passes the threshold.
    n_excluded : int
        Number of samples left out by the threshold.

    Raises
    ------
    ValueError
        If ``threshold`` is negative or the shapes differ.
    DatasetError
        If an input is NaN or infinite.
    """
    threshold = check_range(threshold, "threshold", low=0.0, low_inclusive=True)
    obs = check_finite_array(observed, "observed").ravel()
    pred = check_finite_array(predicted, "predicted").ravel()
    if obs.shape != pred.shape:
        raise InputError(
            f"must have the shape of 'observed' {obs.shape}; got {pred.shape}", key="predicted"
        )
    keep = (np.abs(obs) >= threshold) & (obs != 0.0)
    n_excluded = int((~keep).sum())
    if not keep.any():
        return math.nan, n_excluded
    mape = 100.0 * float(np.mean(np.abs(pred[keep] - obs[keep]) / np.abs(obs[keep])))
    return mape, n_excluded


#: Smallest floor of a bending angle's MAPE, degrees (:func:`mape_floor`).
MAPE_FLOOR_DEG = 5.0
#: Share of the largest ``|θ|`` below which a reading is left out of the MAPE (:func:`mape_floor`).
MAPE_FLOOR_SHARE = 0.05


def mape_floor(
    observed: ArrayLike, *, minimum: float = MAPE_FLOOR_DEG, share: float = MAPE_FLOOR_SHARE
) -> float:
    """Default threshold of a bending angle's MAPE: ``max(minimum, share · max|observed|)``.

    A percentage error divides by the reading, so readings near zero dominate a
    mean of them: a model 2° off on a 3° reading at low pressure is 67 % wrong
    there and the mean over a table then says nothing about the fit (a table of
    30 designs gave mean MAPEs of hundreds of percent that way). Readings below
    the floor are left out of the MAPE (and counted); RMSE, R² and the maximum
    error still use every reading. The two parts:

    - 5°: an FEM sweep's or a bench's error of a fraction of a degree (sensor
      resolution, the solver's tolerance) is at most about 10 % of it;
    - 5 % of the largest ``|θ|``: a surrogate's error is about a fixed share of
      the range it was trained on, so readings in the lowest 5 % of the range
      carry percentage errors of 20 times that share; for an actuator bending to
      300° this floor is 15°.

    Parameters
    ----------
    observed : array_like
        Measured or simulated angles, degrees (finite).
    minimum : float, default 5.0
        Floor in degrees, >= 0.
    share : float, default 0.05
        Share of the largest ``|observed|``, in [0, 1].

    Returns
    -------
    float
        The floor, degrees: pass it as ``threshold`` to :func:`thresholded_mape`.
    """
    minimum = check_range(minimum, "minimum", low=0.0, low_inclusive=True)
    share = check_range(share, "share", low=0.0, low_inclusive=True, high=1.0, high_inclusive=True)
    obs = check_finite_array(observed, "observed").ravel()
    largest = float(np.max(np.abs(obs))) if obs.size else 0.0
    return max(minimum, share * largest)
