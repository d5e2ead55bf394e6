"""``softbend analyze``: preliminary analysis of a campaign (paper B Fig. 4)."""

from __future__ import annotations

from pathlib import Path
from typing import Annotated

import typer

from softbend.cli import _common

#: Files written into ``--out``.
CORRELATION_PNG = "correlation.png"
LOADINGS_PNG = "loadings.png"
PARITY_PNG = "parity.png"
COEFFICIENTS_CSV = "coefficients.csv"
CORRELATION_CSV = "correlation.csv"

#: Everything ``analyze`` writes into ``--out`` (the folder is replaced as a whole).
FILES: tuple[str, ...] = (
    CORRELATION_PNG,
    LOADINGS_PNG,
    PARITY_PNG,
    COEFFICIENTS_CSV,
    CORRELATION_CSV,
)


def analyze(
    db: Annotated[Path, typer.Argument(help="Campaign database (DuckDB file) to analyze.")],
    out: Annotated[
        Path,
        typer.Option(
            "--out",
            "-o",
            help="Folder for the figures and tables (replaced as a whole: a new or empty "
            "folder, or an earlier result of this command).",
        ),
    ],
    mape_threshold_deg: Annotated[
        float,
        typer.Option(
            "--mape-threshold-deg",
            help="Leave samples with |angle| below this (degrees) out of the MAPE.",
        ),
    ] = 1.0,
    json_output: Annotated[bool, typer.Option("--json", help="Print the results as JSON.")] = False,
) -> None:
    """Correlations and standardized regression of a campaign.

    Uses the converged samples of the campaign database DB: Pearson
    correlations of the design parameters, pressure and bending angle, and a
    multiple linear regression of the z-scored angle on the z-scored inputs
    (loadings, t-tests, R², F, MAPE), as paper B, Figure 4. Writes
    correlation.png, loadings.png, parity.png, coefficients.csv and
    correlation.csv into the folder --out. The folder is written as a whole:
    built beside --out and swapped in when every file is complete, so a run
    that fails leaves the previous results as they were. An existing --out may
    hold only what this command writes.

    Example:

    \b
        softbend analyze table1.duckdb --out analysis
    """
    from softbend._io import write_text_atomic
    from softbend._outdir import staged_dir
    from softbend.analysis import analyze_samples
    from softbend.errors import DatasetError
    from softbend.reports.analysis_figures import campaign_analysis_figures

    if not db.exists():
        raise FileNotFoundError(f"Campaign database {str(db)!r} does not exist.")
    if db.is_dir():
        raise DatasetError(f"Campaign database {str(db)!r} is a folder, not a DuckDB file.")
    out = Path(out)
    _common.check_output_dir(out, "--out", inputs=(db,), files=FILES)
    _common.check_replaceable_dir(out, "--out", inputs=(db,))

    from softbend.campaign.store import load_samples

    samples = load_samples(db)
    if len(samples) == 0:
        raise DatasetError(f"Campaign database {str(db)!r} holds no samples to analyze.")

    analysis = analyze_samples(samples, mape_threshold=mape_threshold_deg)
    report, corr = analysis.regression, analysis.correlation

    with (
        _common.output_errors(out, "--out"),
        staged_dir(out) as stage,
        _common.as_written(stage, out),
    ):
        drawn = campaign_analysis_figures(
            analysis,
            stage,
            correlation_png=CORRELATION_PNG,
            loadings_png=LOADINGS_PNG,
            parity_png=PARITY_PNG,
        )
        coefficients = report.coefficients.to_csv(float_format="%.10g")
        write_text_atomic(stage / COEFFICIENTS_CSV, coefficients)
        write_text_atomic(stage / CORRELATION_CSV, corr.to_csv(float_format="%.10g"))
    figures = {key: out / Path(path).name for key, path in drawn.items()}
    tables = {"coefficients": out / COEFFICIENTS_CSV, "correlation": out / CORRELATION_CSV}

    if json_output:
        payload = analysis.to_dict()
        correlation = payload.pop("correlation")  # printed after "database", as before
        payload["database"] = str(db)
        payload["correlation"] = correlation
        payload["files"] = {k: str(v) for k, v in {**figures, **tables}.items()}
        _common.print_json(payload)
        return

    rows = [
        [
            str(feature),
            float(row["loading"]),
            float(row["t_value"]),
            float(row["p_value"]),
            str(row["stars"]) or "n.s.",
        ]
        for feature, row in report.coefficients.iterrows()
    ]
    _common.print_table(
        f"Standardized regression of {report.target} ({report.n_samples} samples)",
        ["feature", "loading", "t", "p", "sig"],
        rows,
    )
    summary = [
        ["R²", report.r2],
        ["adjusted R²", report.adj_r2],
        ["F", report.f_value],
        ["p(F)", report.f_pvalue],
        [f"MAPE % (|θ| ≥ {report.mape_threshold:g}°)", report.mape_pct],
        ["samples left out of MAPE", report.n_mape_excluded],
        ["RMSE (°)", report.rmse],
        ["rows excluded (non-converged / NaN)", report.n_rows_excluded],
    ]
    if report.dropped_features:
        summary.append(["constant features dropped", ", ".join(report.dropped_features)])
    _common.print_table("Fit", ["quantity", "value"], summary)
    _common.console.print(f"Figures and tables written to {out}", highlight=False)
