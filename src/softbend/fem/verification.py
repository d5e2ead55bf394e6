"""Closed-form checks of the FEM core, and the mesh-convergence study.

Each case meshes a simple solid and solves it with the same energy densities
(:mod:`softbend.fem.mechanics`) and the same Newton solver
(:class:`softbend.fem.newton.EnergySolver`) as the actuator:

* :func:`tube_inflation` — a thick-walled incompressible neo-Hookean tube under
  internal (follower) pressure in plane strain, against
  ``P = μ[ln(λa/λb) + ½(λb⁻² − λa⁻²)]`` with ``a² − A² = b² − B²``;
* :func:`cantilever_sag` — a slender clamped beam bending under its own weight,
  against the large-deflection elastica ``EI θ'' = −w (L − s) cos θ``,
  ``θ(0) = 0``, ``θ'(L) = 0``, solved with :func:`scipy.integrate.solve_bvp`;
* :func:`mesh_study` — the actuator's bending angle at several pressures for a
  sequence of element sizes.
"""

from __future__ import annotations

import math
from collections.abc import Callable, Sequence
from dataclasses import dataclass
from typing import TYPE_CHECKING

import numpy as np

from softbend.actuators import Design
from softbend.errors import ConvergenceError, InputError
from softbend.fem._ngsolve import require_ngsolve
from softbend.fem.mechanics import solid_energy, volume_flux
from softbend.fem.newton import EnergySolver
from softbend.materials.models import NeoHookean

if TYPE_CHECKING:
    from ngsolve import BilinearForm, FESpace, GridFunction

    from softbend.fem.options import FEMOptions
    from softbend.models import SweepResult

require_ngsolve()  # NGSolve after PyTorch, or one line naming softbend[fem]

__all__ = [
    "CaseResult",
    "MeshStudyRow",
    "cantilever_sag",
    "elastica_tip_deflection",
    "mesh_study",
    "tube_closed_form_pressure",
    "tube_inflation",
]


@dataclass(frozen=True)
class CaseResult:
    """A verification case: the FEM value, the reference and their relative error."""

    name: str
    quantity: str
    fem: float
    reference: float
    ndof: int

    @property
    def relative_error(self) -> float:
        return abs(self.fem - self.reference) / abs(self.reference)


def tube_closed_form_pressure(
    shear_modulus_mpa: float, inner_mm: float, outer_mm: float, deformed_inner_mm: float
) -> float:
    """Internal pressure that inflates an incompressible neo-Hookean tube (plane strain), MPa.

    ``P = μ[ln(λa/λb) + ½(λb⁻² − λa⁻²)]``, ``λa = a/A``, ``λb = b/B``,
    ``b² = B² + a² − A²``.
    """
    a = deformed_inner_mm
    b = math.sqrt(outer_mm**2 + a**2 - inner_mm**2)
    la, lb = a / inner_mm, b / outer_mm
    return shear_modulus_mpa * (math.log(la / lb) + 0.5 * (lb**-2 - la**-2))


def _ramp_solver(form: BilinearForm, gfu: GridFunction, fes: FESpace) -> EnergySolver:
    """Newton for :func:`_ramp`: every increment starts from the last state, not a
    prediction, so the first iteration may cut the residual less than tenfold and
    the sweep's early give-up rule stays off (as for the sweep's gravity ramp)."""
    return EnergySolver(
        form, gfu, fes.FreeDofs(), rtol=1e-7, max_iterations=30, first_contraction=math.inf
    )


def _ramp(
    solver: EnergySolver,
    set_load: Callable[[float], None],
    force_scale: Callable[[float], float],
    steps: int,
) -> int:
    """Apply the load in ``steps`` equal increments, halving an increment that fails."""
    done, fraction, iterations = 0.0, 1.0 / steps, 0
    while done < 1.0 - 1e-12:
        target = min(1.0, done + fraction)
        set_load(target)
        try:
            iterations += solver.solve(force_scale(target), step=int(target * steps)).iterations
        except ConvergenceError:
            fraction /= 2.0
            if fraction < 1e-3:
                raise
            continue
        done = target
    return iterations


def tube_inflation(
    *,
    inner_mm: float = 5.0,
    outer_mm: float = 10.0,
    shear_modulus_mpa: float = 0.22,
    pressure_mpa: float = 0.09,
    bulk_ratio: float = 100.0,
    maxh_mm: float = 1.5,
    order: int = 2,
) -> CaseResult:
    """Inflate a quarter of a plane-strain tube slice; compare the inner radius.

    The slice ``0 ≤ x ≤ 1 mm`` of the quarter tube ``y, z ≥ 0`` has ``u_x = 0``
    on both end planes (plane strain) and symmetry on ``y = 0`` and ``z = 0``.
    The pressure is the follower load ``−p·V`` with the volume flux over the
    inner face only (``w = (0, y, z)/2`` has no flux through the other faces).

    Returns
    -------
    CaseResult
        ``fem`` and ``reference``: inner-radius displacement ``a − A`` (mm), the
        reference from the closed form solved for ``a`` at the applied pressure.
    """
    import ngsolve as ngs
    from netgen.occ import Box, Cylinder, OCCGeometry, Pnt, X
    from scipy.optimize import brentq

    slab = 1.0
    quarter = Box(Pnt(0, 0, 0), Pnt(slab, outer_mm, outer_mm))
    shape = Cylinder(Pnt(0, 0, 0), X, outer_mm, slab) - Cylinder(Pnt(0, 0, 0), X, inner_mm, slab)
    shape = shape * quarter
    for face in shape.faces:
        c = face.center
        if abs(c.x) < 1e-9 or abs(c.x - slab) < 1e-9:
            face.name = "ends"
        elif abs(c.y) < 1e-9:
            face.name = "ysym"
        elif abs(c.z) < 1e-9:
            face.name = "zsym"
        elif math.hypot(c.y, c.z) < 0.5 * (inner_mm + outer_mm):
            face.name = "inner"
        else:
            face.name = "outer"
    ngs.ngsglobals.msg_level = 0
    mesh = ngs.Mesh(OCCGeometry(shape).GenerateMesh(maxh=maxh_mm))
    mesh.Curve(order)
    fes = ngs.VectorH1(mesh, order=order, dirichletx="ends", dirichlety="ysym", dirichletz="zsym")
    u = fes.TrialFunction()
    F = ngs.Id(3) + ngs.Grad(u)
    Fs = ngs.Id(3) + ngs.Grad(u).Trace()
    model = NeoHookean(c10_mpa=shear_modulus_mpa / 2.0)
    pressure = ngs.Parameter(0.0)
    position = ngs.CoefficientFunction((ngs.x, ngs.y, ngs.z)) + u.Trace()
    flux = volume_flux(position, Fs, ngs.specialcf.normal(3), axes=(1, 2))
    form = ngs.BilinearForm(fes, symmetric=True)
    form += ngs.Variation(solid_energy(F, model, bulk_ratio * shear_modulus_mpa).Compile() * ngs.dx)
    form += ngs.Variation((pressure * flux).Compile() * ngs.ds("inner"))
    gfu = ngs.GridFunction(fes)
    solver = _ramp_solver(form, gfu, fes)
    area = math.pi * inner_mm / 2.0 * slab
    with ngs.TaskManager():
        _ramp(
            solver, lambda s: pressure.Set(s * pressure_mpa), lambda s: s * pressure_mpa * area, 5
        )
    # Mean inner radius over points of the inner face.
    radii = []
    for beta in np.linspace(0.1, 1.47, 8):
        point = (0.5 * slab, inner_mm * math.cos(beta), inner_mm * math.sin(beta))
        disp = gfu(mesh(*point))
        radii.append(math.hypot(point[1] + disp[1], point[2] + disp[2]))
    a_fem = float(np.mean(radii))
    a_ref = brentq(
        lambda a: (
            tube_closed_form_pressure(shear_modulus_mpa, inner_mm, outer_mm, a) - pressure_mpa
        ),
        inner_mm,
        inner_mm * 3.0,
    )
    return CaseResult(
        "thick-walled tube, plane strain",
        "inner radius displacement a - A (mm)",
        a_fem - inner_mm,
        a_ref - inner_mm,
        int(sum(fes.FreeDofs())),
    )


def elastica_tip_deflection(load_parameter: float, length_mm: float) -> tuple[float, float]:
    """Tip of a clamped elastica under a uniform load across it.

    Solves ``θ'' = −α (1 − s) cos θ`` on ``s ∈ [0, 1]`` (``α = w L³ / EI``),
    ``θ(0) = 0``, ``θ'(1) = 0``, and integrates ``(cos θ, sin θ)``.

    Returns
    -------
    (float, float)
        Axial position and transverse deflection of the tip, mm.
    """
    from scipy.integrate import cumulative_trapezoid, solve_bvp

    s = np.linspace(0.0, 1.0, 401)

    def rhs(s_: np.ndarray, y: np.ndarray) -> np.ndarray:
        return np.vstack([y[1], -load_parameter * (1.0 - s_) * np.cos(y[0])])

    def bc(ya: np.ndarray, yb: np.ndarray) -> np.ndarray:
        return np.array([ya[0], yb[1]])

    guess = np.vstack([0.1 * load_parameter * s * (1 - s / 2), np.zeros_like(s)])
    solution = solve_bvp(rhs, bc, s, guess, tol=1e-10, max_nodes=100_000)
    if not solution.success:  # pragma: no cover - smooth problem
        raise ConvergenceError(f"elastica reference did not converge: {solution.message}")
    theta = solution.sol(s)[0]
    x = cumulative_trapezoid(np.cos(theta), s, initial=0.0)[-1]
    z = cumulative_trapezoid(np.sin(theta), s, initial=0.0)[-1]
    return float(x * length_mm), float(z * length_mm)


def cantilever_sag(
    *,
    length_mm: float = 100.0,
    side_mm: float = 4.0,
    load_parameter: float = 4.0,
    density_t_per_mm3: float = 1.08e-9,
    gravity_mm_s2: float = 9810.0,
    bulk_ratio: float = 100.0,
    maxh_mm: float = 2.0,
    order: int = 2,
) -> CaseResult:
    """A square cantilever bending under its own weight; compare the tip deflection.

    The shear modulus is chosen so that ``α = w L³ / EI`` equals
    ``load_parameter`` (``w = ρ g A``, ``E = 9Kμ/(3K + μ)`` of the penalised
    solid), so the beam deflects far beyond the linear range.

    Returns
    -------
    CaseResult
        ``fem`` and ``reference``: transverse tip deflection, mm.
    """
    import ngsolve as ngs
    from netgen.occ import Box, OCCGeometry, Pnt, X

    area = side_mm**2
    inertia = side_mm**4 / 12.0
    w = density_t_per_mm3 * gravity_mm_s2 * area
    youngs = w * length_mm**3 / (load_parameter * inertia)
    # E = 9Kμ/(3K + μ) with K = bulk_ratio·μ  →  μ = E (3·ratio + 1) / (9·ratio)
    mu = youngs * (3.0 * bulk_ratio + 1.0) / (9.0 * bulk_ratio)
    shape = Box(Pnt(0, -side_mm / 2, -side_mm / 2), Pnt(length_mm, side_mm / 2, side_mm / 2))
    shape.faces.Min(X).name = "clamp"
    ngs.ngsglobals.msg_level = 0
    mesh = ngs.Mesh(OCCGeometry(shape).GenerateMesh(maxh=maxh_mm))
    fes = ngs.VectorH1(mesh, order=order, dirichlet="clamp")
    u = fes.TrialFunction()
    F = ngs.Id(3) + ngs.Grad(u)
    factor = ngs.Parameter(0.0)
    form = ngs.BilinearForm(fes, symmetric=True)
    form += ngs.Variation(
        solid_energy(F, NeoHookean(c10_mpa=mu / 2.0), bulk_ratio * mu).Compile() * ngs.dx
    )
    form += ngs.Variation(factor * density_t_per_mm3 * gravity_mm_s2 * u[2] * ngs.dx)
    gfu = ngs.GridFunction(fes)
    solver = _ramp_solver(form, gfu, fes)
    weight = w * length_mm
    with ngs.TaskManager():
        _ramp(solver, factor.Set, lambda s: s * weight, 4)
    tip = gfu(mesh(length_mm, 0.0, 0.0))
    _, z_ref = elastica_tip_deflection(load_parameter, length_mm)
    return CaseResult(
        "cantilever under its own weight",
        "tip deflection (mm)",
        float(-tip[2]),
        z_ref,
        int(sum(fes.FreeDofs())),
    )


@dataclass(frozen=True)
class MeshStudyRow:
    """Bending angles of one mesh size."""

    maxh_mm: float
    elements: int
    ndof: int
    angles_deg: tuple[float, ...]
    wall_time_s: float
    stop_reason: str


def mesh_study(
    design: Design,
    maxh_mm: Sequence[float],
    pressures_mpa: Sequence[float],
    options: FEMOptions | None = None,
    *,
    progress: Callable[[int, int], None] | None = None,
) -> list[MeshStudyRow]:
    """Bending angle at ``pressures_mpa`` for each element size in ``maxh_mm``.

    Each size runs the sweep of the design's FEM family
    (:attr:`~softbend.fem.families.FEMFamily.sweep`, the family of
    :func:`~softbend.fem.families.family_of`) over ``pressures_mpa`` with
    ``output="solve"`` (every pressure a Newton solve), so only the mesh
    differs. The relative change between consecutive rows is the convergence
    measure. ``options`` None: the family's defaults.
    """
    from softbend.fem.families import family_of
    from softbend.fem.stats import fem_stats

    family = family_of(design)
    options = options or family.options()

    def run(opts: FEMOptions) -> SweepResult:
        return family.sweep(design, pressures_mpa, opts)[0]

    sizes = [options.replace(maxh_mm=h).maxh_mm for h in maxh_mm]  # FEMOptions' rule
    if not sizes:
        raise InputError("must hold at least one size; got none", key="maxh_mm")
    rows = []
    for i, h in enumerate(sizes):
        result = run(options.replace(maxh_mm=h, output="solve"))
        angles = [float(a) for a in result.angle_deg]
        angles += [math.nan] * (len(pressures_mpa) - len(angles))
        stats = fem_stats(result)
        rows.append(
            MeshStudyRow(
                h,
                int(result.mesh_size or 0),
                int(stats["ndof"]),
                tuple(angles),
                result.wall_time_s,
                stats["stop_reason"],
            )
        )
        if progress is not None:
            progress(i + 1, len(sizes))
    return rows
