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

The shape is estimated with the method of moments (paper A eqs. 22–26): the
kurtosis of the generalized Gaussian, Γ(5/γ)Γ(1/γ)/Γ(3/γ)², is a strictly
decreasing function of γ (6 at γ = 1, 3 at γ = 2, 1.8 as γ → ∞) and is matched to
the sample kurtosis with a bracketing root finder.

What the moments are taken of
-----------------------------
Paper A writes the kernel as a function of one argument, K(x̃; σ, γ) (eq. 20),
says that x̃ has zero mean and a symmetric distribution, and estimates γ from
"sampling data X = x̃ᵢ" (steps 1–4 after eq. 26). In an SVR the kernel is
evaluated at x̃ = x − z for pairs of regressor vectors, so the samples of its
argument are the **pairwise differences of the training rows**: zero-mean and
symmetric by construction, which the raw regressors are not. The kernel is also
a radial function of a d-vector, and the d-dimensional density
∝ exp(−(g‖x̃‖/σ)^γ) has the radial fourth-moment ratio

    E‖x̃‖⁴ / (E‖x̃‖²)² = Γ((d+4)/γ)·Γ(d/γ) / Γ((d+2)/γ)²     (:func:`gg_radial_kurtosis`),

of which eq. 24 is the case d = 1. Regressors are correlated, so the differences
are modelled as elliptical (x̃ = A·s with s isotropic generalized Gaussian); then
the measured ratio, divided by its Gaussian value 1 + 2/d_eff (d_eff = tr(Σ)²/
tr(Σ²) of their covariance Σ), equals Γ((d+4)/γ)Γ(d/γ)/Γ((d+2)/γ)² · d/(d+2) for
any Σ, so Gaussian regressors of any covariance give γ = 2 and no other choice
of scale enters the shape. :func:`estimate_kernel_shape` offers three readings:

* ``"differences"`` (default of :class:`~softbend.identification.svr.GeneralizedGaussianSVR`):
  the kernel argument x − z over all ordered pairs of training rows (computed
  exactly from the moments of the rows, in O(n·d²), not by forming the n² pairs);
* ``"regressors"``: the centred regressor vectors themselves, radially (x̃ = x − x̄);
* ``"components"``: the project's first reading of paper A §4.3 (eqs. 23–26): the
  centred, per-feature standardized components pooled as 1-D samples, eq. 24 as
  written. It ignores the dimension of the kernel, so it is biased for the very
  density the kernel is (a 4-D elliptical Laplacian-type sample gives γ ≈ 1.3,
  not 1; ``"regressors"`` gives 1.0).

What this changes, measured on softbend's synthetic curling data (paper A's
6 × 512 samples per sign, 3 060 NARX rows of 4 standardized regressors): the
pooled component kurtosis is 1.64–1.75 (per feature 1.55–1.96); the component
kurtosis of the differences is then necessarily (κ + 3)/2 = 2.3–2.5; the radial
ratio of the differences is 2.11–2.13 against its Gaussian 2.67–2.73
(×0.78–0.80, roots γ ≈ 6.8–10). Under every reading these regressors are
*lighter*-tailed than Gaussian (bounded pressures, long holds), so the shape is
2 there, and held-out free-run NRMSE agrees (σ = 1, 2 held-out experiments per
model: 5.9 % at γ = 2, 6.9 % at 1.5, 9.1 % at 1, 12.9 % at 0.7). No
difference-based statistic can turn a light tail into a heavy one: the kurtosis
of x − z for independent x, z is (κ + 3)/2, on the same side of 3 as κ. The
shape carries information where the data are heavier-tailed than Gaussian, e.g.
the ``"impulsive"`` excitation of
:func:`softbend.identification.synthetic.synthetic_dataset`.

How softbend reads paper A's shape estimation (§4.3, eqs. 23–26): *x̃ are the kernel's arguments,
the pairwise differences x − z of the (standardized) regressor vectors; the
fourth-moment ratio of ‖x̃‖, divided by its Gaussian value 1 + 2/d_eff, is matched
to Γ((d+4)/γ)Γ(d/γ)/Γ((d+2)/γ)² · d/(d+2) (eq. 24 is d = 1); σ stays the pooled
per-feature standard deviation of the regressors. The pooled-component reading
remains available as ``moments_of="components"``.*
"""

from __future__ import annotations

import logging
import math
import warnings
from dataclasses import dataclass
from typing import Literal

import numpy as np
from scipy.optimize import brentq
from scipy.spatial.distance import cdist, pdist, squareform
from scipy.special import gammaln

from softbend._validation import check_choice, check_finite_array, check_range, must_be
from softbend.errors import InputError

logger = logging.getLogger(__name__)

__all__ = [
    "MOMENTS_OF",
    "SHAPE_BOUNDS",
    "ShapeClippedWarning",
    "ShapeEstimate",
    "estimate_gg_shape",
    "estimate_kernel_shape",
    "generalized_gaussian_kernel",
    "gg_kurtosis",
    "gg_normalization",
    "gg_radial_kurtosis",
    "gg_scale",
]

#: What the fourth-moment method can be applied to (see the module docstring).
MOMENTS_OF: tuple[str, ...] = ("differences", "regressors", "components")
MomentsOf = Literal["differences", "regressors", "components"]

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
    gamma = check_range(shape, "shape", low=0.0)
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
    s = check_range(sigma, "sigma", low=0.0)
    gamma = check_range(shape, "shape", low=0.0)
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
        raise InputError(must_be("a number in (0, inf)", float(bad)), key="shape")
    value = np.exp(gammaln(5.0 / gamma) + gammaln(1.0 / gamma) - 2.0 * gammaln(3.0 / gamma))
    return float(value) if value.ndim == 0 else value


def gg_radial_kurtosis(shape: float | np.ndarray, dim: float = 1.0) -> float | np.ndarray:
    """Radial fourth-moment ratio of the d-dimensional generalized Gaussian.

    For x̃ ∈ ℝ^d with density ∝ exp(−(‖x̃‖/a)^γ) (the kernel as a density of its
    argument) the radius has E‖x̃‖^k = a^k·Γ((d+k)/γ)/Γ(d/γ), so

        E‖x̃‖⁴ / (E‖x̃‖²)² = Γ((d+4)/γ)·Γ(d/γ) / Γ((d+2)/γ)².

    d = 1 is paper A's eq. 24 (:func:`gg_kurtosis`). It decreases strictly in γ:
    (d+2)/d at γ = 2, tending to (d+2)²/(d(d+4)) (uniform ball) as γ → ∞.

    Parameters
    ----------
    shape : float or ndarray
        Shape parameter(s) γ > 0.
    dim : float, default 1
        Dimension d > 0 of the kernel's argument (number of varying features).

    Returns
    -------
    float or ndarray
        The ratio, dimensionless; a float for a scalar ``shape``.
    """
    d = check_range(dim, "dim", low=0.0)
    gamma = np.asarray(shape, dtype=float)
    if np.any(~(gamma > 0.0)) or np.any(~np.isfinite(gamma)):
        bad = gamma[~((gamma > 0.0) & np.isfinite(gamma))].ravel()[0]
        raise InputError(must_be("a number in (0, inf)", float(bad)), key="shape")
    value = np.exp(
        gammaln((d + 4.0) / gamma) + gammaln(d / gamma) - 2.0 * gammaln((d + 2.0) / gamma)
    )
    return float(value) if value.ndim == 0 else value


def _as_2d(values: object, key: str) -> np.ndarray:
    """Finite float array of shape (n, d); a 1-D input is one feature. Errors keyed ``key``."""
    array = check_finite_array(values, key)
    if array.ndim == 1:
        array = array[:, np.newaxis]
    if array.ndim != 2:
        raise InputError(
            f"must be a 1-D or 2-D array; got an array with {array.ndim} dimensions", key=key
        )
    return array


def _power_in_place(arg: np.ndarray, exponent: float) -> None:
    """arg **= exponent for arg ≥ 0, fast where square roots do it exactly.

    Square roots are correctly rounded and vectorized: t^(1/2), t^(1/4) and
    t^(3/4) = √t·√√t take a few ulp. Other exponents use exp(p·log t), which
    NumPy vectorizes (``np.power`` does not), to within a few ulp of ``np.power``;
    log 0 = −inf gives 0, as the power does.
    """
    if exponent == 1.0:
        return
    if exponent == 0.5:
        np.sqrt(arg, out=arg)
    elif exponent == 0.25:
        np.sqrt(arg, out=arg)
        np.sqrt(arg, out=arg)
    elif exponent == 0.75:
        np.sqrt(arg, out=arg)
        arg *= np.sqrt(arg)
    else:
        with np.errstate(divide="ignore"):
            np.log(arg, out=arg)
        arg *= exponent
        np.exp(arg, out=arg)


def _kernel_from_sqdist(
    sqdist: np.ndarray, *, sigma: float, shape: float, scale: float
) -> np.ndarray:
    """Apply scale·exp(−(g²‖d‖²/σ²)^(γ/2)) elementwise to squared distances, in place.

    Working on squared distances avoids a square root (exact for γ = 2) and
    keeps the Gaussian case a single exponential. The array's dtype is kept
    (float32 for the solver's Gram blocks, which LIBSVM rounds to float32 anyway).
    """
    rate = gg_scale(shape) ** 2 / sigma**2  # g²/σ², in 1/(input unit)²
    arg = sqdist
    arg *= arg.dtype.type(rate)
    _power_in_place(arg, 0.5 * shape)
    np.negative(arg, out=arg)
    np.exp(arg, out=arg)
    if scale != 1.0:
        arg *= arg.dtype.type(scale)
    return arg


def _kernel_block(
    X: np.ndarray,
    Z: np.ndarray,
    *,
    sigma: float,
    shape: float,
    scale: float = 1.0,
    single: bool = False,
) -> np.ndarray:
    """Kernel values between the rows of X (n, d) and Z (m, d), without input checks.

    ``single=True`` evaluates the exponentials in float32 (about 3× faster where
    float64 logarithms are not vectorized) and returns float64 values rounded
    to float32 precision.
    """
    sqdist = cdist(X, Z, "sqeuclidean")
    if single:
        kernel = _kernel_from_sqdist(
            sqdist.astype(np.float32), sigma=sigma, shape=shape, scale=scale
        )
        return kernel.astype(np.float64)
    return _kernel_from_sqdist(sqdist, sigma=sigma, shape=shape, scale=scale)


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
    s = check_range(sigma, "sigma", low=0.0)
    gamma = check_range(shape, "shape", low=0.0, high=2.0, high_inclusive=True)
    X = _as_2d(X, "X")
    if Z is None:
        sqdist = squareform(pdist(X, "sqeuclidean"))
    else:
        Z = _as_2d(Z, "Z")
        if Z.shape[1] != X.shape[1]:
            raise InputError(f"must have {X.shape[1]} features like X; got {Z.shape[1]}", key="Z")
        sqdist = cdist(X, Z, "sqeuclidean")
    scale = gg_normalization(s, gamma) if normalize else 1.0
    return _kernel_from_sqdist(sqdist, sigma=s, shape=gamma, scale=scale)


#: Largest shape the root finder looks at when the estimate lies above 2 (for the report).
_ROOT_CEILING = 1e4


def _solve_shape(relative: float, dim: float) -> tuple[float, float]:
    """Shape γ (clipped to :data:`SHAPE_BOUNDS`) and the unclipped root of the moment equation.

    Solves gg_radial_kurtosis(γ, d)·d/(d+2) = ``relative`` (the measured
    fourth-moment ratio divided by its Gaussian value; 1 at γ = 2). The unclipped
    root is ``inf`` when ``relative`` is at or below the γ → ∞ limit, and the lower
    bound when it is beyond the ratio of the smallest admissible shape.
    """
    low, high = SHAPE_BOUNDS
    norm = dim / (dim + 2.0)

    def residual(log_gamma: float) -> float:
        return math.log(gg_radial_kurtosis(math.exp(log_gamma), dim) * norm) - math.log(relative)

    if relative == 1.0:
        return high, high
    if relative < 1.0:
        if residual(math.log(_ROOT_CEILING)) >= 0.0:
            return high, math.inf
        root = brentq(residual, math.log(high), math.log(_ROOT_CEILING), xtol=1e-12, rtol=1e-14)
        return high, math.exp(root)
    if residual(math.log(low)) <= 0.0:
        return low, low
    root = math.exp(brentq(residual, math.log(low), math.log(high), xtol=1e-14, rtol=1e-14))
    return root, root


def _shape_from_kurtosis(kurtosis: float) -> float:
    """Invert :func:`gg_kurtosis` on :data:`SHAPE_BOUNDS`, clipping with a warning."""
    low, high = SHAPE_BOUNDS
    at_high = gg_kurtosis(high)  # 3, as computed
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
    return _solve_shape(kurtosis / 3.0, 1.0)[0]


def _weighted_rows(
    samples: object, sample_weight: object, key: str
) -> tuple[np.ndarray, np.ndarray]:
    """Varying columns of the positive-weight rows and the normalized weights.

    ``key`` names the samples' parameter in the errors about them.
    """
    X = _as_2d(samples, key)
    n = X.shape[0]
    if sample_weight is None:
        weight = np.ones(n)
    else:
        weight = check_finite_array(sample_weight, "sample_weight")
        if weight.shape != (n,):
            raise InputError(
                f"must have shape ({n},) like the samples; got shape {weight.shape}",
                key="sample_weight",
            )
        if np.any(weight < 0.0):
            raise InputError(
                must_be("non-negative", float(weight[weight < 0.0][0])), key="sample_weight"
            )
        keep = weight > 0.0
        X, weight = X[keep], weight[keep]
        n = X.shape[0]
    if n < _MIN_SAMPLES:
        raise InputError(
            f"must contain at least {_MIN_SAMPLES} samples (with positive weight) to "
            f"estimate a fourth moment; got n_samples = {n}",
            key=key,
        )
    varying = np.ptp(X, axis=0) > 0.0
    if not varying.any():
        raise InputError(
            "must not be constant: the width and the kurtosis are undefined; "
            f"got {n} samples with a single value per feature",
            key=key,
        )
    if not varying.all():
        logger.debug("ignoring %d constant column(s) of %s", int((~varying).sum()), key)
        X = X[:, varying]
    return X, weight / weight.sum()


def _check_moments(sigma: float, kurtosis: float, key: str) -> None:
    if not (math.isfinite(sigma) and sigma > 0.0 and math.isfinite(kurtosis)):
        raise InputError(
            "must have finite, non-zero moments (rescale it); "
            f"got sigma = {sigma!r} and kurtosis = {kurtosis!r}",
            key=key,
        )


def _pooled_moments(
    samples: object, sample_weight: object, key: str = "samples"
) -> tuple[float, float]:
    """Pooled width σ and standardized kurtosis κ (see :func:`estimate_gg_shape`)."""
    X, p = _weighted_rows(samples, sample_weight, key)
    centred = X - p @ X
    squares = centred * centred
    variance = p @ squares  # per column, population
    fourth = p @ (squares * squares)
    sigma = math.sqrt(float(variance.mean()))
    kurtosis = float(np.mean(fourth / variance**2))
    _check_moments(sigma, kurtosis, key)
    return sigma, kurtosis


def _radial_moments(
    samples: object, sample_weight: object, key: str, *, pairwise: bool
) -> tuple[float, float, int, float]:
    """σ, radial fourth-moment ratio, dimension and effective dimension of the kernel argument.

    With x the weighted-centred rows, M = E[x xᵀ] and a = ‖x‖²: for the rows
    themselves E‖x‖² = tr M and E‖x‖⁴ = E[a²]. For the differences x_i − x_j over
    all ordered pairs weighted p_i·p_j (i = j included, a V-statistic),
    E‖x_i − x_j‖² = 2 tr M and E‖x_i − x_j‖⁴ = 2E[a²] + 2(tr M)² + 4‖M‖_F²,
    since the cross terms E[a_i x_iᵀx_j] vanish for centred rows. The
    effective dimension is d_eff = (tr M)²/‖M‖_F², the same for the rows and
    the differences, and the Gaussian value of the ratio is 1 + 2/d_eff.
    """
    X, p = _weighted_rows(samples, sample_weight, key)
    centred = X - p @ X
    second = (centred * p[:, None]).T @ centred  # M, (d, d)
    squared_norm = np.einsum("ij,ij->i", centred, centred)
    trace = float(np.trace(second))
    fourth = float(p @ (squared_norm * squared_norm))
    frobenius = float(np.sum(second * second))
    sigma = math.sqrt(trace / X.shape[1])  # mean per-feature variance, as for "components"
    if pairwise:
        ratio = (2.0 * fourth + 2.0 * trace**2 + 4.0 * frobenius) / (4.0 * trace**2)
    else:
        ratio = fourth / trace**2
    _check_moments(sigma, ratio, key)
    return sigma, ratio, X.shape[1], trace**2 / frobenius


_SUBJECT = {
    "differences": "‖x − z‖ over all pairs of training rows (the kernel's argument)",
    "regressors": "‖x − x̄‖ of the centred regressor vectors",
    "components": "the pooled standardized regressor components",
}


@dataclass(frozen=True)
class ShapeEstimate:
    """Outcome of the fourth-moment method, with what is needed to explain it.

    Attributes
    ----------
    sigma : float
        Kernel width σ: the pooled per-feature standard deviation, input units.
    shape : float
        Shape γ to use, in :data:`SHAPE_BOUNDS`.
    moments_of : str
        What the moments were taken of (one of :data:`MOMENTS_OF`).
    kurtosis : float
        Measured fourth-moment ratio: E‖x̃‖⁴/(E‖x̃‖²)² for the radial readings,
        the pooled standardized kurtosis E[x̃⁴]/E[x̃²]² for ``"components"``.
    gaussian_kurtosis : float
        The value ``kurtosis`` has for Gaussian data: 1 + 2/d_eff, or 3.
    dimension : int
        Dimension d of the density matched (varying features; 1 for ``"components"``).
    effective_dimension : float
        d_eff = tr(Σ)²/tr(Σ²) of the covariance Σ of the kernel argument (1 for
        ``"components"``).
    unclipped_shape : float
        Root of the moment equation before clipping; ``inf`` when the data are at
        least as flat as a uniform ball.
    clipped : bool
        Whether ``shape`` differs from ``unclipped_shape``.
    """

    sigma: float
    shape: float
    moments_of: str
    kurtosis: float
    gaussian_kurtosis: float
    dimension: int
    effective_dimension: float
    unclipped_shape: float
    clipped: bool

    @property
    def relative_kurtosis(self) -> float:
        """``kurtosis / gaussian_kurtosis``: 1 Gaussian, > 1 heavier tails, < 1 lighter."""
        return self.kurtosis / self.gaussian_kurtosis

    @property
    def reason(self) -> str:
        """One sentence saying why the shape is what it is."""
        relative = self.relative_kurtosis
        tails = "heavier" if relative > 1.0 else "lighter" if relative < 1.0 else "the same"
        measured = (
            f"fourth-moment ratio of {_SUBJECT[self.moments_of]} is {self.kurtosis:.3g}, "
            f"{relative:.3g} × its Gaussian value {self.gaussian_kurtosis:.3g} "
            f"({tails} tails than Gaussian)"
        )
        if not self.clipped:
            return f"{measured}; the moment equation gives γ = {self.shape:.3g}"
        if self.unclipped_shape > self.shape:
            unclipped = self.unclipped_shape
            root = (
                "has no finite root (flatter than a uniform ball)"
                if math.isinf(unclipped)
                else f"gives γ ≈ {unclipped:.3g} > 2"
            )
            return (
                f"{measured}; the moment equation {root}, so γ is clipped to "
                f"{self.shape:g} (the kernel is positive definite only for γ ≤ 2)"
            )
        return (
            f"{measured}; beyond the ratio of the smallest admissible shape, clipped to "
            f"{self.shape:g}"
        )


def estimate_gg_shape(
    samples: np.ndarray, *, sample_weight: np.ndarray | None = None
) -> tuple[float, float]:
    """Estimate (σ, γ) of a 1-D generalized Gaussian by the fourth-moment method.

    This is paper A's estimator as written, for samples of one variable; for a
    kernel on regressor vectors use :func:`estimate_kernel_shape` (its
    ``"components"`` reading is this function). Paper A eqs. 22–26 (corrected):
    with x̃ the centred samples, σ² = E[x̃²] and the kurtosis
    κ = E[x̃⁴]/E[x̃²]²; γ solves Γ(5/γ)Γ(1/γ)/Γ(3/γ)² = κ
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
    sigma, kurtosis = _pooled_moments(samples, sample_weight)
    shape = _shape_from_kurtosis(kurtosis)
    logger.debug("estimate_gg_shape: sigma=%.6g kurtosis=%.6g shape=%.6g", sigma, kurtosis, shape)
    return sigma, shape


def estimate_kernel_shape(
    X: np.ndarray,
    *,
    sample_weight: np.ndarray | None = None,
    moments_of: MomentsOf = "differences",
) -> ShapeEstimate:
    """Estimate the kernel's (σ, γ) from regressor vectors by the fourth-moment method.

    σ is the pooled per-feature standard deviation of ``X`` (the mean of the
    per-feature variances, square-rooted; σ = 1 for standardized inputs) in
    every reading. The shape comes from the fourth-moment ratio of what
    ``moments_of`` names (see the module docstring for why the default is the
    kernel's argument):

    * ``"differences"``: x̃ = x_i − x_j over all ordered pairs of rows (weighted
      p_i·p_j), radially: ratio E‖x̃‖⁴/(E‖x̃‖²)², divided by its Gaussian value
      1 + 2/d_eff, matched to gg_radial_kurtosis(γ, d)·d/(d+2). Exact, O(n·d²).
    * ``"regressors"``: the same with x̃ = x − x̄, the centred rows.
    * ``"components"``: :func:`estimate_gg_shape` (pooled standardized components,
      paper A eq. 24 with d = 1).

    For elliptical data (x̃ = A·s, s isotropic generalized Gaussian of shape γ
    in d dimensions) the radial readings are consistent for γ whatever A is; the
    differences of i.i.d. rows are not generalized Gaussian themselves unless
    γ = 2, and their ratio is the mean of the rows' ratio and the Gaussian one.

    Parameters
    ----------
    X : array_like of shape (n,) or (n, d)
        Regressor vectors (finite), in the units the kernel sees.
    sample_weight : array_like of shape (n,), optional
        Non-negative frequency weights (an integer k counts as k copies).
    moments_of : {"differences", "regressors", "components"}, default "differences"
        What the fourth-moment method is applied to.

    Returns
    -------
    ShapeEstimate
        σ, γ and the measured ratio with its Gaussian reference; ``reason``
        says in one sentence why γ is what it is.

    Raises
    ------
    ValueError
        Non-finite samples, fewer than 4 samples with positive weight, every
        column constant, bad weights, or an unknown ``moments_of``.

    Warns
    -----
    ShapeClippedWarning
        If the root lies above 2 (lighter tails than Gaussian; the kernel would
        not be positive definite) or below 0.05, and γ was clipped.
    """
    estimate = _kernel_shape_estimate(X, sample_weight, moments_of)
    if estimate.clipped:
        _warn_clipped(estimate, stacklevel=3)
    logger.debug("estimate_kernel_shape: %s", estimate)
    return estimate


def _warn_clipped(estimate: ShapeEstimate, stacklevel: int) -> None:
    warnings.warn(
        f"The shape estimate was clipped to {estimate.shape:g}: {estimate.reason}.",
        ShapeClippedWarning,
        stacklevel=stacklevel,
    )


def _kernel_shape_estimate(X: object, sample_weight: object, moments_of: str) -> ShapeEstimate:
    """:func:`estimate_kernel_shape` without the warning (callers decide whether to warn)."""
    check_choice(moments_of, "moments_of", MOMENTS_OF)
    if moments_of == "components":
        sigma, kurtosis = _pooled_moments(X, sample_weight, "X")
        dim, effective, gaussian = 1, 1.0, 3.0
    else:
        sigma, kurtosis, dim, effective = _radial_moments(
            X, sample_weight, "X", pairwise=moments_of == "differences"
        )
        gaussian = 1.0 + 2.0 / effective
    shape, unclipped = _solve_shape(kurtosis / gaussian, float(dim))
    return ShapeEstimate(
        sigma=sigma,
        shape=shape,
        moments_of=moments_of,
        kurtosis=kurtosis,
        gaussian_kurtosis=gaussian,
        dimension=dim,
        effective_dimension=effective,
        unclipped_shape=unclipped,
        clipped=shape != unclipped,
    )
