"""Paper B Figs. 4 and 5 on the FEM dataset shipped with softbend (no campaign is rerun).

:func:`add_section` reads :func:`softbend.datasets.table1_fem` (verified against
its checksums), fits the standardized regression of paper B §3.3 (Fig. 4) and
searches the three surrogate families with folds of whole designs (the honest
score of an unseen actuator, primary), then scores each family's chosen
configuration with samples shuffled across designs (paper B's protocol, for
comparison; no second grid search, no refit). The FEM-trained models are saved
under ``paper_b_fem/surrogates/models`` for later use (transfer learning,
control).
"""

from __future__ import annotations

import time
from collections.abc import Callable
from pathlib import Path
from typing import Any

from softbend.reports.html import Report

#: progress(phase, done, total)
Progress = Callable[[str, int, int], None]

#: Designs of paper B's Table 1.
TABLE1_DESIGNS = 972


def _surrogates(
    samples: Any, folder: Path, seed: int, progress: Progress | None, epochs: int | None
) -> tuple[dict[str, Any], dict[str, Any]]:
    """Grouped search with saved models, then the chosen configurations under random folds."""
    from softbend.reports.surrogate_figures import training_figures
    from softbend.surrogates.features import training_data
    from softbend.surrogates.search import search
    from softbend.surrogates.workflow import train_surrogates

    def on_progress(protocol: str) -> Progress:
        def forward(phase: str, done: int, total: int) -> None:
            if progress is not None:
                progress(f"paper B FEM data: surrogates ({protocol} CV), {phase}", done, total)

        return forward

    data = training_data(samples)
    result, grouped = train_surrogates(
        data, folder, grid_name="quick", seed=seed, epochs=epochs, progress=on_progress("grouped")
    )
    grouped["files"].update(training_figures(result, folder))
    started = time.perf_counter()
    chosen = {name: [dict(fam.params)] for name, fam in result.families.items()}
    shuffled = search(
        data,
        models=list(chosen),
        grid_name="quick",
        param_grid=chosen,
        seed=seed,
        epochs=epochs,
        cv="random",
        refit=False,
        progress=on_progress("random"),
    )
    random_summary = {
        "settings": shuffled.settings,
        "seconds": time.perf_counter() - started,
        "models": {
            name: {
                "params": row["params"],
                **{k: float(row[k]) for k in ("r2", "rmse_deg", "mape_pct", "max_abs_error_deg")},
            }
            for name, row in shuffled.summary().set_index("model").iterrows()
        },
    }
    return grouped, random_summary


def add_section(
    report: Report,
    out_dir: Path,
    seed: int,
    progress: Progress | None = None,
    *,
    dataset: str | Path | None = None,
    epochs: int | None = None,
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
    """
    from softbend.analysis import (
        DEFAULT_FEATURES,
        DEFAULT_TARGET,
        correlation_matrix,
        standardized_regression,
    )
    from softbend.datasets import table1_fem, table1_fem_designs, table1_fem_provenance
    from softbend.reports import analysis_figures
    from softbend.reports.paper_b import (
        PAPER_B_FIG4,
        PAPER_B_SAMPLES,
        add_regression_tables,
        surrogate_cells,
    )
    from softbend.surrogates.workflow import PAPER_B_FIG5

    start = time.perf_counter()
    folder = out_dir / "paper_b_fem"
    folder.mkdir(parents=True, exist_ok=True)
    samples = table1_fem(dataset)
    designs = table1_fem_designs(dataset)
    provenance = table1_fem_provenance(dataset)
    converged = samples[samples["converged"]]
    done = designs[designs["status"] == "done"]
    regression = standardized_regression(samples)
    features = [*DEFAULT_FEATURES, DEFAULT_TARGET]
    figures = {
        "correlation": analysis_figures.correlation_heatmap(
            correlation_matrix(samples, features), folder / "fig4a_correlation_fem.png"
        ),
        "loadings": analysis_figures.loadings_bar(regression, folder / "fig4b_loadings_fem.png"),
        "parity": analysis_figures.parity_plot(regression, folder / "fig4c_parity_fem.png"),
    }
    grouped, shuffled = _surrogates(samples, folder / "surrogates", seed, progress, epochs)

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
        f"converging ({PAPER_B_SAMPLES} samples over 972 designs, about 30 per design), ours at "
        f"300°, the stretch limit of the material model, an inflation instability or 0.5 MPa "
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
        section.figure(figures[key], caption, root=out_dir)

    rows = []
    for name, m in grouped["models"].items():
        other = shuffled["models"].get(name, {})
        paper = PAPER_B_FIG5[name]
        rows.append(
            [
                *surrogate_cells(name, m),
                other.get("r2", ""),
                other.get("mape_pct", ""),
                f"{paper['params']}: R² {paper['r2']}, MAPE {paper['mape_pct']} %",
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
            "samples (paper B's protocol)"
        ),
    )
    section.text(
        "Grouped folds score each model on actuators it never saw; random folds score it on "
        "pressures between ones it was trained on, which is easier: the gap between the two "
        f"columns is how much paper B's protocol flatters a surrogate. MAPE leaves out |θ| < "
        f"{settings['mape_threshold_deg']:g}°. MLP {settings['mlp_epochs']} epochs (paper B "
        f"1000): `softbend train` with `--grid paper` runs paper B's grids. Paper B: "
        f"R² {PAPER_B_FIG4['r2']} for the linear model, and the surrogate figures in the last "
        "column.",
        note=True,
    )
    files = grouped["files"]
    if "fig5" in files:
        section.figure(
            Path(files["fig5"]),
            "Fig. 5 on FEM data — out-of-fold predictions (grouped CV) and error distribution",
            root=out_dir,
        )
    return {
        "seconds": time.perf_counter() - start,
        "designs_done": len(done),
        "samples_sha256": provenance["files"]["samples.parquet"]["sha256"],
        "samples": len(samples),
        "converged_samples": len(converged),
        "stops": {str(k): int(v) for k, v in stops.items()},
        "cpu_hours": provenance["cpu_time_s"] / 3600.0,
        "r2": regression.r2,
        "f_value": regression.f_value,
        "mape_pct": regression.mape_pct,
        "loadings": {str(k): float(v) for k, v in regression.coefficients["loading"].items()},
        "surrogates_grouped": {
            name: {k: m[k] for k in ("params", "r2", "rmse_deg", "mape_pct", "max_abs_error_deg")}
            for name, m in grouped["models"].items()
        },
        "surrogates_random": shuffled["models"],
    }
