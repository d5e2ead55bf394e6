"""The finite-element model of one actuator: its energy, state and measurements.

:class:`ActuatorModel` meshes the half actuator of a design, assembles the total
potential energy

    Π(u) = ∫ W_solid dV + ∫_bottom W_layer dA + ∫_outer+bottom Σ± W_fiber dA
           − p·V_cavity(u) − ∫ ρ g·u dV (elastomer, layer and fiber masses)

over quadratic displacements with the base face fixed and ``u_y = 0`` on the
symmetry plane, and exposes what the load stepping needs: set the load, solve,
the derivative of the state with respect to pressure, and the measurements
(bending angle by the arc fit of the backbone, tip position, cavity volume).

Measurement frame (that of :func:`softbend.analytical.tip_position_mm`): origin
at the fixed base on the strain-limiting layer, ``x`` along the undeformed axis,
``z`` normal to the layer towards the side the actuator bends to. The backbone
is the strain-limiting layer on the symmetry plane over the chamber length
``l``; the angle is ``arc length / radius`` of the least-squares arc through it
(paper B §3.1).
"""

from __future__ import annotations

import logging
import math
from dataclasses import dataclass
from typing import Any

import numpy as np

from softbend.actuators import Design
from softbend.design import FIBER_DIAMETER_MM
from softbend.fem._ngsolve import require_ngsolve
from softbend.fem.energy import energy_terms
from softbend.fem.geometry import mesh_actuator
from softbend.fem.mechanics import helix_stiffness_n_per_mm
from softbend.fem.newton import EnergySolver
from softbend.fem.options import FEMOptions
from softbend.kinematics import fit_arc

require_ngsolve()  # NGSolve after PyTorch, or one line naming softbend[fem]

__all__ = ["ActuatorModel", "Measurement", "ModelState"]

logger = logging.getLogger(__name__)


@dataclass(frozen=True)
class Measurement:
    """What is read off a deformed state."""

    angle_deg: float
    tip_x_mm: float
    tip_z_mm: float

    def as_array(self) -> np.ndarray:
        return np.array([self.angle_deg, self.tip_x_mm, self.tip_z_mm])


class ModelState:
    """Loads, state and measurements shared by the FEM models of every family.

    A model class that mixes this in sets ``design`` and ``options``, calls
    :meth:`_set_up` (which builds the mesh, space, state, loads, energy, solver,
    tip point, cavity area and stretch check points from its ``_mesh`` and
    ``_assemble_energy``), then sets ``_weight_n`` and the backbone points; it
    defines ``_bind``, ``backbone_mm`` and ``region_of``.
    """

    mesh: Any
    fes: Any
    gfu: Any
    pressure: Any
    gravity_factor: Any
    options: FEMOptions
    solver: EnergySolver
    volume_form: Any
    geometry: Any
    _cavity_area: float
    _weight_n: float
    _tip_point: Any
    _check_points: Any
    _check_xyz: np.ndarray
    _deformation: Any
    terms: Any

    def _mesh(self) -> tuple[Any, Any]:
        """The model's mesh and geometry (``options`` set)."""
        raise NotImplementedError

    def _assemble_energy(self) -> tuple[Any, Any, Any]:
        """The energy form, the volume form and the weight vector."""
        raise NotImplementedError

    def _bind(self) -> None:
        raise NotImplementedError

    def _energy_forms(self, fiber_mass_per_area: float | None) -> tuple[Any, Any, Any]:
        """The energy form, the volume form and the weight vector of paper B's energy.

        The elastomer, strain-limiting layer (``bottom``) and cavity pressure
        terms of :func:`~softbend.fem.energy.energy_terms`, and its fiber term
        on ``outer|bottom`` unless ``fiber_mass_per_area`` is None. Sets and
        binds (:meth:`_bind`) ``terms``.

        Parameters
        ----------
        fiber_mass_per_area : float or None
            Mass of the fibers per area of ``outer|bottom``, t/mm²; None: no fibers.
        """
        import ngsolve as ngs
        from ngsolve import CoefficientFunction as CF  # noqa: N817
        from ngsolve import ds, dx

        o = self.options
        self.terms = terms = energy_terms(self.fes, o)
        self._bind()
        # Only the lower triangle of the Hessian is stored: sparse Cholesky needs
        # no more, and assembly writes half the entries (about a tenth faster).
        form = ngs.BilinearForm(self.fes, symmetric=True, symmetric_storage=True)
        form += ngs.Variation(terms.solid * dx)
        form += ngs.Variation(terms.layer * ds("bottom"))
        if fiber_mass_per_area is not None:
            form += ngs.Variation(terms.fiber * ds("outer|bottom"))
        form += ngs.Variation(terms.pressure_work * ds("cavity"))
        volume = ngs.BilinearForm(self.fes, symmetric=True)
        volume += ngs.Variation(terms.flux * ds("cavity"))

        # Gravity is a dead load (its potential −ρ g·u is linear in u): assembled
        # once as a force vector and scaled by the gravity factor, instead of
        # being differentiated twice at every Newton iteration.
        v = self.fes.TestFunction()
        g = CF(self._gravity_vector())
        layer_mass = o.layer.density_t_per_mm3 * o.layer_thickness_mm
        weight = ngs.LinearForm(self.fes)
        weight += o.elastomer.density_t_per_mm3 * ngs.InnerProduct(g, v) * dx
        weight += layer_mass * ngs.InnerProduct(g, v.Trace()) * ds("bottom")
        if fiber_mass_per_area is not None:
            weight += fiber_mass_per_area * ngs.InnerProduct(g, v.Trace()) * ds("outer|bottom")
        weight.Assemble()
        return form, volume, weight.vec

    def _set_up(self) -> None:
        """Mesh the model and build its space, state, loads, energy, solver and check points.

        The half model is clamped on the face ``base`` (all three components)
        and held at ``u_y = 0`` on ``symmetry``; the pressure and the gravity
        factor start at 0.
        """
        import ngsolve as ngs

        options = self.options
        ngs.ngsglobals.msg_level = 0
        self.mesh, self.geometry = self._mesh()
        self.fes = ngs.VectorH1(
            self.mesh,
            order=options.order,
            dirichletx="base",
            dirichlety="base|symmetry",
            dirichletz="base",
        )
        self.gfu = ngs.GridFunction(self.fes)
        self.pressure = ngs.Parameter(0.0)
        self.gravity_factor = ngs.Parameter(0.0)
        self.form, self.volume_form, self.weight_vector = self._assemble_energy()
        self.solver = EnergySolver(
            self.form,
            self.gfu,
            self.fes.FreeDofs(),
            rtol=options.rtol,
            max_iterations=options.max_iterations,
            load=self.weight_vector,
            load_factor=self.gravity_factor,
            prepare=self._bind,
        )
        self._tip_point = self.mesh(self.geometry.length_mm, 0.0, 0.0)
        self._cavity_area = ngs.Integrate(
            ngs.CoefficientFunction(1.0), self.mesh, definedon=self.mesh.Boundaries("cavity")
        )
        # The centroid of every tetrahedron: where the stretch is checked.
        rule = ngs.IntegrationRule(points=[(0.25, 0.25, 0.25)], weights=[1.0 / 6.0])
        self._check_points = self.mesh.MapToAllElements(rule, ngs.VOL)
        centroids = ngs.CoefficientFunction((ngs.x, ngs.y, ngs.z))(self._check_points)
        self._check_xyz = np.asarray(centroids)
        self._deformation = ngs.Id(3) + ngs.Grad(self.gfu)

    def backbone_mm(self) -> np.ndarray:
        """Deformed backbone in the measurement frame, shape (n, 2): columns x, z."""
        raise NotImplementedError

    def region_of(self, x_mm: float) -> str:
        """Name of the part of the actuator at axial position ``x_mm``."""
        raise NotImplementedError

    def _gravity_vector(self) -> tuple[float, float, float]:
        g = self.options.gravity_mm_s2
        return {
            "bending": (0.0, 0.0, -g),
            "against": (0.0, 0.0, g),
            "axial": (g, 0.0, 0.0),
            "none": (0.0, 0.0, 0.0),
        }[self.options.gravity]

    @property
    def ndof(self) -> int:
        """Free degrees of freedom."""
        return int(sum(self.fes.FreeDofs()))

    @property
    def n_elements(self) -> int:
        """Tetrahedra of the half model."""
        return int(self.mesh.ne)

    def set_load(self, pressure_mpa: float, gravity_factor: float = 1.0) -> None:
        """Set the cavity pressure (MPa) and the fraction of gravity applied."""
        self.pressure.Set(float(pressure_mpa))
        self.gravity_factor.Set(float(gravity_factor))
        self._bind()

    def force_scale_n(self, pressure_mpa: float) -> float:
        """Load size for the Newton tolerance: pressure resultant on the half cavity + weight, N."""
        return abs(pressure_mpa) * self._cavity_area + self._weight_n

    def state(self) -> np.ndarray:
        """A copy of the displacement vector."""
        return np.array(self.gfu.vec.FV().NumPy(), copy=True)

    def set_state(self, values: np.ndarray) -> None:
        """Overwrite the displacement vector."""
        self.gfu.vec.FV().NumPy()[:] = values

    def pressure_tangent(self, *, refactorize: bool = True) -> np.ndarray:
        """``du/dp`` at the current (converged) state, mm/MPa.

        From ``K du/dp = −∂r/∂p`` with ``∂r/∂p = −∂V/∂u`` (the load is ``−p·V``).
        With ``refactorize=False`` the Hessian factorised by the last Newton
        iteration is used (one Newton update away from the converged state,
        where the residual was already small), which saves a factorisation.
        """
        rhs = self.gfu.vec.CreateVector()
        self.volume_form.Apply(self.gfu.vec, rhs)  # ∂(−V)/∂u = ∂r/∂p
        out = self.gfu.vec.CreateVector()
        if refactorize or not self.solver.has_factorization:
            self.solver.factorize()
        self.solver.solve_tangent(rhs, out)
        return -np.array(out.FV().NumPy(), copy=True)

    def cavity_volume_rate(self, tangent: np.ndarray) -> float:
        """``dV/dp`` of the whole cavity along ``tangent = du/dp``, mm³/MPa."""
        gradient = self.gfu.vec.CreateVector()
        self.volume_form.Apply(self.gfu.vec, gradient)  # ∂(−V_half)/∂u
        free = self.solver.free_mask
        return -2.0 * float(np.dot(gradient.FV().NumPy()[free], tangent[free]))

    def cavity_volume_mm3(self) -> float:
        """Deformed volume of the whole cavity (both halves), mm³."""
        return -2.0 * float(self.volume_form.Energy(self.gfu.vec))

    def measure(self) -> Measurement:
        """Bending angle (arc fit of the backbone, degrees) and tip position (mm)."""
        fit = fit_arc(self.backbone_mm())
        tip = self.gfu(self._tip_point)
        return Measurement(
            angle_deg=float(fit.angle_deg),
            tip_x_mm=float(self.geometry.length_mm + tip[0]),
            tip_z_mm=float(-tip[2]),
        )

    def max_stretch(self) -> tuple[float, np.ndarray]:
        """Largest principal stretch in the elastomer and where it is (undeformed x, y, z mm).

        Checked at the centroid of every tetrahedron, so the singular peak at a
        sharp inner corner (where the chamber meets a cap) is not what counts:
        the value follows the deformation of whole elements.
        """
        F = np.asarray(self._deformation(self._check_points)).reshape(-1, 3, 3)
        C = np.einsum("nki,nkj->nij", F, F)
        largest = np.linalg.eigvalsh(C)[:, -1]
        k = int(np.argmax(largest))
        return float(math.sqrt(largest[k])), self._check_xyz[k].copy()

    def stretch_site(self) -> tuple[float, str]:
        """Largest principal stretch and where it is, e.g. ``"distal cap at x = 104 mm"``."""
        stretch, where = self.max_stretch()
        return stretch, f"{self.region_of(float(where[0]))} at x = {where[0]:.0f} mm"

    def measure_derivative(self, tangent: np.ndarray, step_mpa: float = 1e-5) -> np.ndarray:
        """``d(angle, tip x, tip z)/dp`` along ``tangent = du/dp`` by central differences."""
        base = self.state()
        self.set_state(base + step_mpa * tangent)
        plus = self.measure().as_array()
        self.set_state(base - step_mpa * tangent)
        minus = self.measure().as_array()
        self.set_state(base)
        return (plus - minus) / (2.0 * step_mpa)


class ActuatorModel(ModelState):
    """Mesh, energy and state of the FEM model of ``design``.

    Parameters
    ----------
    design : Design
    options : FEMOptions, optional
    """

    def __init__(self, design: Design, options: FEMOptions | None = None) -> None:
        self.design = design
        self.options = options = options or FEMOptions()
        self._set_up()
        start, end = self.geometry.chamber_mm
        self._backbone_x = np.linspace(start, end, options.backbone_points)
        self._backbone_points = [self.mesh(float(x), 0.0, 0.0) for x in self._backbone_x]
        self._weight_n = self._total_weight_n()

    def _mesh(self) -> tuple[Any, Any]:
        o = self.options
        return mesh_actuator(
            self.design, maxh_mm=o.maxh_mm, order=o.order, base_cap_mm=o.base_cap_mm
        )

    # -- energy --------------------------------------------------------------------------
    def fiber_spacing_mm(self) -> float:
        """Distance between neighbouring fibers of one family, normal to them, mm."""
        phi = math.radians(self.design.phi_deg)
        if self.options.fiber_pitch_mm is not None:
            spacing = self.options.fiber_pitch_mm * math.cos(phi)
        else:
            spacing = self.geometry.perimeter_mm * math.sin(phi)
        return max(spacing, FIBER_DIAMETER_MM)

    def fiber_stiffness_n_per_mm(self) -> float:
        """Smeared stiffness ``E A / s`` of one fiber family, N/mm."""
        return helix_stiffness_n_per_mm(
            self.options.fiber_model.e_mpa, self.options.fiber_radius_mm, self.fiber_spacing_mm()
        )

    def _layer_and_fiber_mass_per_area(self) -> tuple[float, float]:
        o = self.options
        layer = o.layer.density_t_per_mm3 * o.layer_thickness_mm
        fibers = 2.0 * o.fiber.density_t_per_mm3 * math.pi * (FIBER_DIAMETER_MM / 2) ** 2
        return layer, fibers / self.fiber_spacing_mm()

    def _total_weight_n(self) -> float:
        import ngsolve as ngs

        o, geo = self.options, self.geometry
        layer, fibers = self._layer_and_fiber_mass_per_area()
        one = ngs.CoefficientFunction(1.0)
        outer_area = ngs.Integrate(one, self.mesh, definedon=self.mesh.Boundaries("outer|bottom"))
        bottom_area = ngs.Integrate(one, self.mesh, definedon=self.mesh.Boundaries("bottom"))
        mass = o.elastomer.density_t_per_mm3 * geo.half_volume_mm3
        mass += layer * bottom_area + fibers * outer_area
        return mass * o.gravity_mm_s2

    def _assemble_energy(self) -> tuple[Any, Any, Any]:
        """The hyperelastic, fiber and pressure energy, the volume form and the weight vector."""
        self._fiber_stiffness = self.fiber_stiffness_n_per_mm()
        return self._energy_forms(fiber_mass_per_area=self._layer_and_fiber_mass_per_area()[1])

    def _bind(self) -> None:
        """This model's pressure and fiber values into the (possibly shared) energy terms."""
        self.terms.bind(self.pressure.Get(), self.design.phi_deg, self._fiber_stiffness)

    # -- loads and state -----------------------------------------------------------------
    # -- measurements --------------------------------------------------------------------
    def backbone_mm(self) -> np.ndarray:
        """Deformed backbone in the measurement frame, shape (n, 2): columns x, z."""
        values = np.array([self.gfu(p) for p in self._backbone_points])
        x = self._backbone_x + values[:, 0]
        z = -values[:, 2]
        return np.column_stack([x, z])

    def region_of(self, x_mm: float) -> str:
        """Name of the part of the actuator at axial position ``x_mm``."""
        start, end = self.geometry.chamber_mm
        if x_mm < start:
            return "proximal cap"
        if x_mm > end:
            return "distal cap"
        return "chamber wall"
