"""What every transfer strategy shares: the registry, the base class that checks the readings,
and the checks of a fit."""

from __future__ import annotations

import math
from collections.abc import Sequence
from typing import TYPE_CHECKING, ClassVar

import numpy as np
from numpy.typing import ArrayLike
from sklearn.base import BaseEstimator, RegressorMixin
from sklearn.utils.validation import check_is_fitted, validate_data

from softbend._validation import check_range
from softbend.errors import ConvergenceError, InputError, SoftbendError
from softbend.parameters import Range
from softbend.plausibility import check_plausible
from softbend.registry import Registry
from softbend.surrogates.protocol import Surrogate
from softbend.transfer.strategies.parameters import (
    check_estimator,
    takes,
)

if TYPE_CHECKING:
    from softbend.actuators import Actuator


#: The strategies by name, in the order of the tables (filled by its package's ``choice``).
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

#: Epochs without progress on the held-out readings before a network stops training.
_PATIENCE = Range(
    1,
    1_000_000,
    "epochs",
    "at least one epoch without progress before a stop; 'epochs' or more never stops "
    "before the cap (a million is past any training that ends)",
)
#: Relative fall of the held-out loss that counts as progress.
_MIN_DELTA = Range(
    0,
    1,
    "share of the best held-out loss",
    "0 counts any fall as progress; 1 would ask the loss to fall to zero",
    low_inclusive=True,
    high_inclusive=False,
)
#: Share of a fit's readings the held-out check of its network does not train on.
_VALIDATION_SHARE = Range(
    0,
    1,
    "share of the readings",
    "some readings held out to watch, some left to train the watching network on",
    low_inclusive=False,
    high_inclusive=False,
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
