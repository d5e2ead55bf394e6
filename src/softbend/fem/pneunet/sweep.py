"""The pressure sweep of one PneuNet: :func:`run_pneunet_sweep`.

The load stepping of paper B's actuator (:func:`softbend.fem.sweep.run_model_sweep`:
gravity, then adaptive pressure steps with a tangent predictor and Hermite dense
output) on :class:`~softbend.fem.pneunet.model.PneuNetModel`. Besides the stop
reasons of that sweep, a PneuNet sweep without contact stops when neighbouring
chamber walls touch (the reason names the pressure); with contact
(``FEMOptions.contact == "on"``) it goes on with the walls pressing on each
other. The stats add the cavity volume of every converged step (both halves,
mm³), for the volume–pressure curve, and with contact the contact force and
pressure of every step.
"""

from __future__ import annotations

from collections.abc import Callable

from numpy.typing import ArrayLike

from softbend._validation import must_be
from softbend.actuators import Design
from softbend.errors import InputError
from softbend.fem._ngsolve import require_ngsolve
from softbend.fem.options import FEMOptions
from softbend.fem.pneunet.model import PneuNetModel
from softbend.fem.sweep import StepHistory, run_model_sweep
from softbend.models import SweepResult

require_ngsolve()  # NGSolve after PyTorch, or one line naming softbend[fem]

__all__ = ["run_pneunet_sweep"]


def run_pneunet_sweep(
    design: Design,
    pressures_mpa: ArrayLike,
    options: FEMOptions,
    *,
    progress: Callable[[float, float, float], None] | None = None,
    keep_states: bool = False,
) -> tuple[SweepResult, PneuNetModel, StepHistory]:
    """Sweep the FEM model of a PneuNet over increasing pressures.

    Parameters
    ----------
    design : Design
        A checked design of the ``"pneunet"`` family
        (:meth:`softbend.fem.families.FEMFamily.design`).
    pressures_mpa : array_like
        Requested gauge pressures, MPa, strictly increasing from 0 or above.
    options : FEMOptions
        Modelling and solver settings
        (:func:`softbend.fem.pneunet.description.pneunet_options` for the defaults).
    progress : callable, optional
        ``progress(pressure_mpa, angle_deg, pmax_mpa)`` after each converged step.
    keep_states : bool
        Keep the displacement of every step (for VTK output).

    Returns
    -------
    (SweepResult, PneuNetModel, StepHistory)
        As :func:`softbend.fem.sweep.run_sweep`; ``stats["step_volume_mm3"]``
        holds the cavity volume at every converged step, mm³; with
        ``options.contact == "on"``, ``stats["step_contact_force_n"]`` and
        ``stats["step_contact_pressure_kpa"]`` the contact force (N) and mean
        contact pressure (kPa) between the chamber walls at every step.
    """
    if not isinstance(options, FEMOptions):
        raise InputError(must_be("FEMOptions", options), key="options")
    if not isinstance(design, Design) or design.actuator.fem_family != "pneunet":
        raise InputError(must_be("a design of the pneunet family", design), key="design")
    result, model, history = run_model_sweep(
        PneuNetModel, design, pressures_mpa, options, progress=progress, keep_states=keep_states
    )
    assert isinstance(model, PneuNetModel)
    result.stats["step_volume_mm3"] = [float(s.volume_mm3) for s in history.steps]
    if model.contact is not None:
        # The gravity state (step 0) has no contact; a step that stopped the sweep
        # was recorded too.
        k = options.contact_penalty_mpa_per_mm
        forces = [0.0, *model.contact_force_n][: len(history.steps)]
        depths = [0.0, *model.interpenetration_mm][: len(history.steps)]
        result.stats["step_contact_force_n"] = forces
        result.stats["step_contact_pressure_kpa"] = [1000.0 * k * d for d in depths]
    return result, model, history
