"""Benchmark: paper B's MLP grid search, batched training vs one model at a time.

Paper B §4.1 searches two tanh hidden layers of 55–65 units each (121
configurations) with five-fold cross-validation grouped by design, 1000 epochs of
Adam on mini-batches of 1024 rows: 605 trainings on about 24 000 rows each.
:func:`softbend.surrogates.batched.train_mlp_grid` trains all (configuration, fold)
models in one batched tensor program; the baseline is the same code with one
model per call (M = 1), run sequentially.

Data: synthetic and smooth, of the size of paper B's set (the 972 designs of
Table 1, each swept from 0 MPa in steps of 0.005 MPa up to a design-dependent
limit: about 30 000 rows x 7), or a campaign database (``--db PATH``, read with
:func:`softbend.campaign.load_samples` and
:func:`softbend.surrogates.features.training_data`). Five grouped folds
(:class:`sklearn.model_selection.GroupKFold`, one group per design).

Printed: seconds per (configuration, fold) for E epochs, batched and sequential,
the speed-up, and the projected time of the full paper grid (121 configurations x
5 folds x 1000 epochs) from the measured cost per model-epoch. Run::

    taskset -c 0,1 .venv/bin/python benchmarks/bench_mlp_search.py           # K=8, E=20
    .venv/bin/python benchmarks/bench_mlp_search.py --configs 4 --epochs 5 --json

Training paths side by side (``--variants``, one process, the same data and grid):
each variant trains the grid once for one epoch (cold: CUDA context, handles,
compilation) and once for E epochs, waiting for the device at the end of every
epoch; the steady seconds per epoch are those of epochs 2..E (set-up, the first
epoch, graph capture and compilation left out), from which the full grid is
projected. On a CUDA device the E-epoch run is profiled (``torch.profiler``): the
time the GPU ran kernels, copies or fills inside a profiler range over epochs
2..E, over the range's length, is the GPU busy fraction of the epoch loop. Variants are
``+``-joined options of :func:`~softbend.surrogates.batched.train_mlp_grid`:
``host`` / ``device`` (the shuffle), ``graph`` / ``nograph``, ``tf32``, ``compile``::

    python benchmarks/bench_mlp_search.py --fem --configs 121 --epochs 5 --device cuda \
        --variants host+nograph,device+nograph,device+graph,device+graph+tf32

The exhaustive search itself (``--search``): :func:`softbend.surrogates.search.search`
of the paper grid on the shipped FEM data, 1000 epochs, refit included, with the
chosen configuration and its grouped-CV scores::

    python benchmarks/bench_mlp_search.py --search --device cuda [--tf32]
"""

from __future__ import annotations

import argparse
import itertools
import json
import os
import subprocess
import time

import numpy as np
import torch
from _record import record, variant_name
from sklearn.model_selection import GroupKFold

from softbend.references import SURROGATE_TRAINING
from softbend.surrogates.batched import estimate_pass_bytes, train_mlp_grid

# Paper B §4.1: hidden units 55-65 in each layer, five folds, 1000 epochs.
_UNITS_LOW, _UNITS_HIGH = SURROGATE_TRAINING["mlp_hidden_units"].value
_UNITS = range(_UNITS_LOW, _UNITS_HIGH + 1)
PAPER_GRID = [(h1, h2) for h1 in _UNITS for h2 in _UNITS]
PAPER_FOLDS: int = SURROGATE_TRAINING["folds"].value
PAPER_EPOCHS: int = SURROGATE_TRAINING["mlp_epochs"].value


def synthetic_data(seed: int = 0) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
    """Smooth stand-in for paper B's FEM set: (X, angle_deg, design groups)."""
    rng = np.random.default_rng(seed)
    designs = itertools.product(
        (100, 120, 140, 160), (6, 8, 10), (2, 3, 4), (2, 3, 4), (5, 10, 15), (8, 10, 12)
    )
    rows, groups = [], []
    for k, (length, r, t, b, phi, lc) in enumerate(designs):
        p_max = 0.08 + 0.035 * (t - 2) + 0.035 * (b - 2) + rng.uniform(-0.02, 0.02)
        pressures = np.arange(0.0, p_max + 1e-9, 0.005)
        rows.append(
            np.column_stack([np.tile([length, r, t, b, phi, lc], (pressures.size, 1)), pressures])
        )
        groups.append(np.full(pressures.size, k))
    X = np.vstack(rows)
    length, r, t, b, phi, lc, p = X.T
    stiffness = t**0.7 * b**0.4 * (1 + 0.03 * phi)
    y = (
        200
        * np.tanh(1.5 * p * length / 130 * (r / 8) ** 1.5 / stiffness * 10)
        * (1 - 0.02 * (lc - 10))
    )
    return X, y, np.concatenate(groups)


def load_data(args: argparse.Namespace) -> tuple[np.ndarray, np.ndarray, np.ndarray, str]:
    if args.fem:
        from softbend.datasets import table1_fem
        from softbend.surrogates.features import training_data

        data = training_data(table1_fem())
        return data.X, data.y, data.groups, "shipped table1_fem"
    if args.db is None:
        X, y, groups = synthetic_data(args.seed)
        return X, y, groups, "synthetic"
    from softbend.campaign import load_samples
    from softbend.surrogates.features import training_data

    data = training_data(load_samples(args.db))
    return data.X, data.y, data.groups, str(args.db)


def pick_configs(k: int) -> list[tuple[int, int]]:
    """K configurations spread evenly over the paper grid (55–65 x 55–65)."""
    idx = np.unique(np.linspace(0, len(PAPER_GRID) - 1, k).round().astype(int))
    return [PAPER_GRID[i] for i in idx]


def main(argv: list[str] | None = None) -> int:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--configs", type=int, default=8, help="K configurations (default 8)")
    parser.add_argument("--epochs", type=int, default=20, help="E epochs (default 20)")
    parser.add_argument("--batch-size", type=int, default=1024)
    parser.add_argument("--device", default="auto", choices=("auto", "cpu", "cuda"))
    parser.add_argument(
        "--threads",
        type=int,
        default=None,
        help="torch CPU threads (default: the CPUs this process may run on)",
    )
    parser.add_argument(
        "--sequential",
        type=int,
        default=None,
        help="time only this many one-at-a-time trainings (default: all K x 5)",
    )
    parser.add_argument("--db", default=None, help="campaign database instead of synthetic data")
    parser.add_argument("--fem", action="store_true", help="the shipped FEM data (51 965 rows)")
    parser.add_argument("--seed", type=int, default=0)
    parser.add_argument("--json", action="store_true", help="print one JSON object")
    parser.add_argument(
        "--variants", default=None, help="compare training paths, e.g. host+nograph,device+graph"
    )
    parser.add_argument(
        "--search", action="store_true", help="time the exhaustive paper-grid search and refit"
    )
    parser.add_argument("--tf32", action="store_true", help="--search: allow TF32 products")
    parser.add_argument(
        "--search-epochs", type=int, default=PAPER_EPOCHS, help="--search: MLP epochs (1000)"
    )
    args = parser.parse_args(argv)
    if args.search:
        return run_search(args)
    if args.variants:
        return run_variants(args)

    threads = args.threads or len(os.sched_getaffinity(0))
    X, y, groups, source = load_data(args)
    splits = list(GroupKFold(n_splits=PAPER_FOLDS).split(X, y, groups))
    configs = pick_configs(args.configs)
    common = dict(
        epochs=args.epochs,
        batch_size=args.batch_size,
        seed=args.seed,
        device=args.device,
        num_threads=threads,
    )

    n_models = len(configs) * len(splits)
    batched = train_mlp_grid(X, y, splits, configs, **common)
    batched_per_model_epoch = batched.elapsed_s / (n_models * args.epochs)

    jobs = [(c, s) for c in configs for s in splits]
    jobs = jobs[: args.sequential] if args.sequential else jobs
    start = time.perf_counter()
    for config, split in jobs:
        train_mlp_grid(X, y, [split], [config], **common)
    sequential_s = time.perf_counter() - start
    sequential_per_model_epoch = sequential_s / (len(jobs) * args.epochs)

    full_models = len(PAPER_GRID) * PAPER_FOLDS
    n_train_max = max(train.size for train, _ in splits)
    full_pass_gb = (
        estimate_pass_bytes(full_models, X.shape[1], 65, 65, args.batch_size, n_train_max) / 1e9
    )
    val_mape = [
        float(
            np.mean(
                np.abs(m.val_pred_deg - y[m.val_index]) / np.maximum(np.abs(y[m.val_index]), 1.0)
            )
        )
        for m in batched.models
    ]
    report = {
        "data": source,
        "n_rows": int(X.shape[0]),
        "n_designs": int(np.unique(groups).size),
        "device": batched.device,
        "threads": threads,
        "configs": configs,
        "folds": len(splits),
        "epochs": args.epochs,
        "batch_size": args.batch_size,
        "models_batched": n_models,
        "models_sequential": len(jobs),
        "batched_s": batched.elapsed_s,
        "sequential_s": sequential_s,
        "batched_s_per_config_fold": batched.elapsed_s / n_models,
        "sequential_s_per_config_fold": sequential_s / len(jobs),
        "speedup": sequential_per_model_epoch / batched_per_model_epoch,
        "projected_full_grid_batched_h": batched_per_model_epoch
        * full_models
        * PAPER_EPOCHS
        / 3600,
        "projected_full_grid_sequential_h": sequential_per_model_epoch
        * full_models
        * PAPER_EPOCHS
        / 3600,
        "full_grid_one_pass_memory_gb": full_pass_gb,
        "median_val_mape_pct_after_E_epochs": 100 * float(np.median(val_mape)),
    }
    record(
        variant_name("mlp_search", None if batched.device == "cpu" else "gpu"),
        {
            "batched, per (configuration, fold)": round(report["batched_s_per_config_fold"], 3),
            "one at a time, per (configuration, fold)": round(
                report["sequential_s_per_config_fold"], 3
            ),
            "speed-up batched vs one at a time": round(report["speedup"], 2),
            "full paper grid projected, batched": round(report["projected_full_grid_batched_h"], 2),
            "full paper grid projected, one at a time": round(
                report["projected_full_grid_sequential_h"], 2
            ),
        },
        units={
            "batched, per (configuration, fold)": "s",
            "one at a time, per (configuration, fold)": "s",
            "full paper grid projected, batched": "h",
            "full paper grid projected, one at a time": "h",
        },
        notes=f"{source}, {len(configs)} configurations x {len(splits)} folds, "
        f"{args.epochs} epochs, device {batched.device}, {threads} thread(s)",
    )
    if args.json:
        print(json.dumps(report))
        return 0
    print(
        f"{source}: {report['n_rows']} rows x {X.shape[1]}, {report['n_designs']} designs, "
        f"{len(splits)} grouped folds; device {batched.device}, {threads} torch thread(s), "
        f"torch {torch.__version__}"
    )
    print(f"{len(configs)} configurations {configs}, {args.epochs} epochs, batch {args.batch_size}")
    print(f"{'':24}{'models':>8}{'total s':>10}{'s/config-fold':>15}{'ms/model-epoch':>16}")
    for name, count, total, per in (
        ("batched (one program)", n_models, batched.elapsed_s, batched_per_model_epoch),
        ("one at a time (M = 1)", len(jobs), sequential_s, sequential_per_model_epoch),
    ):
        print(f"{name:24}{count:>8}{total:>10.2f}{total / count:>15.3f}{per * 1e3:>16.2f}")
    print(f"speed-up batched vs one at a time: {report['speedup']:.2f}x")
    print(
        f"projected full paper grid ({len(PAPER_GRID)} configs x {PAPER_FOLDS} folds x "
        f"{PAPER_EPOCHS} epochs): batched {report['projected_full_grid_batched_h']:.2f} h, "
        f"one at a time {report['projected_full_grid_sequential_h']:.2f} h "
        f"(one pass of all {full_models} models needs about {full_pass_gb:.1f} GB)"
    )
    return 0


def device_description(device: str) -> str:
    """The GPU, driver, CUDA and torch versions (or the CPU threads) a figure was measured on."""
    if device != "cuda":
        return f"CPU, {torch.get_num_threads()} torch thread(s), torch {torch.__version__}"
    try:
        driver = subprocess.run(
            ["nvidia-smi", "--query-gpu=driver_version", "--format=csv,noheader"],
            capture_output=True,
            text=True,
            check=True,
        ).stdout.strip()
    except (OSError, subprocess.CalledProcessError):
        driver = "unknown"
    return (
        f"{torch.cuda.get_device_name()}, driver {driver}, CUDA {torch.version.cuda}, "
        f"torch {torch.__version__}"
    )


def parse_variant(spec: str) -> dict[str, object]:
    """Options of train_mlp_grid for a variant such as ``device+graph+tf32``."""
    options: dict[str, object] = {"shuffle": "host", "cuda_graph": False}
    for part in spec.split("+"):
        if part in ("host", "device"):
            options["shuffle"] = part
        elif part in ("graph", "nograph"):
            options["cuda_graph"] = part == "graph"
        elif part == "tf32":
            options["tf32"] = True
        elif part == "compile":
            options["compile_step"] = True
        else:
            raise SystemExit(
                f"unknown variant part {part!r}: host, device, graph, nograph, tf32, compile"
            )
    return options


def timed_run(X, y, splits, configs, epochs, options, profile):
    """One train_mlp_grid call: (wall s, steady s per epoch, GPU busy fraction or None).

    The steady figures cover epochs 2..E: the host waits for the device at the end
    of every epoch (the CUDA-graph path does so anyway) and stamps the time; when
    profiling, a profiler range spans the same epochs, and the GPU busy time inside
    it (kernels, copies, fills) over its length is the busy fraction.
    """
    cuda = options["device"] == "cuda"
    sync = torch.cuda.synchronize if cuda else (lambda: None)
    stamps: dict[int, float] = {}
    steady = torch.profiler.record_function("steady epochs")

    def progress(done: int, _total: int) -> None:
        sync()
        stamps[done] = time.perf_counter()
        if profile and done == 1:
            steady.__enter__()
        if profile and done == epochs:
            steady.__exit__(None, None, None)

    def run() -> float:
        sync()
        start = time.perf_counter()
        train_mlp_grid(X, y, splits, configs, epochs=epochs, progress=progress, **options)
        sync()
        return time.perf_counter() - start

    if not profile:
        wall = run()
        return wall, (stamps[epochs] - stamps[1]) / max(epochs - 1, 1), None
    import tempfile

    from torch.profiler import ProfilerActivity
    from torch.profiler import profile as torch_profile

    activities = [ProfilerActivity.CPU] + ([ProfilerActivity.CUDA] if cuda else [])
    with torch_profile(activities=activities) as prof:
        wall = run()
    with tempfile.TemporaryDirectory() as folder:
        trace = os.path.join(folder, "trace.json")
        prof.export_chrome_trace(trace)
        with open(trace) as handle:
            events = json.load(handle)
    events = events.get("traceEvents", events) if isinstance(events, dict) else events
    window = [e for e in events if e.get("name") == "steady epochs" and "dur" in e]
    if not window:
        return wall, (stamps[epochs] - stamps[1]) / max(epochs - 1, 1), None
    begin = float(window[0]["ts"])
    end = begin + float(window[0]["dur"])
    busy = gpu_busy_seconds(events, begin, end) / max((end - begin) / 1e6, 1e-12)
    return wall, (stamps[epochs] - stamps[1]) / max(epochs - 1, 1), busy


def gpu_busy_seconds(events: list[dict], begin_us: float, end_us: float) -> float:
    """Seconds of [begin, end] (trace µs) in which the GPU ran a kernel, copy or fill."""
    spans = sorted(
        (max(float(e["ts"]), begin_us), min(float(e["ts"]) + float(e.get("dur", 0.0)), end_us))
        for e in events
        if e.get("cat") in ("kernel", "gpu_memcpy", "gpu_memset") and "ts" in e
    )
    spans = [(a, b) for a, b in spans if b > a]
    busy_us, end = 0.0, -float("inf")
    for a, b in spans:
        if b <= end:
            continue
        busy_us += b - max(a, end)
        end = b
    return busy_us / 1e6


def run_variants(args: argparse.Namespace) -> int:
    """Steady seconds per epoch of each training path, projections and GPU busy fraction."""
    X, y, groups, source = load_data(args)
    splits = list(GroupKFold(n_splits=PAPER_FOLDS).split(X, y, groups))
    configs = pick_configs(args.configs)
    device = "cuda" if args.device == "auto" and torch.cuda.is_available() else args.device
    device = "cpu" if device == "auto" else device
    threads = args.threads or len(os.sched_getaffinity(0))
    torch.set_num_threads(threads)
    n_models = len(configs) * len(splits)
    print(
        f"{source}: {X.shape[0]} rows, {len(configs)} configurations x {len(splits)} folds "
        f"= {n_models} models, batch {args.batch_size}; {device_description(device)}"
    )
    print(f"{'variant':34}{'cold 1 epoch s':>15}{'s/epoch':>10}{'full grid s':>13}{'GPU busy':>10}")
    rows = []
    for spec in args.variants.split(","):
        options = {
            **parse_variant(spec),
            "device": device,
            "batch_size": args.batch_size,
            "seed": args.seed,
            "num_threads": threads,
        }
        profile = device == "cuda"
        # a cold call first: CUDA context, library handles, compilation (kept apart)
        cold, _, _ = timed_run(X, y, splits, configs, 1, options, False)
        wall, per_epoch, busy = timed_run(X, y, splits, configs, args.epochs, options, profile)
        full = per_epoch * PAPER_EPOCHS * (len(PAPER_GRID) * PAPER_FOLDS) / n_models
        rows.append(
            {
                "variant": spec,
                "s_per_epoch": per_epoch,
                "projected_full_grid_s": full,
                "gpu_busy": busy,
                "cold_1_epoch_s": cold,
                "wall_s": wall,
            }
        )
        busy_text = "-" if busy is None else f"{100 * busy:.0f} %"
        print(f"{spec:34}{cold:>15.2f}{per_epoch:>10.4f}{full:>13.1f}{busy_text:>10}", flush=True)
    figures: dict = {}
    units: dict = {}
    for r in rows:
        for key, label, unit, scale in (
            ("s_per_epoch", "steady epoch", "s", 1),
            ("projected_full_grid_s", "full grid projected", "s", 1),
            ("gpu_busy", "GPU busy", "%", 100),
        ):
            value = r[key]
            figures[f"{r['variant']}: {label}"] = None if value is None else round(scale * value, 4)
            units[f"{r['variant']}: {label}"] = unit
    record(
        variant_name("mlp_search-paths", None if device == "cpu" else "gpu"),
        figures,
        units=units,
        notes=f"{source}, {n_models} models, {args.epochs} epochs; {device_description(device)}",
    )
    if args.json:
        print(json.dumps({"data": source, "device": device_description(device), "rows": rows}))
    return 0


def run_search(args: argparse.Namespace) -> int:
    """The exhaustive paper-grid MLP search on the shipped FEM data, refit included."""
    from softbend.datasets import table1_fem
    from softbend.surrogates.features import training_data
    from softbend.surrogates.search import search

    data = training_data(table1_fem())
    device = "cuda" if args.device == "auto" and torch.cuda.is_available() else args.device
    device = "cpu" if device == "auto" else device
    print(f"shipped table1_fem: {data.n_samples} rows; {device_description(device)}", flush=True)
    start = time.perf_counter()
    result = search(
        data,
        models=("mlp",),
        grid_name="paper",
        device=device,
        seed=args.seed,
        tf32=args.tf32,
        epochs=args.search_epochs,
    )
    total = time.perf_counter() - start
    family = result.families["mlp"]
    report = {
        "device": device_description(device),
        "tf32": args.tf32,
        "epochs": result.settings["mlp_epochs"],
        "configurations": len(result.cv_results),
        "search_s": family.search_s,
        "refit_s": family.fit_s,
        "total_s": total,
        "chosen": family.params,
        "cv": family.cv,
    }
    print(
        f"paper grid, {report['configurations']} configurations x 5 grouped folds x "
        f"{report['epochs']} epochs (tf32 {args.tf32}): search {family.search_s:.1f} s, "
        f"refit {family.fit_s:.1f} s, total {total:.1f} s"
    )
    print(
        f"chosen {family.params}; grouped CV: "
        + ", ".join(f"{k} {v:.6g}" for k, v in family.cv.items())
    )
    print(json.dumps(report, default=str))
    figures = {
        "search": round(family.search_s, 1),
        "refit": round(family.fit_s, 1),
        "total": round(total, 1),
        "chosen": str(family.params),
        **{f"grouped CV {k}": round(float(v), 4) for k, v in family.cv.items()},
    }
    record(
        variant_name("mlp_search-paper-grid", None if device == "cpu" else "gpu"),
        figures,
        units=dict.fromkeys(("search", "refit", "total"), "s"),
        notes=f"{report['configurations']} configurations x 5 grouped folds x "
        f"{report['epochs']} epochs, tf32 {args.tf32}; {report['device']}",
    )
    return 0


if __name__ == "__main__":
    raise SystemExit(main())
