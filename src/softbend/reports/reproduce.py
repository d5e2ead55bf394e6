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
- ``pneunet/``: the second FEM family: the reference PneuNet's θ(p) and V(p), its
  mesh convergence, the main effects of the shipped PneuNet dataset, and a design
  search on a surrogate of it, the best design swept by the FEM.

Each section's computation is in :mod:`softbend.pipeline` (one module per
section, returning its results); this module and the section modules of
:mod:`softbend.reports` draw those results and write the HTML.

The folder is written as a whole: every section writes into a staging folder
beside ``out_dir`` (:func:`softbend._outdir.staged_dir`), swapped in once
``summary.json`` is written, so ``out_dir`` holds one run, never a mix of two,
and a run that fails or is killed leaves the previous report as it was. Two
things are carried over. The campaign database, so that the campaign resumes: the
newest of ``out_dir``'s (copied; the old report keeps its own) and that of a run
that failed or was killed. And the sections a failed, stopped (Ctrl-C) or killed
run finished (:mod:`softbend.reports.resume`): the next run with the same
settings and the same softbend takes them over in order and computes the rest. A
failed or stopped run moves both to the hidden folder ``.NAME.resume`` beside
``out_dir``, a killed one leaves them in its staging folder; the next run takes
them from there and removes the folder once it has finished.
"""

from __future__ import annotations

import contextlib
import logging
import math
import os
import platform
import shutil
import time
from datetime import UTC, datetime
from pathlib import Path
from typing import TYPE_CHECKING, Any

from softbend import __version__
from softbend._io import json_text, write_text_atomic
from softbend._outdir import check_replaceable, staged_dir, stale_staging
from softbend._validation import check_range
from softbend.design import DesignSpace
from softbend.pipeline import Progress
from softbend.references import FEM_DATASET
from softbend.reports.html import Report
from softbend.reports.resume import CHECKPOINTS, Sections, keep

if TYPE_CHECKING:
    from softbend.fem.options import FEMOptions

logger = logging.getLogger(__name__)

__all__ = ["MARKER", "Progress", "run_reproduce"]

#: The file every finished report folder has (written last).
MARKER = "summary.json"

#: The campaign database, relative to the report's folder, and its companion files.
_CAMPAIGN = Path("paper_b") / "campaign.duckdb"
_CAMPAIGN_SUFFIXES = ("", ".wal")


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
    phase = "paper B: surrogates, figures (Fig. 5)"
    if progress is not None:
        progress(phase, 0, 1)
    drawn = training_figures(trained.search, out_dir / "paper_b" / "surrogates")
    training = {**trained.training, "files": {**trained.training["files"], **drawn}}
    paper_b.add_surrogate_section(report, training, root=out_dir)
    if progress is not None:
        progress(phase, 1, 1)
    return {**trained.summary, "seconds": time.perf_counter() - start}


def run_reproduce(
    out_dir: str | Path,
    *,
    seed: int = 0,
    workers: int | None = None,
    progress: Progress | None = None,
    design_space: DesignSpace | None = None,
    fem_options: FEMOptions | None = None,
    fem_pmax_mpa: float | None = None,
    fem_dataset: str | Path | None = None,
    fem_dataset_epochs: int | None = None,
    transfer_options: dict[str, dict[str, Any]] | None = None,
    control_options: dict[str, Any] | None = None,
    design_options: dict[str, Any] | None = None,
    pneunet_options: dict[str, Any] | None = None,
    command: str | None = None,
) -> dict[str, Any]:
    """Run every reproducible section and write ``out_dir/index.html``.

    Parameters
    ----------
    out_dir : path
        Output folder, replaced as a whole when the run is complete: a new or
        empty folder, or an earlier report's (with ``summary.json``).
    seed : int
        Seed of every random process (synthetic data, noise, samplers).
    workers : int, optional
        Local worker processes of the campaign (default: all cores).
    progress : callable, optional
        ``progress(phase, done, total)``.
    design_space : DesignSpace, optional
        Designs of the paper B campaign (default: Table 1, 972 designs). A
        different space needs a new ``out_dir``: the campaign database of the
        previous run (or of a killed one) resumes.
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
    pneunet_options : dict, optional
        Options of the PneuNet section (:func:`softbend.reports.pneunet_section.add_section`,
        e.g. ``{"mesh_sizes_mm": (3.0,), "pmax_mpa": 0.012, "verify": 0}`` for a quick run).
    command : str, optional
        The command line that started the run, shown in the report's provenance.

    Returns
    -------
    dict
        Headline figures per section, the report path and the wall time (also
        written to ``out_dir/summary.json``).

    Raises
    ------
    ValueError
        ``out_dir`` is a file, or a folder with other files than an earlier
        report's (it would be lost when the folder is replaced).
    """
    if workers is not None:
        # Checked before any work starts, not after paper A.
        workers = int(
            check_range(
                workers,
                "workers",
                low=0,
                low_inclusive=True,
                high=4096,
                high_inclusive=True,
            )
        )
    out_dir = Path(out_dir)
    check_replaceable(out_dir, "reproduce", key="out_dir")
    _rescue_interrupted(out_dir)
    kept = _resume_dir(out_dir)
    with staged_dir(out_dir, "reproduce") as stage:
        _seed_campaign(stage, out_dir)
        try:
            summary = _run_into(
                stage,
                out_dir,
                seed=seed,
                workers=workers,
                progress=progress,
                design_space=design_space,
                fem_options=fem_options,
                fem_pmax_mpa=fem_pmax_mpa,
                fem_dataset=fem_dataset,
                fem_dataset_epochs=fem_dataset_epochs,
                transfer_options=transfer_options,
                control_options=control_options,
                design_options=design_options,
                pneunet_options=pneunet_options,
                command=command,
                kept=kept if kept.is_dir() else None,
            )
        except BaseException:
            _keep_finished(stage, out_dir)
            raise
    shutil.rmtree(kept, ignore_errors=True)  # all taken over, or of other settings
    return summary


def _run_into(
    stage: Path,
    final: Path,
    *,
    seed: int,
    workers: int | None,
    progress: Progress | None,
    design_space: DesignSpace | None,
    fem_options: FEMOptions | None,
    fem_pmax_mpa: float | None,
    fem_dataset: str | Path | None,
    fem_dataset_epochs: int | None,
    transfer_options: dict[str, dict[str, Any]] | None,
    control_options: dict[str, Any] | None,
    design_options: dict[str, Any] | None,
    pneunet_options: dict[str, Any] | None,
    command: str | None,
    kept: Path | None = None,
) -> dict[str, Any]:
    """Every section of :func:`run_reproduce` written into ``stage``, paths named under ``final``.

    The summary (returned, and written to ``stage/summary.json``, last) names
    every file where it will be once ``stage`` has replaced ``final``. Sections an
    interrupted run finished are taken over from ``kept`` (see
    :class:`~softbend.reports.resume.Sections`): each one's settings are what its
    figures depend on besides the code.
    """
    out_dir = stage  # every section writes into the staging folder
    started = datetime.now(UTC)
    report = Report(
        "softbend — reproduction report",
        subtitle=(
            f"softbend {__version__}, Python {platform.python_version()}, seed {seed}, "
            f"started {started:%Y-%m-%d %H:%M} UTC"
        ),
    )
    summary: dict[str, Any] = {"seed": seed}
    sections = Sections(
        stage, kept, report, skip=tuple(Path(f"{_CAMPAIGN}{end}") for end in _CAMPAIGN_SUFFIXES)
    )
    summary["paper_a"] = sections.run(
        "paper_a", {"seed": seed}, lambda: _paper_a(report, out_dir, seed, progress)
    )
    space_text = repr(design_space)
    summary["paper_b"] = sections.run(
        "paper_b",
        {"space": space_text},
        lambda: _paper_b(report, out_dir, workers, progress, design_space),
    )
    summary["paper_b_surrogates"] = sections.run(
        "paper_b_surrogates",
        {"seed": seed, "space": space_text},
        lambda: _paper_b_surrogates(report, out_dir, seed, progress),
    )
    from softbend.reports import paper_b_fem

    summary["paper_b_fem"] = sections.run(
        "paper_b_fem",
        {"options": repr(fem_options), "pmax_mpa": fem_pmax_mpa},
        lambda: paper_b_fem.add_section(
            report,
            out_dir,
            progress,
            options=fem_options,
            pmax_mpa=fem_pmax_mpa or paper_b_fem.FIG2_PMAX_MPA,
        ),
    )
    from softbend.reports import paper_b_fem_data

    summary["paper_b_fem_data"] = sections.run(
        "paper_b_fem_data",
        {"seed": seed, "dataset": _dataset_identity(fem_dataset), "epochs": fem_dataset_epochs},
        lambda: paper_b_fem_data.add_section(
            report, out_dir, seed, progress, dataset=fem_dataset, epochs=fem_dataset_epochs
        ),
    )
    from softbend.reports import transfer_section

    summary["transfer"] = sections.run(
        "transfer",
        {"seed": seed, "options": repr(transfer_options)},
        lambda: transfer_section.add_section(
            report, out_dir, seed, progress, options=transfer_options
        ),
    )
    from softbend.reports import control_section

    summary["control"] = sections.run(
        "control",
        {"seed": seed, "options": repr(control_options)},
        lambda: control_section.add_section(
            report, out_dir, seed, progress, **(control_options or {})
        ),
    )
    from softbend.reports import design_section

    summary["design"] = sections.run(
        "design",
        {"options": repr(design_options)},
        lambda: design_section.add_section(report, out_dir, progress, **(design_options or {})),
    )
    from softbend.reports import pneunet_section

    summary["pneunet"] = sections.run(
        "pneunet",
        {"seed": seed, "options": repr(pneunet_options)},
        lambda: pneunet_section.add_section(
            report, out_dir, progress, seed=seed, **(pneunet_options or {})
        ),
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
            ("other PneuNet settings", pneunet_options),
        )
        if value is not None
    ]
    summary["reduced_settings"] = reduced
    add_summary(report, summary, reduced=", ".join(reduced) or None)
    finished = datetime.now(UTC)
    summary["seconds"] = (finished - started).total_seconds()
    fem_data = summary["paper_b_fem_data"]
    report.provenance = {
        "command": command or f"run_reproduce({str(final)!r}, seed={seed})",
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
    if sections.resumed:
        report.provenance["sections taken over from an interrupted run"] = ", ".join(
            sections.resumed
        )
    summary["provenance"] = dict(report.provenance)
    report.write(out_dir / "index.html")
    summary = _renamed(summary, str(stage), str(final))
    summary["report"] = str(final / "index.html")
    shutil.rmtree(out_dir / CHECKPOINTS)  # a finished report is not taken over
    write_text_atomic(out_dir / MARKER, json_text(summary) + "\n")
    return summary


def _renamed(value: Any, staged: str, final: str) -> Any:
    """``value`` (a JSON-ready record) with every path under ``staged`` (text or ``Path``)
    named under ``final``."""
    if isinstance(value, dict):
        return {key: _renamed(item, staged, final) for key, item in value.items()}
    if isinstance(value, list | tuple):
        return type(value)(_renamed(item, staged, final) for item in value)
    if isinstance(value, Path):
        return Path(_renamed(str(value), staged, final))
    if isinstance(value, str) and (value == staged or value.startswith(staged + os.sep)):
        return final + value[len(staged) :]
    return value


def _campaign_time(folder: Path) -> float:
    """When the campaign database under ``folder`` last changed (-inf: there is none)."""
    if not (folder / _CAMPAIGN).is_file():
        return -math.inf
    paths = [folder / f"{_CAMPAIGN}{suffix}" for suffix in _CAMPAIGN_SUFFIXES]
    return max(path.stat().st_mtime for path in paths if path.is_file())


def _resume_dir(out_dir: Path) -> Path:
    """Where a failed or killed run leaves its campaign database for the next run."""
    return out_dir.with_name(f".{out_dir.name}.resume")


def _move_campaign(source: Path, target: Path, *, copy: bool = False) -> None:
    """Move (or copy) the campaign database under ``source`` to the same place under ``target``."""
    (target / _CAMPAIGN).parent.mkdir(parents=True, exist_ok=True)
    for suffix in _CAMPAIGN_SUFFIXES:
        origin, into = source / f"{_CAMPAIGN}{suffix}", target / f"{_CAMPAIGN}{suffix}"
        into.unlink(missing_ok=True)
        if origin.is_file():
            (shutil.copy2 if copy else os.replace)(origin, into)


def _dataset_identity(dataset: str | Path | None) -> Any:
    """What a FEM dataset folder's section depends on: its path, and its files' sizes and times.

    None (the shipped dataset) is covered by the key's digest of the package.
    """
    if dataset is None:
        return None
    folder = Path(dataset)
    files = sorted(path for path in folder.rglob("*") if path.is_file()) if folder.is_dir() else []
    return [str(folder.resolve())] + [
        [path.relative_to(folder).as_posix(), path.stat().st_size, path.stat().st_mtime_ns]
        for path in files
    ]


def _rescue_interrupted(out_dir: Path) -> None:
    """Keep what a killed run finished for this one, before its folder is removed.

    A run killed before its swap leaves its staging folder beside ``out_dir``
    (removed by :func:`~softbend._outdir.staged_dir`); a campaign database there
    newer than the one kept aside (and than ``out_dir``'s) and its finished
    sections move to :func:`_resume_dir`.
    """
    kept = _resume_dir(out_dir)
    newest = max(_campaign_time(out_dir), _campaign_time(kept))
    for folder in stale_staging(out_dir):
        when = _campaign_time(folder)
        if when > newest:
            _move_campaign(folder, kept)
            newest = when
            logger.info("Resuming the campaign of an interrupted run (%s).", folder.name)
        with contextlib.suppress(OSError):
            if taken := keep(folder, kept):
                logger.info("Taking over %s of an interrupted run.", ", ".join(taken))


def _seed_campaign(stage: Path, out_dir: Path) -> None:
    """Put the campaign database to resume into ``stage``: the one kept aside, or a copy.

    The newer of :func:`_resume_dir`'s (moved, and the folder removed) and
    ``out_dir``'s (copied: DuckDB writes in place, and the previous report keeps
    its own as it was if this run fails).
    """
    kept = _resume_dir(out_dir)
    kept_time, out_time = _campaign_time(kept), _campaign_time(out_dir)
    if kept_time > -math.inf and kept_time >= out_time:
        _move_campaign(kept, stage)
    elif out_time > -math.inf:
        _move_campaign(out_dir, stage, copy=True)
    for suffix in _CAMPAIGN_SUFFIXES:  # an older one kept aside is not resumed
        (kept / f"{_CAMPAIGN}{suffix}").unlink(missing_ok=True)


def _keep_finished(stage: Path, out_dir: Path) -> None:
    """Keep aside what a run that fails or is stopped finished, for the next run to resume.

    Its campaign database, if it went further than ``out_dir``'s, and its
    finished sections; best effort (a full disk or a read-only folder: the
    failure itself is what is reported).
    """
    kept = _resume_dir(out_dir)
    with contextlib.suppress(OSError):
        if _campaign_time(stage) > _campaign_time(out_dir):
            _move_campaign(stage, kept)
        if taken := keep(stage, kept):
            logger.info("Kept %s for the next run to take over.", ", ".join(taken))
