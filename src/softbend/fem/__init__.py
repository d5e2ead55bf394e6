"""Nonlinear 3D finite-element model of the fiber-reinforced bending actuator (SPEC §4.2).

NGSolve and netgen are imported only inside this subpackage. The pipeline:
``geometry`` (netgen.occ solid and mesh) → ``mechanics`` (energy densities) →
``energy`` (the energy terms, optionally compiled once per process) →
``actuator`` (the model's energy, state and measurements) → ``newton`` (energy
minimisation) → ``sweep`` (load stepping, :func:`simulate`) → ``model`` (:class:`FEMModel`,
the FEM as a :class:`~softbend.models.BendingModel`); ``verification``
holds the closed-form cases solved with the same core.
"""

# PyTorch (if installed) before NGSolve: see softbend._torch.
import softbend._torch  # noqa: F401  (import order)
from softbend._extras import require

require("ngsolve", "The FEM (softbend.fem)")  # one line naming softbend[fem] if missing

from softbend.fem.energy import use_compiled  # noqa: E402
from softbend.fem.model import FEMModel  # noqa: E402
from softbend.fem.options import GRAVITY_DIRECTIONS, OUTPUT_MODES, FEMOptions  # noqa: E402
from softbend.fem.sweep import simulate  # noqa: E402

__all__ = [
    "GRAVITY_DIRECTIONS",
    "OUTPUT_MODES",
    "FEMModel",
    "FEMOptions",
    "simulate",
    "use_compiled",
]
