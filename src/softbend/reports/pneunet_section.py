"""The PneuNet section: the second FEM family's reference, mesh, design space and a design.

:func:`softbend.pipeline.pneunet.run_pneunet` computes; :func:`add_section`
draws its figures into ``out_dir/pneunet``, writes the design search's files and
adds the section.
"""

from __future__ import annotations

import math
import time
from pathlib import Path
from typing import Any

from softbend.pipeline import Progress
from softbend.reports.html import Report

__all__ = ["add_section"]

#: Why the reference is not set beside a published curve (said in the report).
PUBLISHED_NOTE = (
    "Published curve: not compared. The reference follows GIBBON's PneuNet (an FEBio model "
    "after the fast PneuNet of Mosadegh et al., Adv. Funct. Mater. 24 (2014) 2163), whose "
    "bending angle against pressure is published as a figure only; softbend ships no values "
    "read off it, and none are invented here. The comparison is also limited by the model: "
    "this sweep stops at the first touch of neighbouring walls (no contact), at {angle:.1f}°, "
    "while PneuNets bend much further with their walls pressing on each other (an FEM "
    "matched a fresh PneuNet up to 167° within about 4 %: Libby et al., arXiv 2212.03420, "
    "2022)."
)


def _reference(section: Any, ran: Any, folder: Path, root: Path) -> Path:
    from softbend.fem.pneunet.description import ELASTOSIL_M4601, PAPER_LAYER
    from softbend.reports.pneunet_figures import reference_curves

    stop = ran.sweep.stats["stop_reason"]
    figure = reference_curves(
        ran.step_pressure_mpa,
        ran.step_angle_deg,
        ran.step_volume_mm3,
        folder / "reference_curves.png",
        stop=stop,
        title=f"Reference PneuNet ({ran.design})",
    )
    section.text(
        f"The reference PneuNet: {ran.design} (mm), after GIBBON's PneuNet (Moerman, J. Open "
        "Source Softw. 3 (2018) 506, an FEBio model after Mosadegh et al. 2014) with a 2 mm "
        f"roof. Elastomer: {ELASTOSIL_M4601.name}, Yeoh C10 0.11, C20 0.02 MPa "
        f"({ELASTOSIL_M4601.source.split(':')[0]}); strain-limiting layer: "
        f"{PAPER_LAYER.name.lower()}, E 6.5 GPa, 0.1 mm, under the base. Quadratic tetrahedra "
        "on the half actuator, follower pressure on every chamber. The same sweep: "
        "`softbend fem run --family pneunet --json`.",
        note=True,
    )
    stats = ran.sweep.stats
    section.table(
        ["pressure (kPa)", "bending angle (°)", "cavity volume (mL)"],
        [
            [f"{p * 1e3:.2f}", f"{a:.2f}", f"{v / 1e3:.3f}"]
            for p, a, v in zip(
                ran.step_pressure_mpa, ran.step_angle_deg, ran.step_volume_mm3, strict=True
            )
        ],
        caption=(
            f"Converged steps of the reference's sweep, the last at the touch (between "
            f"the steps around it): {ran.sweep.mesh_size} tetrahedra, "
            f"{stats['ndof']} unknowns, {ran.sweep.wall_time_s:.1f} s; stop: {stop}."
        ),
    )
    section.figure(
        figure,
        "The reference PneuNet: bending angle and cavity volume against pressure, to the "
        "first touch of neighbouring walls.",
        root=root,
    )
    section.text(PUBLISHED_NOTE.format(angle=ran.step_angle_deg[-1]), note=True)
    return figure


def _mesh(section: Any, ran: Any) -> None:
    from softbend.pipeline.pneunet import MESH_PRESSURES_MPA

    finest = ran.mesh[-1].angles_deg
    rows = []
    for row in ran.mesh:
        rows.append(
            [row.maxh_mm, row.elements, row.ndof]
            + [f"{a:.2f}" for a in row.angles_deg]
            + [f"{abs(a - f):.2f}" for a, f in zip(row.angles_deg, finest, strict=True)]
            + [f"{row.wall_time_s:.1f}"]
        )
    kpa = [f"{p * 1e3:g} kPa" for p in MESH_PRESSURES_MPA]
    section.table(
        ["element size (mm)", "tetrahedra", "unknowns"]
        + [f"θ at {k} (°)" for k in kpa]
        + [f"|Δθ| from finest at {k} (°)" for k in kpa]
        + ["s"],
        rows,
        caption=(
            "Mesh convergence of the reference at the largest pressure every mesh reaches "
            "before its walls touch (Newton from the previous converged state at each "
            "pressure). Finer: `softbend fem mesh-study --family pneunet --maxh 3,2,1.5,1.25`."
        ),
    )


def _effects(section: Any, ran: Any, folder: Path, root: Path) -> Path:
    from softbend.reports.pneunet_figures import main_effects_figure

    designs = ran.designs
    stops = designs["stop_kind"].value_counts()
    figure = main_effects_figure(
        ran.effects,
        folder / "main_effects.png",
        title=f"Main effects over the shipped PneuNet dataset ({len(designs)} designs)",
    )
    effects = ran.effects.effects
    section.text(
        f"The shipped PneuNet dataset: {len(designs)} designs of a Sobol sample over the "
        "actuator's ranges, swept 0–50 kPa ("
        + ", ".join(f"{n} {kind}" for kind, n in stops.items())
        + "). Each panel groups the designs by one parameter (quartiles, or its values) and "
        "marks the response's mean per group; the other parameters spread evenly over every "
        "group, so the spread of the means is that parameter's main effect: + when the "
        "means all rise with the parameter, − when they all fall, unsigned (~) otherwise."
    )
    section.table(
        ["parameter", *effects.columns],
        [
            [
                name,
                *[
                    f"~{abs(v):.2f}" if trend == "mixed" else f"{v:+.2f}"
                    for v, trend in zip(
                        effects.loc[name], ran.effects.trends.loc[name], strict=True
                    )
                ],
            ]
            for name in ran.effects.ranking(effects.columns[0])
        ],
        caption="Main effects: the largest minus the smallest group mean, in the response's "
        "unit; ranked by the first response.",
    )
    section.figure(
        figure,
        "Main effects of the PneuNet design space: group means (points) against the "
        "mean over all designs (dashed).",
        root=root,
    )
    return figure


def _verified(verify: int) -> str:
    if not verify:
        return "none swept by the FEM in this run"
    best = "the best design" if verify == 1 else f"the best {verify} designs"
    return (
        f"{best} swept by the FEM, and the next ones while a sweep stops before the "
        "target's pressure"
    )


def _search(section: Any, ran: Any, folder: Path, root: Path) -> dict[str, str]:
    from softbend.pipeline.pneunet import SPECIFICATION_STEPS
    from softbend.reports.design_outputs import write_search

    result = ran.search
    files = write_search(result, ran.model.predictor, folder / "design")
    training = ran.training
    steps = ", ".join(f"{k} {v:g}" for k, v in SPECIFICATION_STEPS.items())
    section.text(
        f"Design find on a surrogate of the dataset: {training['model']} "
        f"({training['params']}), five design-grouped folds, R² {training['r2']:.3f}, "
        f"RMSE {training['rmse_deg']:.2f}°. Target: {result.spec.target.describe()}; "
        f"{result.n_designs} designs on a grid of steps ({steps}), {result.n_meeting} "
        f"meeting it on the surrogate; {_verified(ran.summary['verify'])}. The same "
        "search: `softbend train pneunet --models plr --out pn` then `softbend design find "
        "--model pn/models/plr.json --angle 30 --at 0.02 --verify 1 --replace-stopped "
        "--resolution NAME=STEP ...`."
    )
    rows = []
    for rank, c in enumerate(result.candidates, start=1):
        swept = c.fem_angle_deg is not None or c.fem_meets is not None or c.fem_stop
        fem = (
            ""
            if not swept
            else (
                "stopped"
                if c.fem_angle_deg is None or not math.isfinite(c.fem_angle_deg)
                else f"{c.fem_angle_deg:.2f}"
            )
        )
        verdict = "" if c.fem_meets is None else ("yes" if c.fem_meets else "NO")
        rows.append([rank, str(c.design), f"{c.angle_deg:.2f}", fem, verdict])
    section.table(
        ["rank", "design (mm)", "surrogate angle (°)", "FEM angle (°)", "within tolerance"],
        rows,
        caption="; ".join(
            f"#{rank}: the FEM sweep stopped: {c.fem_stop}"
            for rank, c in enumerate(result.candidates, start=1)
            if c.fem_stop
        )
        or "The candidates, best first; the FEM swept the first.",
    )
    section.figure(
        files["curves.png"],
        "θ(p) of the best designs, surrogate (lines) and FEM (circles).",
        root=root,
    )
    return files


def add_section(
    report: Report,
    out_dir: Path,
    progress: Progress | None = None,
    *,
    seed: int = 0,
    **options: Any,
) -> dict[str, Any]:
    """Append the PneuNet section to ``report``; return its headline figures.

    Parameters
    ----------
    report : Report
    out_dir : path
        The report's folder; files go to ``out_dir/pneunet``.
    progress : callable, optional
        ``progress(phase, done, total)``.
    seed : int
        Seed of the surrogate's folds.
    **options
        ``mesh_sizes_mm`` and ``verify`` of :func:`softbend.pipeline.pneunet.run_pneunet`.
    """
    from softbend.pipeline.pneunet import run_pneunet

    start = time.perf_counter()
    root = Path(out_dir)
    ran = run_pneunet(root, seed=seed, progress=progress, **options)
    folder = root / "pneunet"
    section = report.section("A second actuator: the PneuNet (FEM family pneunet)")
    _reference(section, ran, folder, root)
    _mesh(section, ran)
    _effects(section, ran, folder, root)
    _search(section, ran, folder, root)
    return {**ran.summary, "seconds": time.perf_counter() - start}
