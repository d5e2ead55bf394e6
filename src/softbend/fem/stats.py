"""The solver statistics of an FEM sweep: the typed form of ``SweepResult.stats``.

:func:`softbend.fem.simulate` stores its statistics in
:attr:`softbend.models.SweepResult.stats`, a plain dictionary because that is what
every bending model returns there, what a campaign stores as JSON text with each
design (:meth:`softbend.campaign.CampaignStore.record_success`) and what
``softbend fem run`` writes to ``sweep.json``. :class:`FEMStats` names its keys and
their types, so a reader writes ``fem_stats(result)["stop_reason"]`` and a type
checker finds a misspelt key; the dictionary survives those JSON round trips
unchanged (NaN stays NaN through the campaign store).

This module is pure Python: it needs neither NGSolve nor the FEM's other modules.
"""

# No ``from __future__ import annotations``: TypedDict reads NotRequired from the
# evaluated annotations (``__optional_keys__``), not from their text.
from collections.abc import Mapping
from typing import TYPE_CHECKING, Any, NotRequired, TypedDict, cast

if TYPE_CHECKING:
    from softbend.models import SweepResult

__all__ = ["FEMStats", "FEMTimings", "fem_stats"]


class FEMTimings(TypedDict):
    """Time and work of the Newton solver over the whole sweep (all values floats).

    Attributes
    ----------
    assembly_s, factorization_s, residual_s, solve_s : float
        Seconds spent assembling the tangent, factorising it, assembling the
        residual and solving with the factors.
    iterations, factorizations, chord_steps, chord_rejected : float
        Newton iterations, factorisations, chord (reused-factor) steps and the
        chord steps rejected, as counts.
    """

    assembly_s: float
    factorization_s: float
    residual_s: float
    solve_s: float
    iterations: float
    factorizations: float
    chord_steps: float
    chord_rejected: float


class FEMStats(TypedDict):
    """The keys of an FEM sweep's ``SweepResult.stats``.

    Attributes
    ----------
    model : str
        What was solved ("3D FEM, NGSolve, half model, quadratic tetrahedra").
    stop_reason : str
        Why the sweep ended ("reached the last pressure", "bending angle above …",
        "stretch … above …", "inflation instability above …", "no convergence above …",
        and for the PneuNet "neighbouring chamber walls touch at … kPa" without
        contact, "chamber walls overlap by … mm" with it).
    steps_mpa : list of float
        Pressure of every converged load step, MPa, from 0 (the gravity state).
    step_angles_deg : list of float
        Bending angle at each step, degrees.
    step_iterations : list of int
        Newton iterations of each step.
    step_max_stretch : list of float
        Largest principal stretch in the elastomer at each step (dimensionless).
    step_volume_rate_mm3_per_mpa : list of float
        ``dV/dp`` of the whole cavity at each step, mm³/MPa.
    rejected_steps : int
        Load steps that did not converge and were halved.
    ndof : int
        Free degrees of freedom of the half model.
    setup_s : float
        Seconds spent meshing and building the model before the first solve.
    timings : FEMTimings
        Work of the Newton solver.
    options : dict
        :meth:`softbend.fem.FEMOptions.to_dict` of the options used.
    options_sha256 : str
        :meth:`softbend.fem.FEMOptions.digest` of those options.
    fiber_spacing_mm : float
        Distance between neighbouring fibers of one family, mm (NaN for an actuator
        without fibers).
    step_volume_mm3 : list of float, optional
        Volume of the whole cavity at each step, mm³ (the PneuNet's sweeps).
    step_contact_force_n : list of float, optional
        Contact force between the chamber walls of the whole actuator at each
        step, N (the PneuNet's sweeps with contact; 0 before the walls touch).
    step_contact_pressure_kpa : list of float, optional
        Mean contact pressure of the touching walls at each step, kPa: the
        penalty stiffness times their mean interpenetration.
    failure : str, optional
        The solver's last error, present only when the sweep stopped on one.
    """

    model: str
    stop_reason: str
    steps_mpa: list[float]
    step_angles_deg: list[float]
    step_iterations: list[int]
    step_max_stretch: list[float]
    step_volume_rate_mm3_per_mpa: list[float]
    rejected_steps: int
    ndof: int
    setup_s: float
    timings: FEMTimings
    options: dict[str, Any]
    options_sha256: str
    fiber_spacing_mm: float
    step_volume_mm3: NotRequired[list[float]]
    step_contact_force_n: NotRequired[list[float]]
    step_contact_pressure_kpa: NotRequired[list[float]]
    failure: NotRequired[str]


def fem_stats(source: "SweepResult | Mapping[str, Any]") -> FEMStats:
    """The statistics of an FEM sweep, typed: the same dictionary, not a copy.

    Parameters
    ----------
    source : SweepResult or mapping
        A result of :func:`softbend.fem.simulate`, or its ``stats`` (as read
        back from JSON).

    Returns
    -------
    FEMStats
        ``source.stats`` (or ``source``) itself, for typed key access.
    """
    stats = source if isinstance(source, Mapping) else source.stats
    return cast(FEMStats, stats)
