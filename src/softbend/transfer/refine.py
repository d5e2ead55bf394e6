"""One strategy fitted on every measurement and saved like any other surrogate.

What ``softbend transfer refine`` does: :func:`refine_surrogate` reads a saved surrogate
and a measurements file, fits a strategy of
:data:`~softbend.transfer.strategies.STRATEGIES` on all the readings and
returns a :class:`Refinement`, whose :meth:`~Refinement.save` writes the fitted
model with its record (strategy, parameters, inputs, training error, the
ranges it was trained on). The saved model plugs into ``softbend predict``.

Every refinement is also calibrated (:mod:`softbend.transfer.conformal`): the
strategy is refitted once per measured actuator without it, and the
leave-one-actuator-out errors give the half-width of a 90 % interval for a new
actuator, recorded as the ``interval`` of the record. With too few actuators
for the rule's guarantee the half-width is the plug-in quantile of those
errors (:mod:`softbend.transfer.conformal`), and a warning says so.

A refinement whose predictions on the measured readings, training error, final
loss or calibrated half-width is not finite is a
:class:`~softbend.errors.ConvergenceError` naming what: never a model saved, or
a figure printed, as NaN.
"""

from __future__ import annotations

import os
import warnings
from collections.abc import Mapping, Sequence
from dataclasses import dataclass
from pathlib import Path
from typing import TYPE_CHECKING, Any

import numpy as np
from numpy.typing import ArrayLike

from softbend.errors import ConvergenceError, InputError, keyed
from softbend.surrogates.protocol import Surrogate
from softbend.transfer.conformal import Calibration, angle_floor, calibrate
from softbend.transfer.strategies import (
    STRATEGIES,
    applicable_strategies,
    check_applicable,
    fit_strategy,
    learns,
)
from softbend.transfer.strategies.parameters import check_parameters, recorded_parameters, takes

if TYPE_CHECKING:
    from softbend.actuators import Actuator
    from softbend.surrogates.persistence import SavedSurrogate
    from softbend.transfer.measurements import ActuatorMeasurements, Measurements

__all__ = [
    "REFINE_DEFAULTS",
    "Refinement",
    "default_refine_strategy",
    "refinable_strategies",
    "refine_surrogate",
]

#: The strategy a refinement fits when none is named: the first of these that can start from
#: the base (paper B's refined MLP for an ``mlp`` base; the frozen base corrected linearly,
#: which takes any base, else).
REFINE_DEFAULTS: tuple[str, ...] = ("refined", "scale-offset")


def refinable_strategies() -> tuple[str, ...]:
    """The registered strategies that learn a model to save (the baselines learn nothing)."""
    return tuple(name for name in STRATEGIES if learns(name))


def default_refine_strategy(
    base: object, actuator: Actuator | None = None
) -> tuple[str, dict[str, str]]:
    """The strategy of :data:`REFINE_DEFAULTS` a refinement of ``base`` fits when none is named.

    Parameters
    ----------
    base : estimator
        The base surrogate.
    actuator : Actuator, optional
        What ``base`` is a model of (paper B's actuator by default).

    Returns
    -------
    str
        The first of :data:`REFINE_DEFAULTS` that can start from ``base``.
    dict of str to str
        The ones before it that cannot, each with the reason.
    """
    fits, left_out = applicable_strategies(REFINE_DEFAULTS, base, actuator)
    if not fits:  # every default refused: name the first, refused with its reason
        check_applicable(REFINE_DEFAULTS[:1], base, actuator, among=refinable_strategies())
    first = fits[0]
    return first, {
        k: v for k, v in left_out.items() if REFINE_DEFAULTS.index(k) < REFINE_DEFAULTS.index(first)
    }


@dataclass(frozen=True)
class Refinement:
    """A strategy fitted on every measurement, and its record.

    Attributes
    ----------
    strategy : estimator
        The fitted strategy; ``strategy.model_`` is the surrogate saved.
    metadata : dict
        The record saved with it: ``strategy``, ``parameters`` (every parameter
        as it ran, seed included), ``base``, ``measurements`` (the file, or
        the list of files), ``strategy_left_out`` (the default strategies
        passed over because they cannot start from the base, each with the
        reason; empty when the strategy was named or the first default
        applied), ``measurement_files`` (path, SHA-256, readings and
        synthetic flag of each), ``n_measurements``, ``actuators``,
        ``synthetic_measurements`` (``true``, ``false`` or ``mixed``),
        ``training_rmse_deg`` (degrees), ``training_ranges`` (mm, deg, MPa),
        ``support`` (each design's largest pressure and the largest angle, the
        measured ones and, for a strategy that keeps the base's simulations,
        the base's: :class:`softbend.surrogates.support.Support`) and,
        for the strategies that train a network, ``final_training_mse_deg2``;
        ``interval``: the calibration (:meth:`Calibration.to_dict`, with a
        ``warning`` when too few actuators) or None when not calibrated.
    calibration : Calibration or None
        The calibrated 90 % interval for a new actuator; None when not
        calibrated (one actuator, or ``calibrated=False``).
    """

    strategy: Any
    metadata: dict[str, Any]
    calibration: Calibration | None = None

    def predict_interval(self, X: ArrayLike, level: float = 0.9) -> tuple[np.ndarray, np.ndarray]:
        """The calibrated interval at the rows ``X``, degrees (``level``: the calibration's).

        Raises
        ------
        ValueError
            Not calibrated, or another ``level``.
        """
        from softbend.transfer.conformal import Calibrated

        if self.calibration is None:
            raise ValueError(
                "The refinement has no calibrated interval: it needs measurements of at "
                "least 2 actuators and calibrated=True."
            )
        return Calibrated(self.strategy, self.calibration).predict_interval(X, level)

    def save(self, path: str | os.PathLike[str]) -> Path:
        """Write the fitted model and its record to ``path`` (JSON, atomically); returns it."""
        from softbend._io import json_safe
        from softbend.surrogates.persistence import save_surrogate

        return save_surrogate(self.strategy.model_, path, metadata=json_safe(self.metadata))


def _merged_ranges(own: dict[str, list[float]], base: object) -> dict[str, list[float]]:
    """The ranges of the measurements widened by those the base was trained on."""
    if not isinstance(base, dict):
        return own
    return {k: [min(v[0], base[k][0]), max(v[1], base[k][1])] for k, v in own.items()}


def _check_finite_predictions(strategy: str, predicted: np.ndarray, features: np.ndarray) -> None:
    """Raise :class:`ConvergenceError` if the refit predicts a non-finite angle at a reading."""
    bad = np.flatnonzero(~np.isfinite(predicted))
    if bad.size:
        first = ", ".join(f"{v:g}" for v in features[bad[0]])
        raise ConvergenceError(
            f"The '{strategy}' refit predicts no finite angle at {bad.size} of the "
            f"{predicted.size} measured readings (first: reading {int(bad[0])}, {first}); "
            "it is not saved. Check the strategy's parameters and the base surrogate"
        )


def _check_finite_figures(strategy: str, figures: Mapping[str, float | None]) -> None:
    """Raise :class:`ConvergenceError` naming the first figure of the record that is not finite."""
    for name, value in figures.items():
        if value is not None and not np.isfinite(float(value)):
            raise ConvergenceError(
                f"The '{strategy}' refit's {name} is {float(value):g}, not a finite number; "
                "it is not saved. Check the strategy's parameters (a smaller learning_rate) "
                "and the measurements"
            )


def refine_surrogate(
    base: str | os.PathLike[str],
    measurements: str | os.PathLike[str] | Sequence[str | os.PathLike[str]],
    strategy: str | None = None,
    *,
    seed: int = 0,
    settings: Mapping[str, str] | None = None,
    options: Mapping[str, object] | None = None,
    calibrated: bool = True,
    force: bool = False,
) -> Refinement:
    """Fit ``strategy`` on every reading of a measurements file, starting from a saved surrogate.

    Parameters
    ----------
    base : path
        A surrogate saved by :func:`softbend.surrogates.save_surrogate` (an
        ``mlp`` for the strategies that refine a network).
    measurements : path or sequence of paths
        One or more measurements CSV files, joined
        (:func:`softbend.transfer.measurements.load_measurements_files`).
    strategy : str, optional
        A registered strategy that learns from the measurements
        (:func:`refinable_strategies`) and can start from the base. Default:
        the first of :data:`REFINE_DEFAULTS` that can
        (:func:`default_refine_strategy`); the record's ``strategy_left_out``
        names those before it that cannot, with the reason.
    seed : int, default 0
        Seed of the strategy.
    settings : mapping of str to str, optional
        Parameters of the strategy as text (``{"epochs": "500"}``), read by the
        kind of each parameter's default.
    options : mapping, optional
        Parameters of the strategy as values (``{"epochs": 500}``).
    calibrated : bool, default True
        Also calibrate the 90 % interval over actuators (one more fit per
        actuator; at least 2 actuators). A ``UserWarning`` when there are too
        few for the rule's guarantee (:func:`softbend.transfer.conformal.min_actuators`)
        or too few to calibrate at all.
    force : bool, default False
        Use measured pressures past the base's trained range and angles that
        look like radians as given, with a warning, and record them in the
        model's ``metadata["forced"]`` (:mod:`softbend.transfer.against_base`).

    Returns
    -------
    Refinement

    Raises
    ------
    UnknownNameError
        An unknown strategy or parameter (the known ones listed), keyed
        ``strategy``, ``settings`` or ``options``.
    ValueError
        A strategy that learns nothing (a baseline, key ``strategy``) or
        cannot start from the base (key ``strategy``, before the measurements
        are read), a parameter value of the wrong kind (key ``settings`` or
        ``options``), bad measurements (pressures past the base's range,
        radians: unless ``force``) or a fit that cannot be made.
    FileNotFoundError, SchemaError
        A missing or unreadable input.
    ConvergenceError
        A refit that diverged, or whose predictions on the readings, training
        error, final loss or calibrated half-width is not finite.
    """
    from softbend.surrogates.persistence import load_surrogate
    from softbend.transfer.against_base import load_for_base

    left_out: dict[str, str] = {}
    if strategy is not None:
        with keyed("strategy"):
            STRATEGIES.check(strategy)
        if not learns(strategy):
            raise InputError(
                f"{strategy!r} learns nothing from the measurements, so it has no model to "
                f"save; known strategies that do: {', '.join(refinable_strategies())}",
                key="strategy",
            )
    start = load_surrogate(base)
    actuator = start.actuator
    if strategy is None:
        with keyed("strategy"):
            strategy, left_out = default_refine_strategy(start.model, actuator)
    check_applicable(
        [strategy], start.model, actuator, among=refinable_strategies(), key="strategy"
    )
    cls = STRATEGIES.get(strategy)
    with keyed("settings"):
        from_text = check_parameters(cls, settings, from_text=True)
    with keyed("options"):
        values = {**from_text, **check_parameters(cls, options)}
    files = [measurements] if isinstance(measurements, str | os.PathLike) else list(measurements)
    data, forced = load_for_base(files, start, force=force)  # before any fit
    refinement = _refine(
        strategy,
        start,
        data,
        files,
        base,
        actuator,
        seed=seed,
        values=values,
        calibrated=calibrated,
    )
    if forced:
        refinement.metadata["forced"] = forced
    refinement.metadata["strategy_left_out"] = left_out
    return refinement


def _refine(
    strategy: str,
    start: SavedSurrogate,
    data: Measurements | ActuatorMeasurements,
    files: list[str | os.PathLike[str]],
    base: str | os.PathLike[str],
    actuator: Actuator,
    *,
    seed: int,
    values: dict[str, Any],
    calibrated: bool,
) -> Refinement:
    """:func:`refine_surrogate` once its inputs are read, as a model of ``actuator``."""
    from softbend.surrogates.features import training_ranges
    from softbend.surrogates.support import Support, support_from_rows
    from softbend.transfer.measurements import files_record, synthetic_label

    cls = STRATEGIES.get(strategy)
    model = fit_strategy(strategy, start.model, data, seed=seed, **values)
    ranges = training_ranges(data.features, actuator.features)
    support = support_from_rows(
        data.features,
        data.angle_deg,
        parameters=actuator.names,
        pressure_unit=actuator.pressure_unit,
    )
    if takes(cls, "base"):  # the base's simulations and the measurements
        ranges = _merged_ranges(ranges, start.metadata.get("training_ranges"))
        if isinstance(start.metadata.get("support"), dict):
            support = support.merged(Support.from_dict(start.metadata["support"]))
    predicted = np.asarray(model.predict(data.features), dtype=np.float64)
    _check_finite_predictions(strategy, predicted, data.features)
    with np.errstate(over="ignore", invalid="ignore"):  # checked below
        residual = data.angle_deg - predicted
    metadata: dict[str, Any] = {
        "strategy": strategy,
        "parameters": recorded_parameters(model),
        "base": str(base),
        "measurements": str(files[0]) if len(files) == 1 else [str(f) for f in files],
        "measurement_files": files_record(files, data),  # type: ignore[arg-type]
        "n_measurements": len(data),
        "actuators": list(data.actuator_ids),
        "synthetic_measurements": synthetic_label(data),  # type: ignore[arg-type]
        "training_rmse_deg": float(np.sqrt(np.mean(residual**2))),
        "training_ranges": ranges,
        "support": support.to_dict(),
    }
    metadata["actuator"] = actuator.to_dict()  # every model names its actuator
    if hasattr(model, "loss_curve_"):
        metadata["final_training_mse_deg2"] = float(model.loss_curve_[-1])
    _check_finite_figures(
        strategy,
        {
            "training RMSE (deg)": metadata["training_rmse_deg"],
            "final training MSE (deg²)": metadata.get("final_training_mse_deg2"),
        },
    )
    calibration = _calibrate(data, start.model, strategy, seed, values) if calibrated else None
    if calibration is not None:
        _check_finite_figures(
            strategy, {"calibrated interval half-width (deg)": calibration.half_width_deg}
        )
    metadata["interval"] = None if calibration is None else calibration.to_dict()
    if calibration is not None and calibration.warning() is not None:
        metadata["interval"]["warning"] = calibration.warning()
    return Refinement(model, metadata, calibration)


def _calibrate(
    data: Measurements | ActuatorMeasurements,
    base: Surrogate,
    strategy: str,
    seed: int,
    values: dict[str, Any],
) -> Calibration | None:
    """The 90 % calibration over the actuators of ``data``; warns when they are too few."""
    from softbend.surrogates.predict import INTERVAL_LEVEL
    from softbend.transfer.loco import held_out_residuals

    n = len(data.actuator_ids)
    if n < 2:
        warnings.warn(
            f"{n} actuator measured: no calibrated interval (calibrating over actuators "
            "needs at least 2, and 9 for a guaranteed 90 % interval).",
            UserWarning,
            stacklevel=3,
        )
        return None
    residuals = held_out_residuals(data, base, strategy, seed=seed, options=values)
    calibration = calibrate(residuals, INTERVAL_LEVEL, floor_deg=angle_floor(data.angle_deg))
    message = calibration.warning()
    if message is not None:
        warnings.warn(message, UserWarning, stacklevel=3)
    return calibration
