"""The main job: the papers' pipelines end to end on built-in defaults, one HTML report.

``run_reproduce(out_dir)`` writes ``out_dir/index.html`` with every section
softbend can reproduce, and the data, models and figures beside it:

- ``paper_a/``: synthetic curling-actuator experiments (CSV), the leave-one-
  experiment-out NARX/GG-SVR identification (metrics, models, Figs. 5–7, 9, 10).
- ``paper_b/``: the Table 1 campaign database (DuckDB; resumed if present), its
  Parquet export, the preliminary analysis (Fig. 4), and the surrogate models
  trained on it with the quick grid (``paper_b/surrogates/``, Fig. 5).
- ``paper_b_fem/``: the FEM sweep of the Fig. 2 design and Figs. 4 and 5 on the
  shipped FEM dataset.
- ``transfer/``: transfer learning on the shipped virtual lab (Figs. 6 and 7).
- ``control/``: closed-loop control on the simulated rig, with the lab actuator as a
  mismatched plant (Figs. 8 and 9).
- ``design/``: three design specifications answered on the shipped FEM surrogate,
  the best design of each swept by the FEM.

Each section's computation is in :mod:`softbend.pipeline` (one module per
section, returning its results); this module and the section modules of
:mod:`softbend.reports` draw those results and write the HTML.
"""

from __future__ import annotations

import logging
import os
import platform
import time
from datetime import UTC, datetime
from pathlib import Path
from typing import Any

from softbend import __version__
from softbend._io import json_text, write_text_atomic
from softbend._validation import check_range
from softbend.design import DesignSpace
from softbend.pipeline import Progress
from softbend.references import FEM_DATASET
from softbend.reports.html import Report

logger = logging.getLogger(__name__)

__all__ = ["Progress", "run_reproduce"]


def _paper_a(report: Report, out_dir: Path, seed: int, progress: Progress | None) -> dict[str, Any]:
    from softbend.pipeline.paper_a import run_paper_a
    from softbend.reports import curling_figures, paper_a

    start = time.perf_counter()
    identified = run_paper_a(out_dir, seed=seed, progress=progress)
    paths = {
        **identified.paths,
        **curling_figures.all_figures(identified.result, out_dir / "paper_a"),
    }
    paper_a.add_section(
        report, identified.result, paths, root=out_dir, selections=identified.selections
    )
    return {**identified.summary, "seconds": time.perf_counter() - start}


def _paper_b(
    report: Report,
    out_dir: Path,
    workers: int | None,
    progress: Progress | None,
    space: DesignSpace | None = None,
) -> dict[str, Any]:
    from softbend.pipeline.paper_b import run_campaign_section
    from softbend.reports import paper_b
    from softbend.reports.analysis_figures import campaign_analysis_figures

    folder = out_dir / "paper_b"
    ran = run_campaign_section(out_dir, space=space, workers=workers, progress=progress)
    samples, campaign, regression = ran.samples, ran.summary, ran.analysis.regression
    figures = {
        "curves": paper_b.angle_curves(
            samples,
            paper_b.fig7_design_ids(),
            folder / f"fig7_designs_{campaign['backend']}.png",
            backend=campaign["backend"],
        ),
        **campaign_analysis_figures(
            ran.analysis,
            folder,
            correlation_png="fig4a_correlation.png",
            loadings_png="fig4b_loadings.png",
            parity_png="fig4c_parity.png",
        ),
    }
    paper_b.add_section(
        report, campaign=campaign, regression=regression, figures=figures, root=out_dir
    )
    loadings = regression.coefficients["loading"]
    return {
        **campaign,
        "r2": regression.r2,
        "f_value": regression.f_value,
        "mape_pct": regression.mape_pct,
        "loadings": {str(k): float(v) for k, v in loadings.items()},
    }


def _paper_b_surrogates(
    report: Report, out_dir: Path, seed: int, progress: Progress | None
) -> dict[str, Any]:
    from softbend.pipeline.paper_b import train_campaign_surrogates
    from softbend.reports import paper_b
    from softbend.reports.surrogate_figures import training_figures

    start = time.perf_counter()
    trained = train_campaign_surrogates(out_dir, seed=seed, progress=progress)
    drawn = training_figures(trained.search, out_dir / "paper_b" / "surrogates")
    training = {**trained.training, "files": {**trained.training["files"], **drawn}}
    paper_b.add_surrogate_section(report, training, root=out_dir)
    return {**trained.summary, "seconds": time.perf_counter() - start}


def run_reproduce(
    out_dir: str | Path,
    *,
    seed: int = 0,
    workers: int | None = None,
    progress: Progress | None = None,
    design_space: DesignSpace | None = None,
    fem_options: Any = None,
    fem_pmax_mpa: float | None = None,
    fem_dataset: str | Path | None = None,
    fem_dataset_epochs: int | None = None,
    transfer_options: dict[str, dict[str, Any]] | None = None,
    control_options: dict[str, Any] | None = None,
    design_options: dict[str, Any] | None = None,
    command: str | None = None,
) -> dict[str, Any]:
    """Run every reproducible section and write ``out_dir/index.html``.

    Parameters
    ----------
    out_dir : path
        Output folder (created).
    seed : int
        Seed of every random process (synthetic data, noise, samplers).
    workers : int, optional
        Local worker processes of the campaign (default: all cores).
    progress : callable, optional
        ``progress(phase, done, total)``.
    design_space : DesignSpace, optional
        Designs of the paper B campaign (default: Table 1, 972 designs). A
        different space needs a new ``out_dir``: the campaign database resumes.
    fem_options, fem_pmax_mpa : optional
        Settings of the FEM sweep of the Fig. 2 design (default: the model's
        defaults, 0.17 MPa as in paper B Fig. 2b).
    fem_dataset, fem_dataset_epochs : optional
        The FEM dataset of the Figs. 4 and 5 section on FEM data (default: the
        one shipped in the package, read, never recomputed) and its MLP epochs
        (default: the quick grid's).
    transfer_options : dict, optional
        Options per transfer-learning strategy (e.g. ``{"refined": {"epochs": 30}}``
        for a quick run); default paper B's settings.
    control_options : dict, optional
        Options of the control section (:func:`softbend.reports.control_section.add_section`,
        e.g. ``{"duration_s": 2, "refine_epochs": 20}`` for a quick run).
    design_options : dict, optional
        Options of the design-search section
        (:func:`softbend.reports.design_section.add_section`, e.g.
        ``{"backend": "analytical"}`` for a quick run); default: the best design of
        each specification verified by the FEM.
    command : str, optional
        The command line that started the run, shown in the report's provenance.

    Returns
    -------
    dict
        Headline figures per section, the report path and the wall time (also
        written to ``out_dir/summary.json``).
    """
    if workers is not None:
        # Checked before any work starts, not after paper A.
        workers = int(
            check_range(
                workers,
                "workers",
                "run_reproduce",
                low=0,
                low_inclusive=True,
                high=4096,
                high_inclusive=True,
            )
        )
    out_dir = Path(out_dir)
    out_dir.mkdir(parents=True, exist_ok=True)
    started = datetime.now(UTC)
    report = Report(
        "softbend — reproduction report",
        subtitle=(
            f"softbend {__version__}, Python {platform.python_version()}, seed {seed}, "
            f"started {started:%Y-%m-%d %H:%M} UTC"
        ),
    )
    summary: dict[str, Any] = {"seed": seed}
    summary["paper_a"] = _paper_a(report, out_dir, seed, progress)
    summary["paper_b"] = _paper_b(report, out_dir, workers, progress, design_space)
    summary["paper_b_surrogates"] = _paper_b_surrogates(report, out_dir, seed, progress)
    from softbend.reports import paper_b_fem

    summary["paper_b_fem"] = paper_b_fem.add_section(
        report,
        out_dir,
        progress,
        options=fem_options,
        pmax_mpa=fem_pmax_mpa or paper_b_fem.FIG2_PMAX_MPA,
    )
    from softbend.reports import paper_b_fem_data

    summary["paper_b_fem_data"] = paper_b_fem_data.add_section(
        report, out_dir, seed, progress, dataset=fem_dataset, epochs=fem_dataset_epochs
    )
    from softbend.reports import transfer_section

    summary["transfer"] = transfer_section.add_section(
        report, out_dir, seed, progress, options=transfer_options
    )
    from softbend.reports import control_section

    summary["control"] = control_section.add_section(
        report, out_dir, seed, progress, **(control_options or {})
    )
    from softbend.reports import design_section

    summary["design"] = design_section.add_section(
        report, out_dir, progress, **(design_options or {})
    )
    from softbend.reports.summary_section import add_summary

    reduced = [
        name
        for name, value in (
            ("another design space", design_space),
            ("other FEM options", fem_options),
            ("another Fig. 2 pressure", fem_pmax_mpa),
            ("another FEM dataset", fem_dataset),
            ("fewer MLP epochs on the FEM data", fem_dataset_epochs),
            ("other transfer settings", transfer_options),
            ("other control settings", control_options),
            ("other design settings", design_options),
        )
        if value is not None
    ]
    summary["reduced_settings"] = reduced
    add_summary(report, summary, reduced=", ".join(reduced) or None)
    finished = datetime.now(UTC)
    summary["seconds"] = (finished - started).total_seconds()
    fem_data = summary["paper_b_fem_data"]
    report.provenance = {
        "command": command or f"run_reproduce({str(out_dir)!r}, seed={seed})",
        "softbend": __version__,
        "Python": f"{platform.python_version()} ({platform.python_implementation()})",
        "machine": f"{platform.system()} {platform.machine()}, {os.cpu_count()} logical CPUs",
        "seed": seed,
        "campaign workers": "all cores" if workers is None else workers,
        "FEM dataset": (
            f"{fem_data['designs_done']} of {FEM_DATASET['designs'].value} Table 1 designs, "
            f"samples.parquet SHA-256 "
            f"{fem_data['samples_sha256'][:16]}…"
        ),
        "started (UTC)": f"{started:%Y-%m-%d %H:%M:%S}",
        "finished (UTC)": f"{finished:%Y-%m-%d %H:%M:%S}",
        "wall time": f"{summary['seconds']:.0f} s",
    }
    summary["provenance"] = dict(report.provenance)
    path = report.write(out_dir / "index.html")
    summary["report"] = str(path)
    write_text_atomic(out_dir / "summary.json", json_text(summary) + "\n")
    return summary
