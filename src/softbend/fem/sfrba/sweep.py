"""Paper B's sweep: the load stepping of :mod:`softbend.fem.sweep` on :class:`ActuatorModel`."""

from __future__ import annotations

from typing import cast

from numpy.typing import ArrayLike

from softbend._validation import must_be
from softbend.actuators import SFRBA, Design
from softbend.errors import InputError
from softbend.fem.actuator import ActuatorModel
from softbend.fem.options import FEMOptions
from softbend.fem.sweep import ProgressCallback, StepHistory, run_model_sweep
from softbend.models import SweepResult

__all__ = ["run_sweep", "simulate"]


def simulate(
    design: Design,
    pressures_mpa: ArrayLike,
    options: FEMOptions | None = None,
    *,
    progress: ProgressCallback | None = None,
) -> SweepResult:
    """Sweep the FEM model of ``design`` over increasing pressures.

    Parameters
    ----------
    design : Design
        The actuator (l, r, t, b, φ, lc).
    pressures_mpa : array_like
        Requested gauge pressures, MPa, strictly increasing from 0 or above.
    options : FEMOptions, optional
        Modelling assumptions and solver settings (defaults documented there).
    progress : callable, optional
        ``progress(pressure_mpa, angle_deg, pmax_mpa)`` after each converged step.

    Returns
    -------
    SweepResult
        One entry per requested pressure up to where the sweep stopped. Angle by
        the arc fit of the backbone (degrees), tip in the frame of
        :func:`softbend.analytical.tip_position_mm` (mm), Newton iterations of
        the step that reached each pressure, ``mesh_size`` = tetrahedra of the
        half model. ``stats`` holds the steps, the stop reason, the degrees of
        freedom and the time spent in assembly and factorisation: the keys of
        :class:`~softbend.fem.stats.FEMStats` (read it with
        :func:`~softbend.fem.stats.fem_stats`).

    Raises
    ------
    ConvergenceError
        If the gravity-only state does not converge.
    ValueError
        For a bad pressure grid or options.
    """
    result, _, _ = run_sweep(design, pressures_mpa, options, progress=progress)
    return result


def run_sweep(
    design: Design,
    pressures_mpa: ArrayLike,
    options: FEMOptions | None = None,
    *,
    progress: ProgressCallback | None = None,
    keep_states: bool = False,
) -> tuple[SweepResult, ActuatorModel, StepHistory]:
    """:func:`simulate`, also returning the model and the converged steps.

    With ``keep_states=True`` every step keeps its displacement vector, so the
    deformed shapes can be drawn or exported (``model.set_state(step.state)``).
    """
    options = options or FEMOptions()
    if not isinstance(options, FEMOptions):
        raise InputError(must_be("FEMOptions", options), key="options")
    if not isinstance(design, Design) or design.actuator != SFRBA:
        raise InputError(must_be("a Design of paper B's actuator", design), key="design")
    result, model, history = run_model_sweep(
        ActuatorModel, design, pressures_mpa, options, progress=progress, keep_states=keep_states
    )
    return result, cast(ActuatorModel, model), history
