"""Benchmark: the table base's GP size against its held-out error and fit time.

On the 150 designs × 11 pressures of ``examples/pneunet/simulations.csv``, for
each cap on the Gaussian process's rows (``--gp-rows``, default 300, 600 and
1 000; :data:`softbend.surrogates.table.MAX_GP_POINTS` is the default cap), it
scores :class:`~softbend.surrogates.table.TableRegressor` by grouped 5-fold
cross-validation (seed 0, no optimizer restarts) and prints the held-out RMSE
(degrees) and the median time of one fit (seconds). One BLAS thread is used, so
that the time does not depend on how many cores are free. It records them as
``benchmarks/results/table_base.json``; ``docs/design-log.md`` explains the
default cap from them.

Run::

    .venv/bin/python benchmarks/bench_table_base.py
    .venv/bin/python benchmarks/bench_table_base.py --gp-rows 300,1000
"""

from __future__ import annotations

import argparse
import statistics
import sys
import time
from pathlib import Path

from _record import record

ROOT = Path(__file__).resolve().parents[1]
EXAMPLE = ROOT / "examples" / "pneunet"
COLUMNS = ["n_chambers", "n_layers", "wall_mm", "height_mm", "p_kpa"]


def main(argv: list[str] | None = None) -> int:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--gp-rows", default="300,600,1000", help="caps, comma-separated")
    args = parser.parse_args(argv)
    caps = [int(c) for c in args.gp_rows.split(",")]

    import numpy as np
    import pandas as pd
    from threadpoolctl import threadpool_limits

    from softbend.surrogates.search import grouped_splits
    from softbend.surrogates.table import TableRegressor

    table = pd.read_csv(EXAMPLE / "simulations.csv")
    X, y = table[COLUMNS].to_numpy(float), table["angle_deg"].to_numpy(float)
    splits = grouped_splits(table["design_id"].to_numpy(), 5, 0)
    figures: dict[str, float] = {}
    units: dict[str, str] = {}
    with threadpool_limits(1):
        for cap in caps:
            pred = np.empty_like(y)
            seconds = []
            for train, val in splits:
                start = time.perf_counter()
                model = TableRegressor(max_gp_points=cap, n_restarts=0).fit(X[train], y[train])
                seconds.append(time.perf_counter() - start)
                pred[val] = model.predict(X[val])
            rmse = float(np.sqrt(np.mean((pred - y) ** 2)))
            fit = statistics.median(seconds)
            figures[f"rmse_{cap}_rows"], units[f"rmse_{cap}_rows"] = rmse, "deg"
            figures[f"fit_{cap}_rows"], units[f"fit_{cap}_rows"] = fit, "s"
            print(
                f"GP of at most {cap:5d} rows: held-out RMSE {rmse:6.3f} deg, one fit {fit:5.1f} s",
                flush=True,
            )
    record(
        "table_base",
        figures,
        units=units,
        notes="the table base on the 150 designs of examples/pneunet/simulations.csv, grouped "
        "5-fold CV (seed 0, no restarts, one BLAS thread), per cap on the GP's rows",
    )
    return 0


if __name__ == "__main__":
    sys.exit(main())
