"""The pressure map: a simulation's actuator made as stiff as the measured one.

If every elastic modulus of the elastomer is multiplied by ``k``, the total
potential energy ``k·W(u) − p·V(u)`` has the same equilibria as
``W(u) − (p/k)·V(u)``: the stiffer actuator at pressure ``p`` bends as the
model does at ``p/k``. A surrogate trained on simulations of one elastomer
therefore answers for an elastomer ``k`` times as stiff when it is asked at the
scaled pressure ``s·p``, ``s = 1/k``. Gravity, the fibers and the
strain-limiting layer do not scale with the elastomer, and a real elastomer's
stress–stretch curve differs in shape, not only in scale, from the one
simulated, so the map is a first-order correction: one number, fitted to the
measurements by least squares, with a physical meaning (``s > 1``: the real
elastomer is softer than the simulated one).

:func:`fit_pressure_scale` fits ``s`` for any surrogate; :func:`scale_mlp_pressure`
folds it into an MLP's input standardization exactly, so that a network can be
trained further from the mapped start (the ``scaled-refined`` strategy).
"""

from __future__ import annotations

from typing import TYPE_CHECKING

import numpy as np
from numpy.typing import ArrayLike
from scipy.optimize import minimize_scalar

from softbend.errors import InputError
from softbend.surrogates.corrected import scaled_pressure_rows
from softbend.surrogates.protocol import Surrogate

if TYPE_CHECKING:
    from softbend.actuators import Actuator
    from softbend.surrogates.mlp import NormalizedMLPRegressor

__all__ = ["SCALE_BOUNDS", "fit_pressure_scale", "scale_mlp_pressure"]

#: The pressure scale is searched in this range (the elastomer 4 times softer or stiffer).
SCALE_BOUNDS: tuple[float, float] = (0.25, 4.0)


def fit_pressure_scale(
    base: Surrogate, X: ArrayLike, y: ArrayLike, actuator: Actuator | None = None
) -> float:
    """The ``s`` that minimises ``Σ (base(design, s·p) − θ)²`` over the rows.

    Parameters
    ----------
    base : estimator
        A fitted surrogate on the inputs of ``actuator``.
    X : array_like of shape (n, d)
        Measured designs and pressures (paper B's in mm, deg, MPa; another actuator's
        inputs in its own units), finite.
    y : array_like of shape (n,)
        Measured angles, degrees.
    actuator : Actuator, optional
        The readings' actuator, whose pressure column and unit a message names
        (default paper B's: ``pressure_mpa`` in MPa).

    Returns
    -------
    float
        The pressure scale, dimensionless, within :data:`SCALE_BOUNDS`.

    Raises
    ------
    InputError
        Key ``X``: no row has a positive pressure (the scale is then
        undetermined), or the best scale lies on a bound of :data:`SCALE_BOUNDS`
        (the measured actuators are not this model's actuator made softer or
        stiffer); key ``base``: the base predicts no finite angle at any scale.
    """
    rows = np.asarray(X, dtype=np.float64)
    angles = np.asarray(y, dtype=np.float64)
    if actuator is None:
        from softbend.actuators import SFRBA

        actuator = SFRBA
    column, unit = actuator.pressure_column, actuator.pressure_unit
    if not np.any(rows[:, -1] > 0.0):
        raise InputError(
            f"must include a pressure above 0 {unit} (column '{column}'): the pressure scale "
            "is fitted on pressurized readings",
            key="X",
        )
    low, high = SCALE_BOUNDS

    def loss(scale: float) -> float:
        # A base that cannot answer at some scaled pressure (NaN: beyond where
        # its sweep stops) rules that scale out.
        predicted = np.asarray(base.predict(scaled_pressure_rows(rows, scale)))
        with np.errstate(over="ignore", invalid="ignore"):  # an overflow is an infinite loss
            value = float(np.sum((predicted - angles) ** 2))
        return value if np.isfinite(value) else np.inf

    # A scan of log(s) finds the basin (an MLP asked far outside its training
    # pressures can have spurious minima), then Brent's method refines it.
    grid = np.linspace(np.log(low), np.log(high), 41)
    losses = np.array([loss(float(np.exp(g))) for g in grid])
    if not np.isfinite(losses).any():
        raise InputError(
            "predicts no finite angle at the measured pressures for any pressure scale in "
            f"{low:g}–{high:g}",
            key="base",
        )
    best = int(np.argmin(losses))
    if best in (0, grid.size - 1):
        raise InputError(
            f"gives a pressure scale on its bound ({float(np.exp(grid[best])):.3g}, allowed "
            f"{low:g}–{high:g}): the measured actuators do not behave like the base's actuator "
            f"with a softer or stiffer elastomer. Check that the pressure column '{column}' "
            f"is in {unit}, the base model's unit, and that the base is a surrogate of the same "
            "actuator family",
            key="X",
        )
    found = minimize_scalar(
        lambda log_s: loss(float(np.exp(log_s))),
        bounds=(grid[best - 1], grid[best + 1]),
        method="bounded",
        options={"xatol": 1e-7},
    )
    return float(np.exp(found.x))


def scale_mlp_pressure(model: NormalizedMLPRegressor, scale: float) -> NormalizedMLPRegressor:
    """A copy of a normalized MLP that answers ``model(design, scale·p)`` exactly.

    The network standardizes its inputs as ``(x − mean)/scale_x``; asking it at
    ``s·p`` is the same as standardizing ``p`` with mean ``mean_p/s`` and scale
    ``scale_p/s``. Weights, biases and target scaling are shared unchanged.

    Parameters
    ----------
    model : NormalizedMLPRegressor
        Fitted on :data:`softbend.design.FEATURES` (pressure last).
    scale : float
        The pressure scale ``s`` > 0.

    Returns
    -------
    NormalizedMLPRegressor
    """
    from softbend.surrogates.mlp import NormalizedMLPRegressor

    x_mean = np.array(model.x_mean_, dtype=np.float64, copy=True)
    x_scale = np.array(model.x_scale_, dtype=np.float64, copy=True)
    x_mean[-1] /= scale
    x_scale[-1] /= scale
    return NormalizedMLPRegressor.from_arrays(
        x_mean=x_mean,
        x_scale=x_scale,
        y_mean=float(model.y_mean_),
        y_scale=float(model.y_scale_),
        coefs=model.coefs_,
        intercepts=model.intercepts_,
        **{k: v for k, v in model.get_params().items() if k != "hidden_sizes"},
    )
