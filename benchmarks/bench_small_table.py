"""Benchmark: ``softbend train`` with its defaults on a small simulation table (30 designs).

Cuts ``examples/pneunet/simulations.csv`` to its first ``--designs`` design ids
(30 by default: 330 rows) into a temporary folder, trains on it with
``softbend train``'s defaults and ``examples/pneunet/actuator.json`` (under 100
designs: plr, xgb, mlp and the table base, the small-data grids, grouped 5-fold
CV, seed 0), and prints for every family

- its grouped-CV RMSE (designs held out) and its interpolation RMSE (every
  other interior pressure point of each simulated design held out, the rest
  fitted), degrees;

and for the table base saved by the run, its largest error at the simulated
designs (every row of the cut table, predicted by the saved model as loaded),
degrees, beside the GP's fitted noise level there. It records them as
``benchmarks/results/small_table.json``.

Run::

    .venv/bin/python benchmarks/bench_small_table.py
    .venv/bin/python benchmarks/bench_small_table.py --designs 50
"""

from __future__ import annotations

import argparse
import contextlib
import io
import json
import sys
import tempfile
import time
from pathlib import Path

from _record import record

ROOT = Path(__file__).resolve().parents[1]
EXAMPLE = ROOT / "examples" / "pneunet"


def main(argv: list[str] | None = None) -> int:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--designs", type=int, default=30, help="first design ids kept")
    parser.add_argument("--json", action="store_true", help="print the figures as JSON")
    args = parser.parse_args(argv)

    import numpy as np
    import pandas as pd

    from softbend.cli import main as softbend
    from softbend.surrogates.persistence import load_surrogate

    table = pd.read_csv(EXAMPLE / "simulations.csv")
    kept = sorted(table["design_id"].unique())[: args.designs]
    cut = table[table["design_id"].isin(kept)]
    with tempfile.TemporaryDirectory() as folder:
        path = Path(folder) / "simulations.csv"
        cut.to_csv(path, index=False)
        out = Path(folder) / "trained"
        started = time.perf_counter()
        with contextlib.redirect_stdout(io.StringIO()):  # its JSON summary: read from files
            code = softbend(["train", str(path), "--actuator", str(EXAMPLE / "actuator.json"),
                             "--no-onnx", "-o", str(out), "--json"])  # fmt: skip
        wall = time.perf_counter() - started
        if code != 0:
            print(f"softbend train failed ({code})", file=sys.stderr)
            return 1
        saved = load_surrogate(out / "models" / "table.json")
        names = ["n_chambers", "n_layers", "wall_mm", "height_mm", "p_kpa"]
        error = saved.model.predict(cut[names].to_numpy(float)) - cut["angle_deg"].to_numpy()
        noise = float(saved.model.noise_std_)
        scores = pd.read_csv(out / "summary.csv").set_index("model")
    figures: dict[str, float] = {}
    units: dict[str, str] = {}
    for name in scores.index:
        figures[f"{name}_grouped_cv_rmse"] = float(scores.loc[name, "rmse_deg"])
        figures[f"{name}_interpolation_rmse"] = float(scores.loc[name, "interp_rmse_deg"])
        units[f"{name}_grouped_cv_rmse"] = units[f"{name}_interpolation_rmse"] = "deg"
    figures["table_max_abs_error_at_simulated"] = float(np.max(np.abs(error)))
    figures["table_gp_noise_std"] = noise
    figures["train_wall"] = wall
    units.update(table_max_abs_error_at_simulated="deg", table_gp_noise_std="deg", train_wall="s")
    lines = [
        f"{name:>6}: grouped CV RMSE {figures[f'{name}_grouped_cv_rmse']:7.3f} deg, "
        f"interpolation RMSE {figures[f'{name}_interpolation_rmse']:7.3f} deg"
        for name in scores.index
    ]
    lines.append(
        f"table base at the {len(kept)} simulated designs ({len(cut)} rows): max |error| "
        f"{figures['table_max_abs_error_at_simulated']:.3g} deg (GP noise {noise:.3g} deg)"
    )
    lines.append(f"softbend train wall time: {wall:.1f} s")
    if args.json:
        print(json.dumps(figures, indent=2))
    else:
        print("\n".join(lines))
    record(
        "small_table",
        figures,
        units=units,
        notes=f"softbend train with its defaults on the first {len(kept)} designs of "
        "examples/pneunet/simulations.csv: grouped CV (designs held out) and interpolation "
        "(every other interior pressure point held out) RMSE per family; the table base's "
        "largest error at the simulated designs",
    )
    return 0


if __name__ == "__main__":
    sys.exit(main())
