"""``softbend identify``: a NARX model of any time series, chosen by its held-out free run."""

from __future__ import annotations

import math
from dataclasses import replace
from pathlib import Path
from time import perf_counter, process_time
from typing import TYPE_CHECKING

import typer

from softbend._validation import must_be
from softbend.cli import _common
from softbend.errors import InputError

if TYPE_CHECKING:
    from softbend.identification.segments import RecordingSplit
    from softbend.identification.selection import Selection
    from softbend.identification.timeseries import TimeSeriesSet


def _names(text: str | None, key: str) -> list[str]:
    """The comma-separated names of the option whose parameter is ``key``."""
    names = [n.strip() for n in (text or "").split(",") if n.strip()]
    if text is not None and not names:
        raise InputError(must_be("at least one name", text), key=key)
    return names


DATA_ARGUMENT = typer.Argument(
    ..., help="A CSV file, or a folder of CSV files (one experiment each)."
)
INPUTS_OPTION = typer.Option(..., help="Comma-separated input columns, such as p1,p2,p3.")
OUTPUTS_OPTION = typer.Option(..., help="Comma-separated output columns, such as x,y.")
EXPERIMENT_OPTION = typer.Option(
    None,
    help="Column that splits a file into experiments (contiguous runs). Without it, "
    "one recording is split into contiguous segments: the last for validation, the "
    "others one cross-validation fold each.",
)
TIME_OPTION = typer.Option(None, help="Time column (default: the sample index).")
VALIDATE_ON_OPTION = typer.Option(
    None, help="Experiments kept out of the selection and scored at the end (comma-separated)."
)
FOLDS_OPTION = typer.Option(4, help="Cross-validation folds of whole experiments.")
SEED_OPTION = typer.Option(0, help="Seed of the kernel models' random search.")
MAX_MEMORY_MB_OPTION = typer.Option(
    None, help="Refuse data whose identification would need more memory than this, MiB."
)
OUT_OPTION = typer.Option(..., "--out", "-o", help="Folder for the model, tables, figures.")
AS_JSON_OPTION = typer.Option(False, "--json", help="Print the selection as JSON.")
SEARCH_DELAYS_OPTION = typer.Option(
    True,
    "--search-delays/--no-search-delays",
    help="Also try the degree-2 polynomial fitted by its free run with each input's delay "
    "(dead time, 0-3 samples) searched: for a plant whose inputs act late (a pneumatic "
    "line); about a third more CPU, which --no-search-delays saves.",
)


def identify(
    data: Path = DATA_ARGUMENT,
    inputs: str = INPUTS_OPTION,
    outputs: str = OUTPUTS_OPTION,
    experiment: str = EXPERIMENT_OPTION,
    time: str = TIME_OPTION,
    validate_on: str = VALIDATE_ON_OPTION,
    folds: int = FOLDS_OPTION,
    seed: int = SEED_OPTION,
    max_memory_mb: float = MAX_MEMORY_MB_OPTION,
    out: Path = OUT_OPTION,
    as_json: bool = AS_JSON_OPTION,
    search_delays: bool = SEARCH_DELAYS_OPTION,
) -> None:
    """A NARX model of any time series, chosen by its free run.

    Linear ARX and degree-2 polynomial NARX models, paper A's GG-SVR setting, a seeded
    search of kernel models, and a polynomial and a small neural NARX fitted by their
    free-run error are cross-validated on whole held-out experiments, each run free from its
    first samples; the lowest free-run error wins, and the output says when a linear model
    is the best. A kernel candidate whose one-step error already reaches the best free-run
    error so far is pruned (its remaining folds skipped; the table says after how many). The
    candidates include the polynomial whose inputs' delays (dead time) are searched
    (--no-search-delays leaves it out). Writes the selection table, the model, the held-out
    free runs with a 90 % band (<output>_low, <output>_high) and their figures into --out.
    The chosen model is read physically: each output's gain, time constant (63.2 %) and dead
    time (2 %) for a step of one standard deviation of each input, printed and recorded in
    model.json ("dynamics"). Without --experiment, one recording is split into contiguous
    segments (the last for validation, the others one fold each), recorded in selection.json
    ("split"). A constant input or output is refused, naming the column. 'softbend predict
    MODEL.json --input CSV' runs the model on a new input series.

    Example:

    \b
        softbend identify arm/ --inputs p1_kpa,p2_kpa,p3_kpa --outputs x_mm,y_mm \\
            --time time_s --validate-on val01,val02 --out arm-model
    """
    began, cpu_began = perf_counter(), process_time()
    series, held, split = _checked_series(
        data,
        inputs,
        outputs,
        experiment,
        time,
        validate_on,
        folds,
        seed,
        max_memory_mb,
        out,
        quiet=as_json,
    )
    selection = _select_and_write(
        series, held, split, folds, seed, out, quiet=as_json, delays=search_delays
    )
    seconds, cpu = perf_counter() - began, process_time() - cpu_began
    _print_identification(selection, series, out, seconds, cpu, as_json=as_json)


def _select_and_write(
    series: TimeSeriesSet,
    held: list[str] | None,
    split: RecordingSplit | None,
    folds: int,
    seed: int,
    out: Path,
    *,
    quiet: bool,
    delays: bool = True,
) -> Selection:
    """Select the model (cross-validated, scored on the held-out experiments) and write
    it with its tables and figures into ``out`` as a whole."""
    from softbend._outdir import staged_dir
    from softbend.identification.selection import default_candidates, select_model
    from softbend.reports.identify_outputs import write_identification

    candidates = default_candidates(seed, delays=delays)
    with _common.library_progress(enabled=not quiet):
        selection = select_model(
            series, validate_on=held, folds=folds, seed=seed, candidates=candidates
        )
    if split is not None:
        selection = replace(selection, split=split.to_dict())
    with (
        _common.library_progress(enabled=not quiet),
        _common.output_errors(out, "--out"),
        staged_dir(out) as stage,
    ):
        write_identification(selection, series, stage)
    return selection


def _print_identification(
    selection: Selection,
    series: TimeSeriesSet,
    out: Path,
    seconds: float,
    cpu: float,
    *,
    as_json: bool,
) -> None:
    """The selection as JSON, or its table, verdict, band, dynamics and cost."""
    from softbend.reports.identify_outputs import FILES

    if as_json:
        _common.print_json(
            {
                **selection.to_dict(),
                "total_seconds": seconds,
                "total_cpu_seconds": cpu,
                "files": {name: str(out / name) for name in FILES},
            }
        )
        return
    _print_selection(selection)
    _common.console.print(selection.verdict())
    if selection.band is not None:
        _common.console.print(selection.band.summary())
    _print_dynamics(selection)
    _common.console.print(
        _cost_line(selection, seconds, cpu, sum(e.n_samples for e in series.experiments))
    )
    _common.console.print(f"{', '.join(FILES)} written to {out}")


def _checked_series(
    data: Path,
    inputs: str,
    outputs: str,
    experiment: str | None,
    time: str | None,
    validate_on: str | None,
    folds: int,
    seed: int,
    max_memory_mb: float | None,
    out: Path,
    *,
    quiet: bool,
) -> tuple[TimeSeriesSet, list[str] | None, RecordingSplit | None]:
    """The options checked, the time series read and checked before any fit: the series,
    the experiments held out, and the split of one recording into segments (or None)."""
    from softbend.identification.data import experiment_files
    from softbend.identification.ranges import (
        FOLDS_RANGE,
        MAX_MEMORY_MB_RANGE,
        SEED_RANGE,
        check_integer,
        check_number,
    )
    from softbend.identification.resources import check_identify_memory
    from softbend.identification.selection import default_candidates
    from softbend.identification.timeseries_io import (
        check_experiments_for_lags,
        check_holdout,
        check_signals,
        load_timeseries,
    )

    # every numeric option within its declared range (softbend.identification.ranges)
    check_integer(folds, FOLDS_RANGE, "folds")
    check_integer(seed, SEED_RANGE, "seed")
    if max_memory_mb is not None:
        check_number(max_memory_mb, MAX_MEMORY_MB_RANGE, "max_memory_mb")
    _common.check_output_dir(out, "--out", inputs=(data,))
    _common.check_replaceable_dir(out, "--out", inputs=(data,))
    experiment_files(data)  # a missing path or a folder without CSV: refused first
    need = check_identify_memory(data, max_memory_mb=max_memory_mb)
    if not quiet and need.csv_bytes >= 4 * 2**20:  # long enough to be worth a line
        _common.err_console.print(
            f"reading {need.csv_bytes / 2**20:.1f} MiB of CSV (about {need.rows:,} samples)",
            highlight=False,
        )
    with _common.library_progress(enabled=not quiet):  # a large file's read, from its start
        series = load_timeseries(
            data,
            _names(inputs, "inputs"),
            _names(outputs, "outputs"),
            experiment=experiment,
            time=time,
        )
    held = _names(validate_on, "validate_on") if validate_on is not None else None
    split = None
    if len(series.experiments) == 1:  # one recording: segments of it, or a refusal
        split = _split_one_recording(series, experiment, held, folds)
        series, held = split.data, list(split.validation)
    check_holdout(series, held)
    check_signals(series, held)  # a constant or huge output: refused before any fit
    # every candidate's regressor must fit in every experiment (the longest lags: 3)
    check_experiments_for_lags(series, max(c.build(10).max_lag for c in default_candidates(seed)))
    if split is not None:  # said once the data passed its checks (an error stays one line)
        _common.err_console.print(split.summary(), highlight=False)  # also with --json
    return series, held, split


def _split_one_recording(
    series: TimeSeriesSet, experiment: str | None, held: list[str] | None, folds: int
) -> RecordingSplit:
    """The segments of a set of one recording (see softbend.identification.segments), or a
    refusal naming the option that made it one experiment or that names experiments."""
    from softbend.identification.segments import split_recording

    (only,) = series.names
    if experiment is not None:
        raise InputError(
            f"the column {experiment!r} names one experiment ({only!r}): nothing to hold out "
            "for validation; name a column with at least two experiments, or leave "
            "--experiment out to split the recording into contiguous segments",
            key="experiment",
        )
    if held is not None:
        raise InputError(
            f"names experiments, but the data is one recording ({only!r}, no --experiment "
            "column); leave --validate-on out to split it into contiguous segments for "
            "selection and validation, or give --experiment",
            key="validate_on",
        )
    return split_recording(series, folds)


def _cost_line(selection: object, seconds: float, cpu: float, rows: int) -> str:
    """What the identification took: wall and CPU time, the selection's share, peak memory,
    cores (on a shared machine the wall time grows with the load, the CPU time much less)."""
    import os

    from softbend.identification.selection import Selection

    assert isinstance(selection, Selection)
    peak = selection.peak_memory_mib
    memory = "" if peak is None else f", peak memory {peak:,.0f} MiB"
    cores = len(os.sched_getaffinity(0)) if hasattr(os, "sched_getaffinity") else os.cpu_count()
    return (
        f"{rows:,} rows identified in {seconds:.0f} s (selection {selection.seconds:.0f} s, "
        f"CPU {cpu:.0f} s){memory}, {cores} cores."
    )


def _print_selection(selection: object) -> None:
    from softbend.identification.selection import Selection

    assert isinstance(selection, Selection)
    validated = bool(selection.validation)
    columns = ["candidate", "free run (CV)", "one step (CV)"]
    columns += ["free run (validation)"] if validated else []
    columns += ["fit (s)"]
    rows = []
    for _, r in selection.table.iterrows():
        mark = " ◀" if r["candidate"] == selection.best else ""
        folds = int(r.get("pruned_after_folds", 0))
        free = (
            f"pruned after {folds} fold{'s' * (folds > 1)}"
            if folds
            else f"{r['cv_freerun_nrmse']:.4f}"
        )
        row = [f"{r['candidate']}{mark}", free]
        row.append(f"{r['cv_onestep_nrmse']:.4f}")
        if validated:
            value = r["validation_freerun_nrmse"]
            row.append("" if value != value else f"{value:.4f}")
        row.append(f"{r['fit_s']:.2f}")
        rows.append(row)
    title = (
        f"NRMSE (RMSE / output range) of {len(rows)} candidates, "
        f"{len(selection.train)} training experiments"
    )
    _common.print_table(title, columns, rows)


def _time_text(value: float | None, reading: object, selection: object) -> str:
    """A time of a step reading in s when the unit is known, else in samples."""
    from softbend.identification.dynamics import StepReading
    from softbend.identification.selection import Selection

    assert isinstance(reading, StepReading) and isinstance(selection, Selection)
    if value is None:
        return f"— ({reading.note})"
    if reading.time_unit_s is not None:
        return f"{value * reading.time_unit_s:.3g} s"
    samples = value / selection.sample_period
    return f"{samples:.3g} sample{'' if samples == 1 else 's'}"


def _print_dynamics(selection: object) -> None:
    """The chosen model's step readings: gain, time constant, delay per input → output."""
    from softbend.identification.selection import Selection

    assert isinstance(selection, Selection)
    if not selection.dynamics:
        return
    rows = []
    for r in selection.dynamics:
        defined = math.isfinite(r.gain)
        gain = f"{r.gain:.4g} {r.gain_unit}".rstrip() if defined else f"— ({r.note})"
        rows.append(
            [
                f"{r.input} → {r.output}",
                gain,
                _time_text(r.time_constant, r, selection),
                _time_text(r.delay, r, selection),
            ]
        )
    title = (
        f"{selection.best} read physically: each input stepped by one training standard "
        "deviation from its training mean"
    )
    _common.print_table(title, ["input → output", "gain", "τ (63.2 %)", "delay (2 %)"], rows)
    filters = selection.input_filters
    if filters is not None:
        values, unit = filters
        text = ", ".join(f"{name} {value:.3g} {unit}" for name, value in values.items())
        _common.console.print(f"Input filters learned with the model (first-order lag τ): {text}.")
