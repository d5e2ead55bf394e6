"""Surrogates built on other surrogates: corrected by measurements, or averaged.

Transfer learning (:mod:`softbend.transfer`) corrects a simulation-trained
surrogate with a few measurements. Three of its corrections are models of
their own that save, load and predict like any surrogate (on the rows of
:data:`softbend.surrogates.features.FEATURES`, mm, deg, MPa → degrees), each
with a prediction interval for a new reading:

=====================  =========================================================
``AffineCorrected``    ``θ = scale·θ_base + offset``; Gaussian interval of the
                       fit's residual standard deviation
``GPCorrected``        ``θ = θ_base + GP(z)``, a Gaussian process on the base's
                       error over the standardized inputs and the base's angle;
                       the GP's predictive interval (noise term included)
``MeanEnsemble``       the mean of several surrogates; Gaussian interval of
                       their spread and the residual noise of the mean
``PressureScaled``     ``θ = θ_base(design, s·p)``, the base asked at a scaled
                       pressure (an elastomer ``1/s`` times as stiff, see
                       :mod:`softbend.transfer.pressure_map`); Gaussian
                       interval of the fit's residual standard deviation
=====================  =========================================================

The Gaussian process is scikit-learn's kernel and regression. It is stored as its
fitted log-hyperparameters and training set and rebuilt with them fixed, which
gives back the same predictions; it predicts with
:class:`~softbend.surrogates.gp_core.FixedGP` (NumPy alone, the same numbers to
about 1e-12), so a saved correction loads and predicts without scikit-learn or
SciPy.
"""

from __future__ import annotations

from statistics import NormalDist
from typing import Any

import numpy as np
from numpy.typing import ArrayLike

from softbend._validation import check_range
from softbend.errors import InputError
from softbend.surrogates.gp_core import FixedGP
from softbend.surrogates.protocol import Surrogate

__all__ = [
    "AffineCorrected",
    "GPCorrected",
    "MeanEnsemble",
    "PressureScaled",
    "gp_kernel",
    "scaled_pressure_rows",
]


def _rows(X: ArrayLike, n_features: int) -> np.ndarray:
    rows = np.asarray(X, dtype=np.float64)
    if rows.ndim != 2 or rows.shape[1] != n_features:
        raise InputError(f"must have shape (n, {n_features}); got {rows.shape}", key="X")
    return rows


def scaled_pressure_rows(X: ArrayLike, scale: float) -> np.ndarray:
    """A copy of the rows with the pressure column (the last, MPa) multiplied by ``scale``."""
    rows = np.array(X, dtype=np.float64, copy=True)
    rows[:, -1] *= scale
    return rows


def _half_width(level: float, std: np.ndarray | float) -> np.ndarray | float:
    """Half the central interval of probability ``level`` of a Gaussian of ``std``."""
    level = check_range(level, "level", low=0.0, high=1.0)
    if level == 1.0:
        return np.inf * np.ones_like(std) if isinstance(std, np.ndarray) else np.inf
    return NormalDist().inv_cdf(0.5 + level / 2) * std


class AffineCorrected:
    """A surrogate corrected linearly: ``θ = scale·θ_base + offset`` (degrees).

    Parameters
    ----------
    base : estimator
        A fitted surrogate on the 7 inputs.
    scale : float
        Factor on the base's angle (dimensionless).
    offset : float
        Added angle, degrees.
    residual_std : float
        Standard deviation of the fit's residuals, degrees (>= 0): the
        interval's width.
    """

    def __init__(self, base: Surrogate, scale: float, offset: float, residual_std: float) -> None:
        self.base = base
        self.scale_ = float(scale)
        self.offset_ = float(offset)
        self.residual_std_ = float(residual_std)
        self.n_features_in_ = int(base.n_features_in_)

    def predict(self, X: ArrayLike) -> np.ndarray:
        """Corrected angle, degrees."""
        rows = _rows(X, self.n_features_in_)
        return self.scale_ * np.asarray(self.base.predict(rows), dtype=np.float64) + self.offset_

    def predict_interval(self, X: ArrayLike, level: float = 0.9) -> tuple[np.ndarray, np.ndarray]:
        """Central interval of probability ``level`` (Gaussian residuals), degrees."""
        half = _half_width(level, self.residual_std_)
        mean = self.predict(X)
        return mean - half, mean + half


class PressureScaled:
    """A surrogate asked at a scaled pressure: ``θ = θ_base(design, scale·p)`` (degrees).

    Parameters
    ----------
    base : estimator
        A fitted surrogate on the 7 inputs (pressure last, MPa).
    scale : float
        Factor on the pressure, > 0 (dimensionless): the measured elastomer is
        ``1/scale`` times as stiff as the simulated one.
    residual_std : float
        Standard deviation of the fit's residuals, degrees (>= 0): the
        interval's width.
    """

    def __init__(self, base: Surrogate, scale: float, residual_std: float) -> None:
        self.base = base
        self.scale_ = check_range(scale, "scale", low=0.0)
        self.residual_std_ = float(residual_std)
        self.n_features_in_ = int(base.n_features_in_)

    def predict(self, X: ArrayLike) -> np.ndarray:
        """The base's angle at the scaled pressure, degrees."""
        rows = scaled_pressure_rows(_rows(X, self.n_features_in_), self.scale_)
        return np.asarray(self.base.predict(rows), dtype=np.float64)

    def predict_interval(self, X: ArrayLike, level: float = 0.9) -> tuple[np.ndarray, np.ndarray]:
        """Central interval of probability ``level`` (Gaussian residuals), degrees."""
        half = _half_width(level, self.residual_std_)
        mean = self.predict(X)
        return mean - half, mean + half


def gp_kernel(n_inputs: int) -> Any:
    """The kernel of :class:`GPCorrected`: constant × anisotropic RBF + white noise.

    Hyperparameters start at 1 (0.1 for the noise) with bounds wide enough for
    standardized inputs; their order in ``kernel.theta`` is constant, the
    ``n_inputs`` length scales, noise.
    """
    from sklearn.gaussian_process.kernels import RBF, ConstantKernel, WhiteKernel

    return ConstantKernel(1.0, (1e-3, 1e3)) * RBF(np.ones(n_inputs), (1e-1, 1e5)) + WhiteKernel(
        0.1, (1e-5, 10.0)
    )


class GPCorrected:
    """A surrogate plus a Gaussian process on its error: ``θ = θ_base + GP(z)``.

    ``z`` is the rows with the base's angle appended, standardized by
    ``z_mean`` and ``z_scale`` (so an error that grows with the angle is a
    smooth function of one input). The GP (scikit-learn's regression with
    ``normalize_y``) has the kernel :func:`gp_kernel` fixed at ``kernel_theta``;
    it is fitted here, on ``inputs`` and ``targets``, without optimizing it
    again, and predicts with :class:`~softbend.surrogates.gp_core.FixedGP`
    (NumPy alone; ``gp_`` builds scikit-learn's on first use).

    Parameters
    ----------
    base : estimator
        A fitted surrogate on the 7 inputs.
    z_mean, z_scale : ndarray of shape (8,)
        Standardization of the GP's inputs (``z_scale`` > 0).
    kernel_theta : ndarray of shape (10,)
        The kernel's log-hyperparameters (``kernel.theta``: constant, 8 length
        scales, noise), e.g. those the marginal likelihood chose.
    inputs : ndarray of shape (n, 8)
        Standardized ``z`` of the training rows.
    targets : ndarray of shape (n,)
        The base's error on them (measured minus base), degrees.
    """

    def __init__(
        self,
        base: Surrogate,
        z_mean: ArrayLike,
        z_scale: ArrayLike,
        kernel_theta: ArrayLike,
        inputs: ArrayLike,
        targets: ArrayLike,
    ) -> None:
        self.base = base
        self.z_mean_ = np.asarray(z_mean, dtype=np.float64)
        self.z_scale_ = np.asarray(z_scale, dtype=np.float64)
        self.inputs_ = np.asarray(inputs, dtype=np.float64)
        self.targets_ = np.asarray(targets, dtype=np.float64)
        self._gp = FixedGP(kernel_theta, self.inputs_, self.targets_)
        self._sklearn_gp: Any = None
        self.n_features_in_ = int(base.n_features_in_)

    @property
    def kernel_theta_(self) -> np.ndarray:
        """The kernel's log-hyperparameters (constant, length scales, noise)."""
        return self._gp.theta

    @property
    def gp_(self) -> Any:
        """scikit-learn's ``GaussianProcessRegressor`` fitted with the kernel fixed (built on
        first use; the predictions are :class:`~softbend.surrogates.gp_core.FixedGP`'s)."""
        if self._sklearn_gp is None:
            from sklearn.gaussian_process import GaussianProcessRegressor

            kernel = gp_kernel(self.inputs_.shape[1])
            kernel.theta = self._gp.theta
            gp = GaussianProcessRegressor(kernel=kernel, normalize_y=True, optimizer=None)
            self._sklearn_gp = gp.fit(self.inputs_, self.targets_)
        return self._sklearn_gp

    def _inputs(self, rows: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
        theta = np.asarray(self.base.predict(rows), dtype=np.float64)
        return theta, (np.column_stack([rows, theta]) - self.z_mean_) / self.z_scale_

    def predict(
        self, X: ArrayLike, return_std: bool = False
    ) -> np.ndarray | tuple[np.ndarray, np.ndarray]:
        """Corrected angle, degrees (and the predictive standard deviation, degrees)."""
        theta, z = self._inputs(_rows(X, self.n_features_in_))
        mean, std = self._gp.predict(z)
        return (theta + mean, std) if return_std else theta + mean

    def predict_interval(self, X: ArrayLike, level: float = 0.9) -> tuple[np.ndarray, np.ndarray]:
        """Central interval of probability ``level`` for a new reading, degrees."""
        mean, std = self.predict(X, return_std=True)
        half = _half_width(level, std)
        return mean - half, mean + half


class MeanEnsemble:
    """The mean of several surrogates, with an interval from their spread.

    Parameters
    ----------
    members : list of estimator
        Two or more fitted surrogates on the 7 inputs.
    residual_std : float
        Residual standard deviation of the mean on its training rows, degrees
        (>= 0); added in quadrature to the spread for the interval.
    """

    def __init__(self, members: list[Surrogate], residual_std: float) -> None:
        if len(members) < 2:
            raise InputError(f"must be 2 or more surrogates; got {len(members)}", key="members")
        self.members_ = list(members)
        self.residual_std_ = float(residual_std)
        self.n_features_in_ = int(members[0].n_features_in_)

    def spread(self, X: ArrayLike) -> tuple[np.ndarray, np.ndarray]:
        """The members' mean and sample standard deviation, degrees."""
        rows = _rows(X, self.n_features_in_)
        predictions = np.array([m.predict(rows) for m in self.members_], dtype=np.float64)
        return predictions.mean(axis=0), predictions.std(axis=0, ddof=1)

    def predict(self, X: ArrayLike) -> np.ndarray:
        """Members' mean angle, degrees."""
        return self.spread(X)[0]

    def predict_interval(self, X: ArrayLike, level: float = 0.9) -> tuple[np.ndarray, np.ndarray]:
        """Central interval of probability ``level`` (spread and noise, Gaussian), degrees."""
        mean, spread = self.spread(X)
        half = _half_width(level, np.sqrt(spread**2 + self.residual_std_**2))
        return mean - half, mean + half
