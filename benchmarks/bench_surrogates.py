"""Benchmark: inference time of the surrogates, fast path against predict and ONNX Runtime.

Fits each model family once on analytical data over the Table 1 ranges (or on a
campaign database with ``--db``) and times, with the median of repeated runs:

- ``fast path``: ``model.predictor()(x)`` for one sample (plain NumPy; what a
  control loop at 100 Hz calls; target under 20 µs for the MLP and polynomial);
- ``predict 1``: ``model.predict`` on one row (scikit-learn-style validation);
- ``predict 10k``: ``model.predict`` on 10 000 rows;
- ``ONNX 1`` / ``ONNX 10k``: ONNX Runtime on the exported graph.

Run::

    .venv/bin/python benchmarks/bench_surrogates.py            # analytical data, 200 designs
    .venv/bin/python benchmarks/bench_surrogates.py --db table1.duckdb --json
"""

from __future__ import annotations

import argparse
import json
import time

import numpy as np
from _record import record, variant_name


def _median_us(call, number: int, repeats: int = 7) -> float:
    times = []
    for _ in range(repeats):
        start = time.perf_counter()
        for _ in range(number):
            call()
        times.append((time.perf_counter() - start) / number)
    return 1e6 * float(np.median(times))


def _data(db: str | None, n_designs: int, seed: int):
    from softbend.campaign import load_samples, run_campaign
    from softbend.design import DesignSpace
    from softbend.surrogates.features import training_data

    if db is None:
        import tempfile
        from pathlib import Path

        db = str(Path(tempfile.mkdtemp()) / "bench.duckdb")
        run_campaign(db, DesignSpace.sample(n_designs, seed=seed), backend="analytical", workers=0)
    return training_data(load_samples(db))


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--db", help="campaign database (default: a fresh analytical one)")
    parser.add_argument("--designs", type=int, default=200, help="designs when no --db")
    parser.add_argument("--degree", type=int, default=6)
    parser.add_argument("--hidden", default="63,65")
    parser.add_argument("--epochs", type=int, default=100, help="MLP epochs (timing only)")
    parser.add_argument("--seed", type=int, default=0)
    parser.add_argument("--json", action="store_true")
    args = parser.parse_args()

    from xgboost import XGBRegressor

    from softbend.surrogates.mlp import NormalizedMLPRegressor
    from softbend.surrogates.onnx_export import to_onnx
    from softbend.surrogates.polynomial import PolynomialRegressor

    data = _data(args.db, args.designs, args.seed)
    hidden = tuple(int(v) for v in args.hidden.split(","))
    models = {
        f"polynomial (degree {args.degree})": PolynomialRegressor(degree=args.degree),
        f"MLP {hidden}": NormalizedMLPRegressor(
            hidden_sizes=hidden, epochs=args.epochs, seed=args.seed, device="cpu"
        ),
        "XGBoost (depth 9, lr 0.2, 300 trees)": XGBRegressor(
            n_estimators=300, max_depth=9, learning_rate=0.2, random_state=args.seed
        ),
    }
    rng = np.random.default_rng(args.seed)
    batch = data.X[rng.integers(0, data.n_samples, 10_000)]
    one = batch[:1].copy()
    sample = one[0].copy()
    results = {}
    import onnxruntime as ort

    for name, model in models.items():
        model.fit(data.X, data.y)
        row: dict[str, float | None] = {}
        fast = getattr(model, "predictor", None)
        if callable(fast):
            f = fast()
            f(sample)
            row["fast_path_us"] = _median_us(lambda f=f: f(sample), 5000)
        else:
            row["fast_path_us"] = None
        row["predict_1_us"] = _median_us(lambda m=model: m.predict(one), 200)
        row["predict_10k_ms"] = _median_us(lambda m=model: m.predict(batch), 3) / 1e3
        session = ort.InferenceSession(
            to_onnx(model).SerializeToString(), providers=["CPUExecutionProvider"]
        )
        name_in = session.get_inputs()[0].name
        dtype = np.float64 if "double" in session.get_inputs()[0].type else np.float32
        one_t, batch_t = one.astype(dtype), batch.astype(dtype)
        feed_one, feed_batch = {name_in: one_t}, {name_in: batch_t}
        row["onnx_1_us"] = _median_us(lambda s=session, f=feed_one: s.run(None, f), 500)
        row["onnx_10k_ms"] = _median_us(lambda s=session, f=feed_batch: s.run(None, f), 5) / 1e3
        results[name] = row

    figures: dict = {}
    units: dict = {}
    for m, r in results.items():
        for k, v in r.items():
            label, unit = k.rsplit("_", 1)
            key = f"{m}: {label.replace('_', ' ').replace('onnx', 'ONNX')}"
            figures[key] = None if v is None else round(v, 2)
            units[key] = "µs" if unit == "us" else unit
    record(
        variant_name("surrogates", "db" if args.db else None),
        figures,
        units=units,
        notes=f"median of repeated runs; {data.n_samples} samples ({data.n_groups} designs)",
    )
    if args.json:
        print(json.dumps({"n_samples": data.n_samples, "results": results}, indent=2))
        return
    print(f"surrogate inference on {data.n_samples} training samples ({data.n_groups} designs)")
    print(
        f"{'model':40s}{'fast path µs':>14}{'predict 1 µs':>14}{'predict 10k ms':>16}"
        f"{'ONNX 1 µs':>11}{'ONNX 10k ms':>13}"
    )
    for name, r in results.items():
        fast = f"{r['fast_path_us']:.1f}" if r["fast_path_us"] is not None else "n/a"
        print(
            f"{name:40s}{fast:>14}{r['predict_1_us']:>14.1f}{r['predict_10k_ms']:>16.2f}"
            f"{r['onnx_1_us']:>11.1f}{r['onnx_10k_ms']:>13.2f}"
        )


if __name__ == "__main__":
    main()
