"""The PneuNet as an FEM actuator family: its design parameters, reference and checks.

A PneuNet (the fast PneuNet of Mosadegh et al., Adv. Funct. Mater. 24 (2014)
2163, Fig. 1) is a row of
``n_chambers`` inflatable chambers standing on a base, with a strain-limiting
layer (paper or fabric) bonded under the base. Every chamber is a hollow box
(outer dimensions ``chamber_length_mm`` along the actuator, ``chamber_width_mm``
across it, ``chamber_height_mm`` above the base); neighbouring chambers are
``gap_mm`` apart. The walls that face the neighbouring chambers (the expanding
walls) are ``wall_mm`` thick; the side walls and the roof (the outer walls)
``outer_wall_mm``. The base under the chambers is ``base_mm`` thick and the
strain-limiting layer is its bottom face. Lengths in mm.

The strain-limiting layer's material and thickness are modelling options
(:class:`~softbend.fem.options.FEMOptions` ``layer`` and ``layer_thickness_mm``,
defaults :data:`PAPER_LAYER`, 0.1 mm), as for paper B's actuator: a lab changes
them with its fabric, not per design.

Reference design (:data:`REFERENCE`): the five-chamber Elastosil M4601 PneuNet
of the PneuNet demonstration of GIBBON (Moerman, J. Open Source Softw. 3 (2018)
506; an FEBio model after Mosadegh et al. 2014): chamber length 8, width 15,
height 25, expanding wall 1.2, gap 2.5, side wall 2, base 1 mm plus 1 mm of
elastomer around the paper (``base_mm`` = 2). One change: the roof is as thick
as the side walls (2 mm instead of 4 mm: one outer-wall parameter). Its
bending curve is not yet set beside a published one: the fast PneuNet of
Mosadegh et al. 2014 gives its bending angle against pressure as a figure
only, and softbend ships no values read off it.

The design space (:data:`~softbend.actuators.PNEUNET` ranges): 3–8 chambers 5–12 mm long,
10–20 mm wide and 8–25 mm tall, expanding walls 0.8–2.5 mm, outer walls
1.5–3 mm (with 1 mm outer walls the largest corner, eight 25 × 20 × 12 mm
chambers, stopped converging near 6 kPa at 80° after 270 s of step cutting),
gaps 1–5 mm, base 1–4 mm.
"""

from __future__ import annotations

from typing import TYPE_CHECKING, Any

from softbend.actuators import PNEUNET, Design
from softbend.errors import InputError
from softbend.materials.models import NeoHookean, Yeoh
from softbend.materials.presets import G_PER_CM3_TO_T_PER_MM3, Material

if TYPE_CHECKING:
    from softbend.fem.options import FEMOptions

__all__ = [
    "ELASTOSIL_M4601",
    "MESH_STUDY_MAXH_MM",
    "MESH_STUDY_PRESSURES_MPA",
    "PAPER_LAYER",
    "PNEUNET",
    "PNEUNET_MAXH_MM",
    "REFERENCE",
    "cavity_volume_mm3",
    "length_mm",
    "make_pneunet_design",
    "pneunet_options",
]

#: Elastosil M4601 silicone, Yeoh C10 = 0.11, C20 = 0.02 MPa; 1.13 g/cm³.
ELASTOSIL_M4601 = Material(
    name="Elastosil M4601",
    model=Yeoh(c10_mpa=0.11, c20_mpa=0.02, c30_mpa=0.0),
    density_t_per_mm3=1.13 * G_PER_CM3_TO_T_PER_MM3,
    source=(
        "Polygerinos et al., IEEE Trans. Robot. 31 (2015) 778: Yeoh model of "
        "Elastosil M4601 (C10 = 0.11 MPa, C20 = 0.02 MPa); density 1.13 g/cm³ (data sheet)."
    ),
)

#: Paper strain-limiting layer, E = 6.5 GPa, as an incompressible neo-Hookean
#: membrane of the same small-strain Young's modulus (C10 = E/6); 0.8 g/cm³.
PAPER_LAYER = Material(
    name="Paper strain-limiting layer",
    model=NeoHookean(c10_mpa=6500.0 / 6.0),
    density_t_per_mm3=0.8 * G_PER_CM3_TO_T_PER_MM3,
    source=(
        "Paper, E = 6.5 GPa (ν = 0.2 in the source; the membrane is incompressible), "
        "as in GIBBON's PneuNet model (Moerman, J. Open Source Softw. 3 (2018) 506)."
    ),
)

#: The reference PneuNet (see the module docstring), mm.
REFERENCE: dict[str, float] = {
    "n_chambers": 5.0,
    "chamber_length_mm": 8.0,
    "chamber_width_mm": 15.0,
    "chamber_height_mm": 25.0,
    "wall_mm": 1.2,
    "outer_wall_mm": 2.0,
    "gap_mm": 2.5,
    "base_mm": 2.0,
}


def _refuse(name: str, requirement: str, value: float) -> InputError:
    return InputError(f"must be {requirement}; got {value:g}", key=name)


def make_pneunet_design(values: dict[str, float]) -> Design:
    """The checked PneuNet design of ``values`` (every parameter named, in mm).

    Only what makes the geometry impossible is refused: a design outside the
    ranges of :data:`~softbend.actuators.PNEUNET` (the campaign's design space) is still a solid.

    Raises
    ------
    InputError
        Keyed by the parameter at fault: a chamber count that is not a whole
        number >= 1, a length that is not > 0, walls that leave no cavity
        (``2·wall_mm >= chamber_length_mm``, ``2·outer_wall_mm >=
        chamber_width_mm``, ``outer_wall_mm >= chamber_height_mm``).
    """
    n = values["n_chambers"]
    if not (n >= 1 and float(n).is_integer()):
        raise _refuse("n_chambers", "a whole number of chambers >= 1", n)
    for name in (
        "chamber_length_mm",
        "chamber_width_mm",
        "chamber_height_mm",
        "wall_mm",
        "outer_wall_mm",
        "gap_mm",
        "base_mm",
    ):
        if not values[name] > 0.0:
            raise _refuse(name, "> 0 mm", values[name])
    wall, outer = values["wall_mm"], values["outer_wall_mm"]
    if not 2.0 * wall < values["chamber_length_mm"]:
        raise _refuse(
            "wall_mm",
            f"< chamber_length_mm / 2 = {values['chamber_length_mm'] / 2:g} mm "
            "(two walls and a cavity along the chamber)",
            wall,
        )
    if not 2.0 * outer < values["chamber_width_mm"]:
        raise _refuse(
            "outer_wall_mm",
            f"< chamber_width_mm / 2 = {values['chamber_width_mm'] / 2:g} mm "
            "(two side walls and a cavity across the chamber)",
            outer,
        )
    if not outer < values["chamber_height_mm"]:
        raise _refuse(
            "outer_wall_mm",
            f"< chamber_height_mm = {values['chamber_height_mm']:g} mm (a roof and a cavity)",
            outer,
        )
    return Design(PNEUNET, {k: values[k] for k in PNEUNET.names})


def cavity_volume_mm3(design: Design) -> float:
    """Undeformed volume of all the chambers' cavities (whole actuator), mm³."""
    d = design
    inner = (
        (d.chamber_length_mm - 2.0 * d.wall_mm)
        * (d.chamber_width_mm - 2.0 * d.outer_wall_mm)
        * (d.chamber_height_mm - d.outer_wall_mm)
    )
    return int(d.n_chambers) * inner


def length_mm(design: Design, end_mm: float) -> float:
    """Length of the PneuNet from its fixed face to its tip, mm (``end_mm``: the inlet block)."""
    d = design
    n = int(d.n_chambers)
    return end_mm + n * d.chamber_length_mm + (n - 1) * d.gap_mm


def pneunet_options(**overrides: Any) -> FEMOptions:
    """The PneuNet's modelling defaults, with ``overrides``.

    Elastosil M4601 (:data:`ELASTOSIL_M4601`), a 0.1 mm paper layer
    (:data:`PAPER_LAYER`), no gravity (the weight of the reference, about 0.05 N,
    is small against the pressure on one chamber wall, 1.5 N at 10 kPa), a 3 mm
    inlet block at the fixed end (``base_cap_mm``), pressure steps of 0.1–5 kPa
    (first 2 kPa), and frictionless penalty contact between the facing walls of
    neighbouring chambers, a sweep ending at
    :data:`~softbend.fem.options.CONTACT_MAX_ANGLE_DEG` (``contact="off"``: the
    sweep stops where the walls first touch).
    """
    from softbend.fem.options import CONTACT_MAX_ANGLE_DEG, FEMOptions

    values: dict[str, Any] = {
        "maxh_mm": PNEUNET_MAXH_MM,
        "elastomer": ELASTOSIL_M4601,
        "layer": PAPER_LAYER,
        "layer_thickness_mm": 0.1,
        "gravity": "none",
        "initial_step_mpa": 0.002,
        "min_step_mpa": 1e-4,
        "max_step_mpa": 0.005,
        "predictor_error_mm": 0.2,
        "contact": "on",
        "max_angle_deg": CONTACT_MAX_ANGLE_DEG,
    }
    values.update(overrides)
    return FEMOptions(**values)


#: Default largest element size of the PneuNet's mesh, mm.
PNEUNET_MAXH_MM = 3.0

#: ``fem mesh-study``'s default element sizes for the PneuNet, mm, coarse to fine.
MESH_STUDY_MAXH_MM: tuple[float, ...] = (3.0, 2.5, 2.0)
#: ``fem mesh-study``'s default pressures for the PneuNet, MPa: the reference's walls touch
#: at 6-7 kPa and press on each other past it (with ``--contact off`` the angles past the
#: touch are NaN).
MESH_STUDY_PRESSURES_MPA: tuple[float, ...] = (0.0, 0.004, 0.008, 0.012)
