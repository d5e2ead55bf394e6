"""``softbend reproduce``: the main job, the papers' pipelines end to end."""

from __future__ import annotations

import sys
from pathlib import Path

import typer

from softbend.cli import _common


def reproduce(
    out: Path = typer.Option(
        Path("results/reproduce"),
        "--out",
        "-o",
        help="Folder for the report and its files (replaced as a whole: a new or empty folder, "
        "or an earlier report).",
    ),
    seed: int = typer.Option(0, help="Seed of every random process."),
    workers: int | None = typer.Option(
        None, help="Local worker processes for the campaign (default: all cores)."
    ),
    as_json: bool = typer.Option(False, "--json", help="Print the headline figures as JSON."),
) -> None:
    """Run the papers' pipelines end to end into one report.

    Paper A's identification and paper B's campaign, analysis, surrogates,
    FEM, transfer learning and control, on built-in defaults; the report is
    index.html in the folder --out, with the data, models and figures beside it.
    The folder is written as a whole: built beside --out and swapped in when the
    report is complete, so a run that fails or is stopped leaves the previous
    report as it was. An existing --out may hold only an earlier report. The
    campaign database resumes: from the previous report, or from a run that
    failed or was stopped. The sections such a run finished are taken over by
    the next run with the same settings and the same softbend, which computes
    only the rest (both kept in a hidden folder beside --out until then).

    Example:

    \b
        softbend reproduce --out results/reproduce --workers 2
    """
    from softbend.reports.reproduce import run_reproduce

    out = Path(out)
    _common.check_output_dir(out, "--out")
    _common.check_replaceable_dir(out, "--out")
    # library_progress: the steps deep inside (a refit's epochs) are heard too
    with _common.library_progress(enabled=not as_json) as progress:
        summary = run_reproduce(
            out,
            seed=seed,
            workers=workers,
            progress=progress,
            command=" ".join(["softbend", *sys.argv[1:]]) if sys.argv[1:] else None,
        )
    if as_json:
        _common.print_json(summary)
        return
    rows = [
        [
            key,
            f"{100 * value:.2f}",
            f"{100 * summary['paper_a']['free_run_nrmse_worst'][key]:.2f}",
        ]
        for key, value in summary["paper_a"]["free_run_nrmse_mean"].items()
    ]
    _common.print_table("Paper A: held-out free-run NRMSE", ["model", "mean %", "worst %"], rows)
    b = summary["paper_b"]
    _common.print_table(
        "Paper B: Table 1 campaign and standardized regression (Fig. 4)",
        ["designs done", "failed", "R²", "MAPE %", "loading P", "loading t", "loading b"],
        [
            [
                b["done"],
                b["failed"],
                b["r2"],
                b["mape_pct"],
                b["loadings"]["pressure_mpa"],
                b["loadings"]["t_mm"],
                b["loadings"]["b_mm"],
            ]
        ],
    )
    surrogates = summary["paper_b_surrogates"]["models"]
    _common.print_table(
        "Paper B: surrogates, grouped 5-fold CV on held-out designs (Fig. 5)",
        ["model", "best configuration", "R²", "RMSE °", "MAPE %", "1 sample µs"],
        [
            [
                name,
                m["params"],
                f"{m['r2']:.6f}",
                f"{m['rmse_deg']:.3f}",
                f"{m['mape_pct']:.3f}",
                f"{m['inference_single_us']:.1f}",
            ]
            for name, m in surrogates.items()
        ],
    )
    fem = summary["paper_b_fem"]
    fits = fem["dragon_skin_30_fit"]
    _common.print_table(
        f"Paper B: Dragon Skin 30 fit and FEM sweep of ({fem['fem_design']}) (Fig. 2)",
        ["quantity", "value"],
        [
            [f"{name} fit R² / RMSE MPa", f"{f['r2']:.4f} / {f['rmse_mpa']:.4f}"]
            for name, f in fits.items()
        ]
        + [[f"FEM angle at {p} MPa (°)", f"{a:.1f}"] for p, a in fem["fem_angles_deg"].items()]
        + [["FEM sweep wall time (s)", f"{fem['fem_wall_time_s']:.0f}"]],
    )
    _common.console.print(f"report: {summary['report']}  ({summary['seconds']:.0f} s)")
