"""Ways to correct a simulation-trained surrogate with a few measurements (paper B §4.2).

Every strategy is a scikit-learn regressor on the rows of
:data:`softbend.design.FEATURES` (mm, deg, MPa) → bending angle (degrees) that
starts from a fitted *base* surrogate (any estimator with ``predict``; the MLP
trained on the FEM dataset by default):

======================  ============================================================
``fem-only``            the base, unchanged (paper B's "NMLPR"), a baseline
``base-mean-residual``  the base frozen, plus the measured actuators' mean residual as
                        a function of pressure alone: the baseline every strategy is
                        judged against (it knows nothing of the design)
``analytical``          the analytical model of the actuator, a baseline (no base)
``refined``             paper B's refined MLP: every layer trained further from the
                        base's weights on the measurements, input scaling kept
``experimental``        paper B's experimental MLP: from scratch, measurements only
``residual-gp``         the base frozen, a Gaussian process on its error with a
                        noise term; gives prediction intervals
``scale-offset``        the base frozen, ``θ = a·θ_base + c`` by least squares
``pressure-scale``      the base frozen and asked at ``s·p``: one number for an
                        elastomer softer or stiffer than the simulated one
                        (:mod:`softbend.transfer.pressure_map`); gives intervals
``refined-ensemble``    refined MLPs on bootstrap draws of the measured
                        actuators; mean, and an interval from their spread
``scaled-refined``      the pressure scale fitted first and folded into the MLP,
                        then paper B's refinement from that start
======================  ============================================================

Strategies with intervals have ``predict_interval(X, level)``.

Every numeric parameter declares the range it accepts beside its class
(:func:`~softbend.parameters.declare_ranges`; the table of the guarantees page
lists them): ``--set``, a Python option or a strategy built directly is held to
it before any work. A network whose training diverges anyway (non-finite
losses, or angles no actuator reaches on its own training rows) is a
:class:`~softbend.errors.ConvergenceError`, never a saved model.

:data:`STRATEGIES` maps each name to its class; one call adds a strategy, from
inside softbend or outside it, and every command and report then knows it::

    STRATEGIES.register("my-strategy", MyStrategy)
    # softbend transfer refine BASE.json lab.csv --out m.json --strategy my-strategy

A strategy class is a scikit-learn regressor on the rows above. Its
constructor's ``base`` and ``seed``, if it takes them, are filled by the library;
its other parameters, with defaults, are the ones a user sets
(:mod:`softbend.transfer.parameters`: ``--set NAME=VALUE``). ``fit(X, y)`` sets
``model_``, the surrogate that ``softbend transfer refine`` saves; a class whose
``learns`` is False (a baseline) has nothing to save. A class method
``refusal(base, actuator)`` says why the strategy cannot start from a base (the
network strategies need an ``mlp``; ``analytical``, paper B's actuator), or None
when it can: the default runs leave such a strategy out and say why
(:func:`applicable_strategies`), and a run that names it is refused before any
work (:func:`check_applicable`). A class without one takes any base.
"""

from __future__ import annotations

import math
import warnings
from collections.abc import Sequence
from typing import TYPE_CHECKING, Any, ClassVar, Literal, overload

import numpy as np
from numpy.typing import ArrayLike
from scipy.stats import norm
from sklearn.base import BaseEstimator, RegressorMixin
from sklearn.exceptions import ConvergenceWarning
from sklearn.gaussian_process import GaussianProcessRegressor
from sklearn.utils.validation import check_is_fitted, validate_data

from softbend._validation import check_int, check_range
from softbend.design import SFRBADesign
from softbend.errors import ConvergenceError, InputError, SoftbendError, keyed
from softbend.models import BendingModel
from softbend.parameters import Range, declare_ranges, declared_ranges
from softbend.plausibility import RANGES as PLAUSIBLE
from softbend.plausibility import check_plausible
from softbend.registry import Registry
from softbend.surrogates.corrected import (
    AffineCorrected,
    GPCorrected,
    MeanEnsemble,
    PressureScaled,
    gp_kernel,
    scaled_pressure_rows,
)
from softbend.surrogates.protocol import Surrogate
from softbend.transfer.finetune import check_mlp, fine_tune_many, row_weights
from softbend.transfer.parameters import (
    check_estimator,
    check_parameters,
    describe_range,
    parameter_defaults,
    takes,
)
from softbend.transfer.pressure_map import (
    fit_pressure_scale,
    scale_mlp_pressure,
)

if TYPE_CHECKING:
    from softbend.actuators import Actuator
    from softbend.surrogates.mlp import NormalizedMLPRegressor
    from softbend.transfer.measurements import ActuatorMeasurements, Measurements

__all__ = [
    "BUILTIN_STRATEGIES",
    "FIT_ERRORS",
    "NETWORK_STRATEGIES",
    "STRATEGIES",
    "AnalyticalBaseline",
    "BaseMeanResidual",
    "BaseOnly",
    "ExperimentalMLP",
    "PressureScale",
    "RefinedEnsemble",
    "RefinedMLP",
    "ResidualGP",
    "ScaleOffset",
    "ScaledRefinedMLP",
    "applicable_strategies",
    "base_family",
    "check_applicable",
    "describe_strategies",
    "fit_strategy",
    "has_interval",
    "learns",
    "make_strategy",
    "strategy_parameters",
    "strategy_refusal",
]

#: The strategies by name, in the order of the tables (filled at the end of this module).
STRATEGIES: Registry[type] = Registry("transfer strategy")

#: The strategies that train a network (they take ``epochs``).
NETWORK_STRATEGIES: tuple[str, ...] = (
    "refined",
    "experimental",
    "refined-ensemble",
    "scaled-refined",
)


#: The errors of one strategy's fit on one set of rows that leave the other fits standing
#: (readings it cannot fit, a fit that diverged or failed numerically); any other error (a
#: bug, an interrupt, memory) stops the caller.
FIT_ERRORS: tuple[type[Exception], ...] = (SoftbendError, ValueError, ArithmeticError)


#: Adam steps of a network strategy; the largest is the ``epochs`` limit of
#: :mod:`softbend.limits` (``SOFTBEND_MAX_EPOCHS``), checked beside the range.
_EPOCHS = Range(
    1,
    math.inf,
    "Adam steps",
    "at least one step to train at all; the most is the 'epochs' limit (100 000 unless "
    "SOFTBEND_MAX_EPOCHS raises it): each epoch is a full-batch step of every refit",
)
#: Adam's step size, in the standardized units of the weights.
_LEARNING_RATE = Range(
    0,
    1,
    "standardized units",
    "a step of 0 learns nothing; above 1 Adam's steps overshoot the tanh network's "
    "standardized weights and the training diverges to huge or NaN angles",
    low_inclusive=False,
)


def _registered_name(cls: type) -> str:
    """The name ``cls`` is registered under in :data:`STRATEGIES`, else its class name."""
    return next((name for name, entry in STRATEGIES.items() if entry is cls), cls.__name__)


def base_family(base: object) -> str:
    """The family a base surrogate is saved as (``"plr"``, ``"mlp"``, a composite's kind).

    ``"custom"`` for a model that is no saved family (built in Python), ``"no"`` for None:
    the words a message uses for the base ("a plr surrogate").
    """
    from softbend.surrogates.persistence import kind_of

    if base is None:
        return "no"
    try:
        return kind_of(base)
    except InputError:
        return "custom"


def _needs_mlp(base: object) -> str | None:
    """Why a strategy that trains the base's network further cannot start from ``base``."""
    from softbend.surrogates.mlp import NormalizedMLPRegressor

    if isinstance(base, NormalizedMLPRegressor):
        return None
    return (
        f"trains the base's network further, and the base is a {base_family(base)} "
        "surrogate, not an mlp"
    )


def _fit_failed(estimator: object, error: Exception, keep_going: bool) -> None:
    """One estimator of a batch could not be fitted: raise ``error``, or (``keep_going``)
    record it on the estimator as ``fit_error_`` and let the others be fitted."""
    if not keep_going:
        raise error
    estimator.fit_error_ = error  # type: ignore[attr-defined]


def _tune_batch(
    starts: Any,
    X: np.ndarray,
    y: np.ndarray,
    row_sets: list[np.ndarray],
    first: Any,
    estimators: Sequence[object],
    keep_going: bool,
) -> list[NormalizedMLPRegressor] | None:
    """``fine_tune_many`` of ``starts`` on each of ``row_sets`` with ``first``'s settings.

    None when the batch as a whole fails (every fit of it): the error is raised, or
    (``keep_going``) recorded on each of ``estimators`` (:func:`_fit_failed`).
    """
    try:
        return fine_tune_many(
            starts,
            X,
            y,
            row_weights(row_sets, len(y)),
            epochs=first.epochs,
            learning_rate=first.learning_rate,
            device=first.device,
        )
    except ConvergenceError as error:
        for estimator in estimators:
            _fit_failed(estimator, error, keep_going)
        return None


def _check_trained(
    strategy: str, model: NormalizedMLPRegressor, X: np.ndarray, learning_rate: float
) -> None:
    """Raise :class:`ConvergenceError` if a trained network diverged.

    Diverged: a non-finite training loss, or a non-finite angle or one no
    actuator reaches (outside the plausible range of
    :mod:`softbend.plausibility`) at a reading it was trained on.
    """
    with np.errstate(all="ignore"):
        loss = np.asarray(model.loss_curve_, dtype=np.float64) * model.y_scale_**2
        angles = np.asarray(model.predict(X), dtype=np.float64)
    bounds = PLAUSIBLE["angle_deg"]
    bad = ~np.isfinite(angles) | (angles < bounds.low) | (angles > bounds.high)
    if np.isfinite(loss).all() and not bad.any():
        return
    if bad.any():
        first = float(angles[np.flatnonzero(bad)[0]])
        found = (
            f"it predicts {first:.4g}° at {int(bad.sum())} of the {angles.size} readings it "
            f"was trained on (plausible: {bounds.low:g} to {bounds.high:g}°)"
        )
    else:
        found = "its training loss is not finite"
    raise ConvergenceError(
        f"The '{strategy}' strategy's training diverged at learning_rate {learning_rate:g}: "
        f"{found}. Lower the learning_rate (--set learning_rate=...)"
    )


def _check_base(base: object) -> Surrogate:
    """``base`` if it predicts, else :class:`InputError` keyed ``base``."""
    if not callable(getattr(base, "predict", None)):
        raise InputError(
            f"must be a fitted surrogate with a 'predict' method; got {type(base).__name__}",
            key="base",
        )
    return base  # type: ignore[return-value]


def _check_same(estimators: Sequence[object], names: tuple[str, ...]) -> None:
    """Refuse estimators of one batch (``fit_batch``) that differ in one of ``names``."""
    first = estimators[0]
    for estimator in estimators[1:]:
        for name in names:
            mine, theirs = getattr(estimator, name), getattr(first, name)
            if mine is not theirs and mine != theirs:
                raise InputError(
                    f"must share {name!r}; got {theirs!r} and {mine!r}", key="estimators"
                )


def _row(index: int) -> str:
    return f"row {index}"


def _base_angles(base: Surrogate, X: np.ndarray, strategy: str) -> np.ndarray:
    """The base's angles at the rows, degrees; one error (key ``base``) if not finite."""
    theta = np.asarray(base.predict(X), dtype=np.float64)
    bad = np.flatnonzero(~np.isfinite(theta))
    if bad.size:
        raise InputError(
            f"predicts a non-finite angle at {bad.size} of the {theta.size} measured rows "
            f"(first: row {int(bad[0])}, {', '.join(f'{v:g}' for v in X[bad[0]])}); the "
            f"'{strategy}' strategy cannot correct it there",
            key="base",
        )
    return theta


def _check_readings(strategy: str, y: np.ndarray, least: int, fits: str) -> None:
    """Refuse fewer than ``least`` readings (key ``X``) for a strategy that fits ``fits``."""
    if y.size < least:
        raise InputError(
            f"must hold at least {least} readings: the '{strategy}' strategy fits {fits}; "
            f"got {y.size}",
            key="X",
        )


def _check_finite_fit(strategy: str, actuator: Actuator, **parameters: ArrayLike) -> None:
    """Raise :class:`ConvergenceError` naming ``strategy`` if a fitted parameter is not finite.

    The message names the pressure column of ``actuator``, the readings' actuator.

    A fit that overflowed (absurd angles, a base that answers with huge numbers)
    must fail here, never be saved or used with an infinite spread.
    """
    bad = []
    for name, value in parameters.items():
        array = np.asarray(value, dtype=np.float64)
        if not np.isfinite(array).all():
            bad.append(f"{name}={float(array):g}" if array.ndim == 0 else f"{name} not all finite")
    if bad:
        column, unit = actuator.pressure_column, actuator.pressure_unit
        raise ConvergenceError(
            f"The '{strategy}' strategy fitted non-finite parameters ({', '.join(bad)}): the "
            "measured angles or the base's predictions are too large for the fit. Check the "
            f"measurements (angles in degrees, '{column}' in {unit}) and the base surrogate"
        )


class _Strategy(RegressorMixin, BaseEstimator):
    """Validation shared by the strategies: the inputs of the readings' actuator, finite,
    and plausible angles.

    Each strategy takes the readings' actuator (``actuator``, filled by the
    library as ``base`` is: :func:`make_strategy`); None, or a strategy class
    without the parameter, is paper B's.
    """

    #: Whether fitting learns a model from the measurements (``model_``, saved by refine).
    learns: ClassVar[bool] = True

    @classmethod
    def refusal(cls, base: object, actuator: Actuator) -> str | None:
        """Why the strategy cannot start from ``base`` for a model of ``actuator``; None if it can.

        The reason is the rest of a sentence that begins with the strategy's name
        (``"'refined' trains the base's network further, and ..."``): what chooses
        the strategies that apply to a base (``softbend transfer loco`` by
        default) and refuses one named for a base it cannot take, before any
        work. Here: a strategy that starts from a base needs one that predicts.
        """
        if takes(cls, "base") and not callable(getattr(base, "predict", None)):
            return "starts from a base surrogate that predicts, and none was given"
        return None

    def _described(self) -> Actuator:
        """The readings' actuator: the one filled in, else paper B's."""
        from softbend.actuators import SFRBA

        actuator = getattr(self, "actuator", None)
        return SFRBA if actuator is None else actuator

    def _check_fit_data(self, X: ArrayLike, y: ArrayLike) -> tuple[np.ndarray, np.ndarray]:
        X_arr, y_arr = validate_data(self, X, y, dtype=np.float64, y_numeric=True)
        owner = f"the '{_registered_name(type(self))}' strategy's training readings"
        actuator = self._described()
        features = actuator.features
        if X_arr.shape[1] != len(features):
            raise InputError(
                f"must have the {len(features)} columns {', '.join(features)}; got "
                f"{X_arr.shape[1]} columns",
                key="X",
            )
        column = actuator.pressure_column
        quantity = actuator.quantities.get(column)  # a pressure unit with a plausible range
        if quantity is not None:
            check_plausible(X_arr[:, -1], quantity, source=owner, column=column, where=_row)
        check_plausible(y_arr, "angle_deg", source=owner, column="angle_deg", where=_row)
        return X_arr, y_arr

    def _check_rows(self, X: ArrayLike) -> np.ndarray:
        check_is_fitted(self)
        return validate_data(self, X, reset=False, dtype=np.float64)

    def _check_parameters(self) -> None:
        """Hold the parameters to their declared ranges (a strategy built directly)."""
        check_estimator(self)


class _Corrected(_Strategy):
    """A strategy whose fitted ``model_`` is a surrogate with an interval (``corrected``)."""

    def predict(self, X: ArrayLike) -> np.ndarray:
        """Corrected angle, degrees."""
        return self.model_.predict(self._check_rows(X))

    def predict_interval(self, X: ArrayLike, level: float = 0.9) -> tuple[np.ndarray, np.ndarray]:
        """Central interval of probability ``level`` for a new reading, degrees.

        Gaussian, with the width the model states: the fit's residual spread
        (scale-offset, pressure-scale), the GP's predictive deviation with its
        noise term (residual-gp), the members' spread and the residual noise
        (refined-ensemble).
        """
        level = check_range(level, "level", low=0.0, high=1.0)
        return self.model_.predict_interval(self._check_rows(X), level)


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
            result = self.model_.sweep(SFRBADesign.from_sequence(values), pressures)
            angle = np.full(pressures.size, np.nan)
            done = np.asarray(result.converged, dtype=bool)
            angle[: done.size][done] = np.asarray(result.angle_deg)[done]
            out[rows] = angle[where.ravel()]
        return out


@declare_ranges(epochs=_EPOCHS, learning_rate=_LEARNING_RATE)
class RefinedMLP(_Strategy):
    """Paper B's refined MLP: the FEM-trained MLP trained further on the measurements.

    All layers are trained (paper B names no frozen layers) from the base's
    weights with the base's input and target scaling kept; Adam, full batch
    (paper B's batches of 1024 rows hold any set of measurements).

    Parameters
    ----------
    base : NormalizedMLPRegressor
        The FEM-trained MLP.
    epochs : int, default 1000
        Adam steps over the measurements (paper B Fig. 6: 1000 epochs), >= 1 and
        at most the ``epochs`` limit of :mod:`softbend.limits`.
    learning_rate : float, default 6e-4
        Adam step size (paper B's), in (0, 1].
    device : {"auto", "cpu", "cuda"}, default "auto"
        Where the refits train (:func:`~softbend.transfer.finetune.fine_tune_many`):
        "auto" is the GPU when torch sees one.
    seed : int, default 0
        Unused (full-batch training draws nothing); kept for a uniform interface.

    Attributes
    ----------
    model_ : NormalizedMLPRegressor
        The refined network; saves and loads as an ``mlp`` surrogate.
    loss_curve_ : ndarray
        Training MSE per epoch, deg².
    """

    def __init__(
        self,
        base: Surrogate | None = None,
        *,
        epochs: int = 1000,
        learning_rate: float = 6e-4,
        device: str = "auto",
        seed: int = 0,
        actuator: Actuator | None = None,
    ) -> None:
        self.base = base
        self.epochs = epochs
        self.learning_rate = learning_rate
        self.device = device
        self.seed = seed
        self.actuator = actuator

    @classmethod
    def refusal(cls, base: object, actuator: Actuator) -> str | None:
        """An ``mlp`` base only: its weights are trained further."""
        return _needs_mlp(base)

    def fit(self, X: ArrayLike, y: ArrayLike) -> RefinedMLP:
        """Refine the base on the rows (mm, deg, MPa → degrees)."""
        X, y = self._check_fit_data(X, y)
        return type(self).fit_batch([self], X, y, [np.arange(y.size)])[0]

    @classmethod
    def fit_batch(
        cls,
        estimators: list[RefinedMLP],
        X: np.ndarray,
        y: np.ndarray,
        row_sets: list,
        *,
        keep_going: bool = False,
    ) -> list[RefinedMLP]:
        """Fit each estimator on its rows of ``X, y``, all trained at once.

        The same result as fitting each alone (up to rounding): see
        :mod:`softbend.transfer.finetune`. The estimators must share base,
        epochs and learning rate. With ``keep_going``, an estimator whose rows
        cannot be fitted (its start, or a diverged training) gets the error as
        ``fit_error_`` and the others are fitted; else the first error is raised.
        """
        first = estimators[0]
        for estimator in estimators:
            estimator._check_parameters()
        base = check_mlp(first.base)
        _check_same(estimators, ("base", "epochs", "learning_rate", "device"))
        starts = cls._starts(base, X, y, row_sets, first._described())
        live: list[int] = []
        ready: list[NormalizedMLPRegressor] = []
        for i, start in enumerate(starts):
            if isinstance(start, Exception):
                _fit_failed(estimators[i], start, keep_going)
            else:
                live.append(i)
                ready.append(start)
        if not live:
            return estimators
        models = _tune_batch(
            ready, X, y, [row_sets[i] for i in live], first, [estimators[i] for i in live],
            keep_going,
        )  # fmt: skip
        if models is None:
            return estimators
        name = _registered_name(cls)
        for i, model in zip(live, models, strict=True):
            try:
                _check_trained(name, model, X[np.asarray(row_sets[i])], first.learning_rate)
            except ConvergenceError as error:
                _fit_failed(estimators[i], error, keep_going)
                continue
            estimators[i]._set(model, X)
        return estimators

    @classmethod
    def _starts(
        cls,
        base: NormalizedMLPRegressor,
        X: np.ndarray,
        y: np.ndarray,
        row_sets: list,
        actuator: Actuator,
    ) -> list[NormalizedMLPRegressor | Exception]:
        """Where training starts for each row set (or why it cannot): the base itself."""
        return [base] * len(row_sets)

    def _set(self, model: NormalizedMLPRegressor, X: np.ndarray) -> None:
        self.model_ = model
        self.loss_curve_ = np.asarray(model.loss_curve_) * model.y_scale_**2
        self.n_features_in_ = X.shape[1]

    def predict(self, X: ArrayLike) -> np.ndarray:
        """Refined angle, degrees."""
        return self.model_.predict(self._check_rows(X))


@declare_ranges(
    hidden_sizes=Range(
        1,
        1024,
        "units per layer",
        "two hidden layers (paper B's network); a layer of 0 units divides by zero, and "
        "the weights grow as the product of the sizes: 1024 x 1024 is 8 MB per network "
        "(and Adam's state), 100000 x 100000 would be 80 GB",
        max_items=2,
    ),
    epochs=_EPOCHS,
    learning_rate=_LEARNING_RATE,
)
class ExperimentalMLP(_Strategy):
    """Paper B's experimental MLP: the same network from scratch on the measurements.

    Parameters
    ----------
    hidden_sizes : tuple of int, default (63, 65)
        The sizes of the two hidden layers, each in [1, 1024] (paper B's MLP: 63, 65).
    epochs : int, default 15000
        Paper B Fig. 6; as for :class:`RefinedMLP`.
    learning_rate : float, default 6e-4
        Adam step size (paper B's), in (0, 1].
    device : {"auto", "cpu", "cuda"}, default "auto"
        Where the refits train (:func:`~softbend.transfer.finetune.fine_tune_many`):
        "auto" is the GPU when torch sees one.
    seed : int, default 0
        Seed of the initial weights.

    Attributes
    ----------
    model_ : NormalizedMLPRegressor
    loss_curve_ : ndarray
        Training MSE per epoch, deg².
    """

    def __init__(
        self,
        *,
        hidden_sizes: tuple[int, int] = (63, 65),
        epochs: int = 15000,
        learning_rate: float = 6e-4,
        device: str = "auto",
        seed: int = 0,
        actuator: Actuator | None = None,
    ) -> None:
        self.hidden_sizes = hidden_sizes
        self.epochs = epochs
        self.learning_rate = learning_rate
        self.device = device
        self.seed = seed
        self.actuator = actuator

    def fit(self, X: ArrayLike, y: ArrayLike) -> ExperimentalMLP:
        """Train from a seeded random initialization on the rows."""
        X, y = self._check_fit_data(X, y)
        return type(self).fit_batch([self], X, y, [np.arange(y.size)])[0]

    @classmethod
    def fit_batch(
        cls,
        estimators: list[ExperimentalMLP],
        X: np.ndarray,
        y: np.ndarray,
        row_sets: list,
        *,
        keep_going: bool = False,
    ) -> list[ExperimentalMLP]:
        """Fit each estimator on its rows, all trained at once (full batch).

        Estimator k standardizes inputs and target on its own rows and draws its
        initial weights as the grid trainer's split k does (stream
        ``(seed, h1, h2, k)``, :func:`~softbend.surrogates.mlp_core.init_parameters`);
        the first is what :meth:`fit` gives. Paper B's batches of 1024 rows hold
        any set of measurements, so every epoch is one full-batch Adam step.
        The estimators must share every parameter. ``keep_going`` as for
        :meth:`RefinedMLP.fit_batch`.
        """
        from softbend.surrogates.mlp import NormalizedMLPRegressor
        from softbend.surrogates.mlp_core import init_parameters, model_rng, standardization

        first = estimators[0]
        for estimator in estimators:
            estimator._check_parameters()
        _check_same(estimators, ("hidden_sizes", "epochs", "learning_rate", "device", "seed"))
        h1, h2 = (int(h) for h in first.hidden_sizes)
        starts = []
        for k, rows in enumerate(row_sets):
            coefs, intercepts = init_parameters(
                model_rng(first.seed, h1, h2, k), X.shape[1], h1, h2
            )
            x_mean, x_scale = standardization(X[rows])
            y_mean, y_scale = standardization(y[rows])
            starts.append(
                NormalizedMLPRegressor.from_arrays(
                    x_mean=x_mean,
                    x_scale=x_scale,
                    y_mean=float(y_mean),
                    y_scale=float(y_scale),
                    coefs=coefs,
                    intercepts=intercepts,
                )
            )
        models = _tune_batch(starts, X, y, row_sets, first, estimators, keep_going)
        if models is None:
            return estimators
        name = _registered_name(cls)
        for estimator, model, rows in zip(estimators, models, row_sets, strict=True):
            try:
                _check_trained(name, model, X[np.asarray(rows)], first.learning_rate)
            except ConvergenceError as error:
                _fit_failed(estimator, error, keep_going)
                continue
            estimator.model_ = model
            estimator.loss_curve_ = np.asarray(model.loss_curve_) * model.y_scale_**2
            estimator.n_features_in_ = X.shape[1]
        return estimators

    def predict(self, X: ArrayLike) -> np.ndarray:
        """Angle, degrees."""
        return self.model_.predict(self._check_rows(X))


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


class ScaledRefinedMLP(RefinedMLP):
    """Paper B's refinement started from the pressure-mapped MLP.

    First the pressure scale ``s`` of :class:`PressureScale` is fitted on the
    measurements with the base frozen and folded into the network's input
    standardization (exact: the start predicts ``θ_base(design, s·p)``); then
    every layer is trained further as in :class:`RefinedMLP`. The systematic
    part of the gap (the elastomer's stiffness) is then in place before
    training, and the few measurements are left to learn what one number cannot.

    Parameters
    ----------
    base : NormalizedMLPRegressor
    epochs, learning_rate, seed
        As :class:`RefinedMLP`.

    Attributes
    ----------
    pressure_scale_ : float
        The fitted ``s`` of the start.
    model_ : NormalizedMLPRegressor
        The refined network (its input standardization holds ``s``); saves and
        loads as an ``mlp`` surrogate.
    loss_curve_ : ndarray
        Training MSE per epoch, deg² (the first is the mapped start's error).
    """

    @classmethod
    def _starts(
        cls,
        base: NormalizedMLPRegressor,
        X: np.ndarray,
        y: np.ndarray,
        row_sets: list,
        actuator: Actuator,
    ) -> list[NormalizedMLPRegressor | Exception]:
        """The base mapped with the pressure scale fitted on each row set (or why not)."""
        starts: list[NormalizedMLPRegressor | Exception] = []
        for rows in row_sets:
            try:
                scale = fit_pressure_scale(base, X[rows], y[rows], actuator)
                starts.append(scale_mlp_pressure(base, scale))
            except InputError as error:
                starts.append(error)
        return starts

    def _set(self, model: NormalizedMLPRegressor, X: np.ndarray) -> None:
        super()._set(model, X)
        # Refinement keeps the start's input standardization, which holds s.
        self.pressure_scale_ = float(check_mlp(self.base).x_scale_[-1] / model.x_scale_[-1])


@declare_ranges(
    n_restarts=Range(
        0,
        100,
        "restarts",
        "each restart is one more full optimization of the GP's marginal likelihood "
        "(a Cholesky factorization per step); a billion would never end",
    )
)
class ResidualGP(_Corrected):
    """The base frozen, a Gaussian process on its error (scikit-learn, with a noise term).

    The GP sees the standardized features and the base's angle (so an error that
    grows with the angle is a smooth function of one input); its kernel is a
    constant times an anisotropic RBF plus white noise, hyperparameters by
    marginal likelihood (``n_restarts`` seeded restarts). Prediction intervals
    include the noise term, so they are intervals for a new reading.

    Parameters
    ----------
    base : estimator
        Any fitted surrogate.
    n_restarts : int, default 3
        Restarts of the hyperparameter optimizer, in [0, 100].
    seed : int, default 0
        Seed of the restarts.
    """

    def __init__(
        self,
        base: Surrogate | None = None,
        *,
        n_restarts: int = 3,
        seed: int = 0,
        actuator: Actuator | None = None,
    ) -> None:
        self.base = base
        self.n_restarts = n_restarts
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
        with warnings.catch_warnings():
            warnings.simplefilter("ignore", ConvergenceWarning)
            gp = GaussianProcessRegressor(
                kernel=gp_kernel(Z.shape[1]),
                normalize_y=True,
                n_restarts_optimizer=int(self.n_restarts),
                random_state=self.seed,
            ).fit(inputs, y - theta)
        # The chosen hyperparameters, fixed: the model saves and reloads as it predicts here.
        self.model_ = GPCorrected(base, z_mean, z_scale, gp.kernel_.theta, inputs, y - theta)
        self.z_mean_, self.z_scale_, self.gp_ = z_mean, z_scale, self.model_.gp_
        with np.errstate(all="ignore"):  # checked below
            mean, std = self.gp_.predict(inputs, return_std=True)
        _check_finite_fit(
            "residual-gp",
            self._described(),
            z_mean=z_mean,
            z_scale=z_scale,
            kernel_theta=self.model_.kernel_theta_,
            dual_coef=self.gp_.alpha_,
            training_prediction=mean,
            training_std=std,
        )
        return self

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


@declare_ranges(
    n_members=Range(
        2,
        100,
        "networks",
        "a spread needs at least 2 members; every member is a refined network trained "
        "beside the others (memory and time grow with their number, times the folds of loco)",
    ),
    epochs=_EPOCHS,
    learning_rate=_LEARNING_RATE,
)
class RefinedEnsemble(_Corrected):
    """Refined MLPs on bootstrap draws of the measured actuators.

    Each member is :class:`RefinedMLP` on a draw (with replacement) of the
    actuators, identified by their design columns; the prediction is the members'
    mean and the interval is Gaussian with the members' spread plus the
    residual noise of the mean on the training rows.

    Parameters
    ----------
    base : NormalizedMLPRegressor
    n_members : int, default 5
        Refined networks, in [2, 100].
    epochs, learning_rate, device
        As :class:`RefinedMLP`.
    seed : int, default 0
        Seed of the draws.
    """

    def __init__(
        self,
        base: Surrogate | None = None,
        *,
        n_members: int = 5,
        epochs: int = 1000,
        learning_rate: float = 6e-4,
        device: str = "auto",
        seed: int = 0,
        actuator: Actuator | None = None,
    ) -> None:
        self.base = base
        self.n_members = n_members
        self.epochs = epochs
        self.learning_rate = learning_rate
        self.device = device
        self.seed = seed
        self.actuator = actuator

    @classmethod
    def refusal(cls, base: object, actuator: Actuator) -> str | None:
        """An ``mlp`` base only: its weights are trained further."""
        return _needs_mlp(base)

    def fit(self, X: ArrayLike, y: ArrayLike) -> RefinedEnsemble:
        """Refine ``n_members`` networks on bootstrap draws of the actuators."""
        X, y = self._check_fit_data(X, y)
        return type(self).fit_batch([self], X, y, [np.arange(y.size)])[0]

    def _draws(self, X: np.ndarray, rows: np.ndarray) -> list[np.ndarray]:
        """The members' rows: a seeded draw, with replacement, of the actuators in ``rows``."""
        n_members = int(self.n_members)
        _, group = np.unique(X[rows, :-1], axis=0, return_inverse=True)
        group = group.ravel()
        n_groups = int(group.max()) + 1
        rng = np.random.default_rng([self.seed, 7])
        draws = []
        for _ in range(n_members):
            picked = rng.integers(0, n_groups, size=n_groups)
            draws.append(np.concatenate([rows[group == g] for g in picked]))
        return draws

    @classmethod
    def fit_batch(
        cls,
        estimators: list[RefinedEnsemble],
        X: np.ndarray,
        y: np.ndarray,
        row_sets: list,
        *,
        keep_going: bool = False,
    ) -> list[RefinedEnsemble]:
        """Fit each ensemble on its rows; every member of every ensemble trained at once.

        ``keep_going`` as for :meth:`RefinedMLP.fit_batch`: an ensemble with a
        member that diverged is not fitted.
        """
        first = estimators[0]
        for estimator in estimators:
            estimator._check_parameters()
        base = check_mlp(first.base)
        _check_same(estimators, ("base", "epochs", "learning_rate", "device", "n_members"))
        draws = [
            est._draws(X, np.asarray(rows)) for est, rows in zip(estimators, row_sets, strict=True)
        ]
        flat = [d for member_rows in draws for d in member_rows]
        models = _tune_batch(base, X, y, flat, first, estimators, keep_going)
        if models is None:
            return estimators
        name = _registered_name(cls)
        for i, (estimator, rows) in enumerate(zip(estimators, row_sets, strict=True)):
            members = models[i * first.n_members : (i + 1) * first.n_members]
            try:
                for model, member_rows in zip(members, draws[i], strict=True):
                    _check_trained(name, model, X[member_rows], first.learning_rate)
                mean = np.mean([m.predict(X[rows]) for m in members], axis=0)
                with np.errstate(over="ignore", invalid="ignore"):  # checked below
                    residual_std = float(np.sqrt(np.mean((mean - y[rows]) ** 2)))
                _check_finite_fit(
                    "refined-ensemble", estimator._described(), residual_std=residual_std
                )
            except ConvergenceError as error:
                _fit_failed(estimator, error, keep_going)
                continue
            estimator.members_ = members
            estimator.n_features_in_ = X.shape[1]
            estimator.residual_std_ = residual_std
            estimator.model_ = MeanEnsemble(list[Surrogate](members), residual_std)
        return estimators


for _name, _cls in (
    ("fem-only", BaseOnly),
    ("base-mean-residual", BaseMeanResidual),
    ("analytical", AnalyticalBaseline),
    ("experimental", ExperimentalMLP),
    ("refined", RefinedMLP),
    ("scale-offset", ScaleOffset),
    ("pressure-scale", PressureScale),
    ("residual-gp", ResidualGP),
    ("refined-ensemble", RefinedEnsemble),
    ("scaled-refined", ScaledRefinedMLP),
):
    STRATEGIES.register(_name, _cls)
del _name, _cls

#: softbend's own strategies, in the order of the tables (those registered later are not).
BUILTIN_STRATEGIES: tuple[str, ...] = STRATEGIES.names()


def strategy_parameters(name: str) -> dict[str, Any]:
    """The parameters a user may set on strategy ``name``, with their defaults.

    Raises
    ------
    UnknownNameError
        An unknown name (listing :data:`STRATEGIES`).
    """
    with keyed("name"):
        return parameter_defaults(STRATEGIES.get(name))


def learns(name: str) -> bool:
    """Whether strategy ``name`` learns a model from the measurements (a baseline does not)."""
    with keyed("name"):
        return bool(getattr(STRATEGIES.get(name), "learns", True))


def strategy_refusal(name: str, base: object, actuator: Actuator | None = None) -> str | None:
    """Why strategy ``name`` cannot start from ``base`` (a model of ``actuator``); None if it can.

    Asks the strategy's class (its ``refusal(base, actuator)`` class method; a
    registered class without one takes any base). ``actuator`` defaults to
    paper B's.
    """
    from softbend.actuators import SFRBA

    with keyed("name"):
        cls = STRATEGIES.get(name)
    refusal = getattr(cls, "refusal", None)
    return refusal(base, actuator or SFRBA) if callable(refusal) else None


def applicable_strategies(
    names: Sequence[str], base: object, actuator: Actuator | None = None
) -> tuple[list[str], dict[str, str]]:
    """The strategies of ``names`` that can start from ``base``, and why the others cannot.

    Returns
    -------
    list of str
        The names that apply, in the order given.
    dict of str to str
        Each name left out → its reason (:func:`strategy_refusal`).
    """
    kept, left_out = [], {}
    for name in names:
        reason = strategy_refusal(name, base, actuator)
        if reason is None:
            kept.append(name)
        else:
            left_out[name] = reason
    return kept, left_out


def check_applicable(
    names: Sequence[str],
    base: object,
    actuator: Actuator | None = None,
    *,
    among: Sequence[str] | None = None,
    key: str = "strategies",
) -> None:
    """Refuse, before any work, a strategy of ``names`` that cannot start from ``base``.

    Parameters
    ----------
    names : sequence of str
        The strategies asked for.
    base : estimator or None
        The base surrogate.
    actuator : Actuator, optional
        What ``base`` is a model of (paper B's actuator by default).
    among : sequence of str, optional
        The strategies the message offers instead, those of them that apply
        (default: every registered strategy).
    key : str, default "strategies"
        The parameter the error names.

    Raises
    ------
    InputError
        Keyed ``key``: the first strategy that cannot, with its reason, the
        base's family and the strategies that apply to it.
    """
    for name in names:
        reason = strategy_refusal(name, base, actuator)
        if reason is None:
            continue
        fits, _ = applicable_strategies(
            STRATEGIES.names() if among is None else among, base, actuator
        )
        raise InputError(
            f"{name!r} {reason}; the strategies that apply to this {base_family(base)} base: "
            f"{', '.join(fits) or 'none'}",
            key=key,
        )


def describe_strategies() -> list[dict[str, Any]]:
    """Every registered strategy, in order: what it is and what a user may set.

    Returns
    -------
    list of dict
        ``name``; ``summary`` (the first line of its class's docstring, as text);
        ``parameters`` (``{name: default}``, see :func:`strategy_parameters`);
        ``ranges`` (``{name: range}`` of the parameters that declare one, as
        text, e.g. ``"(0, 1] ..."``); ``uses_base`` (starts from the base
        surrogate); ``learns`` (fits a model that ``softbend transfer refine``
        saves); ``interval`` (gives prediction intervals).
    """
    rows = []
    for name, cls in STRATEGIES.items():
        doc = (cls.__doc__ or "").strip()
        defaults = parameter_defaults(cls)
        rows.append(
            {
                "name": name,
                "summary": doc.splitlines()[0].replace("``", "") if doc else cls.__name__,
                "parameters": defaults,
                "ranges": {
                    key: describe_range(cls, key) for key in declared_ranges(cls) if key in defaults
                },
                "uses_base": takes(cls, "base"),
                "learns": learns(name),
                "interval": callable(getattr(cls, "predict_interval", None)),
            }
        )
    return rows


def make_strategy(
    name: str,
    base: Surrogate | None = None,
    *,
    seed: int = 0,
    actuator: Actuator | None = None,
    **options: object,
) -> Any:
    """A fresh, unfitted strategy by name.

    Parameters
    ----------
    name : str
        One of :data:`STRATEGIES`.
    base : estimator, optional
        The simulation-trained surrogate (not used by ``analytical`` and
        ``experimental``).
    seed : int, default 0
        Seed of the strategy's random choices, >= 0.
    actuator : Actuator, optional
        The actuator of the readings it will fit (their inputs, the plausible range
        of their pressure); default paper B's.
    **options
        Parameters of the strategy (e.g. ``epochs``; see :func:`strategy_parameters`),
        each held to its declared range.

    Raises
    ------
    UnknownNameError
        An unknown name (key ``name``, listing :data:`STRATEGIES`), or a
        parameter the strategy does not take (key ``options``, listing those it takes).
    ValueError
        A value of the wrong kind or outside its declared range (key
        ``options``: :class:`~softbend.parameters.ParameterValueError`), or a
        negative seed (key ``seed``).
    """
    with keyed("name"):
        cls = STRATEGIES.get(name)
    with keyed("options"):
        options = check_parameters(cls, options)
    if takes(cls, "seed"):
        seed = check_int(seed, "seed", low=0)
    filled = {"base": base, "seed": seed, "actuator": actuator}
    return cls(**{k: v for k, v in filled.items() if takes(cls, k)}, **options)


def fit_strategy(
    name: str,
    base: Surrogate | None,
    measurements: Measurements | ActuatorMeasurements,
    *,
    seed: int = 0,
    epochs: int | None = None,
    **options: object,
) -> _Strategy:
    """:func:`make_strategy` fitted on all of ``measurements`` (a :class:`Measurements`).

    ``epochs`` (None: the strategy's default) is passed on with the other options.
    """
    if epochs is not None:
        options["epochs"] = epochs
    actuator = getattr(measurements, "actuator", None)  # paper B's Measurements: None
    strategy: _Strategy = make_strategy(name, base, seed=seed, actuator=actuator, **options)
    strategy.fit(measurements.features, measurements.angle_deg)
    return strategy


def has_interval(estimator: object) -> bool:
    """Whether the strategy gives prediction intervals."""
    return callable(getattr(estimator, "predict_interval", None))
