"""Model selection by the error that matters: free-run on whole held-out experiments.

A NARX model is used run free: its own past outputs feed its next step, for
as long as the experiment lasts. Its one-step error (the measured past fed in)
says little about that, so :func:`select_model` chooses by the **free-run**
error of experiment-grouped cross-validation: the training experiments are
split into folds, each fold's experiments are held out whole, the candidate
is fitted on the others and run free on them from their first ``max_lag``
samples. The error is the RMSE of each output over that output's range in the
training data (NRMSE), averaged over outputs and folds; the one-step NRMSE is
reported beside and never used to choose.

The candidates (:func:`default_candidates`) always include the baselines —
linear ARX models over a grid of lags, degree-2 polynomial NARX models, and
paper A's setting as it was (a GG-SVR, C = 100, ε = 0.1, lags 2 and 2) —
beside a seeded random search of kernel models (C, ε, Gaussian or estimated
shape, lags) raced by successive halving: every kernel candidate is scored
with its maps fitted on :data:`FIRST_RUNG_ROWS` regressor rows, and the best
third again on ``max_rows``.

Candidates that cannot win are pruned by their one-step error. A free run
feeds its own errors back, so its NRMSE is in practice at least the one-step
NRMSE of the same model on the same experiments (every table of
``benchmarks/bench_identify.py`` shows it). The one-step NRMSE is scored first on
each fold, and a candidate is dropped, its remaining folds neither fitted nor
run free, as soon as the sum of its one-step NRMSEs so far over the number of
folds (a lower bound of its cross-validated one-step NRMSE, hence of its
free-run NRMSE) reaches the lowest cross-validated free-run NRMSE of a candidate
that may be chosen. Only candidates fitted one step ahead that are not
baselines are pruned (:func:`prunable`; the kernel search): the baselines are
the yardstick and always scored in full, and a model fitted by its free-run
error may run free better than one step. In the race, the bar is set by the
candidates that may be chosen (not by first-rung scores), and the best third
goes on among the candidates not pruned in the first rung (none when all were);
the table records after how many folds each candidate was pruned.

The model chosen is the lowest cross-validated free-run error among all of
them, whichever family wins; when it is a linear ARX, :meth:`Selection.verdict`
says so plainly. With ``validate_on``, those experiments are never seen by the
selection; every candidate, refitted on all the training experiments, is run
free on them too. The chosen model is then
read physically (:attr:`Selection.dynamics`): the gain, time constant and dead
time of every output's response to a step of every input
(:func:`~softbend.identification.dynamics.step_readings`).

How far the chosen model's free run may stray is read from the same held-out
runs: :attr:`Selection.band` is a 90 % band of the cross-validation free-run
residuals of the chosen candidate (:mod:`softbend.identification.band`), and
its coverage is checked on samples it was not estimated from — the validation
experiments, or without them each fold against the band of the other folds.
Every phase longer than a moment reports its progress
(:func:`softbend._progress.report`); the selection's wall time and the
process's peak memory are recorded (:attr:`Selection.seconds`,
:attr:`Selection.peak_memory_mib`, :attr:`Selection.cpu_seconds`).
"""

from __future__ import annotations

import math
import time
import warnings
from collections.abc import Callable, Sequence
from dataclasses import dataclass, field, replace
from typing import TYPE_CHECKING, Any

import numpy as np

from softbend.errors import ConvergenceError, DatasetError, InputError
from softbend.identification.band import (
    BAND_LEVEL,
    FreeRunBand,
    coverage,
    estimate_band,
    fold_coverage,
    free_run_residuals,
)
from softbend.identification.dynamics import (
    StepReading,
    identified_model,
    seconds_per_unit,
    step_readings,
)
from softbend.identification.kernels import ShapeClippedWarning
from softbend.identification.multi import MultiNARX
from softbend.identification.ranges import FOLDS_RANGE, SEED_RANGE, check_integer
from softbend.identification.resources import peak_memory_mib
from softbend.identification.scoring import _free_run_only, free_run_error, one_step_error
from softbend.identification.simmaps import SIM_FAMILIES
from softbend.identification.timeseries import TimeSeriesSet
from softbend.identification.timeseries_io import check_signals
from softbend.parameters import Range

if TYPE_CHECKING:
    import pandas as pd

__all__ = [
    "FIRST_RUNG_ROWS",
    "Candidate",
    "Selection",
    "default_candidates",
    "free_run_error",
    "one_step_error",
    "prunable",
    "select_model",
]

#: Regressor rows of a kernel candidate's first rung (then the best third get ``max_rows``).
FIRST_RUNG_ROWS = 500

#: Regressor rows a kernel map needs at least: its width and shape are estimated from them.
MIN_KERNEL_ROWS = 4

#: Kernel candidates of :func:`default_candidates`: each costs a cross-validation.
_N_KERNEL_RANGE = Range(0, 1000, "candidates", why="each costs a cross-validation")


@dataclass(frozen=True)
class Candidate:
    """One model to try: a family (:data:`~softbend.identification.multi.STRUCTURES`), its
    lags and its map's parameters."""

    name: str
    family: str
    output_lags: int
    input_lags: int
    params: dict[str, Any] = field(default_factory=dict)

    def build(self, max_rows: int) -> MultiNARX:
        """The unfitted model."""
        return MultiNARX(
            self.family,
            output_lags=self.output_lags,
            input_lags=self.input_lags,
            params=self.params,
            max_rows=max_rows,
        )

    @property
    def baseline(self) -> bool:
        """Whether a baseline (linear, polynomial, paper A's default) rather than a search point."""
        return self.family in ("arx", "poly2") or self.name == "paper-a"


def default_candidates(seed: int = 0, n_kernel: int = 6, *, delays: bool = True) -> list[Candidate]:
    """The baselines, the simulation-error models and ``n_kernel`` seeded kernel candidates.

    The simulation-error models (:mod:`~softbend.identification.simfit`, each
    started from its one-step fit and seeded by ``seed``) are a degree-2
    polynomial with an input filter and a neural NARX, both with lags 2 and 3,
    and with ``delays`` the same polynomial with each input's delay (dead time,
    0–3 samples) searched, after the one without (a tie goes to the first: a
    search that finds no delay does not displace it); the rest as the module
    docstring says.

    Parameters
    ----------
    seed : int, default 0
        Seed of the kernel candidates, in [0, 2**32 - 1].
    n_kernel : int, default 6
        Kernel candidates, in [0, 1000].
    delays : bool, default True
        Add the polynomial whose input delays are searched (about a third more CPU;
        on the synthetic soft arm it lowers the held-out free-run NRMSE from 0.0100
        to 0.0077, see ``benchmarks/bench_identify.py``).
    """
    seed = check_integer(seed, SEED_RANGE, "seed")
    n_kernel = check_integer(n_kernel, _N_KERNEL_RANGE, "n_kernel")
    lags = [(na, nb) for na in (1, 2, 3) for nb in (1, 2, 3)]
    out = [Candidate(f"arx-{na}-{nb}", "arx", na, nb) for na, nb in lags]
    out += [Candidate(f"poly2-{na}-{nb}", "poly2", na, nb) for na, nb in lags if na + nb <= 4]
    out.append(Candidate("paper-a", "gg-svr", 2, 2, {"C": 100.0, "epsilon": 0.1}))
    # fitted by simulation error, from the one-step fit (softbend.identification.simfit)
    out += [
        Candidate("poly2-sim-2-3-filter", "poly2-sim", 2, 3, {"filter": True, "seed": seed}),
    ]
    if delays:
        out.append(
            Candidate(
                "poly2-sim-2-3-filter-delay",
                "poly2-sim",
                2,
                3,
                {"filter": True, "delay": None, "seed": seed},
            )
        )
    out += [
        Candidate("nn-sim-2-3", "nn-sim", 2, 3, {"seed": seed}),
    ]
    rng = np.random.default_rng([seed, 32])
    kernel_lags = [(1, 1), (2, 1), (2, 2), (3, 2)]
    for i in range(n_kernel):
        na, nb = kernel_lags[int(rng.integers(len(kernel_lags)))]
        C = float(10 ** rng.uniform(0.0, 3.0))
        epsilon = float(10 ** rng.uniform(-2.5, -1.0))
        shape = 2.0 if rng.random() < 0.5 else None
        params = {"C": round(C, 3), "epsilon": round(epsilon, 4), "shape": shape}
        out.append(Candidate(f"svr-{i + 1}", "gg-svr", na, nb, params))
    return out


def _fold_of(names: Sequence[str], folds: int) -> dict[str, int]:
    """Experiment → fold: in order, round robin (whole experiments only)."""
    return {name: i % folds for i, name in enumerate(names)}


def prunable(candidate: Candidate) -> bool:
    """Whether :func:`select_model` may prune ``candidate`` by its one-step error: a
    candidate fitted one step ahead that is not a baseline (module docstring)."""
    return not candidate.baseline and candidate.family not in SIM_FAMILIES


@dataclass
class Selection:
    """The result of :func:`select_model`.

    Attributes
    ----------
    table : DataFrame
        One row per candidate scored: ``candidate``, ``family``, ``na``, ``nb``,
        ``settings``, ``rows`` (regressor rows of each map), ``rung``,
        ``cv_freerun_nrmse``, ``cv_onestep_nrmse``, ``validation_freerun_nrmse``
        (NaN without validation experiments, or for a candidate dropped in
        the first rung), ``fit_s``, ``pruned_after_folds`` (0, or the folds after
        which the candidate was pruned: its free-run NRMSEs are then NaN); sorted
        by the cross-validated free-run error.
    best : str
        The chosen candidate.
    model : MultiNARX
        The chosen candidate fitted on every training experiment.
    train, validation : tuple of str
        The experiments of each part.
    input_names, output_names : tuple of str
    ranges : ndarray
        Each output's range over the training experiments (the NRMSE's scale).
    validation_outputs : dict of str to ndarray
        Each validation experiment's free run by the chosen model (n, m).
    seconds : float
        Wall time of the selection, s.
    cv_outputs : dict of str to ndarray
        Each training experiment's free run by the chosen candidate fitted without
        its fold (the cross-validation's held-out runs).
    time_name : str
        The data's time column (``"sample"`` for the sample index).
    sample_period : float
        The data's median sampling interval, in the time column's unit.
    dynamics : list of StepReading
        The chosen model's gain, time constant and delay of every (input,
        output) pair (:func:`~softbend.identification.dynamics.step_readings`).
    band : FreeRunBand, optional
        The band around the chosen model's free run from its cross-validation
        residuals, in the outputs' units, with its coverage on held-out samples
        (:mod:`softbend.identification.band`).
    peak_memory_mib : float, optional
        The process's peak resident memory at the end of the selection, MiB
        (None where the platform cannot tell).
    cpu_seconds : float, optional
        CPU time of the process's threads during the selection, s (beside the
        wall time, which grows with the load of a shared machine).
    split : dict, optional
        Where the experiments came from when they are segments of one recording
        (:meth:`~softbend.identification.segments.RecordingSplit.to_dict`: each
        segment's sample range and role); None for experiments of their own.
    """

    table: Any
    best: str
    model: MultiNARX
    train: tuple[str, ...]
    validation: tuple[str, ...]
    input_names: tuple[str, ...]
    output_names: tuple[str, ...]
    ranges: np.ndarray
    validation_outputs: dict[str, np.ndarray]
    seconds: float
    cv_outputs: dict[str, np.ndarray] = field(default_factory=dict)
    time_name: str = "sample"
    sample_period: float = 1.0
    dynamics: list[StepReading] = field(default_factory=list)
    band: FreeRunBand | None = None
    peak_memory_mib: float | None = None
    cpu_seconds: float | None = None
    split: dict[str, Any] | None = None

    @property
    def time_unit_s(self) -> float | None:
        """Seconds per unit of the time column (None when unknown or the sample index)."""
        return seconds_per_unit(self.time_name)

    @property
    def input_filters(self) -> tuple[dict[str, float], str] | None:
        """The chosen model's learned input filters: each input's time constant and the unit
        (``"s"`` when the time column's unit is known, else ``"samples"``); None without."""
        tau = getattr(self.model, "input_tau_", None)
        if tau is None:
            return None
        unit_s = self.time_unit_s
        scale, unit = (
            (1.0, "samples") if unit_s is None else (float(self.sample_period) * unit_s, "s")
        )
        if unit_s is None and self.time_name != "sample":
            scale, unit = float(self.sample_period), self.time_name
        values = {name: float(t) * scale for name, t in zip(self.input_names, tau, strict=True)}
        return values, unit

    @property
    def holdout_outputs(self) -> dict[str, np.ndarray]:
        """The chosen model's free runs of held-out experiments: the validation experiments
        (fitted on all training ones), else each training experiment run by the model of
        its cross-validation fold (fitted without it)."""
        return self.validation_outputs if self.validation else self.cv_outputs

    def row(self, name: str) -> dict[str, Any]:
        """The table's row of a candidate."""
        return dict(self.table.set_index("candidate").loc[name].to_dict(), candidate=name)

    def best_of(self, family: str) -> dict[str, Any] | None:
        """The row of the lowest cross-validated free-run error of ``family``, if any."""
        rows = self.table[self.table["family"] == family]
        return None if rows.empty else dict(rows.iloc[0].to_dict())

    def verdict(self) -> str:
        """One line: the chosen model against the best linear ARX."""
        best = self.row(self.best)
        linear = self.best_of("arx")
        column = "validation_freerun_nrmse" if self.validation else "cv_freerun_nrmse"
        where = "on the validation experiments" if self.validation else "cross-validated"
        if linear is None:
            return f"Selected {self.best}: free-run NRMSE {best[column]:.4g} {where}."
        if best["family"] == "arx":
            return (
                f"A linear ARX model is the best: {self.best} (free-run NRMSE "
                f"{best[column]:.4g} {where}); no nonlinear candidate ran free better."
            )
        if not linear[column] > 0:  # the linear ARX ran free without error: no ratio
            return (
                f"Selected {self.best} ({best['family']}): free-run NRMSE {best[column]:.4g} "
                f"{where}, against {linear[column]:.4g} for the best linear ARX "
                f"({linear['candidate']})."
            )
        gain = 1.0 - best[column] / linear[column]
        return (
            f"Selected {self.best} ({best['family']}): free-run NRMSE {best[column]:.4g} "
            f"{where}, {100 * gain:.0f} % below the best linear ARX ({linear['candidate']}, "
            f"{linear[column]:.4g})."
        )

    def to_dict(self) -> dict[str, Any]:
        """JSON-friendly: the verdict, the chosen model, the experiments and the table."""
        return {
            "best": self.best,
            "model": self.model.describe(),
            "verdict": self.verdict(),
            "inputs": list(self.input_names),
            "outputs": list(self.output_names),
            "train": list(self.train),
            "validation": list(self.validation),
            "output_ranges": self.ranges.tolist(),
            "time": self.time_name,
            "sample_period": self.sample_period,
            "time_unit_s": self.time_unit_s,
            "dynamics": [r.to_dict() for r in self.dynamics],
            "input_filters": None
            if self.input_filters is None
            else dict(zip(("time_constants", "unit"), self.input_filters, strict=True)),
            "table": self.table.to_dict(orient="records"),
            "band": None if self.band is None else self.band.to_dict(),
            "seconds": self.seconds,
            "peak_memory_mib": self.peak_memory_mib,
            "cpu_seconds": self.cpu_seconds,
            "split": self.split,
        }


def select_model(
    data: TimeSeriesSet,
    *,
    validate_on: Sequence[str] | None = None,
    folds: int = 4,
    candidates: Sequence[Candidate] | None = None,
    seed: int = 0,
    max_rows: int = 2000,
    progress: Callable[[int, int], None] | None = None,
) -> Selection:
    """Choose the NARX model with the lowest cross-validated free-run error.

    Parameters
    ----------
    data : TimeSeriesSet
        The experiments.
    validate_on : sequence of str, optional
        Experiments kept out of the selection and scored at the end.
    folds : int, default 4
        Folds of whole training experiments (at most one per experiment), in
        [2, 1000].
    candidates : sequence of Candidate, optional
        Default :func:`default_candidates` of ``seed``.
    seed : int, default 0
        In [0, 2**32 - 1].
    max_rows : int, default 2000
        Regressor rows of a kernel map in the last rung (evenly spaced over the
        training rows; a kernel fit's cost grows with their square).
    progress : callable, optional
        ``progress(done, total)`` in model fits.

    Raises
    ------
    ValueError
        Fewer than 2 training experiments, an unknown or repeated validation
        experiment, ``folds`` or ``seed`` out of range (all before any fit).
    DatasetError
        Signals :func:`~softbend.identification.timeseries_io.check_signals`
        refuses (a value beyond ±1e50, a constant output), or training folds
        with fewer than :data:`MIN_KERNEL_ROWS` regressor rows for a kernel
        candidate (all before any fit).
    ConvergenceError
        A figure of the selection that is not finite (the reason named).
    """
    import pandas as pd

    from softbend._progress import report

    start, cpu_start = time.perf_counter(), time.process_time()
    held = tuple(validate_on or ())
    unknown = [n for n in held if n not in data.names]
    if unknown:
        raise InputError(
            f"must name experiments of the data ({', '.join(data.names)}); "
            f"got {', '.join(map(repr, unknown))}",
            key="validate_on",
        )
    repeated = sorted({n for n in held if held.count(n) > 1})
    if repeated:
        raise InputError(
            f"must name each experiment once; got {', '.join(map(repr, repeated))} more than once",
            key="validate_on",
        )
    train_names = tuple(n for n in data.names if n not in held)
    if len(train_names) < 2:
        raise InputError(
            f"must leave at least 2 training experiments to hold one out; "
            f"{len(train_names)} remain{'s' if len(train_names) == 1 else ''} "
            f"({', '.join(train_names) or 'none'})",
            key="validate_on",
        )
    folds = min(check_integer(folds, FOLDS_RANGE, "folds"), len(train_names))
    seed = check_integer(seed, SEED_RANGE, "seed")
    check_signals(data, held)
    train = data.subset(train_names)
    ranges = np.ptp(np.vstack([e.outputs for e in train.experiments]), axis=0)
    fold_of = _fold_of(train_names, folds)
    parts = [
        (
            train.subset([n for n in train_names if fold_of[n] != k]),
            train.subset([n for n in train_names if fold_of[n] == k]),
        )
        for k in range(folds)
    ]
    chosen = list(default_candidates(seed) if candidates is None else candidates)
    _check_kernel_rows(chosen, parts)
    cheap = [c for c in chosen if c.family != "gg-svr" or c.baseline]
    raced = [c for c in chosen if c.family == "gg-svr" and not c.baseline]
    survivors = max(1, math.ceil(len(raced) / 3)) if raced else 0
    cv_total = folds * (len(cheap) + len(raced) + survivors)
    total = cv_total + (len(cheap) + survivors) * bool(held)  # pruned ones ticked unrun
    cv_phase = f"cross-validating {len(chosen)} candidates on {folds} folds (fits)"
    final_phase = (
        f"refitting {len(cheap) + survivors} candidates, free runs of the validation experiments"
        if held
        else "refitting the chosen candidate"
    )
    done = 0

    def tick() -> None:
        nonlocal done
        done += 1
        if done <= cv_total:
            report(cv_phase, done, cv_total)
        else:
            report(final_phase, done - cv_total, total - cv_total)
        if progress is not None:
            progress(done, total)

    cv_runs: dict[str, dict[str, np.ndarray]] = {}
    bar = math.inf  # the lowest CV free-run NRMSE of a candidate that may be chosen, so far

    def cross_validate(candidate: Candidate, rows: int, *, eligible: bool) -> dict[str, Any]:
        nonlocal bar
        free, step, fit_s = [], [], 0.0
        runs: dict[str, np.ndarray] = {}
        for fit_on, held_out in parts:
            U, Y, groups = fit_on.stacked()
            began = time.perf_counter()
            model = candidate.build(rows).fit(U, Y, groups)
            fit_s += time.perf_counter() - began
            step.append(one_step_error(model, held_out, ranges))
            tick()
            if prunable(candidate) and sum(step) / folds >= bar:
                break  # its CV one-step NRMSE, hence its free-run NRMSE, reaches the bar
            f, simulated = _free_run_only(model, held_out, ranges)
            runs.update(_split(held_out, simulated))
            free.append(f)
        pruned = len(free) < folds
        for _ in range(folds - len(step)):
            tick()
        if not pruned:
            cv_runs[candidate.name] = runs
            if eligible:
                bar = min(bar, float(np.mean(free)))
        return {
            "candidate": candidate.name,
            "family": candidate.family,
            "na": candidate.output_lags,
            "nb": candidate.input_lags,
            "settings": candidate.build(rows).describe(),
            "rows": model.n_train_rows_,
            "cv_freerun_nrmse": math.nan if pruned else float(np.mean(free)),
            "cv_onestep_nrmse": float(np.mean(step)),
            "fit_s": fit_s / len(step),
            "pruned_after_folds": len(step) if pruned else 0,
        }

    rows_by_name: dict[str, dict[str, Any]] = {}
    with warnings.catch_warnings():
        # A kernel shape clipped to the Gaussian is expected in a search: not a warning here.
        warnings.simplefilter("ignore", ShapeClippedWarning)
        for candidate in cheap:
            rows_by_name[candidate.name] = {
                **cross_validate(candidate, max_rows, eligible=True),
                "rung": "all",
            }
        first = {c.name: cross_validate(c, FIRST_RUNG_ROWS, eligible=False) for c in raced}

        # the best third of the first rung goes on, of the candidates not pruned there
        going_on = sorted(
            (c for c in raced if not first[c.name]["pruned_after_folds"]),
            key=lambda c: first[c.name]["cv_freerun_nrmse"],
        )[:survivors]
        for _ in range(folds * (survivors - len(going_on))):
            tick()  # the final rung's fits of the candidates that do not go on
        for candidate in raced:
            rows_by_name[candidate.name] = (
                {**cross_validate(candidate, max_rows, eligible=True), "rung": "final"}
                if candidate in going_on
                else {**first[candidate.name], "rung": "first"}
            )
        final = [
            c
            for c in chosen
            if rows_by_name[c.name]["rung"] != "first"
            and not rows_by_name[c.name]["pruned_after_folds"]
        ]
        best = min(final, key=lambda c: rows_by_name[c.name]["cv_freerun_nrmse"])

        if not held:
            report(final_phase, 0, 1)
        U, Y, groups = train.stacked()
        validation_outputs: dict[str, np.ndarray] = {}
        fitted: dict[str, MultiNARX] = {}
        for _ in range(bool(held) * (len(cheap) + survivors - len(final))):
            tick()  # the refits of pruned candidates, not run
        for candidate in final:
            row = rows_by_name[candidate.name]
            row["validation_freerun_nrmse"] = math.nan
            if candidate is not best and not held:
                continue
            model = candidate.build(max_rows).fit(U, Y, groups)
            fitted[candidate.name] = model
            if held:
                validation = data.subset(held)
                free, simulated = _free_run_only(model, validation, ranges)
                row["validation_freerun_nrmse"] = free
                tick()
                if candidate is best:
                    validation_outputs = _split(validation, simulated)
    for row in rows_by_name.values():
        row.setdefault("validation_freerun_nrmse", math.nan)
    table = (
        pd.DataFrame(list(rows_by_name.values()))
        .sort_values(["cv_freerun_nrmse", "candidate"])
        .reset_index(drop=True)
    )
    columns = ["candidate", "family", "na", "nb", "settings", "rows", "rung", "cv_freerun_nrmse"]
    columns += ["cv_onestep_nrmse", "validation_freerun_nrmse", "fit_s", "pruned_after_folds"]
    _check_finite(table, validated=bool(held))
    if not held:
        report(final_phase, 1, 1)
    band = _band(
        data,
        train_names,
        held,
        cv_runs[best.name],
        validation_outputs,
        fold_of,
        fitted[best.name].max_lag,
    )
    report("reading the chosen model's step responses", 0, 1)
    identified = identified_model(fitted[best.name], data)
    dynamics = step_readings(identified)
    report("reading the chosen model's step responses", 1, 1)
    return Selection(
        table=table[columns],
        best=best.name,
        model=fitted[best.name],
        train=train_names,
        validation=held,
        input_names=data.input_names,
        output_names=data.output_names,
        ranges=ranges,
        validation_outputs=validation_outputs,
        seconds=time.perf_counter() - start,
        peak_memory_mib=peak_memory_mib(),
        cpu_seconds=time.process_time() - cpu_start,
        cv_outputs=cv_runs[best.name],
        time_name=identified.time_name,
        sample_period=identified.sample_period,
        dynamics=dynamics,
        band=band,
    )


def _band(
    data: TimeSeriesSet,
    train_names: Sequence[str],
    held: Sequence[str],
    cv_outputs: dict[str, np.ndarray],
    validation_outputs: dict[str, np.ndarray],
    fold_of: dict[str, int],
    lag: int,
) -> FreeRunBand:
    """The chosen model's band from its cross-validation runs, its coverage checked on the
    validation experiments, else on each fold against the band of the other folds."""
    outputs = {e.name: e.outputs for e in data.experiments}

    def residuals(names: Sequence[str], runs: dict[str, np.ndarray]) -> np.ndarray:
        return free_run_residuals([outputs[n] for n in names], [runs[n] for n in names], start=lag)

    band = estimate_band(residuals(train_names, cv_outputs), data.output_names, level=BAND_LEVEL)
    if held:
        checked = residuals(held, validation_outputs)
        covered, samples, on = coverage(band, checked), len(checked), "validation experiments"
    else:
        by_fold = [
            residuals([n for n in train_names if fold_of[n] == k], cv_outputs)
            for k in sorted(set(fold_of.values()))
        ]
        covered, samples = fold_coverage(by_fold, data.output_names, level=BAND_LEVEL)
        on = "cross-validation folds"
    return replace(
        band,
        coverage=tuple(float(c) for c in covered),
        coverage_on=on,
        coverage_samples=int(samples),
    )


def _check_kernel_rows(
    candidates: Sequence[Candidate], parts: Sequence[tuple[TimeSeriesSet, TimeSeriesSet]]
) -> None:
    """Refuse, before any fit, folds too short for the kernel candidates' maps."""
    lags = [c.build(10).max_lag for c in candidates if c.family == "gg-svr"]
    if not lags:
        return
    lag = max(lags)
    for fit_on, held_out in parts:
        rows = sum(max(e.n_samples - lag, 0) for e in fit_on.experiments)
        if rows < MIN_KERNEL_ROWS:
            raise DatasetError(
                f"The kernel candidates need at least {MIN_KERNEL_ROWS} regressor rows to fit "
                f"on, but the training experiments without {', '.join(held_out.names)} give "
                f"{rows} (lags up to {lag}; experiments of "
                f"{', '.join(str(e.n_samples) for e in fit_on.experiments)} samples): record "
                "longer experiments."
            )


def _check_finite(table: pd.DataFrame, *, validated: bool) -> None:
    """Raise :class:`ConvergenceError` naming the first figure of ``table`` that is not finite.

    The validation error is NaN by design without validation experiments and for
    a candidate dropped in the first rung; every other figure must be a number.
    """
    for _, row in table.iterrows():
        pruned = bool(row["pruned_after_folds"])
        checked = ["cv_onestep_nrmse", "fit_s"] + ([] if pruned else ["cv_freerun_nrmse"])
        if validated and row["rung"] != "first" and not pruned:
            checked.append("validation_freerun_nrmse")
        for column in checked:
            if not math.isfinite(float(row[column])):
                raise ConvergenceError(
                    f"The {column} of candidate {row['candidate']} is {float(row[column])!r}: "
                    "the selection's figures are not all finite, so none is reported. The "
                    "data's scale or a degenerate signal is the likely cause."
                )


def _split(data: TimeSeriesSet, stacked: np.ndarray) -> dict[str, np.ndarray]:
    """Rows of a stacked array, per experiment of ``data``."""
    offsets = np.cumsum([0] + [e.n_samples for e in data.experiments])
    return {e.name: stacked[offsets[i] : offsets[i + 1]] for i, e in enumerate(data.experiments)}
