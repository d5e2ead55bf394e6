"""What the FEM family ``sfrba`` knows of paper B's actuator beyond its parameters.

Its reference design (paper B's Fig. 2 actuator, ``100,6,2,2,5,10``), the
positional ``l,r,t,b,φ,lc`` text of ``--design``, the mesh-size check, the
analytical model a sweep is compared with and the side outline of a deformed
state. Pure Python: the functions that solve import NGSolve when they run.
"""

from __future__ import annotations

from collections.abc import Sequence
from typing import TYPE_CHECKING, Any

if TYPE_CHECKING:
    import numpy as np
    from numpy.typing import ArrayLike

    from softbend.actuators import Design
    from softbend.fem.actuator import ActuatorModel
    from softbend.fem.options import FEMOptions
    from softbend.models import SweepResult

__all__ = [
    "CAMPAIGN_PMAX_MPA",
    "MESH_STUDY_MAXH_MM",
    "MESH_STUDY_PRESSURES_MPA",
    "REFERENCE",
    "analytical_sweep",
    "make_sfrba_design",
    "parse_sfrba_design",
    "sfrba_mesh_check",
    "sfrba_outline",
    "sfrba_sweep",
]

#: Paper B's reference design (l, r, t, b, φ, lc), mm and degrees.
REFERENCE: dict[str, float] = {
    "l_mm": 100.0,
    "r_mm": 6.0,
    "t_mm": 2.0,
    "b_mm": 2.0,
    "phi_deg": 5.0,
    "lc_mm": 10.0,
}

#: Largest pressure of a campaign's default grid, MPa (paper B's sweeps: 0-0.5 MPa).
CAMPAIGN_PMAX_MPA = 0.5

#: ``fem mesh-study``'s default element sizes, mm, coarse to fine.
MESH_STUDY_MAXH_MM: tuple[float, ...] = (6.0, 5.0, 4.0, 3.0)
#: ``fem mesh-study``'s default pressures, MPa.
MESH_STUDY_PRESSURES_MPA: tuple[float, ...] = (0.0, 0.05, 0.1)


def make_sfrba_design(values: dict[str, float]) -> Design:
    """The checked design of ``values`` (the six parameters by name)."""
    from softbend.design import sfrba_design

    return sfrba_design(**values)


def parse_sfrba_design(text: str) -> Design:
    """The design of ``"100,6,2,2,5,10"`` (l, r, t, b, φ, lc; errors keyed ``design``)."""
    from softbend.design import parse_sfrba

    return parse_sfrba(text)


def sfrba_sweep(
    design: Design, pressures_mpa: ArrayLike, options: FEMOptions | None = None, **kwargs: Any
) -> tuple[SweepResult, Any, Any]:
    """:func:`softbend.fem.sfrba.sweep.run_sweep` (imports NGSolve)."""
    from softbend.fem.sfrba.sweep import run_sweep

    return run_sweep(design, pressures_mpa, options, **kwargs)


def sfrba_mesh_check(designs: Sequence[Design], options: FEMOptions) -> None:
    """Refuse ``options.maxh_mm`` if it meshes one of ``designs`` with too many elements
    (the message names the design of the most elements)."""
    options.check_mesh(designs)


def analytical_sweep(design: Design, pressures_mpa: ArrayLike) -> SweepResult:
    """The analytical model's sweep of ``design`` (Polygerinos et al.), to compare with."""
    from softbend.analytical import AnalyticalModel

    return AnalyticalModel().sweep(design, pressures_mpa)


def sfrba_outline(model: ActuatorModel) -> np.ndarray:
    """The closed side outline (m, 2), mm, of ``model``'s state in the bending plane."""
    from softbend.fem.export import silhouette_mm

    return silhouette_mm(model)
