"""One strategy fitted on every measurement and saved like any other surrogate.

What ``softbend transfer refine`` does: :func:`refine_surrogate` reads a saved surrogate
and a measurements file, fits a strategy of
:data:`~softbend.transfer.strategies.STRATEGIES` on all the readings and
returns a :class:`Refinement`, whose :meth:`~Refinement.save` writes the fitted
model with its record (strategy, parameters, inputs, training error, the
ranges it was trained on). The saved model plugs into ``softbend predict``.
"""

from __future__ import annotations

import os
from collections.abc import Mapping
from dataclasses import dataclass
from pathlib import Path
from typing import Any

import numpy as np

from softbend.transfer.parameters import check_parameters, recorded_parameters, takes
from softbend.transfer.strategies import STRATEGIES, fit_strategy, learns

__all__ = ["Refinement", "refinable_strategies", "refine_surrogate"]


def refinable_strategies() -> tuple[str, ...]:
    """The registered strategies that learn a model to save (the baselines learn nothing)."""
    return tuple(name for name in STRATEGIES if learns(name))


@dataclass(frozen=True)
class Refinement:
    """A strategy fitted on every measurement, and its record.

    Attributes
    ----------
    strategy : estimator
        The fitted strategy; ``strategy.model_`` is the surrogate saved.
    metadata : dict
        The record saved with it: ``strategy``, ``parameters`` (every parameter
        as it ran, seed included), ``base``, ``measurements``,
        ``n_measurements``, ``actuators``, ``synthetic_measurements``,
        ``training_rmse_deg`` (degrees), ``training_ranges`` (mm, deg, MPa) and,
        for the strategies that train a network, ``final_training_mse_deg2``.
    """

    strategy: Any
    metadata: dict[str, Any]

    def save(self, path: str | os.PathLike[str]) -> Path:
        """Write the fitted model and its record to ``path`` (JSON, atomically); returns it."""
        from softbend._io import json_safe
        from softbend.surrogates.persistence import save_surrogate

        return save_surrogate(self.strategy.model_, path, metadata=json_safe(self.metadata))


def _merged_ranges(own: dict[str, list[float]], base: Any) -> dict[str, list[float]]:
    """The ranges of the measurements widened by those the base was trained on."""
    if not isinstance(base, dict):
        return own
    return {k: [min(v[0], base[k][0]), max(v[1], base[k][1])] for k, v in own.items()}


def refine_surrogate(
    base: str | os.PathLike[str],
    measurements: str | os.PathLike[str],
    strategy: str = "refined",
    *,
    seed: int = 0,
    settings: Mapping[str, str] | None = None,
    options: Mapping[str, Any] | None = None,
    field: str = "--set",
) -> Refinement:
    """Fit ``strategy`` on every reading of a measurements file, starting from a saved surrogate.

    Parameters
    ----------
    base : path
        A surrogate saved by :func:`softbend.surrogates.save_surrogate` (an
        ``mlp`` for the strategies that refine a network).
    measurements : path
        A measurements CSV (:func:`softbend.transfer.measurements.load_measurements`).
    strategy : str, default "refined"
        A registered strategy that learns from the measurements
        (:func:`refinable_strategies`).
    seed : int, default 0
        Seed of the strategy.
    settings : mapping of str to str, optional
        Parameters of the strategy as text (``{"epochs": "500"}``), read by the
        kind of each parameter's default.
    options : mapping, optional
        Parameters of the strategy as values (``{"epochs": 500}``).
    field : str, default "--set"
        Where ``settings`` came from, named in messages.

    Returns
    -------
    Refinement

    Raises
    ------
    UnknownNameError
        An unknown strategy or parameter (the known ones listed).
    ValueError
        A strategy that learns nothing (a baseline), a parameter value of the
        wrong kind, bad measurements or a fit that cannot be made.
    FileNotFoundError, SchemaError
        A missing or unreadable input.
    """
    from softbend.surrogates.features import training_ranges
    from softbend.surrogates.persistence import load_surrogate
    from softbend.transfer.measurements import load_measurements

    cls = STRATEGIES.get(strategy, field="strategy")
    if not learns(strategy):
        raise ValueError(
            f"The transfer strategy {strategy!r} learns nothing from the measurements, so it "
            f"has no model to save; known strategies that do: {', '.join(refinable_strategies())}."
        )
    values = {
        **check_parameters(strategy, cls, settings, field=field, from_text=True),
        **check_parameters(strategy, cls, options),
    }
    data = load_measurements(measurements)
    start = load_surrogate(base)
    model = fit_strategy(strategy, start.model, data, seed=seed, **values)
    ranges = training_ranges(data.features)
    if takes(cls, "base"):  # the base's simulations and the measurements
        ranges = _merged_ranges(ranges, start.metadata.get("training_ranges"))
    residual = data.angle_deg - model.predict(data.features)
    metadata: dict[str, Any] = {
        "strategy": strategy,
        "parameters": recorded_parameters(model),
        "base": str(base),
        "measurements": str(measurements),
        "n_measurements": len(data),
        "actuators": list(data.actuator_ids),
        "synthetic_measurements": str(data.metadata.get("synthetic", "false")),
        "training_rmse_deg": float(np.sqrt(np.mean(residual**2))),
        "training_ranges": ranges,
    }
    if hasattr(model, "loss_curve_"):
        metadata["final_training_mse_deg2"] = float(model.loss_curve_[-1])
    return Refinement(model, metadata)
