"""Nonlinear 3D finite-element models of soft bending actuators (paper B §3.1).

The pipeline: ``geometry`` (netgen.occ solid and mesh) → ``mechanics`` (energy
densities) → ``energy`` (the energy terms, optionally compiled once per process) →
``actuator`` (the model's energy, state and measurements) → ``newton`` (energy
minimisation) → ``sweep`` (load stepping, :func:`simulate`) → ``model``
(:class:`FEMModel`, the FEM as a :class:`~softbend.models.BendingModel`);
``verification`` holds the closed-form cases solved with the same core.

Each kind of actuator the FEM simulates is a family of :mod:`softbend.fem.families`
(:func:`get_family`, ``--family``): its actuator description, how it makes a design,
sweeps it and reads the angle, each used the same way (:mod:`softbend.fem.run`
sweeps one into a folder). Paper B's fiber-reinforced actuator (``"sfrba"``,
:mod:`softbend.fem.sfrba`: its reference, its analytical model to compare with,
:func:`simulate`) is the pipeline above; the PneuNet (``"pneunet"``,
:mod:`softbend.fem.pneunet`) reuses the energy terms and the load stepping with
its own geometry and readout (:class:`PneuNetModel`, :func:`run_pneunet_sweep`).

Names are imported lazily, so ``import softbend.fem`` is light and the
pure-Python parts work without NGSolve: :class:`FEMOptions`, the typed solver
statistics :class:`FEMStats` (:func:`fem_stats`) and the dimensions of
:class:`ActuatorGeometry`. The names that solve (:class:`FEMModel`,
:func:`simulate`, :func:`use_compiled`) import NGSolve (after PyTorch, see
:mod:`softbend._torch`) and raise one
:class:`~softbend.errors.MissingExtraError` naming ``softbend[fem]`` without it.
"""

from __future__ import annotations

from typing import TYPE_CHECKING, Any

from softbend._lazy import export as _export

if TYPE_CHECKING:
    from softbend.fem.energy import use_compiled
    from softbend.fem.families import FEM_FAMILIES, FEMFamily, get_family
    from softbend.fem.geometry import ActuatorGeometry
    from softbend.fem.model import FEMModel
    from softbend.fem.options import GRAVITY_DIRECTIONS, OUTPUT_MODES, FEMOptions
    from softbend.fem.pneunet.model import PneuNetModel
    from softbend.fem.pneunet.sweep import run_pneunet_sweep
    from softbend.fem.sfrba.sweep import simulate
    from softbend.fem.stats import FEMStats, FEMTimings, fem_stats

#: Public name → submodule that defines it.
_EXPORTS = {
    "FEM_FAMILIES": "families",
    "FEMFamily": "families",
    "PneuNetModel": "softbend.fem.pneunet.model",
    "get_family": "families",
    "run_pneunet_sweep": "softbend.fem.pneunet.sweep",
    "ActuatorGeometry": "geometry",
    "FEMModel": "model",
    "FEMOptions": "options",
    "FEMStats": "stats",
    "FEMTimings": "stats",
    "GRAVITY_DIRECTIONS": "options",
    "OUTPUT_MODES": "options",
    "fem_stats": "stats",
    "simulate": "softbend.fem.sfrba.sweep",
    "use_compiled": "energy",
}

__all__ = [
    "FEM_FAMILIES",
    "GRAVITY_DIRECTIONS",
    "OUTPUT_MODES",
    "ActuatorGeometry",
    "FEMFamily",
    "FEMModel",
    "FEMOptions",
    "FEMStats",
    "FEMTimings",
    "PneuNetModel",
    "fem_stats",
    "get_family",
    "run_pneunet_sweep",
    "simulate",
    "use_compiled",
]


def __getattr__(name: str) -> Any:
    return _export(__name__, _EXPORTS, name)


def __dir__() -> list[str]:
    return list(__all__)
