"""Paper B §3.1: the Dragon Skin 30 fit (Fig. 2a) and the FEM sweep of its Fig. 2 design."""

from __future__ import annotations

import time
from collections.abc import Callable, Sequence
from dataclasses import dataclass
from pathlib import Path
from typing import TYPE_CHECKING, Any

from softbend.actuators import Design
from softbend.design import parse_sfrba
from softbend.fem.run import FamilySweep
from softbend.pipeline import Progress
from softbend.references import FEM_VALIDATION

if TYPE_CHECKING:  # pragma: no cover
    from numpy.typing import ArrayLike

    from softbend.fem.options import FEMOptions
    from softbend.materials import FitResult, TensileTest

__all__ = ["FIG2_DESIGN", "FIG2_PMAX_MPA", "FEMSweep", "Fig2", "run_fig2", "sweep_with_shapes"]

#: Design and highest pressure (MPa) of paper B Fig. 2b
#: (:data:`softbend.references.FEM_VALIDATION`).
FIG2_DESIGN: str = FEM_VALIDATION["design"].value
FIG2_PMAX_MPA: float = FEM_VALIDATION["pmax_mpa"].value


#: One FEM sweep of :func:`sweep_with_shapes`, the analytical model's on the same
#: grid and the deformed outlines (:class:`softbend.fem.run.FamilySweep`).
FEMSweep = FamilySweep


def sweep_with_shapes(
    design: Design,
    pressures_mpa: ArrayLike,
    options: FEMOptions | None,
    out_dir: str | Path,
    *,
    shape_pressures_mpa: Sequence[float] | int,
    prefix: str = "",
    vtk: bool = False,
    progress: Callable[[float, float, float], None] | None = None,
) -> FamilySweep:
    """Sweep one design of paper B's family with the FEM; keep the analytical curve and the
    deformed outlines (:func:`softbend.fem.run.sweep_with_files`, ``options`` None: the
    family's).

    Writes ``<prefix>sweep.csv`` (pressure, angle, tip, converged, Newton
    iterations) and with ``vtk`` the shapes as ``vtk/shape_p<MPa>MPa.vtu``.
    """
    from softbend.fem.families import get_family
    from softbend.fem.run import sweep_with_files

    family = get_family("sfrba")
    return sweep_with_files(
        family,
        design,
        pressures_mpa,
        options or family.options(),
        out_dir,
        shape_pressures_mpa=shape_pressures_mpa,
        prefix=prefix,
        vtk=vtk,
        progress=progress,
    )


@dataclass(frozen=True)
class Fig2:
    """What :func:`run_fig2` computed.

    Attributes
    ----------
    test : TensileTest
        The shipped Dragon Skin 30 uniaxial test.
    fits : dict
        ``{model name: FitResult}`` of the hyperelastic models fitted to it.
    design : Design
        The swept design (:data:`FIG2_DESIGN`).
    pmax_mpa : float
        Last pressure of the sweep, MPa.
    sweep : FEMSweep
        The sweep, the analytical model on the same grid, the outlines.
    angles : list of (float, float, float)
        ``(pressure MPa, FEM angle °, analytical angle °)`` at the converged
        outputs among 0, 0.05, 0.10, 0.15 MPa and ``pmax_mpa``.
    summary : dict
        Headline figures (fits, angles, FEM wall time and stop reason).
    """

    test: TensileTest
    fits: dict[str, FitResult]
    design: Any
    pmax_mpa: float
    sweep: FEMSweep
    angles: list[tuple[float, float, float]]
    summary: dict[str, Any]


def _angles_at(sweep: FEMSweep, pmax_mpa: float) -> list[tuple[float, float, float]]:
    """(pressure, FEM angle, analytical angle) at the round pressures the sweep converged on."""
    result, analytical = sweep.result, sweep.analytical
    assert analytical is not None  # paper B's family has its analytical model
    picks = sorted({p for p in (0.0, 0.05, 0.10, 0.15, pmax_mpa) if p <= pmax_mpa})
    rows = []
    for p in picks:
        i = int(abs(result.pressure_mpa - p).argmin())
        if abs(result.pressure_mpa[i] - p) < 1e-9 and result.converged[i]:
            rows.append((p, result.angle_deg[i], analytical.angle_deg[i]))
    return rows


def run_fig2(
    out_dir: Path,
    progress: Progress | None = None,
    *,
    options: FEMOptions | None = None,
    pmax_mpa: float = FIG2_PMAX_MPA,
) -> Fig2:
    """Fit the shipped Dragon Skin 30 test and sweep the Fig. 2 design with the FEM.

    Writes ``out_dir/paper_b_fem/fem_sweep.csv``. ``options``
    (:class:`softbend.fem.FEMOptions`) and ``pmax_mpa`` default to the model's
    defaults and paper B's 0.17 MPa; ``progress(phase, done, total)`` counts kPa.
    """
    from softbend.materials import fit_models, load_shipped
    from softbend.models import default_pressures_mpa

    start = time.perf_counter()
    folder = Path(out_dir) / "paper_b_fem"
    phase = "paper B: FEM sweep (kPa)"
    total = round(1000 * pmax_mpa)
    if progress is not None:  # the material fits and the mesh come first (seconds)
        progress(phase, 0, total)
    test = load_shipped("dragon-skin-30")
    fits = fit_models(test)
    design = parse_sfrba(FIG2_DESIGN)
    pressures = default_pressures_mpa(pmax_mpa)

    def on_step(pressure: float, _angle: float, _target: float) -> None:
        if progress is not None:
            progress(phase, round(1000 * pressure), total)

    sweep = sweep_with_shapes(
        design,
        pressures,
        options,
        folder,
        shape_pressures_mpa=[0.0, 0.05, 0.10, pmax_mpa],
        prefix="fem_",
        progress=on_step,
    )
    if progress is not None:
        progress(phase, total, total)
    angles = _angles_at(sweep, pmax_mpa)
    result = sweep.result
    yeoh = fits.get("yeoh")
    summary = {
        "seconds": time.perf_counter() - start,
        "dragon_skin_30_fit": {
            name: {"r2": r.r2, "rmse_mpa": r.rmse_mpa, "model": r.model.to_dict()}
            for name, r in fits.items()
        },
        "yeoh_r2": None if yeoh is None else yeoh.r2,
        "fem_design": str(design),
        "fem_angles_deg": {f"{row[0]:g}": row[1] for row in angles},
        "analytical_angles_deg": {f"{row[0]:g}": row[2] for row in angles},
        "fem_wall_time_s": result.wall_time_s,
        "fem_stop_reason": result.stats["stop_reason"],
    }
    return Fig2(test, fits, design, pmax_mpa, sweep, angles, summary)
