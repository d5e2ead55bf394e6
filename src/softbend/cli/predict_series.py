"""``softbend predict MODEL --input CSV``: an identified model run free on a new input series.

``softbend predict`` reads two kinds of model: a surrogate of ``softbend train``
(a design and pressures in, angles out) and the dynamic model of ``softbend
identify`` (its ``model.json``: an input series in, the outputs' series out).
:func:`is_series_model` tells them apart from the file; :func:`surrogate_options`
holds a surrogate to its options, :func:`predict_series` runs an identified one.

The input CSV is read as ``softbend identify`` reads its data
(:mod:`softbend.tables`: comments, limits, one-line errors naming file, line and
column). It must have the model's input columns; its time column and output
columns are optional. With every output present, their first ``max_lag``
samples are the initial conditions and the free run is scored against the rest
(NRMSE: RMSE over the output's training range, as ``softbend identify``
reports); without them the model starts at rest (the steady state of the first
input row held).
"""

from __future__ import annotations

import math
from pathlib import Path
from typing import Any

from softbend.cli import _common
from softbend.errors import InputError

__all__ = ["is_series_model", "predict_series", "surrogate_options"]

_IDENTIFY = "a model saved by 'softbend identify' (its model.json)"


def is_series_model(model: Path) -> bool:
    """Whether ``model`` is an identified dynamic model rather than a surrogate (read once)."""
    from softbend.identification.dynamics import is_identified_model

    return is_identified_model(model)


def surrogate_options(
    model: Path, design: str | None, pressures: str | None, series: Path | None, out: Path | None
) -> tuple[str, str]:
    """``(design, pressures)`` of a surrogate's prediction; the options it does not take refused.

    Raises
    ------
    InputError
        ``--input`` or ``--out`` given (they are for :data:`_IDENTIFY`), or
        ``--design`` or ``--pressures`` missing.
    """
    why = "" if Path(model).exists() else " (no such file)"
    for key, value in (("series", series), ("out", out)):
        if value is not None:
            raise InputError(f"is for {_IDENTIFY}; {model} is not one{why}", key=key)
    for key, text in (("design", design), ("pressures", pressures)):
        if text is None:
            raise InputError(
                f"is required to predict with a surrogate ({model}); an identified model "
                "takes --input instead",
                key=key,
            )
    assert design is not None and pressures is not None
    return design, pressures


def predict_series(
    model: Path,
    *,
    series: Path | None,
    out: Path | None,
    as_json: bool,
    design: str | None = None,
    pressures: str | None = None,
    strict: bool = False,
) -> None:
    """Run the identified ``model`` free on the input series of ``series``; print or write it.

    Parameters
    ----------
    model : Path
        A ``model.json`` of ``softbend identify``.
    series : Path
        The CSV of the input series (module docstring).
    out : Path, optional
        A CSV to write atomically: the time column (or ``sample``), the inputs,
        ``<output>_simulated`` and, when measured, ``<output>_measured``.
    as_json : bool
        Print the summary and the simulated outputs as JSON.
    design, pressures, strict
        A surrogate's options: refused here, naming the option.
    """
    for key, value in (("design", design), ("pressures", pressures)):
        if value is not None:
            raise InputError(
                f"is for a surrogate model; {model} is {_IDENTIFY}: give its input series "
                "with --input",
                key=key,
            )
    if strict:
        raise InputError(f"is for a surrogate model; {model} is {_IDENTIFY}", key="strict")
    if series is None:
        raise InputError(
            f"is required: {model} is a model of 'softbend identify', run on a CSV of its "
            f"input columns ({', '.join(_input_names(model))})",
            key="series",
        )
    if out is not None:
        _common.check_output_file(Path(out), "--out", inputs=(Path(model), Path(series)))

    from softbend.identification.dynamics import load_identified

    identified = load_identified(model)
    run = _run(identified, Path(series))
    if run["period_mismatch"]:
        _common.warning_line(run["period_mismatch"])
    if out is not None:
        with _common.output_errors(Path(out), "--out"):
            _write_csv(Path(out), identified, run)
    summary = _summary(identified, Path(model), Path(series), out, run)
    if as_json:
        simulated = run["simulated"]
        summary["simulated"] = {
            name: simulated[:, j].tolist() for j, name in enumerate(identified.output_names)
        }
        _common.print_json(summary)
        return
    _print_summary(identified, summary)
    if out is not None:
        _common.console.print(f"{out} written ({summary['rows']} rows).")


def _input_names(model: Path) -> list[str]:
    """The input names a saved identified model records (read without fitting anything)."""
    import json

    try:
        names = json.loads(Path(model).read_text(encoding="utf-8"))["metadata"]["inputs"]
    except (OSError, ValueError, KeyError, TypeError):
        return ["its inputs"]
    return [str(n) for n in names] if isinstance(names, list) else ["its inputs"]


def _run(identified: Any, series: Path) -> dict[str, Any]:
    """Read the series (inputs, optional time and outputs) and run the model free on it."""
    import numpy as np

    from softbend.tables import Column, TableFormat, read_table

    inputs, outputs = identified.input_names, identified.output_names
    time = identified.time_name if identified.time_name != "sample" else None
    columns = [Column(name) for name in inputs]
    columns += [Column(name, required=False) for name in outputs]
    if time is not None and time not in (*inputs, *outputs):
        columns.append(Column(time, required=False, increasing=True))
    table = read_table(series, TableFormat("input series CSV", tuple(columns),
                                           other_columns="ignore"))  # fmt: skip
    frame = table.frame
    present = [name for name in outputs if name in frame.columns]
    if present and len(present) != len(outputs):
        missing = [name for name in outputs if name not in frame.columns]
        raise InputError(
            f"must have all the model's outputs ({', '.join(outputs)}) as initial conditions, "
            f"or none to start at rest; {series} lacks {', '.join(missing)}",
            key="series",
        )
    n, lag = len(frame), identified.max_lag
    if n < lag + 1:
        raise InputError(
            f"must have at least max_lag + 1 = {lag + 1} rows for this model; {series} has {n}",
            key="series",
        )
    U = np.column_stack([frame[name].to_numpy(dtype=np.float64) for name in inputs])
    times = None
    if time is not None and time in frame.columns:
        times = frame[time].to_numpy(dtype=np.float64)  # increasing: held so by the format
    measured = None
    if present:
        measured = np.column_stack([frame[name].to_numpy(dtype=np.float64) for name in outputs])
        simulated = identified.free_run(U, measured[:lag])
    else:
        simulated = identified.free_run(U)
    mismatch = ""
    if times is not None and n > 1:
        period = float(np.median(np.diff(times)))
        if abs(period - identified.sample_period) > 0.05 * identified.sample_period:
            mismatch = (
                f"{series} is sampled every {period:g} {time} but the model was identified at "
                f"{identified.sample_period:g}: the model steps once per row, so its time "
                "scale is off by their ratio."
            )
    return {"U": U, "times": times, "measured": measured, "simulated": simulated,
            "period_mismatch": mismatch}  # fmt: skip


def _summary(
    identified: Any, model: Path, series: Path, out: Path | None, run: dict[str, Any]
) -> dict[str, Any]:
    """The JSON-ready summary: rows, duration, each output's min, max, final and NRMSE."""

    from softbend.identification.multi import FREE_RUN_MARGIN, nrmse

    simulated, measured, times = run["simulated"], run["measured"], run["times"]
    n, lag = simulated.shape[0], identified.max_lag
    duration = (
        float(times[-1] - times[0]) if times is not None else (n - 1) * identified.sample_period
    )
    unit = identified.time_unit_s
    m = identified.model
    spans = (m.y_high_ - m.y_low_) / (1.0 + 2.0 * FREE_RUN_MARGIN)  # the training ranges
    scores = None
    if measured is not None and n > lag:
        scores = nrmse(measured[lag:], simulated[lag:], spans)
    outputs = {}
    for j, name in enumerate(identified.output_names):
        column = simulated[:, j]
        outputs[name] = {
            "min": float(column.min()),
            "max": float(column.max()),
            "final": float(column[-1]),
            "nrmse": None if scores is None else float(scores[j]),
        }
    return {
        "model": str(model),
        "input": str(series),
        "rows": int(n),
        "time": identified.time_name,
        "duration": duration,
        "duration_s": None if unit is None else duration * unit,
        "start": "measured" if measured is not None else "rest",
        "outputs": outputs,
        "out": None if out is None else str(out),
    }


def _print_summary(identified: Any, summary: dict[str, Any]) -> None:
    if summary["duration_s"] is not None:
        duration = f"{summary['duration_s']:.4g} s"
    elif summary["time"] == "sample":
        duration = f"{summary['duration']:.4g} samples"
    else:
        duration = f"{summary['duration']:.4g} ({summary['time']})"
    start = (
        "from the measured outputs' first samples"
        if summary["start"] == "measured"
        else "from rest (the steady state of the first input row)"
    )
    title = f"{summary['model']} run free on {summary['input']}: {summary['rows']} rows, "
    title += f"{duration}, {start}"
    scored = summary["start"] == "measured"
    columns = ["output", "min", "max", "final"] + (["free-run NRMSE"] if scored else [])
    rows = []
    for name, figures in summary["outputs"].items():
        row = [name, *(f"{figures[k]:.4g}" for k in ("min", "max", "final"))]
        if scored:
            value = figures["nrmse"]
            row.append("—" if value is None or not math.isfinite(value) else f"{value:.4f}")
        rows.append(row)
    _common.print_table(title, columns, rows)


def _write_csv(path: Path, identified: Any, run: dict[str, Any]) -> None:
    """The series and its free run as CSV, floats as their shortest round-trip text."""
    import csv
    import io

    from softbend._io import write_text_atomic

    U, simulated, measured, times = run["U"], run["simulated"], run["measured"], run["times"]
    outputs = identified.output_names
    header = [identified.time_name if times is not None else "sample", *identified.input_names]
    header += [f"{name}_simulated" for name in outputs]
    header += [f"{name}_measured" for name in outputs] if measured is not None else []
    buffer = io.StringIO()
    writer = csv.writer(buffer, lineterminator="\n")
    writer.writerow(header)
    for t in range(U.shape[0]):
        row = [repr(float(times[t])) if times is not None else str(t)]
        row += [repr(float(v)) for v in U[t]]
        row += [repr(float(v)) for v in simulated[t]]
        row += [repr(float(v)) for v in measured[t]] if measured is not None else []
        writer.writerow(row)
    write_text_atomic(path, buffer.getvalue())
