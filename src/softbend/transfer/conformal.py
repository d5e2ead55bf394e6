"""Calibrated prediction intervals over actuators (conformal, leave one actuator out).

A strategy fitted on the readings of actuators 1..n predicts a new actuator.
Its readings are not independent of one another (one actuator's readings
share its fabrication error), so the exchangeable unit is the actuator, not
the reading. The calibration here treats it so.

The rule (the pooled-CDF method of Dunn, Wasserman & Ramdas 2022,
"Distribution-free prediction sets for two-layer hierarchical models",
§3.2, on the leave-one-out residuals of the jackknife+ of Barber et al. 2021,
"Predictive inference with the jackknife+", §3):

1. For each actuator ``i``, the strategy is refitted without it and ``R_i``
   are the absolute errors on its ``m_i`` readings, degrees.
2. ``F_i`` is the empirical CDF of ``R_i``; every actuator weighs the same,
   whatever its number of readings.
3. The half-width is ``q = inf{t : Σ_i F_i(t) ≥ level·(n + 1)}``.

With the actuators exchangeable, a new reading of a new actuator lies in
``prediction ± q`` with probability at least ``level`` (the ``+1`` is the
finite-sample price of not knowing the new actuator). ``q`` is finite only
when ``level·(n + 1) ≤ n``, i.e. ``n ≥ level / (1 − level)`` actuators (9 at
90 %). With fewer, no half-width is guaranteed, and softbend says so; it then
takes (``fallback``)

- ``"quantile"`` (the default): the plug-in quantile, ``inf{t : Σ_i F_i(t) ≥
  level·n}``, the rule without its finite-sample ``+1``: about ``level`` on
  average over new actuators, without a guarantee. On the shipped virtual lab
  this covers 80–97 % of a held-out actuator's readings, where
- ``"largest"``, the largest leave-one-out error, guaranteed to cover
  ``n / (n + 1)`` (87.5 % with 7 actuators) in the worst case, covers all of
  them with intervals a third wider (the figures: ``benchmarks/bench_lab_coverage.py``).

The interval is ``[prediction − q, prediction + q]``, its low end raised to
the lowest angle the data allow (:func:`angle_floor`: 0°, or the smallest
angle measured if one is negative). The half-width is a constant, so at
0 MPa the interval would otherwise reach far below zero, where no actuator
bends; the low end never rises above the prediction itself.
"""

from __future__ import annotations

import math
from collections.abc import Mapping
from dataclasses import dataclass
from typing import Any

import numpy as np
from numpy.typing import ArrayLike

from softbend._validation import check_range
from softbend.surrogates.protocol import Surrogate

__all__ = [
    "Calibrated",
    "Calibration",
    "angle_floor",
    "calibrate",
    "conformal_half_width",
    "min_actuators",
]

#: What a calibration takes with too few actuators for the rule's guarantee.
FALLBACKS: tuple[str, ...] = ("quantile", "largest")

#: The rule's name, recorded with every calibration.
RULE = "pooled-cdf leave-one-actuator-out (Dunn et al. 2022; Barber et al. 2021)"


def angle_floor(angles: ArrayLike) -> float:
    """The lowest low end of an angle interval: ``min(0, smallest measured angle)``, degrees.

    A bending actuator does not bend backwards under pressure; a negative
    reading (camera noise at 0 MPa) lowers the floor to what was seen.
    """
    values = np.asarray(angles, dtype=np.float64)
    values = values[np.isfinite(values)]
    return float(min(0.0, values.min())) if values.size else 0.0


def min_actuators(level: float) -> int:
    """The fewest actuators whose calibration keeps its guarantee at ``level``.

    ``⌈level / (1 − level)⌉``: 9 at 90 %, 19 at 95 %.
    """
    level = check_range(level, "level", low=0.0, high=1.0)
    return math.ceil(level / (1.0 - level) - 1e-12)


def conformal_half_width(
    residuals: Mapping[str, ArrayLike], level: float, *, fallback: str = "quantile"
) -> tuple[float, bool]:
    """The rule's half-width from each actuator's leave-one-out errors.

    Parameters
    ----------
    residuals : mapping of str to array
        Actuator id → absolute errors of a model fitted without it, degrees.
        At least one actuator, each with at least one finite error.
    level : float
        Probability of the interval, in (0, 1).
    fallback : {"quantile", "largest"}, default "quantile"
        The half-width when too few actuators for the rule (module docstring).

    Returns
    -------
    half_width : float
        ``q`` of the rule, degrees; with too few actuators, that of ``fallback``.
    guaranteed : bool
        Whether ``level·(n + 1) ≤ n`` (the rule's quantile is finite).

    Raises
    ------
    ValueError
        No actuator, an actuator without finite errors, or a level outside (0, 1).
    """
    level = check_range(level, "level", low=0.0, high=1.0)
    groups = []
    for name, values in residuals.items():
        r = np.abs(np.asarray(values, dtype=np.float64).ravel())
        r = r[np.isfinite(r)]
        if r.size == 0:
            raise ValueError(
                f"The 'residuals' of conformal_half_width must hold finite errors for every "
                f"actuator. Got none for {name!r}."
            )
        groups.append(np.sort(r))
    if not groups:
        raise ValueError("The 'residuals' of conformal_half_width must name at least 1 actuator.")
    if fallback not in FALLBACKS:
        raise ValueError(
            f"The 'fallback' of conformal_half_width must be one of {', '.join(FALLBACKS)}. "
            f"Got {fallback!r} instead."
        )
    n = len(groups)
    target = level * (n + 1)
    guaranteed = target <= n + 1e-12
    if not guaranteed:
        if fallback == "largest":
            return float(max(g[-1] for g in groups)), False
        target = level * n
    # Σ_i F_i(t) steps up only at the errors: the first candidate that reaches the target.
    for t in np.unique(np.concatenate(groups)):
        total = sum(np.searchsorted(g, t, side="right") / g.size for g in groups)
        if total >= target - 1e-12:
            return float(t), guaranteed
    return float(max(g[-1] for g in groups)), guaranteed  # pragma: no cover - target ≤ n


@dataclass(frozen=True)
class Calibration:
    """A conformal half-width and what it was calibrated on.

    Attributes
    ----------
    level : float
        Probability of the interval.
    half_width_deg : float
        ``q``, degrees.
    floor_deg : float
        Lowest low end of an interval, degrees (:func:`angle_floor`).
    n_actuators : int
        Actuators the half-width was calibrated on.
    guaranteed : bool
        Whether ``n_actuators`` is enough for the rule's guarantee at ``level``.
    fallback : str
        What the half-width is when not guaranteed (:data:`FALLBACKS`).
    """

    level: float
    half_width_deg: float
    floor_deg: float
    n_actuators: int
    guaranteed: bool
    fallback: str = "quantile"

    def interval(self, prediction: ArrayLike) -> tuple[np.ndarray, np.ndarray]:
        """``prediction ± half_width_deg``, the low end at least ``floor_deg`` (degrees)."""
        pred = np.asarray(prediction, dtype=np.float64)
        low = np.maximum(pred - self.half_width_deg, self.floor_deg)
        return np.minimum(low, pred), pred + self.half_width_deg

    def warning(self) -> str | None:
        """One line when too few actuators for the guarantee, else None."""
        if self.guaranteed:
            return None
        head = (
            f"{self.n_actuators} actuators are too few to calibrate a guaranteed "
            f"{self.level:.0%} interval (the rule needs {min_actuators(self.level)}): its "
            f"half-width {self.half_width_deg:.3g}° is "
        )
        if self.fallback == "largest":
            worst = self.n_actuators / (self.n_actuators + 1)
            return head + (
                f"the largest leave-one-actuator-out error, guaranteed to cover only "
                f"{worst:.1%} of a new actuator's readings."
            )
        return head + (
            f"the {self.level:.0%} quantile of the leave-one-actuator-out errors: about "
            f"{self.level:.0%} of a new actuator's readings on average, without a guarantee."
        )

    def to_dict(self) -> dict[str, Any]:
        """JSON-friendly record (the ``interval`` metadata of a refined model)."""
        return {
            "method": "conformal",
            "rule": RULE,
            "level": self.level,
            "half_width_deg": self.half_width_deg,
            "floor_deg": self.floor_deg,
            "n_actuators": self.n_actuators,
            "guaranteed": self.guaranteed,
            "fallback": None if self.guaranteed else self.fallback,
            "min_actuators": min_actuators(self.level),
        }


def calibrate(
    residuals: Mapping[str, ArrayLike],
    level: float = 0.9,
    *,
    floor_deg: float = -np.inf,
    fallback: str = "quantile",
) -> Calibration:
    """A :class:`Calibration` from each actuator's leave-one-out errors.

    Parameters
    ----------
    residuals : mapping of str to array
        Actuator id → errors of a model fitted without it, degrees (sign ignored).
    level : float, default 0.9
        Probability of the interval, in (0, 1).
    floor_deg : float, default -inf
        Lowest low end, degrees (:func:`angle_floor` of the measured angles).
    fallback : {"quantile", "largest"}, default "quantile"
        The half-width when too few actuators for the rule's guarantee.

    Returns
    -------
    Calibration
    """
    half_width, guaranteed = conformal_half_width(residuals, level, fallback=fallback)
    return Calibration(
        float(level), half_width, float(floor_deg), len(residuals), guaranteed, fallback
    )


class Calibrated:
    """Any fitted strategy with the calibrated interval of a :class:`Calibration`.

    Parameters
    ----------
    model : estimator
        A fitted strategy (``predict``).
    calibration : Calibration
    """

    def __init__(self, model: Surrogate, calibration: Calibration) -> None:
        self.model = model
        self.calibration = calibration

    def predict(self, X: ArrayLike) -> np.ndarray:
        """The strategy's angle, degrees."""
        return np.asarray(self.model.predict(X), dtype=np.float64)

    def predict_interval(self, X: ArrayLike, level: float = 0.9) -> tuple[np.ndarray, np.ndarray]:
        """The calibrated interval, degrees; ``level`` must be the calibration's."""
        if not math.isclose(float(level), self.calibration.level):
            raise ValueError(
                f"The 'level' of Calibrated.predict_interval must be the calibrated "
                f"{self.calibration.level:g}. Got {level!r} instead."
            )
        return self.calibration.interval(self.predict(X))
