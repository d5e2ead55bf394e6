"""FEM actuator families: the actuators the finite-element model can simulate.

A family is everything the FEM needs to know about one kind of actuator beyond
its elastomer: its named design parameters (an
:class:`~softbend.actuators.Actuator`, the same description the learning
pipeline uses), a reference design, the pressures a sweep covers by default, how
a design is checked, and the sweep itself (geometry, material regions, cavity
surfaces loaded by a follower pressure, fixture and bending-angle readout live
behind :attr:`FEMFamily.sweep`). Paper B's fiber-reinforced actuator is the
first family (``"sfrba"``, :mod:`softbend.fem.sfrba`), the PneuNet the second
(``"pneunet"``, :mod:`softbend.fem.pneunet`); every command and the campaign
use both the same way, reading what differs (positional ``--design`` text, an
analytical model to compare with, outlines of the deformed shapes, mesh-study
defaults) from the family.

Adding a family is one module that builds a :class:`FEMFamily` and calls
``FEM_FAMILIES.register(name, family)``; importing this module never imports
NGSolve (a family's sweep imports it when it runs).
"""

from __future__ import annotations

import math
from collections.abc import Callable, Mapping, Sequence
from dataclasses import dataclass
from typing import TYPE_CHECKING, Any

from softbend._validation import must_be
from softbend.actuators import SFRBA, Design
from softbend.errors import InputError
from softbend.registry import Registry

if TYPE_CHECKING:
    import numpy as np
    from numpy.typing import ArrayLike

    from softbend.actuators import Actuator
    from softbend.fem.options import FEMOptions
    from softbend.models import SweepResult

__all__ = [
    "FEM_FAMILIES",
    "FIRST_FAMILY",
    "FEMFamily",
    "family_name_of",
    "family_of",
    "get_family",
    "parse_assignments",
]


@dataclass(frozen=True)
class FEMFamily:
    """One kind of actuator the FEM simulates.

    Parameters
    ----------
    name : str
        Registry name, as typed after ``--family``.
    title : str
        One line saying what the actuator is.
    actuator : Actuator
        Its design parameters (names, units, ranges, constraints): the design
        columns of its campaigns and the inputs of its surrogates.
    reference : mapping of str to float
        The reference design: what ``fem run --family NAME`` sweeps without
        ``--design``, and the values a partial ``--design`` leaves unnamed.
    pmax_mpa, pstep_mpa : float
        Default largest pressure of a sweep and the step of its output grid, MPa.
    maxh_mm : float
        Default largest element size, mm.
    make_design : callable
        ``make_design(values: dict[str, float]) -> Design``: the checked design,
        or one :class:`~softbend.errors.InputError` keyed by the parameter at
        fault (walls thicker than the chamber, zero chambers, a gap of zero).
    sweep : callable
        ``sweep(design, pressures_mpa, options, *, progress=None,
        keep_states=False) -> (SweepResult, model, history)``, as
        :func:`softbend.fem.sweep.run_sweep`.
    default_options : callable, optional
        ``default_options(**overrides) -> FEMOptions``: the family's modelling
        defaults (strain-limiting layer, gravity, ...); plain :class:`FEMOptions`
        when absent.
    mesh_check : callable, optional
        ``mesh_check(designs, options)``: refuse, before NGSolve loads, a
        ``maxh_mm`` that would mesh one of the sequence ``designs`` with too many
        elements (one :class:`~softbend.errors.InputError` keyed ``maxh_mm``);
        no check when absent.
    parse_text : callable, optional
        ``parse_text(text) -> design``: the family's own ``--design`` text when
        it is not ``NAME=VALUE`` pairs (paper B's positional ``100,6,2,2,5,10``);
        absent: :func:`parse_assignments`.
    analytical : callable, optional
        ``analytical(design, pressures_mpa) -> SweepResult``: a closed-form model
        an FEM sweep is compared with (drawn beside it); absent: none.
    outline : callable, optional
        ``outline(model) -> ndarray (m, 2)``: the side outline, mm, of the
        model's current state in the bending plane (``fem run`` draws the
        deformed shapes with it); absent: no shapes are drawn.
    campaign_pmax_mpa : float, optional
        Largest pressure of a campaign's default grid, MPa (step ``pstep_mpa``);
        None: ``pmax_mpa``.
    recorded : bool, default True
        A campaign database of its designs records the family's name and
        description (its ``meta`` table). False for paper B's: its databases are
        those written before families were recorded, and a database that names
        no family holds its designs (:data:`FIRST_FAMILY`).
    backends : tuple of str, optional
        The campaign backends that sweep the family's designs (a design search's
        ``--verify``); None: every registered backend (paper B's actuator, which its
        analytical model also sweeps). Default: the FEM only, its own sweep.
    mesh_study_maxh_mm, mesh_study_pressures_mpa : tuple of float, optional
        ``fem mesh-study``'s default element sizes (mm, coarse to fine) and
        pressures (MPa); empty: 1.5, 1 and 0.75 times ``maxh_mm`` and 0, half
        and all of ``pmax_mpa``.
    contact : bool, default False
        Its walls can press on each other (:class:`~softbend.fem.contact.PenaltyContact`
        between faces its model names): ``--contact on`` and ``off`` apply
        (:meth:`contact_options`; its ``default_options`` say which is the
        default); False: no faces touch, only ``off``.
    """

    name: str
    title: str
    actuator: Actuator
    reference: Mapping[str, float]
    pmax_mpa: float
    pstep_mpa: float
    maxh_mm: float
    make_design: Callable[[dict[str, float]], Design]
    sweep: Callable[..., tuple[SweepResult, Any, Any]]
    default_options: Callable[..., FEMOptions] | None = None
    mesh_check: Callable[[Sequence[Design], FEMOptions], None] | None = None
    parse_text: Callable[[str], Design] | None = None
    analytical: Callable[[Any, ArrayLike], SweepResult] | None = None
    outline: Callable[[Any], np.ndarray] | None = None
    mesh_study_maxh_mm: tuple[float, ...] = ()
    mesh_study_pressures_mpa: tuple[float, ...] = ()
    campaign_pmax_mpa: float | None = None
    recorded: bool = True
    backends: tuple[str, ...] | None = ("fem",)
    contact: bool = False

    def contact_options(self, contact: str | None) -> dict[str, object]:
        """The option changes of ``--contact`` ``contact`` (None: the family's defaults).

        "on" turns the penalty contact on and ends a sweep at
        :data:`~softbend.fem.options.CONTACT_MAX_ANGLE_DEG` (the working range of an
        actuator whose walls touch), the PneuNet's defaults; "off" turns it off and
        ends a sweep at :class:`~softbend.fem.options.FEMOptions`' own largest angle
        (a PneuNet's sweep then stops where its walls first touch). A family without
        :attr:`contact` takes "off" only (one :class:`~softbend.errors.InputError`
        keyed ``contact``).
        """
        from softbend._validation import check_choice
        from softbend.fem.options import CONTACT_MAX_ANGLE_DEG, CONTACT_MODES, FEMOptions

        if contact is None:
            return {}
        check_choice(contact, "contact", CONTACT_MODES)
        if contact == "on" and not self.contact:
            raise InputError(
                f"must be off for the {self.name} family (none of its walls touch); "
                f"got {contact!r}",
                key="contact",
            )
        if contact == "off":
            return {"contact": "off", "max_angle_deg": FEMOptions.max_angle_deg}
        return {"contact": "on", "max_angle_deg": CONTACT_MAX_ANGLE_DEG}

    @property
    def names(self) -> tuple[str, ...]:
        """The design parameters' names, in order."""
        return self.actuator.names

    def design(self, values: Mapping[str, float] | None = None) -> Design:
        """The checked design of ``values``; parameters left out take the reference's values.

        Raises
        ------
        InputError
            For an unknown parameter name (the message lists the family's), a
            non-finite value, or a value the family refuses, keyed by its name.
        """
        values = dict(values or {})
        unknown = sorted(set(values) - set(self.names))
        if unknown:
            raise InputError(
                f"{', '.join(unknown)} is not a parameter of the {self.name} family; "
                f"its parameters are {', '.join(self.names)}",
                key="design",
            )
        merged = {n: float(values.get(n, self.reference[n])) for n in self.names}
        for n, v in merged.items():
            if not math.isfinite(v):
                raise InputError(must_be("a finite number", v), key=n)
        return self.make_design(merged)

    def parse(self, text: str | None) -> Design:
        """The design of ``"NAME=VALUE,..."`` or the family's own text (None or empty: the
        reference design)."""
        if text and self.parse_text is not None:
            return self.parse_text(text)
        return self.design(parse_assignments(text or "", self.names))

    def mesh_study_defaults(self) -> tuple[tuple[float, ...], tuple[float, ...]]:
        """``fem mesh-study``'s default element sizes (mm) and pressures (MPa)."""
        h, p = self.maxh_mm, self.pmax_mpa
        return (
            self.mesh_study_maxh_mm or (1.5 * h, h, 0.75 * h),
            self.mesh_study_pressures_mpa or (0.0, p / 2, p),
        )

    def options(self, **overrides: Any) -> FEMOptions:
        """The family's default :class:`FEMOptions`, with ``overrides``."""
        if self.default_options is not None:
            return self.default_options(**overrides)
        from softbend.fem.options import FEMOptions

        return FEMOptions(**overrides)

    def check_mesh(self, design: Design, options: FEMOptions) -> None:
        """Refuse ``options.maxh_mm`` if it meshes ``design`` too finely (see ``mesh_check``)."""
        self.check_meshes([design], options)

    def check_meshes(self, designs: Sequence[Design], options: FEMOptions) -> None:
        """Refuse ``options.maxh_mm`` if it meshes one of ``designs`` too finely."""
        if self.mesh_check is not None:
            self.mesh_check(designs, options)

    def campaign_pressures_mpa(
        self, pmax_mpa: float | None = None, pstep_mpa: float | None = None
    ) -> np.ndarray:
        """A campaign's pressure grid, MPa: 0 to ``pmax_mpa`` by ``pstep_mpa``.

        None takes the family's: ``campaign_pmax_mpa`` (else ``pmax_mpa``) and ``pstep_mpa``.
        """
        from softbend.models import default_pressures_mpa

        if pmax_mpa is None:
            pmax_mpa = self.pmax_mpa if self.campaign_pmax_mpa is None else self.campaign_pmax_mpa
        return default_pressures_mpa(pmax_mpa, self.pstep_mpa if pstep_mpa is None else pstep_mpa)

    def simulate(
        self,
        design: Design,
        pressures_mpa: ArrayLike,
        options: FEMOptions | None = None,
        *,
        progress: Callable[[float, float, float], None] | None = None,
    ) -> SweepResult:
        """Sweep ``design`` over increasing pressures, MPa (as :func:`softbend.fem.simulate`)."""
        result, _, _ = self.sweep(
            design, pressures_mpa, options or self.options(), progress=progress
        )
        return result


def parse_assignments(text: str, names: tuple[str, ...]) -> dict[str, float]:
    """``{"n_chambers": 6.0, ...}`` from ``"n_chambers=6,wall_mm=1.5"`` (errors keyed).

    A pair without ``=`` or a name given twice is refused (keyed ``design``); a
    value that is not a number is keyed by its name.
    """
    values: dict[str, float] = {}
    for part in (p.strip() for p in text.split(",")):
        if not part:
            continue
        name, sep, value = part.partition("=")
        name = name.strip()
        if not sep:
            raise InputError(
                must_be(f"NAME=VALUE pairs separated by commas (names: {', '.join(names)})", part),
                key="design",
            )
        if name in values:
            raise InputError(
                f"gives {name!r} twice ({values[name]:g} and {value.strip()}); give it once",
                key="design",
            )
        try:
            values[name] = float(value)
        except ValueError:
            raise InputError(must_be("a number", value.strip()), key=name) from None
    return values


#: The FEM actuator families, by name (``--family``).
FEM_FAMILIES: Registry[FEMFamily] = Registry("FEM actuator family")


def get_family(name: str) -> FEMFamily:
    """The registered family ``name`` (one error listing the known names otherwise)."""
    return FEM_FAMILIES.get(name)


#: The family of a design that names none: paper B's, the first.
FIRST_FAMILY = "sfrba"


def family_name_of(design: object) -> str:
    """The registry name of ``design``'s FEM family: its actuator's ``fem_family``, else its
    ``family``, else :data:`FIRST_FAMILY`."""
    named = getattr(getattr(design, "actuator", None), "fem_family", None)
    return str(named or getattr(design, "family", None) or FIRST_FAMILY)


def family_of(design: object) -> FEMFamily:
    """The registered FEM family of ``design`` (see :func:`family_name_of`)."""
    return get_family(family_name_of(design))


def _register_paper_b() -> FEMFamily:
    from softbend.fem.sfrba import description as sfrba

    family = FEMFamily(
        name="sfrba",
        title=SFRBA.title,
        actuator=SFRBA,
        reference=sfrba.REFERENCE,
        pmax_mpa=0.2,
        pstep_mpa=0.005,
        maxh_mm=5.0,
        make_design=sfrba.make_sfrba_design,
        sweep=sfrba.sfrba_sweep,
        mesh_check=sfrba.sfrba_mesh_check,
        parse_text=sfrba.parse_sfrba_design,
        analytical=sfrba.analytical_sweep,
        outline=sfrba.sfrba_outline,
        mesh_study_maxh_mm=sfrba.MESH_STUDY_MAXH_MM,
        mesh_study_pressures_mpa=sfrba.MESH_STUDY_PRESSURES_MPA,
        campaign_pmax_mpa=sfrba.CAMPAIGN_PMAX_MPA,
        recorded=False,
        backends=None,
    )
    return FEM_FAMILIES.register(family.name, family)


#: Paper B's fiber-reinforced actuator, the first family.
SFRBA_FAMILY: FEMFamily = _register_paper_b()


def _pneunet_sweep(
    design: Design, pressures_mpa: ArrayLike, options: FEMOptions | None = None, **kwargs: Any
) -> tuple[SweepResult, Any, Any]:
    from softbend.fem.pneunet.description import pneunet_options
    from softbend.fem.pneunet.sweep import run_pneunet_sweep

    return run_pneunet_sweep(design, pressures_mpa, options or pneunet_options(), **kwargs)


def _pneunet_mesh_check(designs: Sequence[Design], options: FEMOptions) -> None:
    from softbend.fem.pneunet.geometry import check_pneunet_mesh

    for design in designs:
        check_pneunet_mesh(design, options.maxh_mm, options.base_cap_mm)


def _register_pneunet() -> FEMFamily:
    from softbend.actuators import PNEUNET
    from softbend.fem.pneunet import description as pneunet

    family = FEMFamily(
        name="pneunet",
        title=PNEUNET.title,
        actuator=PNEUNET,
        reference=pneunet.REFERENCE,
        pmax_mpa=0.05,
        pstep_mpa=0.001,
        maxh_mm=pneunet.PNEUNET_MAXH_MM,
        make_design=pneunet.make_pneunet_design,
        sweep=_pneunet_sweep,
        default_options=pneunet.pneunet_options,
        mesh_check=_pneunet_mesh_check,
        mesh_study_maxh_mm=pneunet.MESH_STUDY_MAXH_MM,
        mesh_study_pressures_mpa=pneunet.MESH_STUDY_PRESSURES_MPA,
        contact=True,
    )
    return FEM_FAMILIES.register(family.name, family)


#: The PneuNet (:mod:`softbend.fem.pneunet`), the second family (``--family pneunet``).
PNEUNET_FAMILY: FEMFamily = _register_pneunet()
