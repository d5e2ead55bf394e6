"""A trained surrogate as a :class:`~softbend.models.BendingModel`.

A surrogate predicts the bending angle only; the tip of its sweep is the end of
the constant-curvature arc of that angle plus the straight cap
(:func:`softbend.analytical.tip_position_mm`), an approximation of the tip the
FEM computes. A campaign can run on a surrogate (``get_backend("surrogate", path=...)``),
as can transfer learning and control.
"""

from __future__ import annotations

import os
import time
from dataclasses import dataclass, field
from pathlib import Path

from numpy.typing import ArrayLike

from softbend.actuators import Design
from softbend.analytical import tip_position_mm
from softbend.campaign.backends import BACKENDS, register_backend
from softbend.errors import InputError
from softbend.models import SweepResult, check_pressures_mpa
from softbend.surrogates.protocol import Surrogate

__all__ = ["SurrogateModel"]


@dataclass(frozen=True)
class SurrogateModel:
    """Any fitted surrogate of the angle, swept like the FEM and the analytical model.

    Parameters
    ----------
    estimator : estimator
        Fitted regressor whose ``predict`` maps rows of
        :data:`softbend.design.FEATURES` (mm, deg, MPa) to the angle in degrees:
        ``PolynomialRegressor``, ``NormalizedMLPRegressor``, ``XGBRegressor`` or a
        refined model.
    source : str
        Where it came from (a file path or a description), kept in the sweep's
        ``stats``.

    Examples
    --------
    >>> model = SurrogateModel.load("surrogates/models/mlp.json")  # doctest: +SKIP
    >>> model.sweep(design, default_pressures_mpa(0.2)).angle_deg  # doctest: +SKIP
    """

    estimator: Surrogate
    source: str = ""
    name: str = field(default="surrogate", init=False)

    def __post_init__(self) -> None:
        if not callable(getattr(self.estimator, "predict", None)):
            raise InputError(
                "must be a fitted regressor with a 'predict' method; got "
                f"{type(self.estimator).__name__}",
                key="estimator",
            )

    @classmethod
    def load(cls, path: str | os.PathLike[str]) -> SurrogateModel:
        """Load a surrogate saved by :func:`softbend.surrogates.save_surrogate`.

        Raises
        ------
        FileNotFoundError, softbend.errors.SchemaError
            As :func:`softbend.surrogates.load_surrogate`.
        """
        from softbend.surrogates.persistence import load_surrogate

        saved = load_surrogate(path)
        return cls(saved.model, source=f"{saved.kind} surrogate from {Path(path)}")

    def sweep(self, design: Design, pressures_mpa: ArrayLike) -> SweepResult:
        """Predict the angle at every pressure of the grid (MPa); the tip from the arc.

        A non-finite prediction ends the sweep there (``converged=False``), as a
        solver that failed would.
        """
        start = time.perf_counter()
        grid = check_pressures_mpa(pressures_mpa)
        angle = self.estimator.predict(design.feature_rows(grid))
        tip_x, tip_z = tip_position_mm(design, angle)
        return SweepResult.from_angles(
            design,
            grid,
            angle,
            tip_x,
            tip_z,
            wall_time_s=time.perf_counter() - start,
            stats={
                "model": "surrogate of the bending angle; tip from the constant-curvature arc",
                "source": self.source or type(self.estimator).__name__,
            },
        )


def _saved_surrogate(path: str | os.PathLike[str]) -> SurrogateModel:
    """The ``"surrogate"`` campaign backend: the surrogate saved at ``path``."""
    return SurrogateModel.load(path)


# A saved surrogate sweeps like any backend (``softbend campaign run --backend
# surrogate --model FILE``); the campaign sits below the surrogates in the
# pipeline, so the surrogates register it here, once.
if "surrogate" not in BACKENDS:
    register_backend("surrogate", _saved_surrogate)
