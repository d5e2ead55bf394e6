"""The finite-element model of one PneuNet: its energy, state, measurements and touching walls.

:class:`PneuNetModel` meshes the half PneuNet of a design and assembles

    Π(u) = ∫ W_solid dV + ∫_bottom W_layer dA − p·V_cavities(u) − ∫ ρ g·u dV

over quadratic displacements, the fixed face ``x = 0`` clamped and ``u_y = 0``
on the symmetry plane: the elastomer and strain-limiting membrane terms of
paper B's model (:mod:`softbend.fem.energy`), no fibers. It has the interface
the load stepping of :mod:`softbend.fem.sweep` uses (that of
:class:`~softbend.fem.actuator.ActuatorModel`) and the same measurement frame:
``x`` along the undeformed axis from the fixed face, ``z`` normal to the
strain-limiting layer towards the side the actuator bends to; the bending
angle is ``arc length / radius`` of the least-squares arc
(:func:`softbend.kinematics.fit_arc`) through the strain-limiting layer on the
symmetry plane over the chambered part.

Walls that touch
----------------
As a PneuNet bends, the expanding walls of neighbouring chambers bulge into the
gap between them and meet. The gap is measured after every converged step
between pairs of points at the same ``(y, z)`` on the two facing wall faces
across each gap (:meth:`~softbend.fem.pneunet.geometry.PneuNetGeometry.facing_walls`):
the deformed distance between them, signed by the deformed axial direction of
the base between the chambers (negative once the walls overlap).

With the option ``contact="on"`` the facing faces (``facing_back`` against
``facing_front``) carry frictionless penalty contact
(:class:`~softbend.fem.contact.PenaltyContact`, stiffness
``contact_penalty_mpa_per_mm``), re-paired before every load step
(:meth:`PneuNetModel.before_step`), and the sweep goes on through the touch:
a step within which the walls start to press on each other is cut
(:meth:`PneuNetModel.reject_step`) so that contact starts within a short
step, the contact force and the interpenetration are recorded at every
converged step, and a step whose walls overlap by more than
``contact_tolerance_mm`` stops the sweep (the penalty is too soft for that
load). Until the walls touch the contact energy is zero and
the curve is the contact-free one. (The sampled gap above pairs material
points, which slide along each other once the walls press together: it finds
when they first touch, the contact's own pairs measure the overlap.)

With ``contact="off"`` the sweep stops at first touch, with the pressure
recorded and the reason "neighbouring chamber walls touch at X kPa"
(:meth:`PneuNetModel.stop_after_step`): the touch pressure is where the
smallest gap reaches zero, interpolated linearly between the two steps
around it; outputs are reported up to it.
"""

from __future__ import annotations

import logging
import math
from typing import Any

import numpy as np

from softbend.actuators import Design
from softbend.fem._ngsolve import require_ngsolve
from softbend.fem.actuator import ModelState
from softbend.fem.contact import PenaltyContact
from softbend.fem.options import FEMOptions
from softbend.fem.pneunet.geometry import FACING_FACES, mesh_pneunet

require_ngsolve()  # NGSolve after PyTorch, or one line naming softbend[fem]

__all__ = ["PneuNetModel"]

logger = logging.getLogger(__name__)

#: Facing walls are paired for contact where they are closer than this fraction
#: of the design's gap (at the predicted state of each step): the pairs couple
#: the walls' unknowns in the Hessian, so pairing walls that cannot touch within
#: the step only adds fill-in to the factorisation.
CONTACT_SEARCH_FRACTION = 0.25


class PneuNetModel(ModelState):
    """Mesh, energy and state of the FEM model of a PneuNet design.

    Parameters
    ----------
    design : Design
        A design of the ``"pneunet"`` family.
    options : FEMOptions
        ``base_cap_mm`` is the length of the inlet block at the fixed end;
        the fiber options are not used.
    """

    #: What :func:`softbend.fem.sweep.run_sweep` records as the model in the stats.
    description = "3D FEM, NGSolve, half PneuNet, quadratic tetrahedra"

    def __init__(self, design: Design, options: FEMOptions) -> None:
        import ngsolve as ngs

        self.design = design
        self.options = options
        self._set_up()
        start, end = self.geometry.chambers_mm
        self._backbone_x = np.linspace(start, end, options.backbone_points)
        self._backbone_points = self.mesh(
            self._backbone_x, np.zeros_like(self._backbone_x), np.zeros_like(self._backbone_x)
        )
        self._bottom_area = ngs.Integrate(
            ngs.CoefficientFunction(1.0), self.mesh, definedon=self.mesh.Boundaries("bottom")
        )
        self._weight_n = self._total_weight_n()
        self._walls = [
            (a, b, self._points(a), self._points(b)) for a, b in self.geometry.facing_walls()
        ]
        self._gaps: list[tuple[float, float]] = []  # (pressure MPa, smallest gap mm)
        self.contact: PenaltyContact | None = None
        if options.contact == "on" and self.geometry.n > 1:
            self.contact = PenaltyContact(
                self.fes,
                FACING_FACES[0],
                FACING_FACES[1],
                penalty_mpa_per_mm=options.contact_penalty_mpa_per_mm,
                maxdist_mm=CONTACT_SEARCH_FRACTION * self.design.gap_mm,
            )
            self._give_up_rules = {
                name: getattr(self.solver, name)
                for name in ("first_contraction", "stall_iteration", "progress_iteration")
            }
            self.before_step()
        #: Per converged step: contact force on the walls of the whole actuator (N) and
        #: the mean interpenetration of the touching walls
        #: (:meth:`~softbend.fem.contact.PenaltyContact.mean_depth_mm`, mm); empty
        #: without contact.
        self.contact_force_n: list[float] = []
        self.interpenetration_mm: list[float] = []

    def _mesh(self) -> tuple[Any, Any]:
        o = self.options
        return mesh_pneunet(self.design, maxh_mm=o.maxh_mm, order=o.order, end_mm=o.base_cap_mm)

    def _points(self, xyz: np.ndarray) -> Any:
        return self.mesh(xyz[:, 0], xyz[:, 1], xyz[:, 2])

    # -- energy --------------------------------------------------------------------------
    def _total_weight_n(self) -> float:
        o = self.options
        mass = o.elastomer.density_t_per_mm3 * self.geometry.half_volume_mm3
        mass += o.layer.density_t_per_mm3 * o.layer_thickness_mm * self._bottom_area
        return mass * o.gravity_mm_s2

    def _assemble_energy(self) -> tuple[Any, Any, Any]:
        """The hyperelastic and pressure energy, the volume form and the weight vector."""
        return self._energy_forms(fiber_mass_per_area=None)

    def _bind(self) -> None:
        """This model's pressure into the (possibly shared) energy terms; no fibers."""
        self.terms.bind(self.pressure.Get(), 0.0, 0.0)

    # -- loads and state -----------------------------------------------------------------
    # -- measurements --------------------------------------------------------------------
    def backbone_mm(self) -> np.ndarray:
        """Deformed strain-limiting layer on the symmetry plane, shape (n, 2): columns x, z."""
        values = np.asarray(self.gfu(self._backbone_points))
        return np.column_stack([self._backbone_x + values[:, 0], -values[:, 2]])

    def region_of(self, x_mm: float) -> str:
        """Name of the part of the PneuNet at axial position ``x_mm``."""
        if x_mm < self.geometry.end_mm:
            return "inlet block"
        for i in range(self.geometry.n):
            x0, x1 = self.geometry.chamber_x_mm(i)
            if x0 <= x_mm <= x1:
                return f"chamber {i + 1}"
        return "base between chambers"

    # -- walls that touch ----------------------------------------------------------------
    def wall_gap_mm(self) -> float:
        """Smallest deformed gap between the facing walls of neighbouring chambers, mm.

        Negative once they overlap; ``inf`` for a single chamber (see the module docstring).
        """
        smallest = math.inf
        for back_xyz, front_xyz, back, front in self._walls:
            a = back_xyz + np.asarray(self.gfu(back))
            b = front_xyz + np.asarray(self.gfu(front))
            # The deformed axial direction at the base between the two chambers.
            axis = b[0] - a[0]
            axis = axis / np.linalg.norm(axis)
            d = b - a
            signed = np.sign(d @ axis) * np.linalg.norm(d, axis=1)
            smallest = min(smallest, float(signed.min()))
        return smallest

    def before_step(self) -> None:
        """Before a load step's solve (from its predicted state): pair the facing walls anew.

        Without contact, nothing. The new pairs change the Hessian's sparsity,
        so the solver's factorisation is dropped.
        """
        if self.contact is None:
            return
        self.contact.update(self.gfu, self.form)
        self.solver.forget_factorization()
        # Newton's early give-up rules judge a solve by its first iterations;
        # where contact pairs switch on and off those zigzag before converging
        # (the reference just past the touch: residuals 0.04, 3.1, 0.78, 0.20,
        # 196, … 6e-9 N in 14 iterations), so once the walls are within reach
        # of each other only the iteration limit stays. Before, the rules save
        # the long crawl of a step too long (12 iterations for the reference's
        # first step of 2 kPa against 1).
        near = bool(self._gaps) and self._gaps[-1][1] < self.contact.maxdist_mm
        for name, value in self._give_up_rules.items():
            setattr(
                self.solver,
                name,
                (math.inf if name == "first_contraction" else 10**6) if near else value,
            )

    def linear_predictor(self) -> bool:
        """Whether the next load step starts from the linear predictor, not the cubic.

        True while the walls press on each other (after a converged step with a
        positive contact force). Each step's pairs and normal are found anew, so
        the path through the converged states is only as smooth as the pairing:
        their small kinks, extrapolated by the cubic through the last two
        states, started the reference's steps 4–18 N off equilibrium even 0.1
        kPa apart, and its sweep stalled at 41 kPa; from the linear predictor
        it reaches 50 kPa in 36 steps (the design log's contact section).
        """
        return bool(self.contact_force_n) and self.contact_force_n[-1] > 0.0

    def reject_step(self) -> bool:
        """After a converged step with contact: whether the walls started touching within it.

        True when the walls press on each other now (the contact energy is
        positive) and did not at the last converged step: the sweep then cuts
        the step, so that contact starts within a short step. Always False
        without contact.
        """
        if self.contact is None:
            return False
        touching_before = bool(self.contact_force_n) and self.contact_force_n[-1] > 0.0
        return not touching_before and self.contact.energy_mj(self.gfu) > 0.0

    def stop_after_step(self, pressure_mpa: float) -> tuple[str, float] | None:
        """After a converged step: the reason to stop and the last valid pressure, or None.

        Without contact, stops when neighbouring chamber walls touch; the touch
        pressure is interpolated between the last two steps' gaps (MPa). With
        contact, records the contact force and interpenetration and stops when
        the walls overlap by more than ``contact_tolerance_mm``.
        """
        gap = self.wall_gap_mm()
        previous = self._gaps[-1] if self._gaps else None
        self._gaps.append((pressure_mpa, gap))
        if self.contact is not None:
            force = self.contact.force_n(self.gfu)
            depth = self.contact.mean_depth_mm(self.gfu, force)
            self.contact_force_n.append(2.0 * float(np.linalg.norm(force)))  # both halves
            self.interpenetration_mm.append(depth)
            limit = self.options.contact_tolerance_mm
            if depth > limit:
                return (
                    f"chamber walls overlap by {depth:.3g} mm at {pressure_mpa * 1000:.2f} kPa, "
                    f"beyond contact_tolerance_mm = {limit:g} (raise "
                    "contact_penalty_mpa_per_mm)",
                    self._gaps[-2][0] if len(self._gaps) > 1 else pressure_mpa,
                )
            return None
        if gap > 0.0:
            return None
        touch = pressure_mpa
        if previous is not None and previous[1] > 0.0:
            p0, g0 = previous
            touch = p0 + (pressure_mpa - p0) * g0 / (g0 - gap)
        return f"neighbouring chamber walls touch at {touch * 1000:.2f} kPa", touch
