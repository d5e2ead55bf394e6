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
    "read off it, and none are invented here. For scale: an FEM with wall-to-wall contact "
    "matched a fresh PneuNet up to 167° within about 4 % (Libby et al., arXiv 2212.03420, "
    "2022); this reference reaches {angle:.1f}° at {kpa:.0f} kPa."
)


def _reference(section: Any, ran: Any, folder: Path, root: Path) -> Path:
    from softbend.fem.pneunet.description import ELASTOSIL_M4601, PAPER_LAYER
    from softbend.reports.pneunet_figures import reference_curves

    stop = ran.sweep.stats["stop_reason"]
    contact = ran.step_contact_pressure_kpa.size > 0
    figure = reference_curves(
        ran.step_pressure_mpa,
        ran.step_angle_deg,
        ran.step_volume_mm3,
        folder / "reference_curves.png",
        stop=stop,
        title=f"Reference PneuNet ({ran.design})",
        contact_force_n=ran.step_contact_force_n if contact else None,
    )
    options = ran.sweep.stats["options"]
    section.text(
        f"The reference PneuNet: {ran.design} (mm), after GIBBON's PneuNet (Moerman, J. Open "
        "Source Softw. 3 (2018) 506, an FEBio model after Mosadegh et al. 2014) with a 2 mm "
        f"roof. Elastomer: {ELASTOSIL_M4601.name}, Yeoh C10 0.11, C20 0.02 MPa "
        f"({ELASTOSIL_M4601.source.split(':')[0]}); strain-limiting layer: "
        f"{PAPER_LAYER.name.lower()}, E 6.5 GPa, 0.1 mm, under the base. Quadratic tetrahedra "
        "on the half actuator, follower pressure on every chamber"
        + (
            "; frictionless penalty contact between the facing walls of neighbouring "
            f"chambers (penalty {options['contact_penalty_mpa_per_mm']:g} MPa/mm, "
            f"interpenetration at most {options['contact_tolerance_mm']:g} mm), the load "
            "steps shortened where the walls start to touch"
            if contact
            else ""
        )
        + ". The same sweep: `softbend fem run --family pneunet --json`.",
        note=True,
    )
    stats = ran.sweep.stats
    columns = ["pressure (kPa)", "bending angle (°)", "cavity volume (mL)"]
    values = [ran.step_pressure_mpa * 1e3, ran.step_angle_deg, ran.step_volume_mm3 / 1e3]
    formats = ["{:.2f}", "{:.2f}", "{:.3f}"]
    if contact:
        columns += ["contact force (N)", "mean contact pressure (kPa)"]
        values += [ran.step_contact_force_n, ran.step_contact_pressure_kpa]
        formats += ["{:.3f}", "{:.1f}"]
    section.table(
        columns,
        [
            [f.format(x) for f, x in zip(formats, row, strict=True)]
            for row in zip(*values, strict=True)
        ],
        caption=(
            "Converged steps of the reference's sweep"
            + (
                " (the contact force between the walls of the whole actuator; the mean "
                "contact pressure over the area in contact, which grows as the walls press)"
                if contact
                else ", the last at the touch (between the steps around it)"
            )
            + f": {ran.sweep.mesh_size} tetrahedra, {stats['ndof']} unknowns, "
            f"{len(stats['steps_mpa']) - 1} load steps, {sum(stats['step_iterations'])} Newton "
            f"iterations, {ran.sweep.wall_time_s:.1f} s; stop: {stop}."
        ),
    )
    section.figure(
        figure,
        "The reference PneuNet: bending angle, cavity volume"
        + (" and the force between the walls" if contact else "")
        + " against pressure"
        + (
            ", the dashed line where the walls start to press"
            if contact
            else ", to the first touch of neighbouring walls"
        )
        + ".",
        root=root,
    )
    section.text(
        PUBLISHED_NOTE.format(angle=ran.step_angle_deg[-1], kpa=ran.step_pressure_mpa[-1] * 1e3),
        note=True,
    )
    return figure


def _mesh(section: Any, ran: Any) -> None:
    finest = ran.mesh[-1].angles_deg
    rows = []
    for row in ran.mesh:
        rows.append(
            [row.maxh_mm, row.elements, row.ndof]
            + [f"{a:.2f}" for a in row.angles_deg]
            + [f"{abs(a - f):.2f}" for a, f in zip(row.angles_deg, finest, strict=True)]
            + [f"{row.wall_time_s:.1f}"]
        )
    kpa = [f"{p * 1e3:g} kPa" for p in ran.mesh_pressures_mpa]
    section.table(
        ["element size (mm)", "tetrahedra", "unknowns"]
        + [f"θ at {k} (°)" for k in kpa]
        + [f"|Δθ| from finest at {k} (°)" for k in kpa]
        + ["s"],
        rows,
        caption=(
            "Mesh convergence of the reference, its walls touching from 6–7 kPa and pressing on "
            "each other past it (Newton from the previous converged state at each pressure). "
            "The same study: `softbend fem mesh-study --family pneunet`; to 50 kPa, every kPa "
            "a solve: `python benchmarks/bench_fem_pneunet.py --contact --study-pmax 0.05`."
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


def _verified(verify: int, rounds: int) -> str:
    if not verify:
        return "none swept by the FEM in this run"
    best = "the best design" if verify == 1 else f"the best {verify} designs"
    return (
        f"{best} swept by the FEM (the next ones while a sweep stops before the target's "
        "pressure) and, while the FEM puts it outside the tolerance, the surrogate refined "
        "on the FEM curves swept so far (residual-gp: a Gaussian process on its residuals "
        f"over the design space) and searched again, at most {rounds} times"
    )


def _fem_cell(c: Any) -> str:
    if c.fem_angle_deg is None and c.fem_meets is None and not c.fem_stop:
        return ""
    if c.fem_angle_deg is None or not math.isfinite(c.fem_angle_deg):
        return "stopped"
    return f"{c.fem_angle_deg:.2f}"


def _verdict(c: Any) -> str:
    return "" if c.fem_meets is None else ("yes" if c.fem_meets else "NO")


def _search(section: Any, ran: Any, folder: Path, root: Path) -> dict[str, str]:
    from softbend.pipeline.pneunet import REFINE_ROUNDS, SPECIFICATION_STEPS
    from softbend.reports.design_outputs import write_search

    result = ran.search
    files = write_search(result, ran.model.predictor, folder / "design")
    training = ran.training
    target = result.spec.target
    steps = ", ".join(f"{k} {v:g}" for k, v in SPECIFICATION_STEPS.items())
    section.text(
        f"Design find on a surrogate of the dataset: {training['model']} "
        f"({training['params']}), five design-grouped folds, R² {training['r2']:.3f}, "
        f"RMSE {training['rmse_deg']:.2f}°. Target: {target.describe()}; "
        f"{result.n_designs} designs on a grid of steps ({steps}); "
        f"{_verified(ran.summary['verify'], REFINE_ROUNDS)}. The same search: `softbend "
        f"train pneunet --models {training['model']} --out pn` then `softbend design find "
        f"--model pn/models/{training['model']}.json --angle {target.angle_deg:g} --at "
        f"{target.pressure_mpa:g} --verify 1 --replace-stopped --refine-rounds "
        f"{REFINE_ROUNDS} --resolution NAME=STEP ...`."
    )
    if ran.rounds:
        section.table(
            ["round", "surrogate", "design (mm)", "surrogate angle (°)", "FEM angle (°)",
             "within tolerance"],
            [
                [r.number, Path(r.model).name, str(c.design), f"{c.angle_deg:.2f}",
                 _fem_cell(c), _verdict(c)]
                for r in ran.rounds
                for c in r.verified
            ],
            caption="The designs the FEM swept, round by round: round 0 on the trained "
            "surrogate, each later one on the surrogate refined on every FEM curve before it "
            "(saved in pneunet/surrogate/rounds/).",
        )  # fmt: skip
    rows = [
        [rank, str(c.design), f"{c.angle_deg:.2f}", _fem_cell(c), _verdict(c)]
        for rank, c in enumerate(result.candidates, start=1)
    ]
    section.table(
        ["rank", "design (mm)", "surrogate angle (°)", "FEM angle (°)", "within tolerance"],
        rows,
        caption="; ".join(
            f"#{rank}: the FEM sweep stopped: {c.fem_stop}"
            for rank, c in enumerate(result.candidates, start=1)
            if c.fem_stop
        )
        or (
            f"The candidates of the last search ({Path(ran.model.path).name}), best first; "
            "the FEM swept the first."
        ),
    )
    section.figure(
        files["curves.png"],
        "θ(p) of the best designs of the last search, surrogate (lines) and FEM (circles).",
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
        ``mesh_sizes_mm``, ``mesh_pressures_mpa``, ``pmax_mpa``, ``verify`` and
        ``surrogate`` of :func:`softbend.pipeline.pneunet.run_pneunet`.
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
