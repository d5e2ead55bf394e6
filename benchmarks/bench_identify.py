"""Identification by held-out free-run error: the selection on a nonlinear plant and on paper A.

1. The synthetic soft arm (:func:`softbend.identification.arm.arm_experiments`:
   three chamber pressures in, the tip's x and y out, 12 Hz, 13 training and
   4 validation experiments of steps, ramps, multisines and random pressures,
   44 880 rows): :func:`softbend.identification.selection.select_model` over
   the default candidates, its wall time and the process's peak memory.
2. Paper A's synthetic curling actuator (seed 0; pressure in, ρ and L out), each
   pressure sign on its own, the last experiment of each held out.

Prints, per dataset, every candidate's cross-validated free-run NRMSE, one-step
NRMSE and validation free-run NRMSE, and the verdict against the best linear
ARX. Writes nothing. About two minutes on two cores.

Usage: python benchmarks/bench_identify.py
"""

from __future__ import annotations

import resource
import time

from softbend.identification.arm import ARM_VALIDATION, arm_experiments
from softbend.identification.selection import select_model
from softbend.identification.synthetic import synthetic_dataset
from softbend.identification.timeseries import from_experiments


def show(label: str, selection, seconds: float) -> None:
    print(f"\n{label}: {seconds:.1f} s")
    table = selection.table[
        ["candidate", "cv_freerun_nrmse", "cv_onestep_nrmse", "validation_freerun_nrmse"]
    ]
    print(table.to_string(index=False, float_format=lambda v: f"{v:.4f}"))
    print(selection.verdict())


def main() -> None:
    arm = arm_experiments()
    rows = sum(e.n_samples for e in arm.experiments)
    start = time.perf_counter()
    selection = select_model(arm, validate_on=list(ARM_VALIDATION))
    show(f"soft arm, {rows:,} rows x 3 inputs x 2 outputs", selection, time.perf_counter() - start)
    peak = resource.getrusage(resource.RUSAGE_SELF).ru_maxrss / 1024
    print(f"peak memory of the process: {peak:.0f} MiB")
    for sign, experiments in synthetic_dataset(seed=0).items():
        data = from_experiments(experiments)
        start = time.perf_counter()
        selection = select_model(data, validate_on=[data.names[-1]])
        show(f"paper A curling actuator, {sign} pressure", selection, time.perf_counter() - start)


if __name__ == "__main__":
    main()
