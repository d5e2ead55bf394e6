"""The strategies that learn no model: the base as it is, the base plus a mean residual by
pressure, and the analytical model."""

from __future__ import annotations

from typing import TYPE_CHECKING, ClassVar

import numpy as np
from numpy.typing import ArrayLike
from scipy.stats import norm

from softbend._validation import check_range
from softbend.design import sfrba_from_sequence
from softbend.errors import InputError
from softbend.models import BendingModel
from softbend.parameters import Range, declare_ranges
from softbend.surrogates.protocol import Surrogate
from softbend.transfer.strategies.common import (
    _base_angles,
    _check_base,
    _check_finite_fit,
    _check_readings,
    _Strategy,
)

if TYPE_CHECKING:
    from softbend.actuators import Actuator


class BaseOnly(_Strategy):
    """The base surrogate as it is ("fem-only"); ``fit`` only records the features."""

    learns: ClassVar[bool] = False

    def __init__(self, base: Surrogate | None = None, *, actuator: Actuator | None = None) -> None:
        self.base = base
        self.actuator = actuator

    def fit(self, X: ArrayLike, y: ArrayLike) -> BaseOnly:
        """Check the data; nothing is learned from it."""
        _check_base(self.base)
        self._check_fit_data(X, y)
        self.fitted_ = True
        return self

    def predict(self, X: ArrayLike) -> np.ndarray:
        """The base's angle, degrees."""
        return np.asarray(_check_base(self.base).predict(self._check_rows(X)), dtype=np.float64)


@declare_ranges(
    n_bins=Range(
        1,
        100,
        "pressure bands",
        "1 band is one constant offset at every pressure; each band averages the residuals of "
        "the readings in it, so more bands than distinct measured pressures leave each "
        "pressure a band of its own, and a band of a single reading carries its noise",
    )
)
class BaseMeanResidual(_Strategy):
    """The base plus the training actuators' mean residual at each pressure, ``θ_base + r(p)``.

    The simplest multi-fidelity correction, and the baseline every other strategy
    is judged against (``softbend transfer loco`` reports each strategy's mean
    RMSE relative to it): what the measurements say about the gap between the
    simulation and the rig *on average over the measured actuators*, as a
    function of pressure alone. It learns nothing about the design, so a
    strategy that does not beat it has learned nothing about the design
    either. A baseline: nothing is saved (``softbend transfer refine`` does not
    offer it).

    How ``r(p)`` is fitted on the training rows:

    1. each row's residual ``e = θ_measured − θ_base`` (degrees);
    2. the rows are split into at most ``n_bins`` pressure bands holding about
       as many readings each (quantiles of the measured pressures); readings at
       one pressure are never split, and with ``n_bins`` distinct pressures or
       fewer each pressure is a band of its own;
    3. in each band every actuator (a distinct design) gives the mean of its
       residuals and of its pressures, and the band's node is the mean over the
       actuators in it: each actuator weighs alike, however many readings it has;
    4. ``r(p)`` joins the nodes linearly (:func:`numpy.interp`); the first and
       last segments are carried straight on to the lowest and highest measured
       pressures, and ``r`` is constant beyond them: no trend is extrapolated
       past the measured pressures.

    Averaging over bands and actuators keeps it steady with 1 to 6 measured
    actuators (a band of one actuator is the mean of its few readings); it is
    exact where the gap is a function of pressure alone that is linear between
    the nodes (or any function, at the measured pressures, when each is a band).
    The interval is Gaussian with the standard deviation of the residuals about
    ``r(p)`` (degrees of freedom: readings − nodes, at least 1).

    Parameters
    ----------
    base : estimator
        Any fitted surrogate.
    n_bins : int, default 8
        The most pressure bands, in [1, 100]; 1 is a constant offset.

    Attributes
    ----------
    pressure_nodes_mpa_ : ndarray
        The nodes' pressures, MPa, increasing: the bands' and, with two bands or
        more, the lowest and highest measured pressures.
    residual_nodes_deg_ : ndarray
        ``r`` at the nodes, degrees.
    residual_std_ : float
        Standard deviation of the residuals about ``r(p)`` on the training rows, degrees.
    """

    learns: ClassVar[bool] = False

    def __init__(
        self, base: Surrogate | None = None, *, n_bins: int = 8, actuator: Actuator | None = None
    ) -> None:
        self.base = base
        self.n_bins = n_bins
        self.actuator = actuator

    def fit(self, X: ArrayLike, y: ArrayLike) -> BaseMeanResidual:
        """Fit ``r(p)`` to the residuals ``y − base(X)`` of the rows."""
        self._check_parameters()
        base = _check_base(self.base)
        n_bins = int(self.n_bins)
        X, y = self._check_fit_data(X, y)
        _check_readings("base-mean-residual", y, 2, "the mean residual and the spread around it")
        with np.errstate(over="ignore", invalid="ignore"):  # checked below
            residual = y - _base_angles(base, X, "base-mean-residual")
        pressure = X[:, -1]
        band = _pressure_bands(pressure, n_bins)
        _, actuator = np.unique(X[:, :-1], axis=0, return_inverse=True)
        actuator = actuator.ravel()
        nodes_p, nodes_r = [], []
        for b in range(int(band.max()) + 1):
            rows = band == b
            members = [rows & (actuator == a) for a in np.unique(actuator[rows])]
            nodes_p.append(np.mean([pressure[m].mean() for m in members]))
            with np.errstate(over="ignore", invalid="ignore"):  # checked below
                nodes_r.append(np.mean([residual[m].mean() for m in members]))
        with np.errstate(over="ignore", invalid="ignore"):  # checked below
            nodes = _end_nodes(nodes_p, nodes_r, float(pressure.min()), float(pressure.max()))
        self.pressure_nodes_mpa_, self.residual_nodes_deg_ = nodes
        with np.errstate(over="ignore", invalid="ignore"):  # checked below
            about = residual - self._residual(pressure)
            dof = max(y.size - len(nodes_p), 1)
            self.residual_std_ = float(np.sqrt(np.sum(about**2) / dof))
        _check_finite_fit(
            "base-mean-residual",
            self._described(),
            residual_nodes=self.residual_nodes_deg_,
            residual_std=self.residual_std_,
        )
        return self

    def _residual(self, pressure: np.ndarray) -> np.ndarray:
        """``r(p)``, degrees: the nodes joined linearly, constant beyond the end nodes."""
        return np.interp(pressure, self.pressure_nodes_mpa_, self.residual_nodes_deg_)

    def predict(self, X: ArrayLike) -> np.ndarray:
        """The base's angle plus the mean residual at the row's pressure, degrees."""
        X = self._check_rows(X)
        base = _check_base(self.base)
        return np.asarray(base.predict(X), dtype=np.float64) + self._residual(X[:, -1])

    def predict_interval(self, X: ArrayLike, level: float = 0.9) -> tuple[np.ndarray, np.ndarray]:
        """Central interval of probability ``level`` for a new reading (Gaussian), degrees."""
        level = check_range(level, "level", low=0.0, high=1.0)
        mean = self.predict(X)
        half = float(norm.ppf(0.5 + level / 2)) * self.residual_std_
        return mean - half, mean + half


def _end_nodes(
    pressures: list[float], residuals: list[float], low: float, high: float
) -> tuple[np.ndarray, np.ndarray]:
    """The bands' nodes, with the first and last segments carried to ``low`` and ``high``.

    A band's node lies inside the band, so the readings of the lowest and highest
    pressures are beyond the end nodes; the end segments are extended to them
    (straight), so that a gap linear in pressure is met exactly over the measured
    range. One node stays one (a constant).
    """
    p = np.asarray(pressures, dtype=np.float64)
    r = np.asarray(residuals, dtype=np.float64)
    if p.size < 2:
        return p, r
    first = r[0] + (r[1] - r[0]) / (p[1] - p[0]) * (low - p[0])
    last = r[-1] + (r[-1] - r[-2]) / (p[-1] - p[-2]) * (high - p[-1])
    below, above = bool(low < p[0]), bool(high > p[-1])
    return (
        np.concatenate([[low] * below, p, [high] * above]),
        np.concatenate([[first] * below, r, [last] * above]),
    )


def _pressure_bands(pressure: np.ndarray, n_bins: int) -> np.ndarray:
    """Each row's pressure band, 0, 1, ... in increasing pressure (none empty).

    At most ``n_bins`` bands of about as many rows each (quantiles); rows at one
    pressure share a band, and with ``n_bins`` distinct pressures or fewer each
    pressure is a band.
    """
    distinct = np.unique(pressure)
    if distinct.size <= n_bins:
        return np.searchsorted(distinct, pressure)
    edges = np.quantile(pressure, np.arange(1, n_bins) / n_bins)
    _, band = np.unique(np.searchsorted(edges, pressure, side="right"), return_inverse=True)
    return band.ravel()


class AnalyticalBaseline(_Strategy):
    """A bending model answered row by row (default: the analytical model; no training).

    Rows are grouped by design and each design is swept once over its sorted
    pressures. A pressure beyond where the model stops predicts NaN.

    Parameters
    ----------
    model : BendingModel, optional
        Default :class:`softbend.analytical.AnalyticalModel` (Dragon Skin 30 of
        paper B, no gravity).
    """

    learns: ClassVar[bool] = False

    @classmethod
    def refusal(cls, base: object, actuator: Actuator) -> str | None:
        """An actuator the analytical model describes (its ``analytical``) only."""
        if actuator.analytical:
            return None
        return f"models paper B's actuator only, and the base is a model of {actuator.name}"

    def __init__(
        self, model: BendingModel | None = None, *, actuator: Actuator | None = None
    ) -> None:
        self.model = model
        self.actuator = actuator

    def fit(self, X: ArrayLike, y: ArrayLike) -> AnalyticalBaseline:
        """Check the data; nothing is learned from it."""
        self._check_fit_data(X, y)
        self.model_: BendingModel
        if self.model is None:
            from softbend.analytical import AnalyticalModel

            self.model_ = AnalyticalModel()
        elif callable(getattr(self.model, "sweep", None)):
            self.model_ = self.model
        else:
            raise InputError(
                f"must be a bending model with a 'sweep' method (from Python); got {self.model!r}",
                key="model",
            )
        return self

    def predict(self, X: ArrayLike) -> np.ndarray:
        """The model's angle at each row, degrees (NaN beyond where it stops)."""
        X = self._check_rows(X)
        out = np.full(X.shape[0], np.nan)
        designs, inverse = np.unique(X[:, :-1], axis=0, return_inverse=True)
        for k, values in enumerate(designs):
            rows = np.flatnonzero(inverse.ravel() == k)
            pressures, where = np.unique(X[rows, -1], return_inverse=True)
            result = self.model_.sweep(sfrba_from_sequence(values), pressures)
            angle = np.full(pressures.size, np.nan)
            done = np.asarray(result.converged, dtype=bool)
            angle[: done.size][done] = np.asarray(result.angle_deg)[done]
            out[rows] = angle[where.ravel()]
        return out
