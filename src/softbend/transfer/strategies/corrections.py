"""The strategies that keep the base frozen and correct it: a scale and offset, a pressure
scale, a GP on the residuals."""

from __future__ import annotations

import warnings
from typing import TYPE_CHECKING, Literal, overload

import numpy as np
from numpy.typing import ArrayLike
from sklearn.exceptions import ConvergenceWarning
from sklearn.gaussian_process import GaussianProcessRegressor

from softbend.errors import InputError
from softbend.parameters import Range, declare_ranges
from softbend.surrogates.corrected import (
    AffineCorrected,
    GPCorrected,
    PressureScaled,
    gp_kernel,
    scaled_pressure_rows,
)
from softbend.surrogates.protocol import Surrogate
from softbend.transfer.pressure_map import (
    fit_pressure_scale,
)
from softbend.transfer.strategies.common import (
    _base_angles,
    _check_base,
    _check_finite_fit,
    _check_readings,
    _Corrected,
)

if TYPE_CHECKING:
    from softbend.actuators import Actuator


class ScaleOffset(_Corrected):
    """The base frozen and corrected linearly: ``θ = a·θ_base + c`` (least squares).

    Two numbers learned from the measurements: robust with one measured
    actuator, and it keeps the base's shape of θ(p). The interval is Gaussian
    with the residual standard deviation of the fit.
    """

    def __init__(self, base: Surrogate | None = None, *, actuator: Actuator | None = None) -> None:
        self.base = base
        self.actuator = actuator

    def fit(self, X: ArrayLike, y: ArrayLike) -> ScaleOffset:
        """Fit ``a`` and ``c`` on the rows."""
        base = _check_base(self.base)
        X, y = self._check_fit_data(X, y)
        _check_readings("scale-offset", y, 3, "two numbers and the spread around them")
        theta = _base_angles(base, X, "scale-offset")
        A = np.column_stack([theta, np.ones_like(theta)])
        with np.errstate(over="ignore", invalid="ignore"):  # checked below
            (self.scale_, self.offset_), _, rank, _ = np.linalg.lstsq(A, y, rcond=None)
        if rank < 2:
            raise InputError(
                "must hold readings at more than one pressure: the 'scale-offset' strategy "
                "cannot tell its scale from its offset where the base predicts the same angle "
                f"({theta[0]:g}°) at every reading",
                key="X",
            )
        with np.errstate(over="ignore", invalid="ignore"):  # checked below
            dof = max(y.size - 2, 1)
            self.residual_std_ = float(
                np.sqrt(np.sum((A @ [self.scale_, self.offset_] - y) ** 2) / dof)
            )
        _check_finite_fit(
            "scale-offset",
            self._described(),
            scale=self.scale_,
            offset=self.offset_,
            residual_std=self.residual_std_,
        )
        self.model_ = AffineCorrected(base, self.scale_, self.offset_, self.residual_std_)
        return self


class PressureScale(_Corrected):
    """The base frozen and asked at a scaled pressure: ``θ = θ_base(design, s·p)``.

    One number learned from the measurements, with a physical meaning: the
    measured elastomer is ``1/s`` times as stiff as the simulated one (see
    :mod:`softbend.transfer.pressure_map`, where the map is derived and its
    limits stated). Works with any base surrogate. The interval is Gaussian
    with the residual standard deviation of the fit.

    Attributes
    ----------
    scale_ : float
        The fitted pressure scale ``s``.
    residual_std_ : float
        Residual standard deviation on the training rows, degrees.
    """

    def __init__(self, base: Surrogate | None = None, *, actuator: Actuator | None = None) -> None:
        self.base = base
        self.actuator = actuator

    def fit(self, X: ArrayLike, y: ArrayLike) -> PressureScale:
        """Fit ``s`` by least squares on the rows."""
        base = _check_base(self.base)
        X, y = self._check_fit_data(X, y)
        _check_readings("pressure-scale", y, 2, "one number and the spread around it")
        self.scale_ = fit_pressure_scale(base, X, y, self._described())
        residual = np.asarray(base.predict(scaled_pressure_rows(X, self.scale_))) - y
        with np.errstate(over="ignore", invalid="ignore"):  # checked below
            self.residual_std_ = float(np.sqrt(np.sum(residual**2) / max(y.size - 1, 1)))
        _check_finite_fit(
            "pressure-scale", self._described(), scale=self.scale_, residual_std=self.residual_std_
        )
        self.model_ = PressureScaled(base, self.scale_, self.residual_std_)
        return self


def hyper_rows(n_rows: int, most: int, seed: int) -> np.ndarray:
    """The rows a GP's hyperparameters are chosen on: all ``n_rows`` when at most ``most``,
    else a seeded draw of ``most`` of them without repeats, in increasing order.

    Parameters
    ----------
    n_rows : int
        Training readings.
    most : int
        The most readings the marginal likelihood is optimized on.
    seed : int
        Seed of the draw (stream ``(seed, 11)``).

    Returns
    -------
    ndarray of int
    """
    if n_rows <= most:
        return np.arange(n_rows)
    rng = np.random.default_rng([seed, 11])
    return np.sort(rng.choice(n_rows, size=most, replace=False))


@declare_ranges(
    n_restarts=Range(
        0,
        100,
        "restarts",
        "each restart is one more full optimization of the GP's marginal likelihood "
        "(a Cholesky factorization per step); a billion would never end",
    ),
    hyper_points=Range(
        10,
        100000,
        "readings",
        "the marginal likelihood is optimized on at most this many readings (a seeded "
        "draw; all of them when there are fewer): its cost grows as their cube, and "
        "its memory as their square times 10 (the kernel's gradient)",
    ),
)
class ResidualGP(_Corrected):
    """The base frozen, a Gaussian process on its error (scikit-learn, with a noise term).

    The GP sees the standardized features and the base's angle (so an error that
    grows with the angle is a smooth function of one input); its kernel is a
    constant times an anisotropic RBF plus white noise, hyperparameters by
    marginal likelihood (``n_restarts`` seeded restarts) on at most
    ``hyper_points`` readings, a seeded draw of them (all of them when there are
    fewer); the posterior is then exact on every reading with those
    hyperparameters fixed. The likelihood's optimization is cubic in its
    readings and the posterior is one Cholesky factorization, so a fit on
    5 000 readings costs about what one on ``hyper_points`` does plus that
    factorization (docs/design-log.md gives the figures). Prediction intervals
    include the noise term, so they are intervals for a new reading.

    Parameters
    ----------
    base : estimator
        Any fitted surrogate.
    n_restarts : int, default 3
        Restarts of the hyperparameter optimizer, in [0, 100].
    hyper_points : int, default 200
        Readings the hyperparameters are chosen on, at most, in [10, 100 000].
    seed : int, default 0
        Seed of the restarts and of the draw of ``hyper_points`` readings.

    Attributes
    ----------
    hyper_rows_ : ndarray of int
        The training rows the hyperparameters were chosen on (every row when
        there are at most ``hyper_points``), in increasing order.
    """

    def __init__(
        self,
        base: Surrogate | None = None,
        *,
        n_restarts: int = 3,
        hyper_points: int = 200,
        seed: int = 0,
        actuator: Actuator | None = None,
    ) -> None:
        self.base = base
        self.n_restarts = n_restarts
        self.hyper_points = hyper_points
        self.seed = seed
        self.actuator = actuator

    def fit(self, X: ArrayLike, y: ArrayLike) -> ResidualGP:
        """Fit the GP to ``y − base(X)``."""
        self._check_parameters()
        base = _check_base(self.base)
        X, y = self._check_fit_data(X, y)
        theta = _base_angles(base, X, "residual-gp")
        Z = np.column_stack([X, theta])
        with np.errstate(over="ignore", invalid="ignore"):  # checked below
            z_mean = Z.mean(axis=0)
            scale = Z.std(axis=0)
            z_scale = np.where(scale > 0, scale, 1.0)
            inputs = (Z - z_mean) / z_scale
        _check_finite_fit("residual-gp", self._described(), z_mean=z_mean, z_scale=z_scale)
        # A length scale at its upper bound means "this input does not matter": a
        # normal outcome with six actuators, so the optimizer's warning is muted.
        rows = hyper_rows(y.size, int(self.hyper_points), int(self.seed))
        with warnings.catch_warnings():
            warnings.simplefilter("ignore", ConvergenceWarning)
            gp = GaussianProcessRegressor(
                kernel=gp_kernel(Z.shape[1]),
                normalize_y=True,
                n_restarts_optimizer=int(self.n_restarts),
                random_state=self.seed,
            ).fit(inputs[rows], (y - theta)[rows])
        self.hyper_rows_ = rows
        # The chosen hyperparameters, fixed: the model saves and reloads as it predicts here.
        self.model_ = GPCorrected(base, z_mean, z_scale, gp.kernel_.theta, inputs, y - theta)
        self.z_mean_, self.z_scale_ = z_mean, z_scale
        # The posterior asked at the rows of the hyperparameters (all of them when few):
        # a non-finite factor or dual coefficient shows there, at a bounded cost.
        with np.errstate(all="ignore"):  # checked below
            mean, std = self.model_.predict(X[rows], return_std=True)
        _check_finite_fit(
            "residual-gp",
            self._described(),
            z_mean=z_mean,
            z_scale=z_scale,
            kernel_theta=self.model_.kernel_theta_,
            training_prediction=mean,
            training_std=std,
        )
        return self

    @property
    def gp_(self) -> GaussianProcessRegressor:
        """scikit-learn's GP of the fitted correction, its kernel fixed (built on first use)."""
        gp: GaussianProcessRegressor = self.model_.gp_
        return gp

    @overload
    def predict(self, X: ArrayLike, return_std: Literal[False] = ...) -> np.ndarray: ...

    @overload
    def predict(self, X: ArrayLike, return_std: Literal[True]) -> tuple[np.ndarray, np.ndarray]: ...

    @overload
    def predict(
        self, X: ArrayLike, return_std: bool
    ) -> np.ndarray | tuple[np.ndarray, np.ndarray]: ...

    def predict(
        self, X: ArrayLike, return_std: bool = False
    ) -> np.ndarray | tuple[np.ndarray, np.ndarray]:
        """Corrected angle, degrees (and the predictive standard deviation)."""
        return self.model_.predict(self._check_rows(X), return_std=return_std)
