"""Every modelling and solver assumption of the FEM model, as one validated object."""

from __future__ import annotations

from collections.abc import Iterable
from dataclasses import asdict, dataclass, field, fields
from typing import Any, cast

from softbend._validation import check_choice, check_int, check_range, must_be
from softbend.actuators import Design
from softbend.errors import InputError
from softbend.fem.geometry import check_mesh_size
from softbend.fem.mechanics import FIBER_LAWS
from softbend.materials.models import HyperelasticModel
from softbend.materials.presets import (
    DRAGON_SKIN_30,
    FIBERGLASS_LAYER,
    KEVLAR_FIBER,
    KEVLAR_MODELLED_RADIUS_MM,
    LinearElastic,
    Material,
)

__all__ = [
    "CONTACT_FIELDS",
    "CONTACT_MAX_ANGLE_DEG",
    "CONTACT_MODES",
    "GRAVITY_DIRECTIONS",
    "OUTPUT_MODES",
    "FEMOptions",
]

#: Where gravity points, relative to the actuator (see :class:`FEMOptions`).
GRAVITY_DIRECTIONS: tuple[str, ...] = ("bending", "against", "axial", "none")

#: How outputs on the requested pressure grid are obtained.
OUTPUT_MODES: tuple[str, ...] = ("interpolate", "solve")

#: Whether faces of the model that may touch carry contact (see :class:`FEMOptions`).
CONTACT_MODES: tuple[str, ...] = ("off", "on")

#: Where a sweep with contact stops bending, degrees: the working range of an actuator whose
#: walls press on each other (a PneuNet's 90-270 degrees), short of the folded states past it.
CONTACT_MAX_ANGLE_DEG = 180.0

#: The contact options: left out of :meth:`FEMOptions.to_dict` (and so of the
#: digest) while ``contact`` is "off", so options without contact describe and
#: digest as they did before contact was modelled.
CONTACT_FIELDS: tuple[str, ...] = ("contact", "contact_penalty_mpa_per_mm", "contact_tolerance_mm")


@dataclass(frozen=True)
class FEMOptions:
    """Modelling assumptions and solver settings of :func:`softbend.fem.simulate`.

    Geometry (mm). The actuator lies along ``+x`` from its fixed base face at
    ``x = 0``; the strain-limiting layer is the flat bottom face ``z = 0`` and
    the semicircular chamber is above it. Only the half ``y ≥ 0`` is modelled
    (the bending plane ``y = 0`` is a plane of symmetry of geometry and loads).

    Parameters
    ----------
    maxh_mm : float
        Largest element size, mm, in (0, 20]. The default 5 mm gives quadratic
        tetrahedra with about one element across a 2 mm wall; the thin walls,
        not maxh, set the mesh of the small designs. On the largest corner
        (160, 10, 4, 2, 5, 12) it has 35 % fewer unknowns than 4 mm and bends
        within 0.1 % of it; 3 mm changes its angle by at most 1.5 % (see
        ``softbend fem mesh-study`` for the convergence of the angle).
    order : int
        Polynomial order of the displacement, 2 or 3 (1 locks: the gravity sag of
        linear tetrahedra is half the converged one).
    base_cap_mm : float
        Thickness of the proximal (fixed) end wall, mm, in (0, 50]. Paper B does
        not give it; 3 mm is assumed. The distal cap is the design's ``lc``.
    bulk_ratio : float
        Penalty bulk modulus over the initial shear modulus, ``K/μ0``, in
        [10, 1e5]; 100 (Poisson's ratio 0.495) is nearly incompressible
        without ill-conditioning.
    elastomer, layer : Material
        Hyperelastic materials of the body (Dragon Skin 30, paper B) and of the
        strain-limiting layer (fiberglass, Yeoh C10 = 7.9 MPa).
    layer_thickness_mm : float
        Thickness of the strain-limiting layer, mm (paper B: 0.1). It is a
        membrane bonded to the bottom face, not a meshed solid.
    fiber : Material
        Fiber material, linear elastic (Kevlar, E = 31076 MPa).
    fiber_radius_mm : float
        Radius that sets the fiber stiffness, mm; paper B halves the real radius
        (0.07 mm for 0.28 mm fibers) after Polygerinos et al.
    fiber_pitch_mm : float or None
        Axial distance between neighbouring turns of one helix family, mm. None:
        one fiber per family wound once around the section per
        ``perimeter·tan φ`` of length (paper B gives no pitch). The fibers are
        smeared over the outer faces (curved top, sides, bottom) as two families
        at ``±φ`` from the circumferential direction.
    fiber_law : {"tension-compression", "tension-only"}
        Whether the fibers also carry compression. Paper B ties beam elements to
        the elastomer, which do; default "tension-compression".
    gravity : {"bending", "against", "axial", "none"}
        Direction of gravity: "bending" — across the actuator towards the
        strain-limiting layer, the side it bends to (lying horizontally, layer
        down, as in paper B's experiments); "against" — the opposite; "axial" —
        along the actuator from base to tip (hanging); "none".
    gravity_mm_s2 : float
        Gravitational acceleration, mm/s² (9810).
    max_angle_deg : float
        The sweep stops once the bending angle exceeds this, degrees, in
        (0, 340]; default 300°, where the tip approaches the base.
    max_stretch : float
        The sweep stops once the largest principal stretch anywhere in the
        elastomer exceeds this, in (1, 50]. Default 5: up to there the Yeoh
        constants of paper B follow the shipped Dragon Skin 30 tensile test
        (within 13 % of the stress at a stretch of 5); beyond it they
        overpredict it by 22 % at 5.5 and 33 % at 6, so the model no longer
        describes the material. In practice it is reached by an unreinforced
        end cap ballooning at high pressure.
    initial_step_mpa, min_step_mpa, max_step_mpa : float
        Adaptive pressure stepping: first step, smallest step before the sweep
        is declared stopped (no convergence), largest step, MPa.
    predictor_error_mm : float
        Step size control, mm, in (0, 10]: each pressure step is sized so that
        the extrapolated starting guess misses the converged displacement by
        about this much (largest nodal difference). 0.3 mm lets Newton converge
        in about five iterations. On six slow corner designs it needed 676
        Newton iterations and 14 rejected steps, against 723 and 27 when the
        step grew after every step of five iterations or fewer
        (``python benchmarks/bench_fem_solver.py steps``).
    rtol : float
        Newton tolerance on the residual force relative to the load (pressure
        resultant on the cavity walls plus weight), in (0, 1e-3]. Tight on
        purpose: the global bending mode of a long actuator under its weight
        is ~1e8 times softer than the fibers, so a residual that looks small
        can still leave that mode out of equilibrium, and the extrapolated
        starting guesses of later steps inherit the error. With 1e-7 the
        (160, 6, 2, 2, 5, 8) sweep crawled in 0.0005 MPa steps and took 112 s;
        with 1e-9 it took 44 s (29 s once gravity was also followed in
        fractions).
    max_iterations : int
        Newton iterations per step before the step is cut, >= 3.
    output : {"interpolate", "solve"}
        "interpolate": outputs on the requested pressure grid come from cubic
        Hermite interpolation between converged steps, with the slopes
        ``dθ/dp`` from the tangent stiffness (exact at the steps); "solve": every
        requested pressure is a converged Newton solve.
    backbone_points : int
        Points along the strain-limiting layer used for the arc fit, >= 5.
    threads : int
        Threads of NGSolve's task manager, >= 1 (1: one core per sweep, the
        campaign runs sweeps in parallel instead).
    contact : {"off", "on"}
        Whether the faces of the model that may touch carry frictionless
        penalty contact (:mod:`softbend.fem.contact`): for a PneuNet, the
        facing walls of neighbouring chambers. "off" (the default here; the
        PneuNet family's defaults turn it on): a PneuNet's sweep stops where
        they first touch. Paper B's actuator has no such faces.
    contact_penalty_mpa_per_mm : float
        Penalty stiffness of the contact: contact pressure per mm of
        interpenetration, MPa/mm, in (0, 1e5]. Default 50: about 70 times the
        stiffness ``E/t`` of a 1.2 mm Elastosil wall (E ≈ 0.8 MPa), so the
        walls yield a little while the pairs barely overlap (0.001 mm at a
        contact pressure of 50 kPa).
    contact_tolerance_mm : float
        Largest interpenetration of the contact faces the sweep accepts, mm,
        in (0, 10]: a step whose faces overlap by more stops the sweep (the
        penalty is too soft for that load). Default 0.05 mm.
    """

    maxh_mm: float = 5.0
    order: int = 2
    base_cap_mm: float = 3.0
    bulk_ratio: float = 100.0
    elastomer: Material = DRAGON_SKIN_30
    layer: Material = FIBERGLASS_LAYER
    layer_thickness_mm: float = 0.1
    fiber: Material = KEVLAR_FIBER
    fiber_radius_mm: float = KEVLAR_MODELLED_RADIUS_MM
    fiber_pitch_mm: float | None = None
    fiber_law: str = "tension-compression"
    gravity: str = "bending"
    gravity_mm_s2: float = 9810.0
    max_angle_deg: float = 300.0
    max_stretch: float = 5.0
    initial_step_mpa: float = 0.01
    min_step_mpa: float = 2e-4
    max_step_mpa: float = 0.025
    predictor_error_mm: float = 0.3
    rtol: float = 1e-9
    max_iterations: int = 12
    output: str = "interpolate"
    backbone_points: int = 41
    threads: int = 1
    contact: str = "off"
    contact_penalty_mpa_per_mm: float = 50.0
    contact_tolerance_mm: float = 0.05
    extra: dict[str, Any] = field(default_factory=dict, repr=False, compare=False)

    def __post_init__(self) -> None:
        def number(name: str, low: float, high: float, low_inclusive: bool = False) -> None:
            value = check_range(
                getattr(self, name),
                name,
                low=low,
                high=high,
                low_inclusive=low_inclusive,
                high_inclusive=True,
            )
            object.__setattr__(self, name, value)

        number("maxh_mm", 0.0, 20.0)
        check_choice(check_int(self.order, "order", low=1), "order", (2, 3))
        number("base_cap_mm", 0.0, 50.0)
        number("bulk_ratio", 10.0, 1e5, low_inclusive=True)
        for name in ("elastomer", "layer"):
            material = getattr(self, name)
            if not isinstance(material, Material) or not isinstance(
                material.model, HyperelasticModel
            ):
                raise InputError(
                    must_be("a Material with a hyperelastic model", material), key=name
                )
        if not isinstance(self.fiber, Material) or not isinstance(self.fiber.model, LinearElastic):
            raise InputError(
                must_be("a Material with a LinearElastic model", self.fiber), key="fiber"
            )
        number("layer_thickness_mm", 0.0, 10.0)
        number("fiber_radius_mm", 0.0, 5.0)
        if self.fiber_pitch_mm is not None:
            number("fiber_pitch_mm", 0.0, 1000.0)
        check_choice(self.fiber_law, "fiber_law", FIBER_LAWS)
        check_choice(self.gravity, "gravity", GRAVITY_DIRECTIONS)
        number("gravity_mm_s2", 0.0, 1e6, low_inclusive=True)
        number("max_angle_deg", 0.0, 340.0)
        number("max_stretch", 1.0, 50.0)
        number("max_step_mpa", 0.0, 10.0)
        number("initial_step_mpa", 0.0, self.max_step_mpa)
        number("min_step_mpa", 0.0, self.initial_step_mpa)
        number("predictor_error_mm", 0.0, 10.0)
        number("rtol", 0.0, 1e-3)
        check_int(self.max_iterations, "max_iterations", low=3)
        check_choice(self.output, "output", OUTPUT_MODES)
        check_int(self.backbone_points, "backbone_points", low=5)
        check_int(self.threads, "threads", low=1)
        check_choice(self.contact, "contact", CONTACT_MODES)
        number("contact_penalty_mpa_per_mm", 0.0, 1e5)
        number("contact_tolerance_mm", 0.0, 10.0)

    @property
    def elastomer_model(self) -> HyperelasticModel:
        """The elastomer's constitutive model (checked hyperelastic on construction)."""
        return cast(HyperelasticModel, self.elastomer.model)

    @property
    def layer_model(self) -> HyperelasticModel:
        """The strain-limiting layer's constitutive model (checked hyperelastic)."""
        return cast(HyperelasticModel, self.layer.model)

    @property
    def fiber_model(self) -> LinearElastic:
        """The fibers' constitutive model (checked linear elastic on construction)."""
        return cast(LinearElastic, self.fiber.model)

    def check_mesh(self, designs: Design | Iterable[Design]) -> None:
        """Refuse these options' ``maxh_mm`` if it meshes any of ``designs`` too finely.

        :func:`~softbend.fem.geometry.check_mesh_size` with :attr:`maxh_mm` and
        :attr:`base_cap_mm`: the rule the FEM applies before meshing, checked before any
        sweep starts.

        Raises
        ------
        ValueError
            The estimated mesh of a design exceeds :data:`~softbend.fem.geometry.MAX_ELEMENTS`
            tetrahedra (the message names the design with the most).
        """
        check_mesh_size(designs, self.maxh_mm, base_cap_mm=self.base_cap_mm)

    def replace(self, **changes: object) -> FEMOptions:
        """A copy with ``changes`` applied (validated again)."""
        values = {f.name: getattr(self, f.name) for f in fields(self)}
        unknown = sorted(set(changes) - set(values))
        if unknown:
            raise ValueError(
                f"The options of FEMOptions must be among {', '.join(sorted(values))}. "
                f"Got unknown {unknown!r}."
            )
        values.update(changes)
        return FEMOptions(**values)

    def digest(self) -> str:
        """SHA-256 of :meth:`to_dict` as canonical JSON: equal options, equal digest.

        Stored with every sweep, so data produced with other modelling or solver
        settings can be told apart.
        """
        import hashlib
        import json

        text = json.dumps(self.to_dict(), sort_keys=True, separators=(",", ":"), default=str)
        return hashlib.sha256(text.encode()).hexdigest()

    def to_dict(self) -> dict[str, Any]:
        """JSON-friendly description (materials as their own dicts).

        The contact options are left out while ``contact`` is "off"
        (:data:`CONTACT_FIELDS`).
        """
        out = asdict(self)
        for name in ("elastomer", "layer", "fiber"):
            out[name] = getattr(self, name).to_dict()
        out.pop("extra")
        if self.contact == "off":
            for name in CONTACT_FIELDS:
                out.pop(name)
        return out
