"""Sweep a small design space with the analytical model, then analyse it (paper B Fig. 4).

The same call runs the FEM backend or a Dask cluster (``scheduler="tcp://..."``);
running it again resumes from the database instead of starting over.

Run: ``python examples/design_campaign.py [DB]`` (default ``design_campaign.duckdb``)
"""

from __future__ import annotations

import sys
from pathlib import Path

from softbend.analysis import standardized_regression
from softbend.campaign import run_campaign
from softbend.campaign.store import load_samples
from softbend.design import DesignSpace


def main(db_path: str | Path = "design_campaign.duckdb", *, seed: int = 0) -> dict[str, float]:
    """Run 40 Latin-hypercube designs over the Table 1 ranges; return the loadings."""
    space = DesignSpace.sample(40, method="lhs", seed=seed)
    summary = run_campaign(db_path, space, backend="analytical", workers=2)
    print(f"{summary.n_done} designs run, {summary.n_skipped_done} already in {db_path}")

    samples = load_samples(db_path)  # one row per (design, pressure): a pandas DataFrame
    regression = standardized_regression(samples)
    print(regression.coefficients[["loading", "t_value", "p_value", "stars"]].round(3))
    print(f"R² = {regression.r2:.3f}")
    return {str(k): float(v) for k, v in regression.coefficients["loading"].items()}


if __name__ == "__main__":
    main(*sys.argv[1:2])
