"""Paper B §3.1 section: the Dragon Skin 30 fit (Fig. 2a) and one FEM sweep (Fig. 2b)."""

from __future__ import annotations

import time
from collections.abc import Callable
from pathlib import Path
from typing import Any

from softbend.reports.html import Report

#: Design and pressures of paper B Fig. 2b.
FIG2_DESIGN = "100,6,2,2,5,10"
FIG2_PMAX_MPA = 0.17


def add_section(
    report: Report,
    out_dir: Path,
    progress: Callable[[str, int, int], None] | None = None,
    *,
    options: Any = None,
    pmax_mpa: float = FIG2_PMAX_MPA,
) -> dict[str, Any]:
    """Fit the shipped Dragon Skin 30 test, sweep the Fig. 2 design, add both to ``report``.

    ``options`` (:class:`softbend.fem.FEMOptions`) and ``pmax_mpa`` default to
    the model's defaults and paper B's 0.17 MPa.
    """
    from softbend.design import SFRBADesign
    from softbend.materials import fit_models, load_shipped
    from softbend.models import default_pressures_mpa
    from softbend.reports.fem_figures import sweep_with_files
    from softbend.reports.material_figures import fit_figure

    start = time.perf_counter()
    folder = out_dir / "paper_b_fem"
    test = load_shipped("dragon-skin-30")
    fits = fit_models(test)
    fit_png = fit_figure(test, fits, folder / "dragon_skin_30_fit.png")
    section = report.section("Paper B: material fit and finite-element model (Fig. 2)")
    section.table(
        ["model", "parameters (MPa)", "R²", "RMSE (MPa)"],
        [[name, repr(result.model), result.r2, result.rmse_mpa] for name, result in fits.items()],
        caption=(
            f"Least-squares fits to the uniaxial test of Dragon Skin 30 shipped with softbend "
            f"(Marechal et al., Soft Robotics 2021, ODbL; stretch {test.stretch.min():.2f}–"
            f"{test.stretch.max():.2f}). Paper B: Yeoh best, R² 0.9982, RMSE 0.0204 MPa; the FEM "
            "below uses paper B's constants (C10 0.11, C20 0.003 MPa)."
        ),
    )
    section.figure(fit_png, "Fig. 2a: nominal stress of Dragon Skin 30 and the fits.", root=out_dir)

    design = SFRBADesign.parse(FIG2_DESIGN)
    pressures = default_pressures_mpa(pmax_mpa)
    phase = "paper B: FEM sweep (kPa)"
    total = round(1000 * pmax_mpa)

    def on_step(pressure: float, _angle: float, _target: float) -> None:
        if progress is not None:
            progress(phase, round(1000 * pressure), total)

    sweep = sweep_with_files(
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
    result, analytical = sweep.result, sweep.analytical
    curve_png, shapes_png = sweep.files["curve"], sweep.files["shapes"]
    picks = sorted({p for p in (0.0, 0.05, 0.10, 0.15, pmax_mpa) if p <= pmax_mpa})
    rows = []
    for p in picks:
        i = int(abs(result.pressure_mpa - p).argmin())
        if abs(result.pressure_mpa[i] - p) < 1e-9 and result.converged[i]:
            rows.append([p, result.angle_deg[i], analytical.angle_deg[i]])
    timings = result.stats["timings"]
    section.table(
        ["pressure (MPa)", "FEM angle (°)", "analytical angle (°)"],
        rows,
        caption=(
            f"Design ({design}) swept from 0 to {pmax_mpa:g} MPa: {result.mesh_size} quadratic "
            f"tetrahedra (half model), {result.stats['ndof']} unknowns, "
            f"{sweep.steps} pressure steps, {int(timings['iterations'])} Newton "
            f"iterations, {result.wall_time_s:.0f} s; stop: {result.stats['stop_reason']}. "
            "The analytical model has no gravity (0° at 0 MPa) and no bulging."
        ),
    )
    section.figure(curve_png, "Bending angle against pressure, FEM and analytical.", root=out_dir)
    section.figure(shapes_png, "Fig. 2b: deformed actuator in the bending plane.", root=out_dir)
    yeoh = fits.get("yeoh")
    return {
        "seconds": time.perf_counter() - start,
        "dragon_skin_30_fit": {
            name: {"r2": r.r2, "rmse_mpa": r.rmse_mpa, "model": r.model.to_dict()}
            for name, r in fits.items()
        },
        "yeoh_r2": None if yeoh is None else yeoh.r2,
        "fem_design": str(design),
        "fem_angles_deg": {f"{row[0]:g}": row[1] for row in rows},
        "analytical_angles_deg": {f"{row[0]:g}": row[2] for row in rows},
        "fem_wall_time_s": result.wall_time_s,
        "fem_stop_reason": result.stats["stop_reason"],
    }
