"""Identification by held-out free-run error: the selection on a nonlinear plant and on paper A.

1. The synthetic soft arm (:func:`softbend.identification.arm.arm_experiments`:
   three chamber pressures in, the tip's x and y out, 12 Hz, 13 training and
   4 validation experiments of steps, ramps, multisines and random pressures,
   44 880 rows): :func:`softbend.identification.selection.select_model` over
   the default candidates, its wall and CPU time, the candidates pruned by their
   one-step error, and the process's peak memory. Beside, in the same process,
   the free run of the validation experiments by the step-by-step loop it
   replaced (:func:`softbend.identification.freerun._step_by_step`) against
   :func:`~softbend.identification.freerun.free_run`, for three candidates: the
   ratio of their times (a ratio holds on a loaded machine, a time does not) and
   the largest difference of their outputs. Then the same selection with the
   candidate whose input delays are searched left out (``identify --no-search-delays``).
2. Paper A's synthetic curling actuator (seed 0; pressure in, ρ and L out), each
   pressure sign on its own, the last experiment of each held out.

Prints, per dataset, every candidate's cross-validated free-run NRMSE, one-step
NRMSE and validation free-run NRMSE, the verdict against the best linear ARX,
and the candidate the selection would pick among those fitted one step ahead
only (the selection before the free-run-fitted families), and records the figures
in benchmarks/results/. About three minutes on two quiet cores (the budget of
the soft arm's selection: 150 s).

Usage: python benchmarks/bench_identify.py
"""

from __future__ import annotations

import resource
import time

import numpy as np
from _record import record

from softbend.identification.arm import ARM_VALIDATION, arm_experiments
from softbend.identification.freerun import _step_by_step
from softbend.identification.narx import _segments
from softbend.identification.selection import default_candidates, select_model
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


def free_run_ratios(arm, figures: dict, units: dict) -> None:
    """The step-by-step free run against the vectorised one, same models, same process."""
    train = arm.subset([n for n in arm.names if n not in ARM_VALIDATION])
    U, Y, groups = train.stacked()
    Uv, Yv, gv = arm.subset(list(ARM_VALIDATION)).stacked()
    candidates = {c.name: c for c in default_candidates()}
    print("\nfree run of the validation experiments: step by step / vectorised")
    for name in ("poly2-2-2", "nn-sim-2-3", "paper-a"):
        model = candidates[name].build(2000).fit(U, Y, groups)
        segments = _segments(gv, len(Uv), model.max_lag)
        maps = [getattr(e, "_expansion", e.predict) for e in model.estimators_]
        args = (
            model._inputs_standard(Uv, segments),
            (Yv - model.y_mean_) / model.y_std_,
            (segments.starts, segments.lengths),
            (model.output_lags, model.input_lags),
            model._standard_bounds(),
        )
        old, new = [], []
        for _ in range(3):  # alternate, the best of three each
            began = time.perf_counter()
            reference = _step_by_step(maps, *args) * model.y_std_ + model.y_mean_
            old.append(time.perf_counter() - began)
            began = time.perf_counter()
            simulated = model.simulate(Uv, Yv, gv)
            new.append(time.perf_counter() - began)
        ratio, gap = min(old) / min(new), float(np.abs(simulated - reference).max())
        print(
            f"{name}: {min(old):.3f} s / {min(new):.3f} s = {ratio:.1f}x, outputs within {gap:.1e}"
        )
        figures[f"free run, {name}: step by step / vectorised"] = round(ratio, 1)
        units[f"free run, {name}: step by step / vectorised"] = "x"
        figures[f"free run, {name}: largest difference"] = float(f"{gap:.1e}")
        units[f"free run, {name}: largest difference"] = "mm"


def main() -> None:
    arm = arm_experiments()
    rows = sum(e.n_samples for e in arm.experiments)
    figures: dict = {}
    units: dict = {}
    start = time.perf_counter()
    selection = select_model(arm, validate_on=list(ARM_VALIDATION))
    seconds = time.perf_counter() - start
    show(f"soft arm, {rows:,} rows x 3 inputs x 2 outputs", selection, seconds, figures, units)
    pruned = selection.table[selection.table["pruned_after_folds"] > 0]
    print(
        f"CPU time of the selection {selection.cpu_seconds:.1f} s; pruned by their one-step "
        f"error: {len(pruned)} of {len(selection.table)} ({', '.join(pruned['candidate'])})"
    )
    figures["soft arm: CPU time of the selection"] = round(selection.cpu_seconds, 1)
    units["soft arm: CPU time of the selection"] = "s"
    figures["soft arm: candidates pruned by their one-step error"] = (
        f"{len(pruned)} of {len(selection.table)}"
    )
    units["soft arm: candidates pruned by their one-step error"] = ""
    start = time.perf_counter()
    delayed = select_model(
        arm, validate_on=list(ARM_VALIDATION), candidates=default_candidates(delays=False)
    )
    seconds = time.perf_counter() - start
    label = "soft arm, with --no-search-delays"
    print(f"\n{label}: {seconds:.1f} s, CPU {delayed.cpu_seconds:.1f} s")
    print(delayed.verdict())
    best = delayed.row(delayed.best)
    for key, value, unit in (
        ("wall time", round(seconds, 1), "s"),
        ("CPU time of the selection", round(delayed.cpu_seconds, 1), "s"),
        ("selected", delayed.best, ""),
        ("selected: fitted", delayed.model.describe(), ""),
        (
            "selected: validation free-run NRMSE",
            round(float(best["validation_freerun_nrmse"]), 4),
            "",
        ),
    ):
        figures[f"{label}: {key}"], units[f"{label}: {key}"] = value, unit
    free_run_ratios(arm, figures, units)
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
