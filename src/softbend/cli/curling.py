"""``softbend curling``: the curling actuator of paper A (simulate, identify)."""

from __future__ import annotations

from pathlib import Path
from typing import TYPE_CHECKING, Any

import typer

from softbend.cli import _common

if TYPE_CHECKING:
    from softbend.identification.data import Experiment
    from softbend.identification.selection import Selection
    from softbend.identification.study import IdentificationConfig, IdentificationResult
    from softbend.identification.timeseries import TimeSeriesSet

    #: The free-run selection per pressure sign and the data it was made on.
    Selections = dict[str, tuple[Selection, TimeSeriesSet]]

app = typer.Typer(
    help="The curling actuator of paper A.\n\n"
    "Synthetic experiments and NARX/SVR identification of its bending.",
    no_args_is_help=True,
)


@app.command("simulate")
def simulate(
    out: Path = typer.Option(
        ...,
        "--out",
        "-o",
        help="Folder for the experiment CSV files (replaced as a whole: a new or empty folder, "
        "or an earlier result of this command).",
    ),
    experiments: int = typer.Option(6, help="Experiments per pressure sign."),
    samples: int = typer.Option(512, help="Samples per experiment."),
    dt: float = typer.Option(0.02, "--dt", help="Sample period, s."),
    seed: int = typer.Option(0, help="Seed of the experiment design and the camera noise."),
    excitation: str = typer.Option(
        "mixed", help="Pressure profiles: mixed (paper A-like) or impulsive (rare short pulses)."
    ),
    as_json: bool = typer.Option(False, "--json", help="Print a JSON summary instead of a table."),
) -> None:
    """Write synthetic curling-actuator experiments as CSV.

    Experiments at positive and at negative pressure, one CSV file each, in
    the folder --out; the data are synthetic and say so. The folder is written
    as a whole: built beside --out and swapped in when every file is complete,
    so a run that fails leaves the previous experiments as they were and a
    rerun never leaves an earlier run's experiments beside the new ones. An
    existing --out may hold only experiments this command wrote.

    Example:

    \b
        softbend curling simulate --out experiments --experiments 6
    """
    from softbend._outdir import staged_dir
    from softbend.identification.data import save_experiments
    from softbend.identification.synthetic import check_synthetic_size, synthetic_dataset

    check_synthetic_size(samples, dt)
    out = Path(out)
    _common.check_output_dir(out, "--out")
    _common.check_replaceable_dir(out, "--out")
    choice: Any = excitation  # one of EXCITATIONS: synthetic_dataset checks it
    dataset = synthetic_dataset(
        n_experiments=experiments, n_samples=samples, dt_s=dt, seed=seed, excitation=choice
    )
    all_experiments = [e for group in dataset.values() for e in group]
    with (
        _common.output_errors(out, "--out"),
        staged_dir(out) as stage,
        _common.as_written(stage, out),
    ):
        paths = [out / p.name for p in save_experiments(all_experiments, stage)]
    _print_experiments(all_experiments, paths, out, as_json)


def _print_experiments(
    experiments: list[Experiment], paths: list[Path], out: Path, as_json: bool
) -> None:
    """The written experiments: a table, or the JSON summary with ``as_json``."""
    rows = [
        [
            e.name,
            e.n_samples,
            float(e.pressure_kpa.min()) + 0.0,
            float(e.pressure_kpa.max()) + 0.0,
            str(p),
        ]
        for e, p in zip(experiments, paths, strict=True)
    ]
    if as_json:
        _common.print_json(
            {
                "out": str(out),
                "synthetic": True,
                "experiments": [
                    dict(
                        zip(["name", "n_samples", "p_min_kpa", "p_max_kpa", "path"], r, strict=True)
                    )
                    for r in rows
                ],
            }
        )
        return
    _common.print_table(
        "Synthetic curling-actuator experiments",
        ["experiment", "samples", "p min (kPa)", "p max (kPa)", "file"],
        rows,
    )


#: Everything ``curling identify`` writes into its ``--out`` folder (``--select``: the last two).
IDENTIFY_FILES: tuple[str, ...] = (
    "metrics.csv",
    "summary.csv",
    "models",
    "fig5_tip_positions.png",
    "fig6_bending_grade.png",
    "fig7_arc_length.png",
    "fig9_identified_rho.png",
    "fig10_identified_length.png",
    "selection_positive",
    "selection_negative",
)


_DATA = typer.Argument(..., help="A CSV file or a folder of CSV files.")
_IDENTIFY_OUT = typer.Option(
    ...,
    "--out",
    "-o",
    help="Folder for metrics, models and figures (replaced as a whole: a new or empty "
    "folder, or an earlier result of this command).",
)
_C = typer.Option(100.0, "--C", help="SVR penalty C (paper A calls it gamma).")
_EPSILON = typer.Option(0.1, help="SVR epsilon, in units of the standardized output.")
_OUTPUT_LAGS = typer.Option(2, help="Past outputs in the regressor.")
_INPUT_LAGS = typer.Option(2, help="Inputs in the regressor, u(t) included.")
_KERNEL = typer.Option(
    "moments", help="Kernel width/shape: 'moments' (paper A) or 'cv' (cross-validated)."
)
_MOMENTS_OF = typer.Option(
    "differences",
    help="What the fourth-moment shape is measured on: differences (the kernel's "
    "arguments x - z), regressors, or components (the pooled regressors, before).",
)
_MAX_MEMORY_MB = typer.Option(
    None,
    "--max-memory-mb",
    help="Memory the run may use, MiB; data estimated to need more are refused before "
    "reading. Default: the memory available.",
)
_SELECT = typer.Option(
    False,
    "--select",
    help="Also choose a model per pressure sign by held-out free-run error among linear, "
    "polynomial and kernel NARX models of rho and L together (out/selection_<sign>/).",
)
_IDENTIFY_JSON = typer.Option(False, "--json", help="Print metrics as JSON.")


@app.command("identify")
def identify(
    data: Path = _DATA,
    out: Path = _IDENTIFY_OUT,
    c: float = _C,
    epsilon: float = _EPSILON,
    output_lags: int = _OUTPUT_LAGS,
    input_lags: int = _INPUT_LAGS,
    kernel: str = _KERNEL,
    moments_of: str = _MOMENTS_OF,
    max_memory_mb: float | None = _MAX_MEMORY_MB,
    select: bool = _SELECT,
    as_json: bool = _IDENTIFY_JSON,
) -> None:
    """Identify NARX models of rho and L per pressure sign.

    Fits SVR-based NARX models of the bending grade rho and the arc length L
    to the experiments in DATA, one per output and pressure sign, and scores
    each held-out experiment (leave one experiment out), as paper A. The
    folder --out (with --select's subfolders) is written as a whole: built
    beside it and swapped in when every file is complete, so a run that fails
    leaves the previous results as they were. An existing --out may hold only
    what this command writes.

    Example:

    \b
        softbend curling identify experiments --out identification
    """
    from softbend.identification.data import experiment_files
    from softbend.identification.ranges import check_settings

    # every numeric option within its declared range (softbend.identification.ranges),
    # before anything is read: lags of 10**9 would allocate GiB before the first fit
    numbers: dict[str, Any] = {
        "epsilon": epsilon,
        "output_lags": output_lags,
        "input_lags": input_lags,
    }
    check_settings(C=c, max_memory_mb=max_memory_mb, **numbers)
    if not Path(data).exists():  # one line naming it, before the fitting's imports (seconds)
        experiment_files(data)

    from softbend.identification.study import IdentificationConfig, n_fits
    from softbend.identification.study import identify as run_identify

    choices: dict[str, Any] = {"kernel": kernel, "moments_of": moments_of}  # checked there
    config = IdentificationConfig(C=c, **numbers, **choices)
    out = Path(out)
    csvs = [p for p in data.iterdir() if p.suffix.lower() == ".csv"] if data.is_dir() else []
    inputs = (data, *csvs)
    _common.check_output_dir(out, "--out", inputs=inputs, files=("metrics.csv", "summary.csv"))
    _common.check_replaceable_dir(out, "--out", inputs=inputs)
    experiments = _read_experiments(data, config, max_memory_mb, as_json)
    with _common.progress_bar(
        "fitting NARX models", n_fits(experiments), enabled=not as_json
    ) as bar:
        result = run_identify(experiments, config, progress=lambda label: bar(last=label))
    selections = _select(experiments, as_json) if select else {}
    outputs = _write_identification(out, result, selections)
    _print_identification(result, outputs, selections, out, as_json)


def _read_experiments(
    data: Path, config: IdentificationConfig, max_memory_mb: float | None, quiet: bool
) -> list[Experiment]:
    """The experiments of ``data``, refused before reading when they would not fit in memory
    and checked against ``config`` (lags the data can hold) before any fit."""
    from softbend.identification.data import experiment_files, load_experiments
    from softbend.identification.resources import check_identify_memory
    from softbend.identification.study import check_experiments

    experiment_files(data)  # missing data and files over the size limit: refused first
    need = check_identify_memory(data, max_memory_mb=max_memory_mb)
    if not quiet and need.csv_bytes >= 4 * 2**20:  # long enough to be worth a line
        _common.err_console.print(
            f"reading {need.csv_bytes / 2**20:.1f} MiB of CSV (about {need.rows:,} samples)",
            highlight=False,
        )
    experiments = load_experiments(data)
    check_experiments(experiments, config)
    return experiments


def _write_identification(
    out: Path, result: IdentificationResult, selections: Selections
) -> dict[str, Path]:
    """Write the identification (and the selections) into ``out`` as a whole; the files."""
    from softbend._outdir import staged_dir
    from softbend.reports.identify_outputs import write_identification
    from softbend.reports.paper_a import write_identification_outputs

    with (
        _common.output_errors(out, "--out"),
        staged_dir(out) as stage,
        _common.as_written(stage, out),
    ):
        written = write_identification_outputs(result, stage)
        for sign, (selection, series) in selections.items():
            write_identification(selection, series, stage / f"selection_{sign}")
    return {key: out / Path(path).relative_to(stage) for key, path in written.items()}


def _print_identification(
    result: IdentificationResult,
    outputs: dict[str, Path],
    selections: Selections,
    out: Path,
    as_json: bool,
) -> None:
    """The metrics and the selections' verdicts: tables, or JSON with ``as_json``."""
    verdicts = {sign: selection.verdict() for sign, (selection, _) in selections.items()}
    if as_json:
        _common.print_json(
            {
                "metrics": result.metrics.to_dict(orient="records"),
                "summary": result.summary().to_dict(orient="records"),
                "kernel": {f"{s}/{o}": v for (s, o), v in result.kernel_params.items()},
                "files": {k: str(v) for k, v in outputs.items()},
                "selection": verdicts,
            }
        )
        return
    print_metrics(result, outputs.get("metrics"))
    for sign, verdict in verdicts.items():
        _common.console.print(f"{sign} pressure: {verdict}")
    _common.console.print(f"models, metrics and figures written to {out}")


def _select(experiments: list[Any], quiet: bool) -> dict[str, tuple[Any, Any]]:
    """The free-run selection per pressure sign and the data it was made on.

    Returns ``{sign: (selection, series)}``, written to ``out/selection_<sign>/``;
    a sign with fewer than two experiments has nothing to hold out and no entry.
    """
    from softbend.identification.selection import select_model
    from softbend.identification.study import split_by_sign
    from softbend.identification.timeseries import from_experiments

    chosen = {}
    with _common.library_progress(enabled=not quiet):
        for sign, group in split_by_sign(experiments).items():
            if len(group) < 2:
                continue  # nothing to hold out: paper A's leave-one-out says so above
            data = from_experiments(group)
            chosen[sign] = (select_model(data), data)
    return chosen


#: Held-out rows shown by :func:`print_metrics` (the best free runs); the rest are in the CSV.
BEST_ROWS = 5


def print_metrics(result, metrics_path: Path | None = None) -> None:
    """Print the summary over held-out experiments and the best free runs, compactly.

    The summary gives each pressure sign, output and mode its mean and worst
    NRMSE; below it the :data:`BEST_ROWS` held-out free runs of lowest NRMSE, and
    one line naming the file with every row (``metrics_path``, per experiment,
    output and mode).
    """
    summary = [
        [r.sign, r.output, r.mode, 100 * r.nrmse_mean, 100 * r.nrmse_max, r.r2_mean]
        for r in result.summary().itertuples()
    ]
    _common.print_table(
        "Summary over held-out experiments (leave-one-experiment-out)",
        ["sign", "output", "mode", "NRMSE mean %", "NRMSE worst %", "R² mean"],
        summary,
    )
    metrics = result.metrics
    free = metrics[metrics["mode"] == "free-run"] if "mode" in metrics else metrics
    best = free.sort_values("nrmse", na_position="last").head(BEST_ROWS)
    _common.print_table(
        f"Best {len(best)} of {len(free)} held-out free runs (lowest NRMSE)",
        ["sign", "output", "experiment", "RMSE", "NRMSE %", "R²", "fit %"],
        [
            [r.sign, r.output, r.experiment, r.rmse, 100 * r.nrmse, r.r2, r.fit_percent]
            for r in best.itertuples()
        ],
    )
    where = f" in {metrics_path}" if metrics_path is not None else ""
    _common.console.print(
        f"all {len(metrics)} held-out rows (per experiment, output and mode){where}",
        highlight=False,
    )
