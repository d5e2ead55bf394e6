"""Time the transfer refits (:func:`softbend.transfer.finetune.fine_tune_many`) on CPU and GPU.

The workload is the shipped FEM-trained MLP refined on the rows of the shipped
virtual-lab measurements, K variants at once (leave-one-actuator-out folds and
bootstrap members stack the same way), 1000 full-batch Adam epochs as in
``softbend transfer refine``. Prints wall time per device and K, the GPU's
kernel-busy share of the wall time (CUDA events around the epoch loop), and the
largest weight difference between the CPU and GPU models (both train in float64).

    python benchmarks/bench_finetune_device.py [--variants 8,64,512] [--epochs 1000]
"""

from __future__ import annotations

import argparse
import json
import time

import numpy as np
from _record import record

from softbend.transfer.base import load_base
from softbend.transfer.finetune import fine_tune_many
from softbend.transfer.lab import shipped_measurements


def _workload(k: int, seed: int = 0) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
    data = shipped_measurements()
    X, y = data.features, data.angle_deg
    rng = np.random.default_rng(seed)
    weights = np.array(
        [np.bincount(rng.integers(0, y.size, y.size), minlength=y.size) for _ in range(k)]
    )
    return X, y, weights.astype(float)


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--variants", default="8,64,512", help="K values, comma-separated.")
    parser.add_argument("--epochs", type=int, default=1000)
    parser.add_argument("--devices", default="cpu,cuda")
    args = parser.parse_args()
    import torch

    base = load_base()
    devices = [d for d in args.devices.split(",") if d != "cuda" or torch.cuda.is_available()]
    print(f"torch {torch.__version__}, CPU threads {torch.get_num_threads()}", flush=True)
    if torch.cuda.is_available():
        print(f"GPU {torch.cuda.get_device_name(0)}, CUDA {torch.version.cuda}", flush=True)
    rows = []
    figures: dict = {}
    units: dict = {}
    for k in (int(v) for v in args.variants.split(",")):
        X, y, w = _workload(k)
        models = {}
        for device in devices:
            fine_tune_many(base, X, y, w[:1], epochs=5, device=device)  # warm-up
            if device == "cuda":
                torch.cuda.synchronize()
            start = time.perf_counter()
            models[device] = fine_tune_many(base, X, y, w, epochs=args.epochs, device=device)
            seconds = time.perf_counter() - start
            row = {
                "device": device,
                "variants": k,
                "rows": int(y.size),
                "epochs": args.epochs,
                "seconds": round(seconds, 3),
            }
            if device == "cuda":
                with torch.profiler.profile(
                    activities=[torch.profiler.ProfilerActivity.CUDA]
                ) as prof:
                    fine_tune_many(base, X, y, w, epochs=min(args.epochs, 200), device=device)
                    torch.cuda.synchronize()
                busy_us = sum(e.self_device_time_total for e in prof.key_averages())
                row["gpu_busy_s_per_epoch"] = busy_us / 1e6 / min(args.epochs, 200)
                row["gpu_busy_pct"] = round(
                    100 * row["gpu_busy_s_per_epoch"] * args.epochs / seconds, 1
                )
            rows.append(row)
            figures[f"{device}, K={k}: wall time"], units[f"{device}, K={k}: wall time"] = (
                row["seconds"],
                "s",
            )
            if "gpu_busy_pct" in row:
                figures[f"{device}, K={k}: GPU busy"] = row["gpu_busy_pct"]
                units[f"{device}, K={k}: GPU busy"] = "%"
            print(json.dumps(row), flush=True)
        if len(models) == 2:
            diff = max(
                float(np.abs(a - b).max())
                for mc, mg in zip(models["cpu"], models["cuda"], strict=True)
                for a, b in zip(mc.coefs_, mg.coefs_, strict=True)
            )
            print(json.dumps({"variants": k, "max_weight_diff_cpu_vs_cuda": diff}), flush=True)
            figures[f"K={k}: largest weight difference, CPU vs GPU"] = diff
    record(
        "finetune_device",
        figures,
        units=units,
        notes=f"{args.epochs} epochs, float64; CPU threads {torch.get_num_threads()}",
    )


if __name__ == "__main__":
    main()
