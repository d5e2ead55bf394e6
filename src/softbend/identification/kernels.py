"""Generalized-Gaussian kernel and its shape estimation (paper A §4, eqs. 20–26).

The generalized Gaussian (generalized normal) density of zero mean, standard
deviation ``sigma`` and shape ``gamma`` is used as an SVR kernel on the distance
between two regressor vectors::

    K(x, z) = c · exp(−(g(γ)·‖x − z‖ / σ)^γ),   g(γ) = sqrt(Γ(3/γ) / Γ(1/γ)),
    c = g(γ)·γ / (2·σ·Γ(1/γ))   (the density's normalization; 1 if not normalized).

γ = 2 is the Gaussian (RBF with ``gamma = 1/(2σ²)``), γ = 1 the Laplacian, γ → ∞
tends to a uniform density on (−√3σ, √3σ). As a kernel it is positive definite
only for 0 < γ ≤ 2 (the function exp(−‖d‖^γ) is then a characteristic function
of a stable law; for γ > 2 it is not), so every estimate above 2 is clipped.

The shape is estimated with the method of moments (paper A eqs. 22–26, as
corrected in the project specification): the kurtosis of the generalized
Gaussian, Γ(5/γ)Γ(1/γ)/Γ(3/γ)², is a strictly decreasing function of γ (6 at
γ = 1, 3 at γ = 2, 1.8 as γ → ∞) and is matched to the sample kurtosis with a
bracketing root finder.
"""

from __future__ import annotations

import logging
import math
import warnings

import numpy as np
from scipy.optimize import brentq
from scipy.spatial.distance import cdist, pdist, squareform
from scipy.special import gammaln

from softbend._validation import check_finite_array, check_range

logger = logging.getLogger(__name__)

__all__ = [
    "SHAPE_BOUNDS",
    "ShapeClippedWarning",
    "estimate_gg_shape",
    "generalized_gaussian_kernel",
    "gg_kurtosis",
    "gg_normalization",
    "gg_scale",
]

#: Range the shape estimate is confined to. The upper bound is the largest
#: shape for which the kernel is positive definite; the lower bound keeps the
#: root finder away from the degenerate limit γ → 0 (kurtosis ≈ 1e12 there).
SHAPE_BOUNDS: tuple[float, float] = (0.05, 2.0)

#: Minimum number of samples for a fourth-moment estimate.
_MIN_SAMPLES = 4


class ShapeClippedWarning(UserWarning):
    """The moment estimate of the shape fell outside :data:`SHAPE_BOUNDS` and was clipped."""


def gg_scale(shape: float) -> float:
    """Scale factor g(γ) = sqrt(Γ(3/γ) / Γ(1/γ)) of the generalized Gaussian.

    With it the density c·exp(−(g|x|/σ)^γ) has standard deviation σ for every γ.

    Parameters
    ----------
    shape : float
        Shape parameter γ > 0 (dimensionless).

    Returns
    -------
    float
        g(γ); 1/√2 at γ = 2, √2 at γ = 1, tending to 1/√3 as γ → ∞.
    """
    gamma = check_range(shape, "shape", "gg_scale", low=0.0)
    return math.exp(0.5 * (gammaln(3.0 / gamma) - gammaln(1.0 / gamma)))


def gg_normalization(sigma: float, shape: float) -> float:
    """Normalization constant c = g(γ)·γ / (2σ·Γ(1/γ)) of the 1-D generalized Gaussian.

    Parameters
    ----------
    sigma : float
        Standard deviation σ > 0, in the units of the kernel's inputs.
    shape : float
        Shape parameter γ > 0.

    Returns
    -------
    float
        c, in 1/(input unit): the peak value of the 1-D density
        (1/(σ√(2π)) for γ = 2, 1/(σ√2) for γ = 1).
    """
    s = check_range(sigma, "sigma", "gg_normalization", low=0.0)
    gamma = check_range(shape, "shape", "gg_normalization", low=0.0)
    return math.exp(math.log(gg_scale(gamma) * gamma / (2.0 * s)) - gammaln(1.0 / gamma))


def gg_kurtosis(shape: float | np.ndarray) -> float | np.ndarray:
    """Kurtosis φ(γ) = Γ(5/γ)Γ(1/γ) / Γ(3/γ)² of the generalized Gaussian (paper A eq. 24).

    This is the ordinary (non-excess) kurtosis E[x⁴]/E[x²]², strictly decreasing
    in γ: 6 for the Laplacian (γ = 1), 3 for the Gaussian (γ = 2), tending to
    1.8 (the uniform density) as γ → ∞ and to infinity as γ → 0.

    Parameters
    ----------
    shape : float or ndarray
        Shape parameter(s) γ > 0.

    Returns
    -------
    float or ndarray
        φ(γ), a float for a scalar input.
    """
    gamma = np.asarray(shape, dtype=float)
    if np.any(~(gamma > 0.0)) or np.any(~np.isfinite(gamma)):
        bad = gamma[~((gamma > 0.0) & np.isfinite(gamma))].ravel()[0]
        raise ValueError(
            f"The 'shape' of gg_kurtosis must be a number in (0, inf). Got {bad!r} instead."
        )
    value = np.exp(gammaln(5.0 / gamma) + gammaln(1.0 / gamma) - 2.0 * gammaln(3.0 / gamma))
    return float(value) if value.ndim == 0 else value


def _as_2d(values: object, name: str, owner: str) -> np.ndarray:
    """Finite float array of shape (n, d); a 1-D input is one feature."""
    array = check_finite_array(values, name, owner)
    if array.ndim == 1:
        array = array[:, np.newaxis]
    if array.ndim != 2:
        raise ValueError(
            f"The '{name}' of {owner} must be a 1-D or 2-D array. "
            f"Got an array with {array.ndim} dimensions instead."
        )
    return array


def _kernel_from_sqdist(
    sqdist: np.ndarray, *, sigma: float, shape: float, scale: float
) -> np.ndarray:
    """Apply scale·exp(−(g²‖d‖²/σ²)^(γ/2)) elementwise to squared distances.

    Working on squared distances avoids a square root (exact for γ = 2) and
    keeps the Gaussian case a single exponential.
    """
    rate = gg_scale(shape) ** 2 / sigma**2  # g²/σ², in 1/(input unit)²
    arg = sqdist * rate
    if shape != 2.0:
        if shape == 1.0:
            np.sqrt(arg, out=arg)
        else:
            np.power(arg, 0.5 * shape, out=arg)
    np.negative(arg, out=arg)
    np.exp(arg, out=arg)
    if scale != 1.0:
        arg *= scale
    return arg


def generalized_gaussian_kernel(
    X: np.ndarray,
    Z: np.ndarray | None = None,
    *,
    sigma: float,
    shape: float,
    normalize: bool = True,
) -> np.ndarray:
    """Gram matrix of the generalized-Gaussian kernel (paper A eq. 20, corrected).

    K(x, z) = c · exp(−(g(γ)·‖x − z‖/σ)^γ) with the Euclidean norm, g from
    :func:`gg_scale` and c from :func:`gg_normalization` (or 1).

    Parameters
    ----------
    X : array_like of shape (n, d)
        First set of points (a 1-D array is n points of one feature).
    Z : array_like of shape (m, d), optional
        Second set of points; ``X`` itself when omitted (the symmetric training Gram).
    sigma : float
        Kernel width σ > 0, in the units of the inputs (1 for standardized inputs).
    shape : float
        Shape γ in (0, 2]; 2 is the Gaussian, 1 the Laplacian. Larger values give
        a kernel that is not positive definite and are rejected.
    normalize : bool, default True
        Multiply by the density's normalization constant c (paper A's pdf form).
        For an SVR this is equivalent to multiplying the penalty C by c.

    Returns
    -------
    ndarray of shape (n, m)
        Kernel values, symmetric positive semi-definite when ``Z`` is omitted.

    Raises
    ------
    ValueError
        If σ ≤ 0, γ outside (0, 2], inputs are not finite or the feature counts differ.
    """
    owner = "generalized_gaussian_kernel"
    s = check_range(sigma, "sigma", owner, low=0.0)
    gamma = check_range(shape, "shape", owner, low=0.0, high=2.0, high_inclusive=True)
    X = _as_2d(X, "X", owner)
    if Z is None:
        sqdist = squareform(pdist(X, "sqeuclidean"))
    else:
        Z = _as_2d(Z, "Z", owner)
        if Z.shape[1] != X.shape[1]:
            raise ValueError(
                f"The 'Z' of {owner} must have {X.shape[1]} features like X. "
                f"Got {Z.shape[1]} instead."
            )
        sqdist = cdist(X, Z, "sqeuclidean")
    scale = gg_normalization(s, gamma) if normalize else 1.0
    return _kernel_from_sqdist(sqdist, sigma=s, shape=gamma, scale=scale)


def _shape_from_kurtosis(kurtosis: float) -> float:
    """Invert :func:`gg_kurtosis` on :data:`SHAPE_BOUNDS`, clipping with a warning."""
    low, high = SHAPE_BOUNDS
    at_high = gg_kurtosis(high)  # 3.0
    at_low = gg_kurtosis(low)
    if kurtosis < at_high:
        warnings.warn(
            f"Sample kurtosis {kurtosis:.4g} is below the Gaussian value 3, which "
            f"corresponds to a shape above 2 (flatter than Gaussian); the shape is "
            f"clipped to {high:g} to keep the kernel positive definite.",
            ShapeClippedWarning,
            stacklevel=3,
        )
        return high
    if kurtosis == at_high:
        return high
    if kurtosis >= at_low:
        warnings.warn(
            f"Sample kurtosis {kurtosis:.4g} exceeds the kurtosis {at_low:.4g} of the "
            f"smallest admissible shape; the shape is clipped to {low:g}.",
            ShapeClippedWarning,
            stacklevel=3,
        )
        return low
    log_kurtosis = math.log(kurtosis)

    def residual(log_gamma: float) -> float:
        g = math.exp(log_gamma)
        return float(gammaln(5.0 / g) + gammaln(1.0 / g) - 2.0 * gammaln(3.0 / g)) - log_kurtosis

    log_gamma = brentq(residual, math.log(low), math.log(high), xtol=1e-14, rtol=1e-14)
    return math.exp(log_gamma)


def _pooled_moments(
    samples: object, sample_weight: object, owner: str, name: str = "samples"
) -> tuple[float, float]:
    """Pooled width σ and standardized kurtosis κ (see :func:`estimate_gg_shape`)."""
    X = _as_2d(samples, name, owner)
    n = X.shape[0]
    if sample_weight is None:
        weight = np.ones(n)
    else:
        weight = check_finite_array(sample_weight, "sample_weight", owner)
        if weight.shape != (n,):
            raise ValueError(
                f"The 'sample_weight' of {owner} must have shape ({n},) like the samples. "
                f"Got shape {weight.shape} instead."
            )
        if np.any(weight < 0.0):
            raise ValueError(
                f"The 'sample_weight' of {owner} must be non-negative. "
                f"Got {weight[weight < 0.0][0]!r} instead."
            )
        keep = weight > 0.0
        X, weight = X[keep], weight[keep]
        n = X.shape[0]
    if n < _MIN_SAMPLES:
        raise ValueError(
            f"The '{name}' of {owner} must contain at least {_MIN_SAMPLES} samples "
            f"(with positive weight) to estimate a fourth moment. Got n_samples = {n} instead."
        )
    varying = np.ptp(X, axis=0) > 0.0
    if not varying.any():
        raise ValueError(
            f"The '{name}' of {owner} must not be constant: the width and the kurtosis are "
            f"undefined. Got {n} samples with a single value per feature instead."
        )
    if not varying.all():
        logger.debug("%s: ignoring %d constant column(s)", owner, int((~varying).sum()))
        X = X[:, varying]

    p = weight / weight.sum()
    centred = X - p @ X
    squares = centred * centred
    variance = p @ squares  # per column, population
    fourth = p @ (squares * squares)
    sigma = math.sqrt(float(variance.mean()))
    kurtosis = float(np.mean(fourth / variance**2))
    if not (math.isfinite(sigma) and sigma > 0.0 and math.isfinite(kurtosis)):
        raise ValueError(
            f"The '{name}' of {owner} must have finite, non-zero moments; rescale it. "
            f"Got sigma = {sigma!r} and kurtosis = {kurtosis!r} instead."
        )
    return sigma, kurtosis


def estimate_gg_shape(
    samples: np.ndarray, *, sample_weight: np.ndarray | None = None
) -> tuple[float, float]:
    """Estimate (σ, γ) of a generalized Gaussian by the fourth-moment method.

    Paper A eqs. 22–26 (corrected): with x̃ the centred samples, σ² = E[x̃²] and
    the kurtosis κ = E[x̃⁴]/E[x̃²]²; γ solves Γ(5/γ)Γ(1/γ)/Γ(3/γ)² = κ
    (Brent's method on log γ over :data:`SHAPE_BOUNDS`). Moments are population
    moments (divided by the total weight, not by n − 1).

    For a 2-D array of regressor vectors (n samples, d features) the components
    are pooled, with two deliberate choices:

    * **width**: σ² is the mean of the per-feature variances, i.e. the pooled
      mean of the centred squares. It keeps the units of the inputs, so the
      kernel width follows their scale; for standardized inputs (as the NARX
      model feeds them) σ = 1.
    * **shape**: κ is the kurtosis of the pooled components after each column is
      standardized by its own standard deviation (the mean of the per-column
      kurtoses), so a feature with a large scale does not dominate the shape,
      which is scale-free.

    Constant columns carry no information about either and are left out of both
    (they add nothing to ‖x − z‖ between training points).

    Parameters
    ----------
    samples : array_like of shape (n,) or (n, d)
        Samples of one variable, or regressor vectors; finite.
    sample_weight : array_like of shape (n,), optional
        Non-negative frequency weights; an integer weight k counts like k copies
        of the sample. Samples with weight 0 are ignored.

    Returns
    -------
    sigma : float
        Estimated standard deviation σ, in the units of ``samples``.
    shape : float
        Estimated shape γ in [0.05, 2].

    Raises
    ------
    ValueError
        Non-finite samples, fewer than 4 samples with positive weight, all
        samples (all columns) constant, or bad weights.

    Warns
    -----
    ShapeClippedWarning
        If the kurtosis is below 3 (the root would be γ > 2, where the kernel is
        not positive definite), γ is set to 2; if it is beyond the kurtosis of
        γ = 0.05, γ is set to 0.05.
    """
    sigma, kurtosis = _pooled_moments(samples, sample_weight, "estimate_gg_shape")
    shape = _shape_from_kurtosis(kurtosis)
    logger.debug("estimate_gg_shape: sigma=%.6g kurtosis=%.6g shape=%.6g", sigma, kurtosis, shape)
    return sigma, shape
