"""Benchmark: reading and checking a large simulation table, training plr on it, predicting.

Writes seeded four-parameter simulation tables (``design_id``, the four
parameters of ``examples/pneunet/actuator.json``, ``p_kpa`` and ``angle_deg``,
ten pressures per design, as ``examples/pneunet/simulations.csv``) of
``--rows`` and ``--big-rows`` rows into ``--cache`` (once; a later run reuses
them), then measures, in this process:

- **read**: :func:`softbend.surrogates.simulation_table.table_training_data`
  with the actuator description (the path ``softbend train TABLE --actuator``
  reads and checks a table with), best of ``--repeats``, against
  ``pandas.read_csv(engine="c")`` of the same file, best of as many, and the
  ratio of the two (the budget: at most 1.5);
- **first progress**: the seconds from the start of the read to the first
  progress report (:mod:`softbend._progress`), and the longest gap between two
  reports (or the read's start and end), on the ``--big-rows`` table;

and, each in a fresh process (the ``softbend`` command):

- **train plr**: ``softbend train BIG.csv --actuator ... --models plr
  --no-onnx`` end to end, its wall seconds and the longest time stderr stayed
  silent (the plain progress lines off a terminal);
- **predict**: ``softbend predict MODEL --design ... --pressures ...`` on the
  model that training saved, best and median of ``--predict-runs`` (after one
  warm-up run).

Run::

    .venv/bin/python benchmarks/bench_tables.py
    .venv/bin/python benchmarks/bench_tables.py --rows 200000 --big-rows 1000000 --repeats 3
    .venv/bin/python benchmarks/bench_tables.py --skip-train   # the reads only
    .venv/bin/python benchmarks/bench_tables.py --stages 15    # each stage of the read, CPU ms
"""

from __future__ import annotations

import argparse
import itertools
import os
import resource
import statistics
import subprocess
import sys
import tempfile
import threading
import time
from pathlib import Path

import numpy as np
from _record import record

ROOT = Path(__file__).resolve().parents[1]

#: The actuator the tables describe.
ACTUATOR = ROOT / "examples" / "pneunet" / "actuator.json"

#: Where the tables and the trained model are kept between runs.
CACHE = Path(tempfile.gettempdir()) / "softbend-bench-tables"

#: Pressures per design.
PRESSURES = 10


def write_table(path: Path, rows: int, seed: int = 0) -> Path:
    """A seeded simulation table of ``rows`` rows (``rows // 10`` designs) at ``path``, once."""
    if path.is_file():
        return path
    import pandas as pd

    rng = np.random.default_rng(seed)
    n = rows // PRESSURES
    chambers = rng.integers(6, 15, n)
    layers = rng.integers(1, 4, n)
    wall = np.round(rng.uniform(1.0, 3.0, n), 1)
    height = np.round(rng.uniform(8.0, 16.0, n) * 2) / 2
    height = np.maximum(height, 2 * wall + 0.5)  # the constraint 2 * wall_mm < height_mm
    top = np.round(rng.uniform(40.0, 120.0, n))
    steps = np.linspace(0.0, 1.0, PRESSURES)
    p = (top[:, None] * steps[None, :]).ravel()
    rep = np.repeat
    slope = rep(chambers * np.sqrt(height / wall) / (1.0 + 0.4 * layers), PRESSURES)
    angle = 1.5 * slope * p / (1.0 + p / 60.0) + rng.normal(0.0, 0.05, p.size) * (p > 0)
    frame = pd.DataFrame(
        {
            "design_id": rep([f"d{i:06d}" for i in range(n)], PRESSURES),
            "n_chambers": rep(chambers, PRESSURES),
            "n_layers": rep(layers, PRESSURES),
            "wall_mm": rep(wall, PRESSURES),
            "height_mm": rep(height, PRESSURES),
            "p_kpa": np.round(p, 2),
            "angle_deg": np.round(angle, 3),
        }
    )
    path.parent.mkdir(parents=True, exist_ok=True)
    temp = path.with_suffix(".tmp")
    frame.to_csv(temp, index=False)
    os.replace(temp, path)
    return path


def time_read(path: Path, repeats: int) -> dict[str, float]:
    """Best wall and CPU seconds of softbend's read-and-check and of pandas' C parser,
    interleaved (one untimed read of each first)."""
    import pandas as pd

    from softbend.actuators import actuator_from
    from softbend.surrogates.simulation_table import table_training_data

    actuator = actuator_from(str(ACTUATOR))
    pd.read_csv(path, engine="c")
    table_training_data(path, actuator=actuator)
    walls: dict[str, list[float]] = {"softbend": [], "pandas": []}
    cpus: dict[str, list[float]] = {"softbend": [], "pandas": []}
    for _ in range(repeats):
        for name, read in (
            ("pandas", lambda: pd.read_csv(path, engine="c")),
            ("softbend", lambda: table_training_data(path, actuator=actuator)),
        ):
            wall, cpu = time.perf_counter(), time.process_time()
            read()
            walls[name].append(time.perf_counter() - wall)
            cpus[name].append(time.process_time() - cpu)
    best = {name: min(values) for name, values in walls.items()}
    best_cpu = {name: min(values) for name, values in cpus.items()}
    return {
        "softbend": best["softbend"],
        "pandas": best["pandas"],
        "ratio": best["softbend"] / best["pandas"],
        "cpu ratio": best_cpu["softbend"] / best_cpu["pandas"],
    }


def _first(module: object, *names: str) -> str:
    """The first of ``names`` that ``module`` has."""
    return next(name for name in names if hasattr(module, name))


def time_stages(path: Path, repeats: int) -> dict[str, float]:
    """Mean CPU milliseconds of each stage of softbend's read over ``repeats`` reads (after one
    untimed read), and of ``pandas.read_csv(engine="c")`` read in turn with them."""
    import collections
    import functools

    import pandas as pd

    import softbend._io
    import softbend.surrogates.simulation_table as simulation_table
    import softbend.tables
    from softbend.actuators import actuator_from

    spent: dict[str, float] = collections.defaultdict(float)
    stages = [
        # the file's bytes (its text, decoded, before softbend read bytes: an older tree compares)
        (softbend._io, _first(softbend._io, "read_input_bytes", "read_input_text"), "the file"),
        (softbend.tables, "row_lines", "rows and widths (row_lines)"),
        (softbend.tables, "parse_rows", "pandas' parse and the column checks (parse_rows)"),
        (simulation_table, "data_hash", "the training data's hash"),
        (simulation_table, "table_training_data", "in all"),
    ]
    saved = [(module, name, getattr(module, name)) for module, name, _ in stages]

    def timed(function, label):
        @functools.wraps(function)
        def call(*args, **kwargs):
            start = time.process_time()
            try:
                return function(*args, **kwargs)
            finally:
                spent[label] += time.process_time() - start

        return call

    actuator = actuator_from(str(ACTUATOR))
    try:
        for module, name, label in stages:
            setattr(module, name, timed(getattr(module, name), label))
        simulation_table.table_training_data(path, actuator=actuator)
        spent.clear()
        for _ in range(repeats):
            simulation_table.table_training_data(path, actuator=actuator)
            start = time.process_time()
            pd.read_csv(path, engine="c")
            spent["pandas.read_csv(engine='c')"] += time.process_time() - start
    finally:
        for module, name, function in saved:
            setattr(module, name, function)
    return {label: 1e3 * seconds / repeats for label, seconds in spent.items()}


def time_progress(path: Path) -> dict[str, float]:
    """Seconds to the first progress report of a read, and the longest silence in it."""
    from softbend._progress import listening
    from softbend.actuators import actuator_from
    from softbend.surrogates.simulation_table import table_training_data

    actuator = actuator_from(str(ACTUATOR))
    stamps: list[float] = []
    start = time.perf_counter()
    with listening(lambda phase, done, total: stamps.append(time.perf_counter())):
        table_training_data(path, actuator=actuator)
    end = time.perf_counter()
    marks = [start, *stamps, end]
    return {
        "first": (stamps[0] - start) if stamps else float("inf"),
        "silent": max(b - a for a, b in itertools.pairwise(marks)),
        "total": end - start,
    }


def _timed_run(argv: list[str]) -> tuple[float, float, float, str, str]:
    """Wall seconds of a command, its CPU seconds (user and system), the longest time its
    stderr stayed silent and the line before that silence, and its stderr."""
    env = {**os.environ, "PYTHONPATH": str(ROOT / "src"), "COLUMNS": "200"}
    before = resource.getrusage(resource.RUSAGE_CHILDREN)
    start = time.perf_counter()
    proc = subprocess.Popen(
        argv, stdout=subprocess.PIPE, stderr=subprocess.PIPE, text=True, env=env
    )
    stamps = [start]
    lines: list[str] = []

    def drain() -> None:
        assert proc.stderr is not None
        for line in proc.stderr:
            stamps.append(time.perf_counter())
            lines.append(line)

    reader = threading.Thread(target=drain)
    reader.start()
    assert proc.stdout is not None
    proc.stdout.read()
    proc.wait()
    reader.join()
    end = time.perf_counter()
    after = resource.getrusage(resource.RUSAGE_CHILDREN)
    cpu = (after.ru_utime - before.ru_utime) + (after.ru_stime - before.ru_stime)
    stamps.append(end)
    if proc.returncode != 0:
        raise RuntimeError(f"{argv[3:5]} failed ({proc.returncode}): {''.join(lines)[-2000:]}")
    gaps = [b - a for a, b in itertools.pairwise(stamps)]
    silent = max(gaps)
    # where the longest silence was: after which line (the first gap is before the first)
    longest = gaps.index(silent)
    quiet_after = lines[longest - 1].strip() if longest > 0 else "(the start)"
    return end - start, cpu, silent, quiet_after, "".join(lines)


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--rows", type=int, default=200_000, help="rows of the read's table")
    parser.add_argument("--big-rows", type=int, default=1_000_000, help="rows of the large one")
    parser.add_argument("--repeats", type=int, default=3, help="reads timed (best counts)")
    parser.add_argument("--predict-runs", type=int, default=5, help="predictions timed")
    parser.add_argument("--cache", type=Path, default=CACHE, help="folder of the tables")
    parser.add_argument("--skip-train", action="store_true", help="time the reads only")
    parser.add_argument("--no-record", action="store_true", help="print, do not record")
    parser.add_argument(
        "--stages",
        type=int,
        default=0,
        metavar="N",
        help="only print the mean CPU ms of each stage of N reads of the --rows table",
    )
    args = parser.parse_args()
    if args.stages:
        small = write_table(args.cache / f"sims_{args.rows}.csv", args.rows)
        for label, ms in time_stages(small, args.stages).items():
            print(f"{label}: {ms:.1f} CPU ms")
        return

    small = write_table(args.cache / f"sims_{args.rows}.csv", args.rows)
    big = write_table(args.cache / f"sims_{args.big_rows}.csv", args.big_rows)
    figures: dict[str, object] = {}
    units: dict[str, str] = {}

    read = time_read(small, args.repeats)
    print(
        f"read {args.rows} rows: softbend {read['softbend']:.3f} s, pandas C "
        f"{read['pandas']:.3f} s, ratio {read['ratio']:.2f} (CPU seconds: {read['cpu ratio']:.2f})"
    )
    head = f"read {args.rows} rows"
    figures.update(
        {
            f"{head}: softbend": round(read["softbend"], 3),
            f"{head}: pandas C parser": round(read["pandas"], 3),
            f"{head}: ratio": round(read["ratio"], 2),
            f"{head}: ratio of CPU seconds": round(read["cpu ratio"], 2),
        }
    )
    units.update({f"{head}: softbend": "s", f"{head}: pandas C parser": "s"})

    progress = time_progress(big)
    print(
        f"read {args.big_rows} rows: {progress['total']:.2f} s, first progress after "
        f"{progress['first']:.3f} s, longest silence {progress['silent']:.2f} s"
    )
    head = f"read {args.big_rows} rows"
    figures.update(
        {
            head: round(progress["total"], 2),
            f"{head}: first progress": round(progress["first"], 3),
            f"{head}: longest silence": round(progress["silent"], 2),
        }
    )
    units.update({key: "s" for key in list(figures)[-3:]})

    if not args.skip_train:
        out = args.cache / "plr_model"
        cli = [sys.executable, "-c", "import sys; from softbend.cli import run; run()"]
        train = [*cli, "train", str(big), "--actuator", str(ACTUATOR), "--models", "plr"]
        wall, cpu, silent, quiet_after, log = _timed_run([*train, "--no-onnx", "--out", str(out)])
        print(log, end="")
        print(
            f"train plr on {args.big_rows} rows: {wall:.1f} s ({cpu:.1f} CPU seconds), "
            f"longest silence {silent:.1f} s, after {quiet_after!r}"
        )
        model = out / "models" / "plr.json"
        predict = [*cli, "predict", str(model), "--design", "10,2,2.0,12.0", "--pressures", "50"]
        _timed_run(predict)  # warms the disk cache
        runs = [_timed_run(predict) for _ in range(args.predict_runs)]
        walls = [run[0] for run in runs]
        cpus = [run[1] for run in runs]
        print(
            f"predict: best {min(walls):.3f} s, median {statistics.median(walls):.3f} s "
            f"(CPU seconds: best {min(cpus):.3f}, median {statistics.median(cpus):.3f})"
        )
        head = f"train plr {args.big_rows} rows"
        figures.update(
            {
                head: round(wall, 1),
                f"{head}: CPU seconds": round(cpu, 1),
                f"{head}: longest silence": round(silent, 1),
                "predict: best": round(min(walls), 3),
                "predict: median": round(statistics.median(walls), 3),
                "predict: median CPU seconds": round(statistics.median(cpus), 3),
            }
        )
        units.update({key: "s" for key in list(figures)[-6:]})

    if not args.no_record:
        record(
            "tables",
            figures,
            units=units,
            notes="softbend train's table read and check against pandas' C parser in the same "
            "process (budget: ratio <= 1.5); progress and silences on a 10^6-row read; train plr "
            "(budget 60 s, no silence over 2 s) and predict (budget 1 s) in fresh processes",
        )


if __name__ == "__main__":
    main()
