"""Support vector regression with the generalized-Gaussian kernel (paper A §4).

The kernel's hyperparameters (σ, γ) are estimator parameters, so grid search
and ``get_params`` see them: the estimator computes the Gram matrix itself and
fits :class:`sklearn.svm.SVR` on it (``kernel="precomputed"``). Prediction is a
plain NumPy kernel expansion over the stored support vectors, and
:meth:`GeneralizedGaussianSVR.predict_one` is a low-overhead path for control
loops and free-run simulation.
"""

from __future__ import annotations

import logging
import math
from numbers import Integral

import numpy as np
from scipy.spatial.distance import cdist, pdist, squareform
from sklearn.base import BaseEstimator, RegressorMixin
from sklearn.exceptions import NotFittedError
from sklearn.svm import SVR
from sklearn.utils.validation import _check_sample_weight, check_is_fitted, validate_data

from softbend._validation import check_choice, check_range
from softbend.errors import ConvergenceError
from softbend.identification.kernels import (
    _kernel_from_sqdist,
    _pooled_moments,
    _shape_from_kurtosis,
    gg_normalization,
    gg_scale,
)

logger = logging.getLogger(__name__)

__all__ = ["GeneralizedGaussianSVR"]

_OWNER = "GeneralizedGaussianSVR"


def _check_max_iter(value: object) -> int:
    if isinstance(value, bool) or not isinstance(value, Integral) or value < -1 or value == 0:
        raise ValueError(
            f"The 'max_iter' of {_OWNER} must be -1 (no limit) or a positive integer. "
            f"Got {value!r} instead."
        )
    return int(value)


def _merge_duplicates(
    X: np.ndarray, y: np.ndarray, weight: np.ndarray
) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
    """Drop zero-weight rows, merge identical (x, y) rows and sort them.

    Identical training pairs have identical slacks in the SVR primal, so one row
    carrying the summed weight is the same problem with a smaller Gram matrix.
    The lexicographic order makes the fit independent of the sample order, and
    makes an integer weight k exactly equivalent to k copies of the sample.
    """
    keep = weight > 0.0
    rows = np.column_stack([X[keep], y[keep]])
    unique, inverse = np.unique(rows, axis=0, return_inverse=True)
    merged_weight = np.bincount(inverse.ravel(), weights=weight[keep], minlength=len(unique))
    return np.ascontiguousarray(unique[:, :-1]), unique[:, -1].copy(), merged_weight


class GeneralizedGaussianSVR(RegressorMixin, BaseEstimator):
    """ε-SVR with the generalized-Gaussian kernel K = c·exp(−(g(γ)‖x − z‖/σ)^γ).

    The model is f(x) = Σᵢ βᵢ K(sᵢ, x) + b over the support vectors sᵢ, fitted
    by LIBSVM's ε-insensitive dual on a precomputed Gram matrix (paper A §4).
    When ``sigma`` or ``shape`` is None it is estimated from the training inputs
    by the fourth-moment method of :func:`~softbend.identification.kernels.estimate_gg_shape`
    (pooled per-feature variance for σ, pooled standardized kurtosis for γ,
    clipped to γ ≤ 2 with a ``ShapeClippedWarning``).

    Parameters
    ----------
    C : float, default 100.0
        Penalty on errors beyond the ε tube, > 0 (paper A calls it γ and uses 100).
        With ``normalize=True`` the kernel carries the factor c, which is
        equivalent to an RBF-type SVR with penalty c·C.
    epsilon : float, default 0.1
        Half-width of the insensitive tube, ≥ 0, in the units of the target
        (paper A: 0.1 on the scaled target).
    sigma : float or None, default None
        Kernel width σ > 0 in the units of the inputs; estimated when None.
    shape : float or None, default None
        Kernel shape γ in (0, 2] (2 Gaussian, 1 Laplacian); estimated when None.
        Values above 2 are rejected: the kernel would not be positive definite.
    normalize : bool, default True
        Multiply the kernel by the density normalization c = g(γ)γ/(2σΓ(1/γ)).
    tol : float, default 1e-3
        Stopping tolerance of the LIBSVM solver, > 0.
    cache_size : float, default 200.0
        Kernel cache of the solver, MB, > 0.
    max_iter : int, default -1
        Solver iteration limit, -1 for none.

    Attributes
    ----------
    sigma_ : float
        Kernel width used, input units.
    shape_ : float
        Kernel shape used.
    kernel_scale_ : float
        Constant factor c of the kernel (1 when ``normalize=False``).
    support_vectors_ : ndarray of shape (n_sv, n_features)
        Support vectors, in the lexicographic order of the merged training rows.
    dual_coef_ : ndarray of shape (n_sv,)
        Coefficients βᵢ of the kernel expansion, target units.
    intercept_ : float
        Offset b, target units.
    n_support_ : int
        Number of support vectors.
    n_iter_ : int
        Solver iterations.
    n_features_in_ : int
        Number of input features.
    feature_names_in_ : ndarray of str
        Feature names, when X was a DataFrame with string column names.

    Notes
    -----
    Before solving, zero-weight rows are dropped and identical (x, y) pairs are
    merged into one row carrying the summed sample weight (the SVR primal is
    unchanged by this); rows are sorted, so the fit does not depend on the order
    of the samples and an integer weight k is the same as k copies.
    """

    def __init__(
        self,
        *,
        C: float = 100.0,
        epsilon: float = 0.1,
        sigma: float | None = None,
        shape: float | None = None,
        normalize: bool = True,
        tol: float = 1e-3,
        cache_size: float = 200.0,
        max_iter: int = -1,
    ) -> None:
        self.C = C
        self.epsilon = epsilon
        self.sigma = sigma
        self.shape = shape
        self.normalize = normalize
        self.tol = tol
        self.cache_size = cache_size
        self.max_iter = max_iter

    def fit(
        self, X: np.ndarray, y: np.ndarray, sample_weight: np.ndarray | None = None
    ) -> GeneralizedGaussianSVR:
        """Estimate the kernel (if needed) and solve the SVR dual.

        Parameters
        ----------
        X : array_like of shape (n_samples, n_features)
            Training inputs (regressor vectors), finite.
        y : array_like of shape (n_samples,)
            Targets, finite.
        sample_weight : array_like of shape (n_samples,), optional
            Non-negative per-sample weights; they multiply C sample by sample.

        Returns
        -------
        GeneralizedGaussianSVR
            The fitted estimator.

        Raises
        ------
        ValueError
            Bad hyperparameter (naming it), non-finite data, or too few distinct
            samples to estimate σ/γ.
        ConvergenceError
            If the solver returns non-finite coefficients.
        """
        C = check_range(self.C, "C", _OWNER, low=0.0)
        epsilon = check_range(self.epsilon, "epsilon", _OWNER, low=0.0, low_inclusive=True)
        tol = check_range(self.tol, "tol", _OWNER, low=0.0)
        cache_size = check_range(self.cache_size, "cache_size", _OWNER, low=0.0)
        max_iter = _check_max_iter(self.max_iter)
        normalize = bool(check_choice(self.normalize, "normalize", _OWNER, (True, False)))
        sigma = None if self.sigma is None else check_range(self.sigma, "sigma", _OWNER, low=0.0)
        shape = (
            None
            if self.shape is None
            else check_range(self.shape, "shape", _OWNER, low=0.0, high=2.0, high_inclusive=True)
        )

        X, y = validate_data(self, X, y, dtype=np.float64, y_numeric=True)
        weight = _check_sample_weight(sample_weight, X, dtype=np.float64, ensure_non_negative=True)
        X_fit, y_fit, w_fit = _merge_duplicates(X, y, weight)

        if sigma is None or shape is None:
            n_distinct = X_fit.shape[0]
            if n_distinct < 4:
                raise ValueError(
                    f"The 'X' of {_OWNER} must contain at least 4 distinct samples to "
                    f"estimate sigma/shape (or pass both). Got n_samples = {n_distinct} instead."
                )
            try:
                sigma_hat, kurtosis = _pooled_moments(X_fit, w_fit, _OWNER, name="X")
            except ValueError as err:
                raise ValueError(f"{err} Pass sigma and shape explicitly.") from None
            if sigma is None:
                sigma = sigma_hat
            if shape is None:
                shape = _shape_from_kurtosis(kurtosis)
            logger.debug("%s: kernel sigma=%.6g shape=%.6g", _OWNER, sigma, shape)

        scale = gg_normalization(sigma, shape) if normalize else 1.0
        sqdist = squareform(pdist(X_fit, "sqeuclidean"))
        gram = _kernel_from_sqdist(sqdist, sigma=sigma, shape=shape, scale=scale)

        svr = SVR(
            kernel="precomputed",
            C=C,
            epsilon=epsilon,
            tol=tol,
            cache_size=cache_size,
            max_iter=max_iter,
        )
        unit_weights = bool(np.all(w_fit == 1.0))
        svr.fit(gram, y_fit, sample_weight=None if unit_weights else w_fit)

        dual_coef = np.asarray(svr.dual_coef_, dtype=float).ravel()
        intercept = float(np.asarray(svr.intercept_).ravel()[0])
        if not (np.all(np.isfinite(dual_coef)) and math.isfinite(intercept)):
            raise ConvergenceError(
                f"The SVR solver of {_OWNER} returned non-finite coefficients; "
                "check the scaling of X and y, sigma and C."
            )

        self.sigma_ = float(sigma)
        self.shape_ = float(shape)
        self.kernel_scale_ = float(scale)
        self.support_vectors_ = np.ascontiguousarray(X_fit[svr.support_])
        self.dual_coef_ = dual_coef
        self.intercept_ = intercept
        self.n_support_ = int(dual_coef.size)
        self.n_iter_ = int(np.asarray(svr.n_iter_).ravel()[0])
        self._precompute()
        return self

    def _precompute(self) -> None:
        """Derive what prediction needs from the public fitted attributes.

        K = c·exp(−(rate·d²)^(γ/2)), with c folded into the coefficients. Called by
        ``fit`` and by :func:`softbend.identification.persistence.load_narx`.
        """
        self._rate = gg_scale(self.shape_) ** 2 / self.sigma_**2
        self._half_shape = 0.5 * self.shape_
        self._coef = self.dual_coef_ * self.kernel_scale_
        self._x_shape = (self.n_features_in_,)

    def _expansion(self, sqdist: np.ndarray) -> np.ndarray:
        kernel = _kernel_from_sqdist(sqdist, sigma=self.sigma_, shape=self.shape_, scale=1.0)
        return kernel @ self._coef + self.intercept_

    def predict(self, X: np.ndarray) -> np.ndarray:
        """Predict targets by the kernel expansion f(x) = Σ βᵢ K(sᵢ, x) + b.

        Parameters
        ----------
        X : array_like of shape (n_samples, n_features)
            Inputs, finite, in the units used for training.

        Returns
        -------
        ndarray of shape (n_samples,)
            Predicted targets.
        """
        check_is_fitted(self)
        X = validate_data(self, X, reset=False, dtype=np.float64)
        return self._expansion(cdist(X, self.support_vectors_, "sqeuclidean"))

    def predict_one(self, x: np.ndarray) -> float:
        """Predict the target of one sample with minimal overhead.

        Meant for control loops and free-run (simulation) of NARX models, where
        one regressor vector is evaluated at a time: no DataFrame handling or
        scikit-learn validation, only a shape and a finiteness check. The result
        equals ``predict(x[None, :])[0]`` up to rounding.

        Parameters
        ----------
        x : ndarray of shape (n_features,)
            One input vector (float64 avoids a conversion).

        Returns
        -------
        float
            Predicted target.
        """
        try:
            support_vectors = self.support_vectors_
        except AttributeError:
            raise NotFittedError(
                f"This {_OWNER} instance is not fitted yet. Call 'fit' before 'predict_one'."
            ) from None
        x = np.asarray(x, dtype=np.float64)
        if x.shape != self._x_shape:
            raise ValueError(
                f"The 'x' of {_OWNER}.predict_one must have shape {self._x_shape}. "
                f"Got shape {x.shape} instead."
            )
        if not all(map(math.isfinite, x.tolist())):
            raise ValueError(f"The 'x' of {_OWNER}.predict_one must be finite. Got {x!r} instead.")
        diff = support_vectors - x
        arg = np.einsum("ij,ij->i", diff, diff)
        arg *= self._rate
        if self._half_shape == 0.5:
            np.sqrt(arg, out=arg)
        elif self._half_shape != 1.0:
            np.power(arg, self._half_shape, out=arg)
        np.negative(arg, out=arg)
        np.exp(arg, out=arg)
        return float(arg @ self._coef) + self.intercept_
