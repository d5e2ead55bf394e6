"""What a fitted surrogate answers: the :class:`Surrogate` protocol.

A surrogate maps rows of :data:`softbend.surrogates.features.FEATURES` (l, r,
t, b in mm, φ in degrees, lc in mm, P in MPa) to the bending angle in degrees.
Everything that predicts with one (``softbend predict``, a campaign on a
surrogate, transfer learning, the search's timing) needs only
:class:`Surrogate`; a control loop that evaluates one sample per step also uses
the fast path of :class:`FastSurrogate`.

==========================================  ===========  ===============
surrogate                                   Surrogate    FastSurrogate
==========================================  ===========  ===============
``PolynomialRegressor`` (``plr``)           yes          yes
``NormalizedMLPRegressor`` (``mlp``)        yes          yes
``xgboost.XGBRegressor`` (``xgb``)          yes          no
the corrections of                          yes          no
:mod:`softbend.surrogates.corrected`
==========================================  ===========  ===============

XGBoost's regressor has no ``predictor()`` (softbend does not wrap its trees
in one), nor do the composites, whose prediction is their base's with a
correction; :func:`softbend.surrogates.metrics.inference_time` times
``predict`` on one row for them. Both protocols are runtime-checkable:
``isinstance(model, Surrogate)`` holds for a fitted model only (an unfitted one
has no ``n_features_in_``).
"""

from __future__ import annotations

from collections.abc import Callable
from typing import Protocol, runtime_checkable

import numpy as np
from numpy.typing import ArrayLike

__all__ = ["FastSurrogate", "Surrogate"]


@runtime_checkable
class Surrogate(Protocol):
    """A fitted surrogate of the bending angle.

    Attributes
    ----------
    n_features_in_ : int
        Number of input columns it was fitted on (7, :data:`FEATURES`).
    """

    n_features_in_: int

    def predict(self, X: ArrayLike) -> np.ndarray:
        """Bending angles, degrees, of the rows ``X`` of shape (n, 7) (mm, deg, MPa)."""
        ...


@runtime_checkable
class FastSurrogate(Surrogate, Protocol):
    """A :class:`Surrogate` with a one-sample fast path for control loops."""

    def predictor(self) -> Callable[[ArrayLike], float]:
        """``f(x) -> float``: the angle (degrees) of one row ``x`` of shape (7,),
        equal to ``predict([x])[0]`` up to rounding, without scikit-learn's checks."""
        ...
