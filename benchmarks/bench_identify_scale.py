"""``softbend identify`` on about 50 000 rows, run as a user runs it: time, memory, result.

Builds a recording of the synthetic soft arm
(:func:`softbend.identification.arm.arm_experiments`: three chamber pressures
in, the tip's x and y out, 12 Hz) of ``--rows`` rows cut into ``--experiments``
experiments of equal length (the last 4, or 1 when there are fewer than 8, kept
for validation), writes it as one CSV file and runs the ``softbend identify``
command on it in a child process over the default candidates. Prints and
records the wall time, the child's peak resident memory, the selected model,
its validation free-run NRMSE, the band's coverage on the validation
experiments, the cores and the load average before and after, and the
command's CPU time (user + system: on a shared machine the wall time grows with
the load, the CPU time much less). The default, 19 experiments of 2632 rows
(50 008 rows), is the default arm set (17 experiments of 2640 rows) with two
more training experiments.

Usage: python benchmarks/bench_identify_scale.py [--rows 50000] [--experiments 19]
"""

from __future__ import annotations

import argparse
import json
import math
import os
import resource
import subprocess
import sys
import tempfile
import time
from pathlib import Path

from _record import record, variant_name

from softbend.identification.arm import arm_experiments
from softbend.identification.timeseries_io import save_timeseries

#: The arm's sample rate, Hz.
RATE_HZ = 12.0


def _cores() -> int:
    return len(os.sched_getaffinity(0)) if hasattr(os, "sched_getaffinity") else os.cpu_count()


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--rows", type=int, default=50_000, help="rows at least (default 50000)")
    parser.add_argument("--experiments", type=int, default=19, help="experiments (default 19)")
    args = parser.parse_args()
    n_validate = 4 if args.experiments >= 8 else 1
    n_train = args.experiments - n_validate
    if n_train < 2:
        parser.error("--experiments must leave at least 2 training experiments")
    per_experiment = math.ceil(args.rows / args.experiments)
    data = arm_experiments(
        n_train=n_train, n_validate=n_validate, duration_s=per_experiment / RATE_HZ, seed=0
    )
    rows = sum(e.n_samples for e in data.experiments)
    validation = [n for n in data.names if n.startswith("val")]
    with tempfile.TemporaryDirectory(prefix="bench-identify-scale-") as tmp:
        csv = save_timeseries(data, Path(tmp) / "arm.csv")
        out = Path(tmp) / "model"
        command = [
            sys.executable, "-c", "from softbend.cli import run; run()",
            "identify", str(csv),
            "--inputs", ",".join(data.input_names), "--outputs", ",".join(data.output_names),
            "--experiment", "experiment", "--time", data.time_name,
            "--validate-on", ",".join(validation), "--out", str(out),
        ]  # fmt: skip
        load_before = os.getloadavg()[0]
        start = time.perf_counter()
        subprocess.run(command, check=True)
        seconds = time.perf_counter() - start
        load_after = os.getloadavg()[0]
        usage = resource.getrusage(resource.RUSAGE_CHILDREN)
        peak = usage.ru_maxrss / 1024  # KiB → MiB
        cpu = usage.ru_utime + usage.ru_stime
        selection = json.loads((out / "selection.json").read_text(encoding="utf-8"))
    best = next(r for r in selection["table"] if r["candidate"] == selection["best"])
    band = selection["band"]
    label = f"soft arm, {rows:,} rows in {len(data.experiments)} experiments"
    print(f"\n{label}, {_cores()} cores, load {load_before:.1f} before, {load_after:.1f} after")
    print(
        f"wall time {seconds:.1f} s (selection {selection['seconds']:.1f} s), CPU time {cpu:.1f} s"
    )
    print(f"peak memory of the command: {peak:.0f} MiB")
    print(selection["verdict"])
    print(band["summary"])
    figures = {
        "rows": rows,
        "experiments": len(data.experiments),
        "wall time of the command": round(seconds, 1),
        "selection": round(selection["seconds"], 1),
        "CPU time of the command": round(cpu, 1),
        "peak memory of the command": round(peak),
        "selected": selection["best"],
        "selected: validation free-run NRMSE": round(float(best["validation_freerun_nrmse"]), 4),
        "90 % band: coverage on the validation experiments": round(100 * band["coverage_mean"], 1),
        "cores": _cores(),
        "load average before": round(load_before, 2),
        "load average after": round(load_after, 2),
    }
    units = {
        "wall time of the command": "s",
        "selection": "s",
        "CPU time of the command": "s",
        "peak memory of the command": "MiB",
        "90 % band: coverage on the validation experiments": "%",
    }
    default = args.rows == 50_000 and args.experiments == 19
    name = (
        "identify-scale" if default else variant_name("identify-scale", args.rows, args.experiments)
    )
    record(name, figures, units=units, notes="softbend identify run as a command on one CSV file")


if __name__ == "__main__":
    main()
