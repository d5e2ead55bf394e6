"""Paper A outputs: files of an identification run and its section of the HTML report."""

from __future__ import annotations

from pathlib import Path
from typing import TYPE_CHECKING, Any

from softbend.references import CURLING_ACTUATOR
from softbend.reports import curling_figures
from softbend.reports.html import Report, Section

if TYPE_CHECKING:  # pragma: no cover
    from softbend.identification.selection import Selection
    from softbend.identification.study import IdentificationResult


def write_identification_outputs(result: IdentificationResult, out_dir: Path) -> dict[str, Path]:
    """Write metrics (CSV), the fitted models (JSON) and paper A Figs. 5–7, 9, 10.

    The data are :func:`softbend.pipeline.paper_a.write_identification_data`'s.

    Returns
    -------
    dict
        ``{artefact name: path}``.
    """
    from softbend.pipeline.paper_a import write_identification_data

    paths = write_identification_data(result, out_dir)
    paths.update(curling_figures.all_figures(result, Path(out_dir)))
    return paths


def add_section(
    report: Report,
    result: IdentificationResult,
    paths: dict[str, Path],
    root: Path,
    selections: dict[str, Any] | None = None,
) -> None:
    """Append the paper A section (tables and figures) to ``report``; with ``selections``
    (per pressure sign, :class:`~softbend.identification.selection.Selection`), the
    models chosen by held-out free-run error beside paper A's setting."""
    config = result.config
    section = report.section("Paper A — curling actuator: NARX identification with a GG-SVR")
    synthetic = any(e.synthetic for group in result.experiments.values() for e in group)
    if synthetic:
        rest, longest, shortest = (
            CURLING_ACTUATOR[k] for k in ("rest_length_mm", "max_length_mm", "min_length_mm")
        )
        section.text(
            "All data in this section are SYNTHETIC: paper A's measurements are not public, so "
            "softbend's synthetic curling actuator (pneumatic lag, viscoelastic creep, "
            f"rate-independent hysteresis, camera noise; calibrated to L0 = {rest.value} mm, "
            f"L = {longest.value} mm at full pressure and {shortest.value} mm at full vacuum: "
            f"paper A {rest.source}, {longest.source}, {shortest.source}) generated them.",
            note=True,
        )
    counts = {sign: len(group) for sign, group in result.experiments.items()}
    section.text(
        f"Regressor φ(t) = [y(t−1) … y(t−{config.output_lags}), u(t) … "
        f"u(t−{config.input_lags - 1})], C = {config.C:g}, ε = {config.epsilon:g} "
        f"(standardized output), kernel parameters by '{config.kernel}'. Experiments: "
        + ", ".join(f"{n} {sign}" for sign, n in counts.items())
        + ". Every metric is on an experiment the model did not see "
        "(leave-one-experiment-out); NRMSE = RMSE / range of the measured output."
    )
    summary = result.summary()
    section.table(
        ["sign", "output", "mode", "NRMSE mean (%)", "NRMSE worst (%)", "R² mean", "fit mean (%)"],
        [
            [
                r.sign,
                r.output,
                r.mode,
                100 * r.nrmse_mean,
                100 * r.nrmse_max,
                r.r2_mean,
                r.fit_percent_mean,
            ]
            for r in summary.itertuples()
        ],
        caption="Held-out accuracy, mean and worst over experiments",
    )
    section.table(
        ["model", "σ (std units)", "shape γ", "clipped to 2", "support vectors", "why this shape"],
        [
            [
                f"{sign} {output}",
                p["sigma"],
                p["shape"],
                "yes" if p["shape_clipped"] else "no",
                p["n_support"],
                p.get("shape_reason") or p.get("shape_source", ""),
            ]
            for (sign, output), p in result.kernel_params.items()
        ],
        caption="Generalized-Gaussian kernel of the final models",
    )
    captions = {
        "fig5_tip_positions": "Fig. 5 — measured tip positions",
        "fig6_bending_grade": "Fig. 6 — bending grade ρ against pressure",
        "fig7_arc_length": "Fig. 7 — arc length L against pressure",
        "fig9_identified_rho": "Fig. 9 — identified ρ (held out) against measured",
        "fig10_identified_length": "Fig. 10 — identified L (held out) against measured",
    }
    for key, caption in captions.items():
        if key in paths:
            section.figure(paths[key], caption, root=root)
    section.frame(
        result.metrics.assign(nrmse_percent=100 * result.metrics["nrmse"]).drop(columns="nrmse"),
        caption="Per held-out experiment",
    )
    if selections:
        _add_selection(section, selections, result, root)


def _add_selection(
    section: Section, selections: dict[str, Selection], result: IdentificationResult, root: Path
) -> None:
    """The models chosen by held-out free-run error, beside paper A's setting."""
    from softbend.identification.timeseries import from_experiments
    from softbend.reports.identify_outputs import write_identification

    section.text(
        "Beside paper A's setting, softbend chooses the model by the error that matters: "
        "the free run of whole held-out experiments (cross-validated over the experiments "
        "of each pressure sign), among linear ARX and degree-2 polynomial NARX models "
        "(lags 1–3), paper A's GG-SVR setting and a seeded search of kernel models, each "
        "modelling ρ and L together (every output's regressor holds both outputs' lags). "
        "The one-step error is shown, never used to choose. `softbend curling identify "
        "--select` and `softbend identify` run it on any data."
    )
    rows = []
    for sign, selection in selections.items():
        table = selection.table
        keep = table[
            (table["candidate"] == selection.best)
            | (table["candidate"] == "paper-a")
            | (table["candidate"] == (selection.best_of("arx") or {}).get("candidate"))
            | (table.index < 5)
        ]
        for _, r in keep.iterrows():
            mark = " (selected)" if r["candidate"] == selection.best else ""
            rows.append(
                [
                    sign,
                    f"{r['candidate']}{mark}",
                    r["settings"],
                    r["cv_freerun_nrmse"] * 100,
                    r["cv_onestep_nrmse"] * 100,
                ]
            )
    section.table(
        ["sign", "candidate", "model", "free-run NRMSE (%)", "one-step NRMSE (%)"],
        rows,
        caption="Cross-validated on whole held-out experiments, mean over ρ and L; "
        + " ".join(s.verdict() for s in selections.values()),
    )
    for sign, selection in selections.items():
        folder = root / "paper_a" / f"selection_{sign}"
        data = from_experiments(result.experiments[sign])
        files = write_identification(selection, data, folder)
        section.figure(
            files["freerun.png"],
            f"{sign} pressure: {selection.best} run free on each experiment, fitted without it",
            root=root,
        )
