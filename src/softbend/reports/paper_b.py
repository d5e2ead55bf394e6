"""Paper B data section: the design-space campaign and its preliminary analysis (Fig. 4)."""

from __future__ import annotations

from pathlib import Path
from typing import TYPE_CHECKING, Any

from softbend.references import (
    DESIGN_SPACE,
    FEM_DATASET,
    LINEAR_MODEL,
    SURROGATE_TRAINING,
    SURROGATES,
    values,
)

if TYPE_CHECKING:  # pragma: no cover
    import pandas as pd

    from softbend.analysis import RegressionReport
    from softbend.reports.html import Report, Section

#: Paper B §3.3 (FEM data, 972 designs): standardized loadings, R², F and MAPE
#: (:data:`softbend.references.LINEAR_MODEL`).
PAPER_B_FIG4: dict[str, float] = values(LINEAR_MODEL)

#: Samples of paper B's FEM dataset (§3.3).
PAPER_B_SAMPLES: int = FEM_DATASET["samples"].value


def angle_curves(
    samples: pd.DataFrame, designs: list[str], path: Path, *, backend: str = "analytical"
) -> Path:
    """Bending angle against pressure for the given design ids (one line each).

    Line styles alternate so that designs with identical curves (the analytical
    model ignores φ and lc) stay visible; a dotted line marks 360°, where the tip
    of a real actuator would reach its own base.
    """
    from matplotlib.figure import Figure

    fig = Figure(figsize=(7, 4.5))
    ax = fig.subplots()
    styles = ("-", "--", ":", "-.")
    for index, design_id in enumerate(designs):
        rows = samples[(samples["design_id"] == design_id) & samples["converged"]]
        if rows.empty:
            continue
        first = rows.iloc[0]
        label = ",".join(
            f"{first[c]:g}" for c in ("l_mm", "r_mm", "t_mm", "b_mm", "phi_deg", "lc_mm")
        )
        ax.plot(
            rows["pressure_mpa"],
            rows["angle_deg"],
            linestyle=styles[index % len(styles)],
            lw=1.6,
            label=label,
        )
    ax.axhline(360.0, color="0.4", lw=0.8, ls=":")
    ax.annotate(
        "360°: tip reaches the base",
        (0.0, 360.0),
        xytext=(2, 3),
        textcoords="offset points",
        fontsize=8,
        color="0.3",
    )
    ax.set_xlabel("pressure (MPa)")
    ax.set_ylabel("bending angle (°)")
    ax.set_title(f"{backend} backend: Fig. 7 designs (l, r, t, b, φ, lc in mm, °)")
    ax.grid(alpha=0.3)
    ax.legend(fontsize=8)
    path.parent.mkdir(parents=True, exist_ok=True)
    fig.savefig(path, dpi=130, bbox_inches="tight")
    return path


def add_section(
    report: Report,
    *,
    campaign: dict[str, Any],
    regression: RegressionReport,
    figures: dict[str, Path],
    root: Path,
) -> None:
    """Append the campaign summary and the Fig. 4 analysis to ``report``."""
    section = report.section("Paper B — design space, campaign and preliminary analysis (Fig. 4)")
    section.text(
        f"Campaign over paper B Table 1 ({campaign['n_designs']} designs, pressure "
        f"0–{DESIGN_SPACE['pressure_max_mpa'].value:g} MPa in "
        f"{DESIGN_SPACE['pressure_step_mpa'].value:g} MPa steps) with the "
        f"'{campaign['backend']}' backend: the quasi-static "
        "moment-balance model of Polygerinos et al. (no gravity; the fiber angle φ and cap "
        "length lc do not enter it). Sweeps end at the first pressure the backend cannot solve "
        "or at its physical stop. Angles above 360° mean the tip would pass its own base: "
        "the analytical model has no contact, so read them as its extrapolation. "
        "The FEM backend replaces it when available; paper B's "
        "numbers below come from its FEM data, so they are a reference, not a target.",
        note=True,
    )
    section.table(
        ["designs", "done", "failed", "samples", "run now", "wall time (s)", "designs/s"],
        [
            [
                campaign["n_designs"],
                campaign["done"],
                campaign["failed"],
                campaign["n_samples"],
                campaign.get("run_now", campaign["done"]),
                campaign["seconds"],
                "— (resumed: nothing left to run)"
                if campaign["designs_per_s"] is None
                else campaign["designs_per_s"],
            ]
        ],
        caption="Campaign",
    )
    add_regression_tables(section, regression)
    captions = {
        "curves": "Bending angle of the seven Fig. 7 actuators (curves that coincide differ "
        "only in φ or lc)",
        "correlation": "Fig. 4a — Pearson correlation of inputs and bending angle",
        "loadings": "Fig. 4b — standardized regression coefficients (loadings)",
        "parity": "Fig. 4c — multiple linear regression against the data",
    }
    for key, caption in captions.items():
        if key in figures:
            section.figure(figures[key], caption, root=root)


def surrogate_cells(name: str, model: dict[str, Any]) -> list[Any]:
    """Model, configuration, R², RMSE, MAPE, max error and inference times of a family."""
    from softbend.surrogates.families import FAMILIES

    keys = ("params", "r2", "rmse_deg", "mape_pct", "max_abs_error_deg")
    timing = ("inference_single_us", "inference_batch_ms")
    title = FAMILIES.get(name).title if name in FAMILIES else name
    return [title, *(model[k] for k in keys), *(model[k] for k in timing)]


def add_regression_tables(section: Section, regression: RegressionReport, data: str = "") -> None:
    """The loadings and the fit of paper B's linear model beside paper B's, as two tables.

    ``data`` names the data in the captions and the column (e.g. ``"FEM"``).
    """
    suffix = f" ({data} data)" if data else ""
    section.table(
        ["feature", "loading", "t", "p", "sig.", "paper B loading"],
        loadings_rows(regression),
        caption=f"Standardized multiple linear regression of the bending angle{suffix} "
        f"(paper B: {LINEAR_MODEL['pressure_mpa'].source})",
    )
    section.table(
        ["metric", f"softbend {data}".rstrip(), "paper B"],
        fit_rows(regression),
        caption=f"Fit of the linear model{suffix} (paper B: {LINEAR_MODEL['r2'].source}; "
        f"samples {FEM_DATASET['samples'].source})",
    )


def loadings_rows(regression: RegressionReport) -> list[list[Any]]:
    """Rows (feature, loading, t, p, stars, paper B's loading) of the Fig. 4 table."""
    rows = []
    for feature, row in regression.coefficients.iterrows():
        paper = PAPER_B_FIG4.get(str(feature))
        rows.append(
            [
                str(feature),
                float(row["loading"]),
                float(row["t_value"]),
                float(row["p_value"]),
                str(row["stars"]),
                "" if paper is None else paper,
            ]
        )
    return rows


def fit_rows(regression: RegressionReport) -> list[list[Any]]:
    """Rows (metric, softbend, paper B) of the linear model's fit: R², F, MAPE, samples."""
    return [
        ["R²", regression.r2, PAPER_B_FIG4["r2"]],
        ["F-value", regression.f_value, PAPER_B_FIG4["f_value"]],
        [
            f"MAPE (%; |θ| ≥ {regression.mape_threshold:g}°)",
            regression.mape_pct,
            PAPER_B_FIG4["mape_pct"],
        ],
        ["samples", float(regression.n_samples), float(PAPER_B_SAMPLES)],
    ]


def fig7_design_ids() -> list[str]:
    """Design ids of :data:`softbend.design.PAPER_B_FIG7_DESIGNS`."""
    from softbend.design import PAPER_B_FIG7_DESIGNS

    return [design.design_id for design in PAPER_B_FIG7_DESIGNS]


def add_surrogate_section(report: Report, summary: dict[str, Any], *, root: Path) -> None:
    """Append the surrogate search (paper B Fig. 5) to ``report``."""

    settings = summary["settings"]
    section = report.section("Paper B — surrogate models (Fig. 5)")
    section.text(
        f"Grid search ('{settings['grid']}' grid) with {settings['folds']}-fold cross-validation "
        f"grouped by design on the campaign above ({settings['n_samples']} samples, "
        f"{settings['n_designs']} designs): every score is that of designs the model never saw. "
        f"The best configuration of each family (lowest mean fold RMSE) is refitted on all "
        f"designs; its inference time is measured on this machine (single sample: the NumPy "
        f"fast path where the model has one). MAPE leaves out |θ| < "
        f"{settings['mape_threshold_deg']:g}°. MLP: {settings['mlp_epochs']} epochs; XGBoost: "
        f"{settings['xgb_trees']} trees. Paper B's figures come from its FEM data."
        + (
            " The 'quick' grid is this report's reduced one (its MLP is paper B's "
            f"{SURROGATE_TRAINING['mlp_hidden'].value} alone); `softbend train --grid paper` "
            "runs paper B's grids."
            if str(settings["grid"]).startswith("quick")
            else ""
        ),
        note=True,
    )
    rows = []
    for name, m in summary["models"].items():
        paper = m["paper_b"]
        rows.append(
            [
                *surrogate_cells(name, m),
                m.get("onnx_max_abs_diff_deg", ""),
                paper["params"],
                paper["r2"],
                paper["mape_pct"],
                paper["inference_ms"],
            ]
        )
    section.table(
        [
            "model",
            "best configuration",
            "R²",
            "RMSE (°)",
            "MAPE (%)",
            "max |error| (°)",
            "1 sample (µs)",
            "10 000 samples (ms)",
            "ONNX − predict (°)",
            "paper B configuration",
            "paper B R²",
            "paper B MAPE (%)",
            "paper B inference (ms)",
        ],
        rows,
        caption="Best model of each family, cross-validated on held-out designs "
        f"({SURROGATES['mlp']['r2'].cite()})",
    )
    files = summary["files"]
    if "fig5" in files:
        section.figure(
            Path(files["fig5"]),
            "Fig. 5 — out-of-fold predictions against the data, and the error distribution",
            root=root,
        )
    if "mlp_loss" in files:
        section.figure(Path(files["mlp_loss"]), "Training loss of the refitted MLP", root=root)
