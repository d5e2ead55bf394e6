"""Benchmark: wall time of ``softbend predict`` for one angle, in a fresh process, per family.

Runs ``softbend.cli.main(["predict", <model>, "--design", ..., "--pressures",
...])`` in a new Python process several times (the first run warms the disk
cache and is not counted) for a model of every saved kind: the shipped MLP
(paper B's Table 1 campaign), a polynomial (``plr``), XGBoost (``xgb``) and the
composites of :mod:`softbend.surrogates.corrected` (``affine-corrected``,
``pressure-scaled``, ``gp-corrected``, ``ensemble``). It prints, per kind, the
best and median wall seconds and the heavy modules (PyTorch, scikit-learn, SciPy,
pandas, ...) the process imported. A saved MLP, polynomial or a composite of
them (a GP correction included) predicts with NumPy alone, so none should
appear; XGBoost needs its own library.

The models other than the shipped MLP are built once into ``--cache`` (seeded,
a few seconds): the polynomial and XGBoost are fitted on 2 000 angles of the
shipped MLP at random designs and pressures, and the composites wrap them with
fixed corrections (the GP's on 60 of those rows). ``--model FILE`` times that
file alone (recorded as ``predict-model``).

Run::

    .venv/bin/python benchmarks/bench_predict.py
    .venv/bin/python benchmarks/bench_predict.py --runs 10 --json
    .venv/bin/python benchmarks/bench_predict.py --model my_model.json
"""

from __future__ import annotations

import argparse
import json
import statistics
import subprocess
import sys
import tempfile
import time
from pathlib import Path

from _record import record

ROOT = Path(__file__).resolve().parents[1]

#: The MLP shipped with softbend (paper B, Table 1 campaign).
SHIPPED_MLP = ROOT / "src" / "softbend" / "data" / "transfer" / "table1_fem_mlp.json"

#: Where the models of the other kinds are built once.
CACHE = Path(tempfile.gettempdir()) / "softbend-bench-predict"

#: The kinds built into the cache (every saved kind but the shipped MLP's).
BUILT = ("plr", "xgb", "affine-corrected", "pressure-scaled", "gp-corrected", "ensemble")

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


def build_models(cache: Path) -> dict[str, Path]:
    """A saved model of every kind (the shipped MLP, the others built into ``cache`` once)."""
    import numpy as np

    from softbend.surrogates import corrected
    from softbend.surrogates.persistence import load_surrogate, save_surrogate

    paths = {kind: cache / f"{kind}.json" for kind in BUILT}
    models: dict[str, Path] = {"mlp": SHIPPED_MLP, **paths}
    if all(path.is_file() for path in paths.values()):
        return models
    from xgboost import XGBRegressor

    from softbend.surrogates.polynomial import PolynomialRegressor

    mlp = load_surrogate(SHIPPED_MLP).model
    rng = np.random.default_rng(0)
    low = np.array([80, 4, 1.5, 1.5, 0, 5, 0.0])
    high = np.array([120, 8, 3, 3, 10, 10, 0.06])
    X = low + (high - low) * rng.random((2000, 7))
    y = mlp.predict(X)
    plr = PolynomialRegressor(degree=4).fit(X, y)
    xgb = XGBRegressor(n_estimators=100, max_depth=4, random_state=0, n_jobs=1).fit(X, y)
    theta = mlp.predict(X[:60])
    Z = np.column_stack([X[:60], theta])
    z_mean, z_scale = Z.mean(axis=0), Z.std(axis=0)
    errors = 0.1 * theta + rng.normal(0.0, 1.0, 60)
    built = {
        "plr": plr,
        "xgb": xgb,
        "affine-corrected": corrected.AffineCorrected(mlp, 1.1, 2.0, 1.5),
        "pressure-scaled": corrected.PressureScaled(mlp, 0.9, 1.5),
        "gp-corrected": corrected.GPCorrected(
            mlp, z_mean, z_scale, corrected.gp_kernel(8).theta, (Z - z_mean) / z_scale, errors
        ),
        "ensemble": corrected.MeanEnsemble([mlp, plr], 1.0),
    }
    for kind, model in built.items():
        save_surrogate(model, paths[kind], metadata={"note": "bench_predict model"})
    return models


def time_model(model: str, design: str, pressures: str, runs: int) -> tuple[list[float], list[str]]:
    """Wall seconds of ``runs`` fresh-process predictions (after one warm-up), heavy modules."""
    _run_once(model, design, pressures)  # warm the disk cache
    walls = []
    heavy: list[str] = []
    for _ in range(runs):
        wall, heavy = _run_once(model, design, pressures)
        walls.append(wall)
    return walls, heavy


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--model", default=None, help="time this saved surrogate (JSON) alone")
    parser.add_argument("--cache", default=str(CACHE), help="folder of the built models")
    parser.add_argument("--design", default="100,6,2,2,5,8", help="l,r,t,b,phi,lc (mm, deg)")
    parser.add_argument("--pressures", default="0.05", help="pressures, MPa")
    parser.add_argument("--runs", type=int, default=5, help="timed runs (after one warm-up)")
    parser.add_argument("--json", action="store_true", help="print the figures as JSON")
    args = parser.parse_args()
    if args.runs < 1:
        parser.error(f"--runs must be >= 1, got {args.runs}")

    if args.model is not None:
        models = {"model": Path(args.model)}
    else:
        models = build_models(Path(args.cache))
    results = []
    for kind, path in models.items():
        walls, heavy = time_model(str(path), args.design, args.pressures, args.runs)
        results.append(
            {
                "kind": kind,
                "model": str(path),
                "best_s": round(min(walls), 3),
                "median_s": round(statistics.median(walls), 3),
                "heavy_modules": heavy,
            }
        )
    figures: dict[str, object] = {}
    units: dict[str, str] = {}
    for r in results:
        figures[f"{r['kind']} best"] = r["best_s"]
        figures[f"{r['kind']} median"] = r["median_s"]
        figures[f"{r['kind']} heavy modules"] = ", ".join(r["heavy_modules"]) or "none"
        units[f"{r['kind']} best"] = units[f"{r['kind']} median"] = "s"
    record(
        "predict" if args.model is None else "predict-model",
        figures,
        units=units,
        notes=f"design {args.design}, {args.pressures} MPa, {args.runs} fresh processes (warm) "
        "per saved kind",
    )
    if args.json:
        print(
            json.dumps(
                {
                    "design": args.design,
                    "pressures_mpa": args.pressures,
                    "runs": args.runs,
                    "models": results,
                },
                indent=2,
            )
        )
        return
    print(f"softbend predict, {args.runs} fresh processes (warm) per model")
    print(f"  {'kind':<17} {'best s':>7} {'median s':>9}  heavy modules imported")
    for r in results:
        heavy = ", ".join(r["heavy_modules"]) or "none"
        print(f"  {r['kind']:<17} {r['best_s']:>7.3f} {r['median_s']:>9.3f}  {heavy}")


if __name__ == "__main__":
    main()
