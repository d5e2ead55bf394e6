"""The strategies that train a network from the measurements: the base MLP refined (alone,
from a pressure-scaled start, or as an ensemble) and a fresh MLP."""

from __future__ import annotations

from collections.abc import Sequence
from typing import TYPE_CHECKING, Any

import numpy as np
from numpy.typing import ArrayLike

from softbend.errors import ConvergenceError, InputError
from softbend.parameters import Range, declare_ranges
from softbend.plausibility import RANGES as PLAUSIBLE
from softbend.surrogates.corrected import (
    MeanEnsemble,
)
from softbend.surrogates.protocol import Surrogate
from softbend.transfer.finetune import EarlyStop, check_mlp, fine_tune_many, row_weights
from softbend.transfer.pressure_map import (
    fit_pressure_scale,
    scale_mlp_pressure,
)
from softbend.transfer.strategies.common import (
    _EPOCHS,
    _LEARNING_RATE,
    _MIN_DELTA,
    _PATIENCE,
    _VALIDATION_SHARE,
    _check_finite_fit,
    _check_same,
    _Corrected,
    _registered_name,
    _Strategy,
    base_family,
)

if TYPE_CHECKING:
    from softbend.actuators import Actuator
    from softbend.surrogates.mlp import NormalizedMLPRegressor


#: Patience of the refinements, epochs: paper B's 1000, its cap, so by default they train
#: to it. On paper B's virtual lab the held-out readings' loss stops falling after about 230
#: epochs, yet the held-out actuators' RMSE keeps falling to the cap (refined 7.60° at the
#: cap, 8.00° stopped at the plateau; scaled-refined 7.06° and 7.35°): docs/design-log.md.
REFINED_PATIENCE = 1000

#: Patience of the experimental MLP (from random weights; cap: paper B's 15 000 epochs) and
#: the relative fall that counts as progress: a coarse plateau, since on a few hundred
#: readings its held-out loss keeps falling by a little for thousands of epochs (14 actuators
#: x 41 readings: 275 s of CPU at 1e-3 and 500 epochs, 140 s at these, 7.36° and 7.45°;
#: paper B's lab: 42.55° and 41.31°): docs/design-log.md.
EXPERIMENTAL_PATIENCE = 200
EXPERIMENTAL_MIN_DELTA = 0.01

#: The parameters of the held-out stop, the same for every network of a batch.
_STOP = ("patience", "min_delta", "validation_share", "seed")


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
            stop=EarlyStop(
                int(first.patience),
                float(first.min_delta),
                float(first.validation_share),
                int(first.seed),
            ),
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


@declare_ranges(
    epochs=_EPOCHS,
    learning_rate=_LEARNING_RATE,
    patience=_PATIENCE,
    min_delta=_MIN_DELTA,
    validation_share=_VALIDATION_SHARE,
)
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
    patience : int, default 1000
        Epochs without progress on the held-out readings before training stops
        (:class:`~softbend.transfer.finetune.EarlyStop`: a shadow network trains on
        the rows less a seeded ``validation_share`` of them and is scored on those),
        >= 1; ``epochs`` is the cap (a patience of ``epochs`` or more never stops early).
    min_delta : float, default 1e-3
        Relative fall of the held-out loss that counts as progress, >= 0.
    validation_share : float, default 0.2
        Share of the readings the shadow holds out, in (0, 1).
    seed : int, default 0
        Seed of the held-out draw (full-batch training draws nothing else).

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
        patience: int = REFINED_PATIENCE,
        min_delta: float = 1e-3,
        validation_share: float = 0.2,
        seed: int = 0,
        actuator: Actuator | None = None,
    ) -> None:
        self.base = base
        self.epochs = epochs
        self.learning_rate = learning_rate
        self.device = device
        self.patience = patience
        self.min_delta = min_delta
        self.validation_share = validation_share
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
        _check_same(estimators, ("base", "epochs", "learning_rate", "device", *_STOP))
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
    patience=_PATIENCE,
    min_delta=_MIN_DELTA,
    validation_share=_VALIDATION_SHARE,
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
    patience : int, default 200
        Epochs without progress on the held-out readings before training stops
        (:class:`~softbend.transfer.finetune.EarlyStop`: a shadow network trains on
        the rows less a seeded ``validation_share`` of them and is scored on those),
        >= 1; ``epochs`` is the cap (a patience of ``epochs`` or more never stops early).
    min_delta : float, default 0.01
        Relative fall of the held-out loss that counts as progress, >= 0.
    validation_share : float, default 0.2
        Share of the readings the shadow holds out, in (0, 1).
    seed : int, default 0
        Seed of the initial weights and of the held-out draw.

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
        patience: int = EXPERIMENTAL_PATIENCE,
        min_delta: float = EXPERIMENTAL_MIN_DELTA,
        validation_share: float = 0.2,
        seed: int = 0,
        actuator: Actuator | None = None,
    ) -> None:
        self.hidden_sizes = hidden_sizes
        self.epochs = epochs
        self.learning_rate = learning_rate
        self.device = device
        self.patience = patience
        self.min_delta = min_delta
        self.validation_share = validation_share
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
        _check_same(
            estimators, ("hidden_sizes", "epochs", "learning_rate", "device", "seed", *_STOP)
        )
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
    n_members=Range(
        2,
        100,
        "networks",
        "a spread needs at least 2 members; every member is a refined network trained "
        "beside the others (memory and time grow with their number, times the folds of loco)",
    ),
    epochs=_EPOCHS,
    learning_rate=_LEARNING_RATE,
    patience=_PATIENCE,
    min_delta=_MIN_DELTA,
    validation_share=_VALIDATION_SHARE,
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
    epochs, learning_rate, device, patience, min_delta, validation_share
        As :class:`RefinedMLP`: each member stops on its own plateau.
    seed : int, default 0
        Seed of the draws and of the held-out draw.
    """

    def __init__(
        self,
        base: Surrogate | None = None,
        *,
        n_members: int = 5,
        epochs: int = 1000,
        learning_rate: float = 6e-4,
        device: str = "auto",
        patience: int = REFINED_PATIENCE,
        min_delta: float = 1e-3,
        validation_share: float = 0.2,
        seed: int = 0,
        actuator: Actuator | None = None,
    ) -> None:
        self.base = base
        self.n_members = n_members
        self.epochs = epochs
        self.learning_rate = learning_rate
        self.device = device
        self.patience = patience
        self.min_delta = min_delta
        self.validation_share = validation_share
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
        _check_same(estimators, ("base", "epochs", "learning_rate", "device", "n_members", *_STOP))
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
