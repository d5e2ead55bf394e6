"""Benchmark: ``softbend transfer loco`` with every default strategy, and ``residual-gp``'s fit.

Three cases (``--cases``, default all):

``pneunet``
    Leave one configuration out on ``examples/pneunet/measurements.csv`` (six
    actuators) with every default strategy that applies to the base, once with
    a ``plr`` and once with an ``mlp`` base, each trained by ``softbend train
    examples/pneunet/simulations.csv --models plr,mlp --seed 0`` (kept in
    ``--cache``). Budget: 60 s per base.
``lab14``
    The same on a four-parameter table of 14 actuators × 41 pressures drawn
    with the lumped model of ``examples/pneunet/generate.py`` (seeded Latin
    hypercube designs, the as-built deviations and reading noise of its
    measurement table); its simulation table is the example's. Budget: 120 s
    per base.
``gp``
    One ``residual-gp`` fit on 1 000 and on 5 000 readings of such a table
    (plr base). Budget: 5 s at 1 000.
``gp-levers`` (not by default)
    ``residual-gp`` at 1 000 readings with each lever: the hyperparameters on
    every reading or a seeded draw of 800, 400 or 200, and 3, 1 or 0 optimizer
    restarts; fit seconds and the RMSE on ten actuators it never saw.
``paper-b``
    Paper B's run (``softbend reproduce``'s transfer section): every default
    strategy on the shipped virtual lab with the shipped FEM-trained MLP; the
    mean LOCO RMSE of each strategy is what ``docs/validation.md`` reports.

Per run: each strategy's seconds (all its fits: the folds, the learning curve
and the fit on every actuator) and mean held-out RMSE, and the run's wall time.
The base's time (loading, the fits of the strategies) is in the run's wall;
training the bases is not. Run::

    PYTHONPATH=src .venv/bin/python benchmarks/bench_transfer_loco.py
"""

from __future__ import annotations

import argparse
import importlib.util
import subprocess
import sys
import time
from pathlib import Path
from types import ModuleType
from typing import Any

import numpy as np
import pandas as pd
from _record import record

ROOT = Path(__file__).resolve().parents[1]
EXAMPLE = ROOT / "examples" / "pneunet"


def _generator() -> ModuleType:
    """``examples/pneunet/generate.py`` as a module (the lumped PneuNet model)."""
    spec = importlib.util.spec_from_file_location("pneunet_generate", EXAMPLE / "generate.py")
    assert spec is not None and spec.loader is not None
    module = importlib.util.module_from_spec(spec)
    sys.modules[spec.name] = module
    spec.loader.exec_module(module)
    return module


def lab_table(n_actuators: int, n_points: int, seed: int = 0) -> pd.DataFrame:
    """``n_actuators`` built PneuNets, each read at ``n_points`` pressures, 0 to its top.

    Designs by a seeded Latin hypercube; each actuator built and read as
    ``generate.measurement_table`` builds and reads the example's six.
    """
    from dataclasses import replace

    gen = _generator()
    rng = np.random.default_rng([seed, 5])
    designs = gen.latin_hypercube_designs(n_actuators, rng)
    rows = []
    for i, design in enumerate(designs.itertuples(index=False)):
        values = tuple(design)
        build = replace(
            gen.AS_BUILT,
            wall_extra_mm=gen.AS_BUILT.wall_extra_mm + gen.WALL_EXTRA_SD_MM * rng.normal(),
        )
        precurvature = gen.PRECURVATURE_SD_DEG * rng.normal()
        p_set = np.linspace(0.0, float(gen.max_pressure_kpa(*values)[()]), n_points)
        p_read = p_set + gen.PRESSURE_NOISE_SD_KPA * rng.normal(size=n_points) * (p_set > 0)
        p_read = np.round(np.clip(p_read, 0.0, p_set[-1]), 1)
        angle = (
            gen.bending_angle_deg(p_read, *values, build=build)
            + precurvature
            + gen.ANGLE_NOISE_SD_DEG * rng.normal(size=n_points)
        )
        rows.append(
            pd.DataFrame(
                {
                    "actuator": f"L{i + 1:03d}",
                    **dict(zip(gen.DESIGN_COLUMNS, values, strict=True)),
                    "p_kpa": p_read,
                    "angle_deg": np.round(angle, 2),
                }
            )
        )
    return pd.concat(rows, ignore_index=True)[list(gen.MEASUREMENT_COLUMNS)]


def _bases(cache: Path) -> dict[str, Path]:
    """The plr and mlp bases of the example's simulation table (trained once, kept)."""
    folder = cache / "base"
    paths = {m: folder / "models" / f"{m}.json" for m in ("plr", "mlp")}
    if not all(p.is_file() for p in paths.values()):
        subprocess.run(
            [
                sys.executable,
                "-c",
                "import sys; from softbend.cli import run; sys.argv[0] = 'softbend'; run()",
                "train",
                str(EXAMPLE / "simulations.csv"),
                "--actuator",
                str(EXAMPLE / "actuator.json"),
                "--models",
                "plr,mlp",
                "--seed",
                "0",
                "-o",
                str(folder),
            ],
            check=True,
        )
    return paths


def _loco(
    measurements: list[Path] | None,
    base: Path | None,
    label: str,
    settings: dict[str, str] | None = None,
) -> dict[str, Any]:
    """One ``transfer loco`` run as the command runs it; per-strategy seconds and RMSE.

    ``measurements`` None: paper B's run as ``softbend reproduce`` makes it (the
    shipped virtual lab and FEM-trained MLP).
    """
    from softbend.transfer.against_base import load_for_base
    from softbend.transfer.base import load_base, load_base_saved
    from softbend.transfer.lab import shipped_measurements
    from softbend.transfer.loco import leave_one_configuration_out

    start, cpu_start = time.perf_counter(), time.process_time()
    if measurements is None:
        data, model = shipped_measurements(), load_base()
    else:
        saved = load_base_saved(base)
        data, _ = load_for_base(measurements, saved)
        model = saved.model
    seconds: dict[str, float] = {}
    cpu: dict[str, float] = {}
    mark = [time.perf_counter(), time.process_time()]

    def progress(done: int, total: int, name: str) -> None:
        now = [time.perf_counter(), time.process_time()]
        seconds[name], cpu[name] = now[0] - mark[0], now[1] - mark[1]
        mark[:] = now

    from softbend.actuators import SFRBA
    from softbend.transfer.loco import DEFAULT_STRATEGIES, strategy_options
    from softbend.transfer.strategies import applicable_strategies

    actuator = getattr(data, "actuator", SFRBA)  # paper B's measurements: its actuator
    names, _ = applicable_strategies(DEFAULT_STRATEGIES, model, actuator)
    options = strategy_options(names, settings or {})
    result = leave_one_configuration_out(
        data, model, names, seed=0, progress=progress, options=options
    )
    wall, cpu_all = time.perf_counter() - start, time.process_time() - cpu_start
    rmse = dict(zip(result.summary["strategy"], result.summary["rmse_deg"], strict=True))
    print(f"\n{label}: {len(data)} readings of {len(data.actuator_ids)} actuators")
    print(f"  {'strategy':<20} {'fit s':>8} {'CPU s':>8} {'LOCO RMSE °':>12}")
    for name in result.summary["strategy"]:
        print(
            f"  {name:<20} {seconds.get(name, float('nan')):8.2f} "
            f"{cpu.get(name, float('nan')):8.2f} {rmse[name]:12.3f}"
        )
    print(f"  {'total':<20} {wall:8.2f} {cpu_all:8.2f}", flush=True)
    return {"wall": wall, "cpu": cpu_all, "seconds": seconds, "cpu_seconds": cpu, "rmse": rmse}


def _readings(table: pd.DataFrame, base: Path) -> tuple[Any, Any]:
    """The base's model and ``table`` read as its measurements (as ``transfer loco`` reads)."""
    import tempfile

    from softbend.transfer.against_base import load_for_base
    from softbend.transfer.base import load_base_saved

    saved = load_base_saved(base)
    with tempfile.TemporaryDirectory() as folder:
        path = Path(folder) / "lab.csv"
        table.to_csv(path, index=False, lineterminator="\n")
        data, _ = load_for_base([path], saved)
    return saved.model, data


def _gp_fit(n_points: int, base: Path, seed: int = 0, **options: Any) -> tuple[float, float]:
    """Seconds of one ``residual-gp`` fit on ``n_points`` readings (41 per actuator)."""
    from softbend.transfer.strategies import ResidualGP

    table = lab_table(int(np.ceil(n_points / 41)), 41, seed=seed).iloc[:n_points]
    model, data = _readings(table, base)
    start, cpu = time.perf_counter(), time.process_time()
    ResidualGP(model, seed=seed, actuator=data.actuator, **options).fit(
        data.features, data.angle_deg
    )
    seconds, cpu = time.perf_counter() - start, time.process_time() - cpu
    print(
        f"residual-gp {options or ''} fit on {n_points} readings: {seconds:.2f} s "
        f"({cpu:.2f} s CPU)",
        flush=True,
    )
    return seconds, cpu


def _gp_levers(base: Path, n_points: int = 1000) -> dict[str, float]:
    """``residual-gp``'s fit seconds and held-out RMSE at ``n_points`` for each lever.

    Trained on ``n_points`` readings of a 41-pressure table (seed 0), scored on
    ten other actuators (seed 1): the hyperparameters chosen on every reading or
    on a seeded draw of ``hyper_points``, with 3, 1 or 0 restarts.
    """
    from softbend.metrics import rmse
    from softbend.transfer.strategies import ResidualGP

    model, train = _readings(lab_table(int(np.ceil(n_points / 41)), 41, seed=0), base)
    rows = np.arange(n_points)
    _, test = _readings(lab_table(10, 41, seed=1), base)
    out: dict[str, float] = {}
    print(f"\nresidual-gp levers at {n_points} readings (held out: {len(test)} readings)")
    for restarts, most in [(3, 200), (3, 400), (1, 400), (0, 400), (3, 800), (3, n_points)]:
        start, cpu = time.perf_counter(), time.process_time()
        fitted = ResidualGP(
            model, n_restarts=restarts, hyper_points=most, actuator=train.actuator
        ).fit(train.features[rows], train.angle_deg[rows])
        seconds, cpu = time.perf_counter() - start, time.process_time() - cpu
        error = rmse(test.angle_deg, fitted.predict(test.features))
        label = f"restarts {restarts}, hyper_points {most}"
        print(f"  {label:<32} {seconds:7.2f} s {cpu:7.2f} s CPU  held-out RMSE {error:.3f}°")
        out[f"gp lever {label} CPU"] = cpu
        out[f"gp lever {label} RMSE"] = error
    return out


def main(argv: list[str] | None = None) -> int:
    parser = argparse.ArgumentParser(description=__doc__.split("\n")[0])
    parser.add_argument(
        "--cases", nargs="+", default=["pneunet", "lab14", "gp", "paper-b"],
        choices=["pneunet", "lab14", "gp", "gp-levers", "paper-b"],
    )  # fmt: skip
    parser.add_argument("--gp-sizes", type=int, nargs="+", default=[1000, 5000])
    parser.add_argument("--cache", type=Path, default=ROOT / ".bench_transfer_loco")
    parser.add_argument("--notes", default="", help="Recorded with the figures.")
    parser.add_argument(
        "--set",
        action="append",
        default=[],
        metavar="[STRATEGY.]NAME=VALUE",
        help="A strategy parameter of every loco run, as transfer loco's --set.",
    )
    parser.add_argument("--no-record", action="store_true", help="Print only.")
    args = parser.parse_args(argv)

    settings = dict(item.split("=", 1) for item in args.set)
    args.cache.mkdir(parents=True, exist_ok=True)
    bases = _bases(args.cache)
    figures: dict[str, float] = {}
    units: dict[str, str] = {}

    def keep(prefix: str, run: dict[str, Any]) -> None:
        figures[f"{prefix} wall"] = run["wall"]
        figures[f"{prefix} CPU"] = run["cpu"]
        units[f"{prefix} wall"] = units[f"{prefix} CPU"] = "s"
        for name, value in run["seconds"].items():
            figures[f"{prefix} {name} fit"] = value
            figures[f"{prefix} {name} CPU"] = run["cpu_seconds"][name]
            units[f"{prefix} {name} fit"] = units[f"{prefix} {name} CPU"] = "s"
        for name, value in run["rmse"].items():
            figures[f"{prefix} {name} RMSE"] = value
            units[f"{prefix} {name} RMSE"] = "deg"

    if "pneunet" in args.cases:
        for kind, path in bases.items():
            keep(
                f"pneunet {kind}",
                _loco([EXAMPLE / "measurements.csv"], path, f"pneunet, {kind}", settings),
            )
    if "lab14" in args.cases:
        lab = args.cache / "lab14x41.csv"
        lab_table(14, 41, seed=0).to_csv(lab, index=False, lineterminator="\n")
        for kind, path in bases.items():
            keep(
                f"14x41 {kind}",
                _loco([lab], path, f"14 actuators x 41 pressures, {kind}", settings),
            )
    if "gp" in args.cases:
        for n in args.gp_sizes:
            wall, cpu = _gp_fit(n, bases["plr"])
            figures[f"residual-gp fit {n} points"] = wall
            figures[f"residual-gp fit {n} points CPU"] = cpu
            units[f"residual-gp fit {n} points"] = units[f"residual-gp fit {n} points CPU"] = "s"
    if "gp-levers" in args.cases:
        for key, value in _gp_levers(bases["plr"]).items():
            figures[key] = value
            units[key] = "deg" if key.endswith("RMSE") else "s"
    if "paper-b" in args.cases:
        keep("paper B", _loco(None, None, "paper B's virtual lab, shipped MLP", settings))
    if not args.no_record:
        record("transfer_loco", figures, units=units, notes=args.notes)
    return 0


if __name__ == "__main__":
    raise SystemExit(main())
