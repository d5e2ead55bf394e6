"""FEM actuator families: the actuators the finite-element model can simulate.

A family is everything the FEM needs to know about one kind of actuator beyond
its elastomer: its named design parameters (an
:class:`~softbend.actuators.Actuator`, the same description the learning
pipeline uses), a reference design, the pressures a sweep covers by default, how
a design is checked, and the sweep itself (geometry, material regions, cavity
surfaces loaded by a follower pressure, fixture and bending-angle readout live
behind :attr:`FEMFamily.sweep`). Paper B's fiber-reinforced actuator is the
first family (``"sfrba"``), the PneuNet the second; a family's designs are
:class:`~softbend.actuators.Design` objects of its actuator, checked by the family.

Adding a family is one module that builds a :class:`FEMFamily` and calls
``FEM_FAMILIES.register(name, family)``; importing this module never imports
NGSolve (a family's sweep imports it when it runs).
"""

from __future__ import annotations

import math
from collections.abc import Callable, Mapping
from dataclasses import dataclass
from typing import TYPE_CHECKING, Any

from softbend._validation import must_be
from softbend.actuators import SFRBA, Design
from softbend.design import sfrba_design
from softbend.errors import InputError
from softbend.registry import Registry

if TYPE_CHECKING:
    from numpy.typing import ArrayLike

    from softbend.actuators import Actuator
    from softbend.fem.options import FEMOptions
    from softbend.models import SweepResult

__all__ = [
    "FEM_FAMILIES",
    "FEMFamily",
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
        ``mesh_check(design, options)``: refuse, before NGSolve loads, a
        ``maxh_mm`` that would mesh ``design`` with too many elements (one
        :class:`~softbend.errors.InputError` keyed ``maxh_mm``); no check when absent.
    backends : tuple of str, optional
        The campaign backends that sweep the family's designs (a design search's
        ``--verify``); None: every registered backend (paper B's actuator, which its
        analytical model also sweeps). Default: the FEM only.
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
    mesh_check: Callable[[Design, FEMOptions], None] | None = None
    backends: tuple[str, ...] | None = ("fem",)

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
        """The design of ``"NAME=VALUE,..."`` (None or empty: the reference design)."""
        return self.design(parse_assignments(text or "", self.names))

    def options(self, **overrides: Any) -> FEMOptions:
        """The family's default :class:`FEMOptions`, with ``overrides``."""
        if self.default_options is not None:
            return self.default_options(**overrides)
        from softbend.fem.options import FEMOptions

        return FEMOptions(**overrides)

    def check_mesh(self, design: Design, options: FEMOptions) -> None:
        """Refuse ``options.maxh_mm`` if it meshes ``design`` too finely (see ``mesh_check``)."""
        if self.mesh_check is not None:
            self.mesh_check(design, options)

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


def _sfrba_design(values: dict[str, float]) -> Design:
    return sfrba_design(**values)


def _sfrba_sweep(
    design: Design, pressures_mpa: ArrayLike, options: FEMOptions | None = None, **kwargs: Any
) -> tuple[SweepResult, Any, Any]:
    from softbend.fem.sweep import run_sweep

    return run_sweep(design, pressures_mpa, options, **kwargs)


def _sfrba_mesh_check(design: Design, options: FEMOptions) -> None:
    options.check_mesh(design)


def _register_paper_b() -> FEMFamily:
    family = FEMFamily(
        name="sfrba",
        title=SFRBA.title,
        actuator=SFRBA,
        reference={
            "l_mm": 100.0,
            "r_mm": 6.0,
            "t_mm": 2.0,
            "b_mm": 2.0,
            "phi_deg": 5.0,
            "lc_mm": 10.0,
        },
        pmax_mpa=0.2,
        pstep_mpa=0.005,
        maxh_mm=5.0,
        make_design=_sfrba_design,
        sweep=_sfrba_sweep,
        mesh_check=_sfrba_mesh_check,
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


def _pneunet_mesh_check(design: Design, options: FEMOptions) -> None:
    from softbend.fem.pneunet.geometry import check_pneunet_mesh

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
    )
    return FEM_FAMILIES.register(family.name, family)


#: The PneuNet (:mod:`softbend.fem.pneunet`), the second family (``--family pneunet``).
PNEUNET_FAMILY: FEMFamily = _register_pneunet()
