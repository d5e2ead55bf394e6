"""Campaign throughput and overhead: paper B Table 1 (972 designs x 101 pressures).

Runs the analytical backend into temporary DuckDB files, serially and on local
worker processes, and the same campaigns with a no-op backend that returns a
precomputed sweep (so only the runner and the database are timed). Prints
designs per second and the campaign overhead per design:

* ``serial, analytical``: (wall time - sum of sweep times) / designs;
* ``no-op`` rows: wall time / designs, i.e. the runner (scheduling, pickling,
  progress) plus the database (one transaction per design, durable commit);
* ``processes, analytical``: wall time beyond perfect scaling of the sweeps,
  (wall - sum of sweep times / workers) / designs.

The target is an overhead under 20 ms per design.

Usage::

    python benchmarks/bench_campaign.py [--space table1] [--workers N] [--json]
"""

from __future__ import annotations

import argparse
import json
import os
import sys
import tempfile
import time
from dataclasses import dataclass
from pathlib import Path

import numpy as np
from _record import record, variant_name

from softbend.actuators import Design
from softbend.campaign import SweepResult, default_pressures_mpa, get_backend, run_campaign
from softbend.cli.campaign import parse_space

TARGET_OVERHEAD_MS = 20.0


@dataclass(frozen=True)
class PrecomputedBackend:
    """Returns one precomputed analytical sweep for every design (no solver work)."""

    template: SweepResult
    name: str = "no-op"

    def sweep(self, design: Design, pressures_mpa: np.ndarray) -> SweepResult:
        t = self.template
        return SweepResult(
            design=design,
            pressure_mpa=t.pressure_mpa,
            angle_deg=t.angle_deg,
            tip_x_mm=t.tip_x_mm,
            tip_z_mm=t.tip_z_mm,
            converged=t.converged,
            newton_iterations=t.newton_iterations,
            wall_time_s=0.0,
            stats={"precomputed": True},
        )


def _run(label: str, backend, designs, grid, workers: int, folder: Path) -> dict:
    path = folder / f"{label.replace(', ', '-').replace(' ', '_')}.duckdb"
    start = time.perf_counter()
    summary = run_campaign(path, designs, backend=backend, pressures_mpa=grid, workers=workers)
    wall = time.perf_counter() - start
    n = summary.n_run
    n_workers = 1 if summary.executor == "serial" else workers
    if backend == "analytical" and n_workers > 1:
        overhead = (wall - summary.sweep_time_s / n_workers) / n
    else:
        overhead = (wall - summary.sweep_time_s) / n
    return {
        "run": label,
        "executor": summary.executor,
        "chunk_size": summary.chunk_size,
        "designs": n,
        "failed": summary.n_failed,
        "wall_s": wall,
        "designs_per_s": n / wall,
        "sweep_time_s": summary.sweep_time_s,
        "overhead_ms_per_design": 1e3 * overhead,
        "db_mb": path.stat().st_size / 1e6,
    }


def main(argv: list[str] | None = None) -> int:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--space", default="table1", help="table1, corners, lhs:N or sobol:N")
    parser.add_argument("--workers", type=int, default=os.cpu_count() or 1)
    parser.add_argument("--json", action="store_true", help="print the results as JSON")
    args = parser.parse_args(argv)

    designs = parse_space(args.space)
    grid = default_pressures_mpa()
    # Import the model once so that a one-off import is not charged to the campaign.
    template = get_backend("analytical").sweep(designs[0], grid)
    noop = PrecomputedBackend(template)
    rows = []
    with tempfile.TemporaryDirectory(prefix="bench-campaign-") as tmp:
        folder = Path(tmp)
        rows.append(_run("no-op, serial", noop, designs, grid, 0, folder))
        rows.append(_run("no-op, processes", noop, designs, grid, args.workers, folder))
        rows.append(_run("analytical, serial", "analytical", designs, grid, 0, folder))
        rows.append(
            _run("analytical, processes", "analytical", designs, grid, args.workers, folder)
        )

    header = {
        "space": designs.name,
        "n_designs": len(designs),
        "n_pressures": len(grid),
        "workers": args.workers,
        "cpu_count": os.cpu_count(),
        "target_overhead_ms_per_design": TARGET_OVERHEAD_MS,
    }
    figures: dict = {}
    units: dict = {}
    for row in rows:
        for key, figure, unit in (
            ("designs_per_s", "throughput", "designs/s"),
            ("overhead_ms_per_design", "overhead", "ms/design"),
        ):
            figures[f"{row['run']}: {figure}"] = round(row[key], 2)
            units[f"{row['run']}: {figure}"] = unit
    record(
        variant_name("campaign", None if args.space == "table1" else args.space),
        figures,
        units=units,
        notes=f"{len(designs)} designs x {len(grid)} pressures, {args.workers} workers; "
        f"target overhead < {TARGET_OVERHEAD_MS:g} ms/design",
    )
    if args.json:
        print(json.dumps({**header, "runs": rows}, indent=2))
        return 0
    print(
        f"campaign benchmark: {len(designs)} designs ({designs.name}) x {len(grid)} pressures, "
        f"{args.workers} workers on {os.cpu_count()} cores"
    )
    columns = (
        "run",
        "executor",
        "wall_s",
        "designs_per_s",
        "sweep_time_s",
        "overhead_ms_per_design",
    )
    print(
        f"{'run':<24}{'executor':>14}{'wall s':>9}{'designs/s':>11}{'sweeps s':>10}"
        f"{'overhead ms/design':>20}"
    )
    for row in rows:
        values = [row[c] for c in columns]
        print(
            f"{values[0]:<24}{values[1]:>14}{values[2]:>9.2f}{values[3]:>11.1f}"
            f"{values[4]:>10.2f}{values[5]:>20.2f}"
        )
    worst = max(r["overhead_ms_per_design"] for r in rows)
    verdict = "met" if worst < TARGET_OVERHEAD_MS else "NOT met"
    print(f"largest overhead {worst:.2f} ms/design; target < {TARGET_OVERHEAD_MS:g} ms: {verdict}")
    return 0


if __name__ == "__main__":
    sys.exit(main())
