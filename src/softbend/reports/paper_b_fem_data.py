"""Paper B Figs. 4 and 5 on the FEM dataset shipped with softbend (no campaign is rerun).

:func:`softbend.pipeline.paper_b_fem_data.run_fem_data` reads the dataset, fits
paper B's regression and searches the surrogates under both protocols; this
module draws Figs. 4 and 5 from its results and adds the section.
"""

from __future__ import annotations

import time
from collections.abc import Sequence
from pathlib import Path
from typing import Any

from softbend.pipeline import Progress
from softbend.pipeline.paper_b_fem_data import TABLE1_DESIGNS, FEMData
from softbend.references import DESIGN_SPACE, FEM_DATASET, SURROGATE_TRAINING, SURROGATES
from softbend.reports.html import Report

__all__ = ["TABLE1_DESIGNS", "add_fem_data", "add_section"]


def add_section(
    report: Report,
    out_dir: Path,
    seed: int,
    progress: Progress | None = None,
    *,
    dataset: str | Path | None = None,
    epochs: int | None = None,
    models: Sequence[str] | None = None,
) -> dict[str, Any]:
    """Append Figs. 4 and 5 on the shipped FEM data to ``report``; return the headline figures.

    Parameters
    ----------
    report : Report
    out_dir : path
        The report's folder; figures and models go to ``out_dir/paper_b_fem``.
    seed : int
        Seed of the folds and of the models.
    progress : callable, optional
    dataset : path, optional
        A dataset folder (default: the one shipped in the package).
    epochs : int, optional
        MLP epochs (default: the quick grid's).
    models : sequence of str, optional
        Surrogate families (default: all three of paper B).
    """
    from softbend.pipeline.paper_b_fem_data import run_fem_data

    start = time.perf_counter()
    fem_data = run_fem_data(out_dir, seed, progress, dataset=dataset, epochs=epochs, models=models)
    add_fem_data(report, fem_data, out_dir)
    return {**fem_data.summary, "seconds": time.perf_counter() - start}


def add_fem_data(report: Report, fem_data: FEMData, root: Path) -> dict[str, Any]:
    """Draw Figs. 4 and 5 of ``fem_data`` into ``root/paper_b_fem``; add the section.

    Returns
    -------
    dict
        ``{"correlation", "loadings", "parity"}`` paths of the Fig. 4 panels and
        the surrogate figures (``"fig5"``, ``"mlp_loss"``) drawn.
    """
    from softbend.reports import analysis_figures
    from softbend.reports.paper_b import (
        PAPER_B_FIG4,
        PAPER_B_SAMPLES,
        add_regression_tables,
        surrogate_cells,
    )
    from softbend.reports.surrogate_figures import training_figures
    from softbend.surrogates.workflow import PAPER_B_FIG5

    folder = root / "paper_b_fem"
    designs, provenance, regression = fem_data.designs, fem_data.provenance, fem_data.regression
    samples, converged, done = fem_data.samples, fem_data.converged, fem_data.done
    grouped, shuffled = fem_data.grouped, fem_data.shuffled
    figures: dict[str, Any] = {
        "correlation": analysis_figures.correlation_heatmap(
            fem_data.correlation, folder / "fig4a_correlation_fem.png"
        ),
        "loadings": analysis_figures.loadings_bar(regression, folder / "fig4b_loadings_fem.png"),
        "parity": analysis_figures.parity_plot(regression, folder / "fig4c_parity_fem.png"),
    }
    files = {**grouped["files"], **training_figures(fem_data.search, folder / "surrogates")}

    section = report.section("Paper B — Figs. 4 and 5 on softbend's FEM data")
    complete = len(done) == TABLE1_DESIGNS
    section.text(
        f"The shipped dataset (softbend.datasets.table1_fem, checked against its SHA-256 "
        f"on loading): {len(done)} of the {TABLE1_DESIGNS} Table 1 designs swept by the 3D "
        f"FEM, {len(converged)} converged samples, {provenance['cpu_time_s'] / 3600:.1f} CPU "
        f"hours; made with: {provenance['command']}."
        + (
            ""
            if complete
            else " The campaign is not complete yet: the figures below are on "
            "the designs swept so far (every N-th design of the table, spread over the space)."
        ),
        note=True,
    )
    stops = done["stop_kind"].value_counts()
    regions = done[done["stop_region"] != ""].groupby(["stop_kind", "stop_region"]).size()
    section.table(
        ["quantity", "value"],
        [
            ["designs swept / in Table 1", f"{len(done)} / {TABLE1_DESIGNS}"],
            ["designs failed", int((designs["status"] == "failed").sum())],
            ["samples (converged)", f"{len(samples)} ({len(converged)})"],
            *[[f"designs stopped by: {k}", int(v)] for k, v in stops.items()],
            *[[f"  {k} in the {r}", int(v)] for (k, r), v in regions.items()],
            ["sweep wall time per design, median (s)", float(done["wall_time_s"].median())],
            ["CPU time, total (h)", provenance["cpu_time_s"] / 3600.0],
            ["softbend version(s)", ", ".join(provenance["softbend_versions"])],
            ["FEM options (SHA-256)", ", ".join(h[:12] for h in provenance["options_sha256"])],
        ],
        caption="The FEM dataset",
    )
    add_regression_tables(section, regression, "FEM")
    section.text(
        f"Why the numbers differ from paper B: its sweeps stopped where ABAQUS stopped "
        f"converging ({PAPER_B_SAMPLES} samples over {FEM_DATASET['designs'].value} designs, "
        f"about 30 per design; {FEM_DATASET['samples'].cite()}), ours at "
        f"300°, the stretch limit of the material model, an inflation instability or "
        f"{DESIGN_SPACE['pressure_max_mpa'].value:g} MPa "
        f"({len(converged) / max(len(done), 1):.0f} converged samples per design): the linear "
        f"model is fitted over a wider range of angles, where the angle grows faster than "
        f"linearly with pressure, so its R² and MAPE are not the same quantity. Our FEM also "
        f"carries gravity from 0 MPa and a smeared fiber model (see the FEM section).",
        note=True,
    )
    for key, caption in (
        ("correlation", "Fig. 4a on FEM data — Pearson correlation of inputs and angle"),
        ("loadings", "Fig. 4b on FEM data — standardized loadings"),
        ("parity", "Fig. 4c on FEM data — linear model against the data"),
    ):
        section.figure(figures[key], caption, root=root)

    rows = []
    for name, m in grouped["models"].items():
        other = shuffled["models"].get(name, {})
        paper = PAPER_B_FIG5.get(name)  # a family of one's own has no paper figure
        rows.append(
            [
                *surrogate_cells(name, m),
                other.get("r2", ""),
                other.get("mape_pct", ""),
                f"{paper['params']}: R² {paper['r2']}, MAPE {paper['mape_pct']} %"
                if paper
                else "—",
            ]
        )
    settings = grouped["settings"]
    section.table(
        [
            "model",
            "best configuration (grouped CV)",
            "R²",
            "RMSE (°)",
            "MAPE (%)",
            "max |error| (°)",
            "1 sample (µs)",
            "10 000 samples (ms)",
            "R², random CV",
            "MAPE (%), random CV",
            "paper B (random CV)",
        ],
        rows,
        caption=(
            f"Surrogates on FEM data, '{settings['grid']}' grid, {settings['folds']}-fold CV: "
            "grouped by design (primary) and, for the configuration it chose, over shuffled "
            f"samples (paper B's protocol; {SURROGATES['mlp']['r2'].cite()})"
        ),
    )
    section.text(
        "Grouped folds score each model on actuators it never saw; random folds score it on "
        "pressures between ones it was trained on, which is easier: the gap between the two "
        f"columns is how much paper B's protocol flatters a surrogate. MAPE leaves out |θ| < "
        f"{settings['mape_threshold_deg']:g}°. MLP {settings['mlp_epochs']} epochs (paper B "
        f"{SURROGATE_TRAINING['mlp_epochs'].value}): `softbend train` with `--grid paper` runs "
        "paper B's grids. Paper B: "
        f"R² {PAPER_B_FIG4['r2']} for the linear model, and the surrogate figures in the last "
        "column.",
        note=True,
    )
    if "fig5" in files:
        section.figure(
            Path(files["fig5"]),
            "Fig. 5 on FEM data — out-of-fold predictions (grouped CV) and error distribution",
            root=root,
        )
    figures.update({k: files[k] for k in ("fig5", "mlp_loss") if k in files})
    return figures
