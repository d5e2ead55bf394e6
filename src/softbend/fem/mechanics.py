"""Strain energy densities of the actuator's parts, as NGSolve coefficient functions.

The whole finite-element model is one potential energy minimised by Newton's
method on its exact (automatically differentiated) Hessian, so every part of the
physics is a scalar energy density here:

* :func:`solid_energy` — nearly incompressible hyperelastic solid, isochoric
  ``W(Ī1)`` plus a volumetric penalty ``K/2 (J − 1)²`` (MPa = mJ/mm³);
* :func:`membrane_energy` — an incompressible hyperelastic membrane bonded to a
  face (the 0.1 mm strain-limiting layer), energy per reference area (N/mm);
* :func:`fiber_energy` — one family of fibers smeared over a face, energy per
  reference area (N/mm);
* :func:`volume_flux` — the integrand whose surface integral is the enclosed
  cavity volume in the deformed state, so a follower pressure is the
  conservative load ``−p·V``.

All functions take NGSolve coefficient functions (a deformation gradient ``F``
on volumes, or the surface deformation gradient ``F_s = I + ∇_Γu`` on faces) and
return one. They are pure: no mesh, no state.
"""

from __future__ import annotations

import math
from collections.abc import Sequence
from typing import TYPE_CHECKING

from softbend._validation import must_be
from softbend.errors import InputError
from softbend.materials.models import HyperelasticModel

if TYPE_CHECKING:
    from ngsolve import CoefficientFunction

__all__ = [
    "FIBER_LAWS",
    "fiber_energy",
    "helix_stiffness_n_per_mm",
    "membrane_energy",
    "solid_energy",
    "volume_flux",
]

#: Fiber laws: "tension-compression" (a tied beam, paper B) or "tension-only" (a thread).
FIBER_LAWS: tuple[str, ...] = ("tension-compression", "tension-only")


def solid_energy(
    F: CoefficientFunction, model: HyperelasticModel, bulk_modulus_mpa: float
) -> CoefficientFunction:
    """Nearly incompressible solid: ``W(Ī1) + K/2 (J − 1)²``, MPa.

    The isochoric split ``Ī1 = J^(−2/3) tr(FᵀF)`` makes the deviatoric response
    independent of the volume change, and the penalty with bulk modulus ``K``
    keeps ``J`` close to 1. With quadratic tetrahedra and ``K = 100 μ``
    (Poisson's ratio ≈ 0.495) the element does not lock; see
    :class:`softbend.fem.FEMOptions`.

    Parameters
    ----------
    F : CoefficientFunction
        Deformation gradient, 3×3.
    model : HyperelasticModel
        Isochoric law.
    bulk_modulus_mpa : float
        Penalty bulk modulus ``K``, MPa.
    """
    from ngsolve import Det, InnerProduct

    J = Det(F)
    # tr(FᵀF) as F:F: the same number, a third cheaper to differentiate twice.
    I1_bar = J ** (-2.0 / 3.0) * InnerProduct(F, F)
    return model.energy(I1_bar) + 0.5 * bulk_modulus_mpa * (J - 1.0) ** 2


def membrane_energy(
    Fs: CoefficientFunction,
    tangents: Sequence[CoefficientFunction],
    model: HyperelasticModel,
    thickness_mm: float,
) -> CoefficientFunction:
    """Incompressible hyperelastic membrane bonded to a face, N/mm (energy per area).

    With ``C_s`` the 2×2 metric of the deformed face in the orthonormal reference
    tangents ``t1, t2``, incompressibility sets the thickness stretch to
    ``det(C_s)^(−1/2)``, so ``I1 = tr C_s + 1/det C_s``; the energy per reference
    area is ``h·W(I1)``. The membrane has no bending stiffness: it follows the
    face it is bonded to.

    Parameters
    ----------
    Fs : CoefficientFunction
        Surface deformation gradient ``I + ∇_Γ u``, 3×3.
    tangents : pair of CoefficientFunction
        Orthonormal tangent vectors of the reference face.
    model : HyperelasticModel
        The membrane's law (MPa).
    thickness_mm : float
        Reference thickness ``h``, mm.
    """
    from ngsolve import InnerProduct

    a1, a2 = (Fs * t for t in tangents)
    c11, c22, c12 = InnerProduct(a1, a1), InnerProduct(a2, a2), InnerProduct(a1, a2)
    I1 = c11 + c22 + 1.0 / (c11 * c22 - c12 * c12)
    return thickness_mm * model.energy(I1)


def fiber_energy(
    Fs: CoefficientFunction,
    direction: CoefficientFunction,
    stiffness_n_per_mm: float,
    law: str = "tension-compression",
    *,
    smoothing: float = 0.01,
) -> CoefficientFunction:
    """One family of fibers smeared over a face, N/mm (energy per reference area).

    A fiber along the unit reference direction ``a`` stretches by
    ``λ = |F_s a|``; with ``k = E_f A_f / s`` (axial stiffness per unit width of
    the family, fiber spacing ``s``) the energy is ``k/2 (λ − 1)²``.

    * ``"tension-compression"``: the fiber carries compression as well, as the
      beams tied to the elastomer of paper B do (the matrix around it holds it
      against buckling).
    * ``"tension-only"``: a thread: ``k/2 ⟨λ − 1⟩²`` with the ramp smoothed over
      ``|λ − 1| ≲ smoothing`` so the Hessian stays continuous.

    Parameters
    ----------
    Fs : CoefficientFunction
        Surface deformation gradient, 3×3.
    direction : CoefficientFunction
        Unit fiber direction in the reference face.
    stiffness_n_per_mm : float
        ``E_f A_f / s``, N/mm.
    law : {"tension-compression", "tension-only"}
    smoothing : float
        Width of the smoothed ramp of the tension-only law (stretch units).
    """
    from ngsolve import InnerProduct, sqrt

    stretched = Fs * direction
    strain = sqrt(InnerProduct(stretched, stretched)) - 1.0
    if law == "tension-compression":
        return 0.5 * stiffness_n_per_mm * strain * strain
    if law == "tension-only":
        positive = 0.5 * (strain + sqrt(strain * strain + smoothing * smoothing))
        return 0.5 * stiffness_n_per_mm * positive * positive
    raise InputError(must_be(f"one of {', '.join(repr(v) for v in FIBER_LAWS)}", law), key="law")


def volume_flux(
    position: CoefficientFunction,
    Fs: CoefficientFunction,
    normal: CoefficientFunction,
    axes: Sequence[int],
) -> CoefficientFunction:
    """Integrand of the enclosed volume: ``w(x)·n da`` per reference area, mm.

    By the divergence theorem the volume enclosed by a closed surface is
    ``∫ w·n da`` for any field with ``div w = 1``. With
    ``w = x_axes / len(axes)`` (only the listed components of the deformed
    position ``x``), faces on which ``w·n = 0`` may be left out: symmetry planes
    normal to an axis not in ``axes``, and the end planes of a plane-strain
    slice. Nanson's relation gives ``n da = cof(F_s) N dA``. With ``normal`` the
    outward normal of the solid (pointing into the cavity) the result is the
    *negative* cavity volume.

    Parameters
    ----------
    position : CoefficientFunction
        Deformed position ``X + u``, 3-vector, mm.
    Fs : CoefficientFunction
        Surface deformation gradient, 3×3.
    normal : CoefficientFunction
        Reference unit normal ``N`` of the face.
    axes : sequence of int
        Components of ``w`` (0, 1, 2 for x, y, z), non-empty.
    """
    from ngsolve import Cof

    if not axes:
        raise InputError(must_be("at least one of 0, 1, 2", list(axes)), key="axes")
    nda = Cof(Fs) * normal
    return sum(position[i] * nda[i] for i in axes) / float(len(axes))


def helix_stiffness_n_per_mm(e_mpa: float, radius_mm: float, spacing_mm: float) -> float:
    """Smeared axial stiffness ``E A / s`` of a fiber family, N/mm."""
    return e_mpa * math.pi * radius_mm**2 / spacing_mm
