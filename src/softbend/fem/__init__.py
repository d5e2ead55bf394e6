"""Nonlinear 3D finite-element model of the fiber-reinforced bending actuator (SPEC §4.2).

NGSolve and netgen are imported only inside this subpackage. The pipeline:
``geometry`` (netgen.occ solid and mesh) → ``mechanics`` (energy densities) →
``actuator`` (the model's energy, state and measurements) → ``newton`` (energy
minimisation) → ``sweep`` (load stepping, :func:`simulate`) → ``model`` (:class:`FEMModel`,
the FEM as a :class:`~softbend.models.BendingModel`); ``verification``
holds the closed-form cases solved with the same core.
"""

# PyTorch is loaded before NGSolve on purpose. NGSolve's bundled OpenBLAS
# exports the BLAS symbols that PyTorch's CPU kernels otherwise bind to: with
# NGSolve imported first, a batched matrix product in PyTorch (the surrogates'
# MLP training) crashes the interpreter with a segmentation fault. Loaded in
# this order, both work in one process.
import torch  # noqa: F401  (import order, see above)

from softbend.fem.model import FEMModel
from softbend.fem.options import GRAVITY_DIRECTIONS, OUTPUT_MODES, FEMOptions
from softbend.fem.sweep import simulate

__all__ = ["GRAVITY_DIRECTIONS", "OUTPUT_MODES", "FEMModel", "FEMOptions", "simulate"]
