"""Benchmark: wall time of ``softbend predict`` for one angle, in a fresh process.

Runs ``softbend.cli.main(["predict", <shipped MLP>, "--design", ..., "--pressures",
...])`` in a new Python process several times (the first run warms the disk
cache and is not counted), and prints the best and median wall seconds and the
heavy modules (PyTorch, scikit-learn, SciPy, pandas, ...) the process imported.
A saved MLP or polynomial predicts with NumPy alone, so none should appear.

Run::

    .venv/bin/python benchmarks/bench_predict.py
    .venv/bin/python benchmarks/bench_predict.py --runs 10 --json
"""

from __future__ import annotations

import argparse
import json
import statistics
import subprocess
import sys
import time
from pathlib import Path

from _record import record

ROOT = Path(__file__).resolve().parents[1]

#: The MLP shipped with softbend (paper B, Table 1 campaign).
SHIPPED_MLP = ROOT / "src" / "softbend" / "data" / "transfer" / "table1_fem_mlp.json"

#: Top-level packages whose import dominates a start-up.
HEAVY = ("torch", "sklearn", "scipy", "xgboost", "pandas", "duckdb", "matplotlib", "onnx")

_CHILD = """
import sys
from softbend.cli import main
code = main(["predict", {model!r}, "--design", {design!r}, "--pressures", {pressures!r}])
heavy = sorted({{m.split(".")[0] for m in sys.modules}} & set({heavy!r}))
print("HEAVY=" + ",".join(heavy), file=sys.stderr)
sys.exit(code)
"""


def _run_once(model: str, design: str, pressures: str) -> tuple[float, list[str]]:
    """Wall seconds of one fresh-process predict, and the heavy modules it imported."""
    code = _CHILD.format(model=model, design=design, pressures=pressures, heavy=HEAVY)
    start = time.perf_counter()
    done = subprocess.run([sys.executable, "-c", code], capture_output=True, text=True, check=False)
    wall = time.perf_counter() - start
    if done.returncode != 0:
        raise RuntimeError(f"softbend predict failed ({done.returncode}): {done.stderr.strip()}")
    line = next(x for x in done.stderr.splitlines() if x.startswith("HEAVY="))
    heavy = [m for m in line.removeprefix("HEAVY=").split(",") if m]
    return wall, heavy


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--model", default=str(SHIPPED_MLP), help="saved surrogate (JSON)")
    parser.add_argument("--design", default="100,6,2,2,5,8", help="l,r,t,b,phi,lc (mm, deg)")
    parser.add_argument("--pressures", default="0.05", help="pressures, MPa")
    parser.add_argument("--runs", type=int, default=5, help="timed runs (after one warm-up)")
    parser.add_argument("--json", action="store_true", help="print the figures as JSON")
    args = parser.parse_args()
    if args.runs < 1:
        parser.error(f"--runs must be >= 1, got {args.runs}")

    _run_once(args.model, args.design, args.pressures)  # warm the disk cache
    walls = []
    heavy: list[str] = []
    for _ in range(args.runs):
        wall, heavy = _run_once(args.model, args.design, args.pressures)
        walls.append(wall)
    result = {
        "model": args.model,
        "design": args.design,
        "pressures_mpa": args.pressures,
        "runs": args.runs,
        "best_s": round(min(walls), 3),
        "median_s": round(statistics.median(walls), 3),
        "heavy_modules": heavy,
    }
    record(
        "predict",
        {
            "best": result["best_s"],
            "median": result["median_s"],
            "heavy modules imported": ", ".join(heavy) or "none",
        },
        units={"best": "s", "median": "s"},
        notes=f"design {args.design}, {args.pressures} MPa, {args.runs} fresh processes (warm)",
    )
    if args.json:
        print(json.dumps(result, indent=2))
        return
    print(f"softbend predict, {args.runs} fresh processes (warm): {args.model}")
    print(f"  best   {result['best_s']:.3f} s")
    print(f"  median {result['median_s']:.3f} s")
    print(f"  heavy modules imported: {', '.join(heavy) or 'none'}")


if __name__ == "__main__":
    main()
