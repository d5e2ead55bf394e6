"""Paper B §3.1 section: the Dragon Skin 30 fit (Fig. 2a) and one FEM sweep (Fig. 2b).

:func:`softbend.pipeline.paper_b_fem.run_fig2` computes; this module draws.
"""

from __future__ import annotations

import time
from collections.abc import Callable
from pathlib import Path
from typing import TYPE_CHECKING, Any

from softbend.pipeline.paper_b_fem import FIG2_DESIGN, FIG2_PMAX_MPA, Fig2
from softbend.references import MATERIALS
from softbend.reports.html import Report

if TYPE_CHECKING:
    from softbend.fem.options import FEMOptions

__all__ = ["FIG2_DESIGN", "FIG2_PMAX_MPA", "add_fig2", "add_section"]


def add_fig2(report: Report, fig2: Fig2, root: Path) -> dict[str, Path]:
    """Draw Fig. 2a, the angle–pressure curve and Fig. 2b into ``root/paper_b_fem``; add them.

    Returns
    -------
    dict
        ``{"fit", "curve", "shapes"}`` paths of the figures.
    """
    from softbend.reports.fem_figures import angle_pressure_curve, deformed_shapes
    from softbend.reports.material_figures import fit_figure

    folder = root / "paper_b_fem"
    test, fits, design, sweep = fig2.test, fig2.fits, fig2.design, fig2.sweep
    figures = {"fit": fit_figure(test, fits, folder / "dragon_skin_30_fit.png")}
    paper = MATERIALS["dragon-skin-30"]
    section = report.section("Paper B: material fit and finite-element model (Fig. 2)")
    section.table(
        ["model", "parameters (MPa)", "R²", "RMSE (MPa)"],
        [[name, repr(result.model), result.r2, result.rmse_mpa] for name, result in fits.items()],
        caption=(
            f"Least-squares fits to the uniaxial test of Dragon Skin 30 shipped with softbend "
            f"(Marechal et al., Soft Robotics 2021, ODbL; stretch {test.stretch.min():.2f}–"
            f"{test.stretch.max():.2f}). Paper B: Yeoh best, R² {paper['fit_r2'].value}, RMSE "
            f"{paper['fit_rmse_mpa'].value} MPa ({paper['fit_r2'].source}); the FEM below uses "
            f"paper B's constants (C10 {paper['c10_mpa'].value}, C20 {paper['c20_mpa'].value} "
            f"MPa; {paper['c10_mpa'].source})."
        ),
    )
    section.figure(
        figures["fit"], "Fig. 2a: nominal stress of Dragon Skin 30 and the fits.", root=root
    )
    figures["curve"] = angle_pressure_curve(
        sweep.result, folder / "fem_angle_pressure.png", analytical=sweep.analytical
    )
    figures["shapes"] = deformed_shapes(
        sweep.outlines, folder / "fem_shapes.png", title=f"Design ({design}), FEM"
    )
    result = sweep.result
    timings = result.stats["timings"]
    section.table(
        ["pressure (MPa)", "FEM angle (°)", "analytical angle (°)"],
        [list(row) for row in fig2.angles],
        caption=(
            f"Design ({design}) swept from 0 to {fig2.pmax_mpa:g} MPa: {result.mesh_size} "
            f"quadratic tetrahedra (half model), {result.stats['ndof']} unknowns, "
            f"{sweep.steps} pressure steps, {int(timings['iterations'])} Newton "
            f"iterations, {result.wall_time_s:.0f} s; stop: {result.stats['stop_reason']}. "
            "The analytical model has no gravity (0° at 0 MPa) and no bulging."
        ),
    )
    section.figure(
        figures["curve"], "Bending angle against pressure, FEM and analytical.", root=root
    )
    section.figure(figures["shapes"], "Fig. 2b: deformed actuator in the bending plane.", root=root)
    return figures


def add_section(
    report: Report,
    out_dir: Path,
    progress: Callable[[str, int, int], None] | None = None,
    *,
    options: FEMOptions | None = None,
    pmax_mpa: float = FIG2_PMAX_MPA,
) -> dict[str, Any]:
    """Fit the shipped Dragon Skin 30 test, sweep the Fig. 2 design, add both to ``report``.

    ``options`` (:class:`softbend.fem.FEMOptions`) and ``pmax_mpa`` default to
    the model's defaults and paper B's 0.17 MPa. Returns the headline figures of
    :func:`~softbend.pipeline.paper_b_fem.run_fig2`, ``seconds`` with the drawing.
    """
    from softbend.pipeline.paper_b_fem import run_fig2

    start = time.perf_counter()
    fig2 = run_fig2(out_dir, progress, options=options, pmax_mpa=pmax_mpa)
    add_fig2(report, fig2, out_dir)
    return {**fig2.summary, "seconds": time.perf_counter() - start}
