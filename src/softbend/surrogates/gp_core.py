"""A Gaussian process with fixed hyperparameters, in NumPy alone (no SciPy, no scikit-learn).

:class:`~softbend.surrogates.corrected.GPCorrected` corrects a surrogate by a
Gaussian process whose kernel is :func:`~softbend.surrogates.corrected.gp_kernel`
(constant × anisotropic RBF + white noise) at fixed log-hyperparameters. This is
scikit-learn's ``GaussianProcessRegressor(kernel, normalize_y=True,
optimizer=None, alpha=1e-10)`` fitted and asked the same way (Rasmussen &
Williams, Algorithm 2.1), so that a saved correction predicts without importing
scikit-learn; the two agree to about 1e-12 (the same operations, other LAPACK
calls for the triangular solves).
"""

from __future__ import annotations

import numpy as np
from numpy.typing import ArrayLike

__all__ = ["FixedGP"]

#: Added to the kernel matrix's diagonal (scikit-learn's default ``alpha``).
JITTER = 1e-10


def _sq_distances(a: np.ndarray, b: np.ndarray) -> np.ndarray:
    """Squared Euclidean distances between the rows of ``a`` (n, d) and ``b`` (m, d), summed
    input by input in order (as SciPy's ``cdist``, to the last bit)."""
    out = np.zeros((a.shape[0], b.shape[0]))
    for k in range(a.shape[1]):
        out += (a[:, None, k] - b[None, :, k]) ** 2
    return out


class FixedGP:
    """GP regression on ``inputs`` → ``targets`` with the kernel fixed at ``kernel_theta``.

    Parameters
    ----------
    kernel_theta : array_like of shape (d + 2,)
        Natural logarithms of the constant, the ``d`` RBF length scales and the
        white-noise level (``kernel.theta`` of :func:`gp_kernel`).
    inputs : array_like of shape (n, d)
        Training inputs (standardized, dimensionless).
    targets : array_like of shape (n,)
        Training targets (degrees); normalized to zero mean and unit variance inside.

    Raises
    ------
    numpy.linalg.LinAlgError
        If the kernel matrix is not positive definite.
    """

    def __init__(self, kernel_theta: ArrayLike, inputs: ArrayLike, targets: ArrayLike) -> None:
        params = np.exp(np.asarray(kernel_theta, dtype=np.float64))
        self.constant = float(params[0])
        self.length_scale = params[1:-1]
        self.noise = float(params[-1])
        #: The log-hyperparameters as the kernel reports them back (``log(exp(θ))``).
        self.theta = np.log(params)
        self.inputs = np.asarray(inputs, dtype=np.float64)
        targets = np.asarray(targets, dtype=np.float64)
        self.y_mean = float(np.mean(targets))
        std = float(np.std(targets))
        self.y_std = 1.0 if std < 10 * np.finfo(np.float64).eps else std
        y = (targets - self.y_mean) / self.y_std
        self._scaled = self.inputs / self.length_scale
        K = self.constant * np.exp(-0.5 * _sq_distances(self._scaled, self._scaled))
        np.fill_diagonal(K, self.constant)
        K[np.diag_indices_from(K)] += self.noise
        K[np.diag_indices_from(K)] += JITTER
        self.L = np.linalg.cholesky(K)
        self.alpha = np.linalg.solve(self.L.T, np.linalg.solve(self.L, y))

    def predict_mean(self, Z: ArrayLike) -> np.ndarray:
        """Predictive mean alone at rows ``Z``, degrees (``predict``'s first output, without
        the cost of the variance).

        Parameters
        ----------
        Z : array_like of shape (m, d)
            Inputs, standardized as the training inputs.

        Returns
        -------
        ndarray of shape (m,)
        """
        Z = np.asarray(Z, dtype=np.float64)
        K_trans = self.constant * np.exp(-0.5 * _sq_distances(Z / self.length_scale, self._scaled))
        return self.y_std * (K_trans @ self.alpha) + self.y_mean

    def predict(self, Z: ArrayLike) -> tuple[np.ndarray, np.ndarray]:
        """Predictive mean and standard deviation (noise included) at rows ``Z``, degrees.

        Parameters
        ----------
        Z : array_like of shape (m, d)
            Inputs, standardized as the training inputs.

        Returns
        -------
        mean, std : ndarray of shape (m,)
        """
        Z = np.asarray(Z, dtype=np.float64)
        K_trans = self.constant * np.exp(-0.5 * _sq_distances(Z / self.length_scale, self._scaled))
        mean = self.y_std * (K_trans @ self.alpha) + self.y_mean
        V = np.linalg.solve(self.L, K_trans.T)
        var = np.full(Z.shape[0], self.constant) + self.noise
        var -= np.einsum("ij,ji->i", V.T, V)
        var[var < 0] = 0.0
        return mean, np.sqrt(var * self.y_std**2)
