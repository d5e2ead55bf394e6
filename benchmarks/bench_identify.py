"""Identification by held-out free-run error: the selection on a nonlinear plant and on paper A.

1. The synthetic soft arm (:func:`softbend.identification.arm.arm_experiments`:
   three chamber pressures in, the tip's x and y out, 12 Hz, 13 training and
   4 validation experiments of steps, ramps, multisines and random pressures,
   44 880 rows): :func:`softbend.identification.selection.select_model` over
   the default candidates, its wall time and the process's peak memory.
2. Paper A's synthetic curling actuator (seed 0; pressure in, ρ and L out), each
   pressure sign on its own, the last experiment of each held out.

Prints, per dataset, every candidate's cross-validated free-run NRMSE, one-step
NRMSE and validation free-run NRMSE, the verdict against the best linear ARX,
and the candidate the selection would pick among those fitted one step ahead
only (the selection before the free-run-fitted families), and records the figures
in benchmarks/results/. About four minutes on two cores.

Usage: python benchmarks/bench_identify.py
"""

from __future__ import annotations

import resource
import time

from _record import record

from softbend.identification.arm import ARM_VALIDATION, arm_experiments
from softbend.identification.selection import select_model
from softbend.identification.synthetic import synthetic_dataset
from softbend.identification.timeseries import from_experiments


def one_step_best(selection, column: str) -> list[tuple[str, object, str]]:
    """The candidate the selection picks among those fitted one step ahead only (every
    candidate but the free-run-fitted ``*-sim`` families), and its validation NRMSE."""
    table = selection.table[~selection.table["family"].str.endswith("-sim")]
    if table.empty:
        return []
    row = table.loc[table["cv_freerun_nrmse"].idxmin()]
    return [
        ("best fitted one step ahead", row["candidate"], ""),
        ("best fitted one step ahead: validation free-run NRMSE", round(float(row[column]), 4), ""),
    ]


def show(label: str, selection, seconds: float, figures: dict, units: dict) -> None:
    print(f"\n{label}: {seconds:.1f} s")
    table = selection.table[
        ["candidate", "cv_freerun_nrmse", "cv_onestep_nrmse", "validation_freerun_nrmse"]
    ]
    print(table.to_string(index=False, float_format=lambda v: f"{v:.4f}"))
    print(selection.verdict())
    best, linear = selection.row(selection.best), selection.best_of("arx")
    column = "validation_freerun_nrmse"
    for key, value, unit in (
        ("wall time", round(seconds, 1), "s"),
        ("selected", selection.best, ""),
        ("selected: validation free-run NRMSE", round(float(best[column]), 4), ""),
        ("best linear ARX: validation free-run NRMSE", round(float(linear[column]), 4), "")
        if linear
        else ("best linear ARX", "none", ""),
        *one_step_best(selection, column),
    ):
        figures[f"{label}: {key}"], units[f"{label}: {key}"] = value, unit


def main() -> None:
    arm = arm_experiments()
    rows = sum(e.n_samples for e in arm.experiments)
    figures: dict = {}
    units: dict = {}
    start = time.perf_counter()
    selection = select_model(arm, validate_on=list(ARM_VALIDATION))
    seconds = time.perf_counter() - start
    show(f"soft arm, {rows:,} rows x 3 inputs x 2 outputs", selection, seconds, figures, units)
    peak = resource.getrusage(resource.RUSAGE_SELF).ru_maxrss / 1024
    print(f"peak memory of the process: {peak:.0f} MiB")
    figures["soft arm: peak memory of the process"] = round(peak)
    units["soft arm: peak memory of the process"] = "MiB"
    for sign, experiments in synthetic_dataset(seed=0).items():
        data = from_experiments(experiments)
        start = time.perf_counter()
        selection = select_model(data, validate_on=[data.names[-1]])
        seconds = time.perf_counter() - start
        show(f"paper A curling actuator, {sign} pressure", selection, seconds, figures, units)
    record("identify", figures, units=units, notes="held-out free-run NRMSE; selection by CV")


if __name__ == "__main__":
    main()
