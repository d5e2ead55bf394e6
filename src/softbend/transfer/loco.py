"""Leave-one-configuration-out evaluation of the refinement strategies (paper B Fig. 7).

For every measured actuator, every strategy is fitted on the measurements of the
other actuators and scored on the held-out one: RMSE, MAPE, largest error, and for
strategies with intervals the share of held-out readings inside the interval.
Every strategy (but the two slowest) also gets a calibrated interval
(:mod:`softbend.transfer.conformal`), nested: the held-out actuator's interval
is calibrated on the leave-one-out errors of the other actuators, each from a
model fitted without it and without the held-out one, as a lab with those
actuators alone would have calibrated it. A learning curve repeats this with
1, 2, ... of the other actuators measured.

The MAPE of paper B's actuator keeps paper B's definition (the 0 MPa points
included; only exact zeros left out), to compare with paper B Fig. 7 (6.45 %).
Any other actuator's leaves out the readings below
:func:`softbend.metrics.mape_floor` of all its measured angles, max(5°, 5 % of
the largest), as ``softbend train`` does: near 0° a percentage says nothing.
The floor is ``mape_floor_deg`` of the settings, and each row counts the
readings it used (``n_mape_used``).

Every strategy's mean RMSE is also stated relative to the baseline's,
``base-mean-residual`` (:data:`BASELINE_STRATEGY`: the base plus the training
actuators' mean residual as a function of pressure alone, nothing learned about
the design): a strategy that does not beat it has learned nothing about the
design either.
"""

from __future__ import annotations

import inspect
import os
import time
from collections.abc import Callable, Mapping, Sequence
from dataclasses import dataclass, field
from pathlib import Path
from typing import TYPE_CHECKING, Any

import numpy as np
import pandas as pd

from softbend._io import json_text, write_text_atomic
from softbend._validation import check_int, check_range
from softbend.errors import InputError, SoftbendError, keyed
from softbend.metrics import mape_floor, rmse, thresholded_mape
from softbend.registry import UnknownNameError
from softbend.surrogates.protocol import Surrogate
from softbend.transfer.conformal import Calibration, angle_floor, calibrate
from softbend.transfer.measurements import ActuatorMeasurements, Measurements
from softbend.transfer.strategies import (
    BUILTIN_STRATEGIES,
    FIT_ERRORS,
    STRATEGIES,
    applicable_strategies,
    check_applicable,
    has_interval,
    make_strategy,
    strategy_parameters,
)
from softbend.transfer.strategies.parameters import check_parameters, recorded_parameters

if TYPE_CHECKING:
    from softbend.actuators import Actuator

__all__ = [
    "BASELINE_STRATEGY",
    "CURVE_SIZES",
    "DEFAULT_STRATEGIES",
    "MIN_CALIBRATION_ACTUATORS",
    "LocoResult",
    "check_calibration",
    "held_out_residuals",
    "learning_curve_sizes",
    "leave_one_configuration_out",
    "strategy_options",
]

#: The strategies of a default evaluation: softbend's own, in the order of the tables, those
#: of them that apply to the base (:func:`~softbend.transfer.strategies.applicable_strategies`).
DEFAULT_STRATEGIES: tuple[str, ...] = BUILTIN_STRATEGIES

#: Strategies left out of the learning curve and the nested calibration (the longest training).
_SLOW = ("experimental", "refined-ensemble")

#: The most training-set sizes of a learning curve (:func:`learning_curve_sizes`): paper B's
#: seven actuators give five, each size; 14 actuators give 1, 2, 3, 4, 7 and 12 of the 12.
CURVE_SIZES = 6

#: The strategy every other is judged against (``rmse_vs_baseline_pct`` of the summary): the
#: base plus the mean residual of the training actuators as a function of pressure alone.
BASELINE_STRATEGY = "base-mean-residual"

#: Actuators the nested calibration needs: the held-out one, and at least two others,
#: each predicted by a model fitted without it and without the held-out one.
MIN_CALIBRATION_ACTUATORS = 3


@dataclass(frozen=True)
class LocoResult:
    """What :func:`leave_one_configuration_out` measured.

    Attributes
    ----------
    per_actuator : DataFrame
        One row per (strategy, held-out actuator): ``n_points``, ``rmse_deg``,
        ``mape_pct`` (over the readings at or above the settings'
        ``mape_floor_deg``; NaN when none is), ``n_mape_used``, ``max_error_deg``,
        ``coverage`` (share inside the interval, NaN without one),
        ``calibrated_coverage`` and ``calibrated_width_deg``
        (share inside, and mean width in degrees, of the calibrated interval,
        calibrated without the held-out actuator; NaN when not calibrated),
        ``calibration_half_width_deg``, ``calibration_guaranteed``, ``fit_s``;
        ``status`` ("ok", or "failed": the strategy could not be fitted without
        that actuator, its scores NaN) and ``error`` (why, else None).
    summary : DataFrame
        One row per strategy: the means over actuators (coverages weighted by
        readings), the worst actuator and its RMSE and MAPE. ``rmse_deg`` and
        ``rmse_deg_mean`` are the same figure, the mean over held-out actuators
        of their RMSE (degrees; an actuator with no finite prediction left
        out); ``rmse_vs_baseline_pct`` is ``100 · (rmse_deg_mean /
        baseline's − 1)`` against :data:`BASELINE_STRATEGY` (NaN when it is not
        in the run); ``calibrated_coverage`` is the share of held-out readings
        inside the calibrated interval, and ``calibrated_coverage_reason`` says
        why it is NaN (None when it is not). The means are over the actuators
        the strategy was fitted without; ``n_failed`` counts those it could not be.
    predictions : DataFrame
        Every held-out reading with each strategy's prediction (``lo``/``hi`` for
        interval strategies, ``cal_lo_deg``/``cal_hi_deg`` for the calibrated
        interval).
    learning_curve : DataFrame
        ``strategy, n_actuators, held_out, rmse_deg, mape_pct, error``: fitted on
        the first ``n`` of the other actuators in a seeded order (``error``: why
        a fit failed, its scores NaN; None when it did not).
    loss_curves : dict of str to ndarray
        Training MSE per epoch (deg²) of the MLP strategies fitted on all
        actuators (paper B Fig. 6).
    level : float
        Probability of the intervals.
    settings : dict
        Strategies, seed, interval level, time taken; ``baseline``, the
        strategy ``rmse_vs_baseline_pct`` is relative to (None when it is not
        in the run); ``left_out``, each default strategy that cannot start
        from the base with the reason; ``failed``, each (strategy, held-out
        actuator) that could not be fitted with the reason, and
        ``failed_other_fits``, how many fits of the learning curve, the
        nested calibration and the fit on every actuator failed.
    calibrations : dict of str to dict
        Per calibrated strategy, the calibration on all the actuators (what
        ``softbend transfer refine`` would record; :meth:`Calibration.to_dict`).
    """

    per_actuator: pd.DataFrame
    summary: pd.DataFrame
    predictions: pd.DataFrame
    learning_curve: pd.DataFrame
    loss_curves: dict[str, np.ndarray] = field(default_factory=dict)
    level: float = 0.9
    settings: dict[str, Any] = field(default_factory=dict)
    calibrations: dict[str, dict[str, Any]] = field(default_factory=dict)

    def best(self) -> str:
        """The strategy with the lowest mean RMSE."""
        return str(self.summary.sort_values("rmse_deg").iloc[0]["strategy"])

    def write(self, out: str | os.PathLike[str]) -> dict[str, str]:
        """Write the tables (CSV) and ``loco.json`` into the folder ``out``; returns the paths.

        Each file is written whole (temporary file, then rename); ``loco.json`` is
        strict JSON (NaN as null). The command line writes the folder as a whole
        (:func:`softbend._outdir.staged_dir`).
        """
        folder = Path(out)
        folder.mkdir(parents=True, exist_ok=True)
        files = {}
        for name in ("summary", "per_actuator", "predictions", "learning_curve"):
            path = folder / f"{name}.csv"
            write_text_atomic(path, getattr(self, name).to_csv(index=False))
            files[name] = str(path)
        curves = pd.DataFrame({k: pd.Series(v) for k, v in self.loss_curves.items()})
        curves.index = pd.RangeIndex(1, len(curves) + 1, name="epoch")
        write_text_atomic(folder / "loss_curves_deg2.csv", curves.to_csv())
        files["loss_curves"] = str(folder / "loss_curves_deg2.csv")
        write_text_atomic(folder / "loco.json", json_text(self.to_dict()) + "\n")
        files["json"] = str(folder / "loco.json")
        return files

    def to_dict(self) -> dict[str, Any]:
        """JSON-friendly: summary and per-actuator rows, learning curve, settings."""
        return {
            "summary": self.summary.to_dict(orient="records"),
            "per_actuator": self.per_actuator.to_dict(orient="records"),
            "learning_curve": self.learning_curve.to_dict(orient="records"),
            "final_loss_deg2": {k: float(v[-1]) for k, v in self.loss_curves.items()},
            "level": self.level,
            "calibration": self.calibrations,
            "settings": self.settings,
        }


def _score(
    strategy: str,
    held_out: str,
    y: np.ndarray,
    pred: np.ndarray,
    interval: tuple[np.ndarray, np.ndarray] | None,
    floor: float = 0.0,
) -> dict[str, Any]:
    ok = np.isfinite(pred)
    row: dict[str, Any] = {
        "strategy": strategy,
        "actuator_id": held_out,
        "n_points": int(y.size),
        "n_predicted": int(ok.sum()),
    }
    if ok.any():
        err = pred[ok] - y[ok]
        row["rmse_deg"] = rmse(y[ok], pred[ok])
        row["mape_pct"], left_out = thresholded_mape(y[ok], pred[ok], threshold=floor)
        row["n_mape_used"] = int(ok.sum()) - left_out
        row["max_error_deg"] = float(np.max(np.abs(err)))
    else:
        row.update(rmse_deg=np.nan, mape_pct=np.nan, n_mape_used=0, max_error_deg=np.nan)
    if interval is not None:
        lo, hi = interval
        row["coverage"] = float(np.mean((y >= lo) & (y <= hi)))
    else:
        row["coverage"] = np.nan
    return row


def _fit_all(
    name: str,
    base: Surrogate | None,
    options: dict[str, Any],
    seed: int,
    X: np.ndarray,
    y: np.ndarray,
    row_sets: list[np.ndarray],
    actuator: Actuator | None = None,
) -> tuple[list[Any], float]:
    """Fit one fresh ``name`` strategy per row set (readings of ``actuator``, paper B's by
    default); batched where the strategy can.

    Returns each fitted strategy, or the error (one of
    :data:`~softbend.transfer.strategies.FIT_ERRORS`) that stopped its fit: one
    row set that cannot be fitted leaves the others' fits. A batch whose
    ``fit_batch`` takes ``keep_going`` records its failures itself; one that
    does not, and fails, is fitted again one row set at a time.
    """
    start = time.perf_counter()
    models: list[Any] = [
        make_strategy(name, base, seed=seed, actuator=actuator, **options) for _ in row_sets
    ]
    fit_batch = getattr(type(models[0]), "fit_batch", None)
    if fit_batch is not None and "keep_going" in inspect.signature(fit_batch).parameters:
        fit_batch(models, X, y, row_sets, keep_going=True)
        models = [getattr(m, "fit_error_", None) or m for m in models]
    elif fit_batch is not None:
        try:
            fit_batch(models, X, y, row_sets)
        except FIT_ERRORS:
            models = [
                _fit_one(m, X, y, rows, fit_batch) for m, rows in zip(models, row_sets, strict=True)
            ]
    else:
        models = [_fit_one(m, X, y, rows) for m, rows in zip(models, row_sets, strict=True)]
    return models, (time.perf_counter() - start) / len(row_sets)


def _fit_one(
    model: Any, X: np.ndarray, y: np.ndarray, rows: np.ndarray, fit_batch: Any = None
) -> Any:
    """``model`` fitted on ``rows`` (alone, as a batch of one with ``fit_batch``), or its error."""
    try:
        if fit_batch is not None:
            fit_batch([model], X, y, [rows])
        else:
            model.fit(X[rows], y[rows])
    except FIT_ERRORS as error:
        return error
    return model


def _reason(error: BaseException) -> str:
    """Why one fit failed, in the words of the run: the readings, the base, a parameter."""
    if not isinstance(error, SoftbendError) or error.key is None:
        return " ".join(str(error).split())
    subject = {"X": "training readings", "y": "training readings", "base": "base"}.get(
        error.key, error.key
    )
    return " ".join(error.described(subject).split())


def learning_curve_sizes(n_actuators: int, most: int = CURVE_SIZES) -> list[int]:
    """The numbers of training actuators a learning curve fits on, with ``n_actuators`` in all.

    One actuator is held out and the main evaluation fits on the n − 1 others,
    so the curve's sizes lie in 1 … n − 2: each of them while there are at most
    ``most``, else at most ``most`` sizes spaced geometrically from 1 to n − 2 (the
    curve changes most at few actuators; its fits cost most at many).

    Parameters
    ----------
    n_actuators : int
        Actuators in the measurements, held-out one included.
    most : int, default CURVE_SIZES
        The most sizes, at least 2.

    Returns
    -------
    list of int
        Increasing sizes; none below three actuators.
    """
    top = int(n_actuators) - 2
    if top < 1:
        return []
    if top <= most:
        return list(range(1, top + 1))
    return sorted({round(float(size)) for size in np.geomspace(1, top, most)})


def leave_one_configuration_out(
    measurements: Measurements | ActuatorMeasurements,
    base: Surrogate | None,
    strategies: Sequence[str] | None = None,
    *,
    level: float = 0.9,
    learning_curve: bool = True,
    calibrated: bool = False,
    fallback: str = "quantile",
    seed: int = 0,
    options: dict[str, dict[str, Any]] | None = None,
    progress: Callable[[int, int, str], None] | None = None,
) -> LocoResult:
    """Score every strategy on every held-out actuator, trained on the others.

    Parameters
    ----------
    measurements : Measurements
        At least two actuators.
    base : estimator
        The simulation-trained surrogate the strategies start from (an ``mlp``
        surrogate for ``refined``, ``refined-ensemble``).
    strategies : sequence of str, optional
        Names among :data:`~softbend.transfer.strategies.STRATEGIES` (any
        registered strategy), each one that can start from ``base``. Default:
        those of :data:`DEFAULT_STRATEGIES` that can; the others, with the
        reason, are the settings' ``left_out``.
    level : float, default 0.9
        Probability of the prediction intervals, in (0, 1).
    learning_curve : bool, default True
        Also fit on fewer of the other actuators (n−1 is the main evaluation):
        each of 1, 2, ..., n−2 up to :data:`CURVE_SIZES` sizes, beyond that
        at most that many, spaced geometrically from 1 to n−2
        (:func:`learning_curve_sizes`); not ``experimental`` and
        ``refined-ensemble``, whose training would dominate the time.
    calibrated : bool, default False
        Also score the calibrated interval of :mod:`softbend.transfer.conformal`
        on each held-out actuator, nested (n − 1 more fits per held-out
        actuator, each without it and one other); not ``experimental`` and
        ``refined-ensemble``. Refused (:func:`check_calibration`) with fewer
        than :data:`MIN_CALIBRATION_ACTUATORS` actuators or with no strategy
        but those two.
    fallback : {"quantile", "largest"}, default "quantile"
        The calibrated half-width with too few actuators for the conformal
        guarantee (:func:`softbend.transfer.conformal.calibrate`).
    seed : int, default 0
        Seed of the strategies and of the learning curve's actuator order.
    options : dict, optional
        Parameters per strategy name, e.g. ``{"refined": {"epochs": 500}}``
        (see :func:`strategy_options` for text such as ``epochs=500``).
    progress : callable, optional
        ``progress(done, total, strategy)`` after each strategy's fits.

    Returns
    -------
    LocoResult
        A fit that fails on one held-out actuator (readings it cannot fit, a
        training that diverged) leaves the others: its row of ``per_actuator``
        has ``status`` "failed", the reason in ``error`` and NaN scores, the
        summary's means are over the actuators it did fit (``n_failed``
        counts the others) and the settings' ``failed`` lists them.

    Raises
    ------
    InputError
        Bad input, keyed by the parameter; among them ``strategies`` naming one
        that cannot start from ``base`` (before any fit), ``calibrated`` with
        too few actuators or only the slowest strategies
        (:func:`check_calibration`). Every fit on every held-out actuator
        failing raises the first one's error.
    """
    if not isinstance(measurements, Measurements | ActuatorMeasurements):
        raise InputError(
            "must be Measurements (see load_measurements) or ActuatorMeasurements; got "
            f"{type(measurements).__name__}",
            key="measurements",
        )
    from softbend.actuators import SFRBA

    actuator = getattr(measurements, "actuator", SFRBA)  # paper B's Measurements: SFRBA
    left_out: dict[str, str] = {}
    if strategies is None:
        strategies, left_out = applicable_strategies(DEFAULT_STRATEGIES, base, actuator)
    # An actuator's own MAPE floor (paper B's: only exact zeros left out); else the readings'.
    fixed = actuator.transfer_mape_floor_deg
    floor = mape_floor(measurements.angle_deg) if fixed is None else fixed
    result = _leave_one_out(  # the strategies check the inputs of this actuator
        measurements,
        base,
        strategies,
        level=level,
        learning_curve=learning_curve,
        calibrated=calibrated,
        fallback=fallback,
        seed=seed,
        options=options,
        progress=progress,
        floor=floor,
        actuator=actuator,
    )
    result.settings["left_out"] = left_out
    if actuator.named_in_outputs:
        result.settings["actuator"] = actuator.to_dict()
        result.settings["pressure_column"] = actuator.pressure_column
        result.settings["pressure_unit"] = actuator.pressure_unit
    return result


def _leave_one_out(
    measurements: Measurements | ActuatorMeasurements,
    base: Surrogate | None,
    strategies: Sequence[str],
    *,
    level: float,
    learning_curve: bool,
    calibrated: bool,
    fallback: str,
    seed: int,
    options: dict[str, dict[str, Any]] | None,
    progress: Callable[[int, int, str], None] | None,
    floor: float = 0.0,
    actuator: Actuator | None = None,
) -> LocoResult:
    """:func:`leave_one_configuration_out` once the measurements' kind is known.

    ``floor``: the smallest ``|θ|`` in the MAPE, degrees; ``actuator``: what the
    base is a model of (paper B's actuator by default).
    """
    names = tuple(strategies)
    if not names:
        raise InputError(f"must name at least one of {', '.join(STRATEGIES)}", key="strategies")
    with keyed("strategies"):
        for name in names:
            STRATEGIES.check(name)
    if len(set(names)) != len(names):
        raise InputError(f"must be distinct; got {list(names)}", key="strategies")
    level = check_range(level, "level", low=0.0, high=1.0)
    seed = check_int(seed, "seed", low=0)
    with keyed("options"):
        options = {
            name: check_parameters(STRATEGIES.get(name), values)
            for name, values in dict(options or {}).items()
        }
    ids = measurements.actuator_ids
    _check_two_actuators(ids)
    if calibrated:
        check_calibration(ids, names)
    check_applicable(names, base, actuator, key="strategies")  # before any fit
    X, y, groups = measurements.features, measurements.angle_deg, measurements.groups
    rng = np.random.default_rng([seed, 3])
    curve_names = [n for n in names if n not in _SLOW] if learning_curve else []
    nested_names = [n for n in names if n not in _SLOW] if calibrated else []
    start = time.perf_counter()

    # Every fit is a task: (kind, held-out actuator, n actuators, strategy, train, test rows).
    tasks: list[tuple[str, str, int, str, np.ndarray, np.ndarray]] = []
    for held_out in ids:
        test = np.flatnonzero(groups == held_out)
        train = np.flatnonzero(groups != held_out)
        tasks += [("loco", held_out, len(ids) - 1, n, train, test) for n in names]
        others = [a for a in ids if a != held_out]
        order = [others[i] for i in rng.permutation(len(others))]
        for size in learning_curve_sizes(len(ids)):
            rows = np.flatnonzero(np.isin(groups, order[:size]))
            tasks += [("curve", held_out, size, n, rows, test) for n in curve_names]
        # Nested calibration: each other actuator predicted without it and without held_out.
        for inner in others:
            rows = np.flatnonzero(~np.isin(groups, [held_out, inner]))
            inner_test = np.flatnonzero(groups == inner)
            tasks += [
                ("nested", f"{held_out}\x00{inner}", len(ids) - 2, n, rows, inner_test)
                for n in nested_names
            ]
    everything = np.arange(len(y))
    tasks += [("all", "", len(ids), n, everything, everything[:0]) for n in names]
    results: list[dict[str, Any]] = [{} for _ in tasks]
    done = 0
    for name in names:
        mine = [i for i, task in enumerate(tasks) if task[3] == name]
        # The nested calibration's fits in a batch of their own: the others' as without it.
        for batch in (
            [i for i in mine if tasks[i][0] != "nested"],
            [i for i in mine if tasks[i][0] == "nested"],
        ):
            if not batch:
                continue
            sets = [tasks[i][4] for i in batch]
            models, fit_s = _fit_all(name, base, options.get(name, {}), seed, X, y, sets, actuator)
            for i, model in zip(batch, models, strict=True):
                test = tasks[i][5]
                out: dict[str, Any] = {"fit_s": fit_s}
                if isinstance(model, BaseException):
                    out.update(pred=np.full(test.size, np.nan), interval=None, error=model)
                    results[i] = out
                    continue
                if test.size:
                    out["pred"] = np.asarray(model.predict(X[test]), dtype=np.float64)
                    out["interval"] = (
                        model.predict_interval(X[test], level) if has_interval(model) else None
                    )
                if hasattr(model, "loss_curve_"):
                    out["loss_curve"] = np.asarray(model.loss_curve_)
                results[i] = out
        done += len(mine)
        if progress is not None:
            progress(done, len(tasks), name)

    # Leave-one-out errors: nested[(name, held_out)][inner], loco_errors[name][held_out].
    nested: dict[tuple[str, str], dict[str, np.ndarray]] = {}
    loco_errors: dict[str, dict[str, np.ndarray]] = {}
    for (kind, held_out, _, name, _, test), out in zip(tasks, results, strict=True):
        if kind == "nested":
            outer, inner = held_out.split("\x00")
            nested.setdefault((name, outer), {})[inner] = np.abs(out["pred"] - y[test])
        elif kind == "loco" and name in nested_names:
            loco_errors.setdefault(name, {})[held_out] = np.abs(out["pred"] - y[test])

    failed = [
        (task, out["error"])
        for task, out in zip(tasks, results, strict=True)
        if task[0] == "loco" and "error" in out
    ]
    if len(failed) == len(ids) * len(names):  # nothing to report: the first fit's error
        raise failed[0][1]
    scores, predictions, curve = [], [], []
    loss_curves: dict[str, np.ndarray] = {}
    for (kind, held_out, size, name, train, test), out in zip(tasks, results, strict=True):
        if kind == "all":
            if "loss_curve" in out:
                loss_curves[name] = out["loss_curve"]
            continue
        if kind == "nested":
            continue
        row = _score(name, held_out, y[test], out["pred"], out["interval"], floor)
        row["status"] = "failed" if "error" in out else "ok"
        row["error"] = _reason(out["error"]) if "error" in out else None
        if kind == "loco":
            row["fit_s"] = out["fit_s"]
            cal = _calibration(nested.get((name, held_out)), level, y[train], fallback)
            row.update(_score_calibrated(cal, y[test], out["pred"]))
            scores.append(row)
            part = measurements.frame.iloc[test].assign(strategy=name, predicted_deg=out["pred"])
            if out["interval"] is not None:
                part = part.assign(lo_deg=out["interval"][0], hi_deg=out["interval"][1])
            if cal is not None:
                lo, hi = cal.interval(out["pred"])
                part = part.assign(cal_lo_deg=lo, cal_hi_deg=hi)
            predictions.append(part)
        if kind == "curve" or (kind == "loco" and name in curve_names):
            curve.append(
                {
                    "strategy": name,
                    "n_actuators": size,
                    "held_out": held_out,
                    "rmse_deg": row["rmse_deg"],
                    "mape_pct": row["mape_pct"],
                    "error": row["error"],
                }
            )
    base_curve, y_scale = getattr(base, "loss_curve_", None), getattr(base, "y_scale_", None)
    if base_curve is not None and y_scale is not None and "fem-only" in names:
        loss_curves["fem-only"] = np.asarray(base_curve) * y_scale**2

    per_actuator = pd.DataFrame(scores)
    return LocoResult(
        per_actuator=per_actuator,
        summary=_summarize(per_actuator, names, calibrated=calibrated),
        predictions=pd.concat(predictions, ignore_index=True),
        learning_curve=pd.DataFrame(
            curve,
            columns=["strategy", "n_actuators", "held_out", "rmse_deg", "mape_pct", "error"],
        )
        .sort_values(["strategy", "n_actuators", "held_out"], kind="stable")
        .reset_index(drop=True),
        loss_curves=loss_curves,
        level=level,
        calibrations={
            name: cal.to_dict()
            for name in nested_names
            if (cal := _calibration(loco_errors.get(name), level, y, fallback)) is not None
        },
        settings={
            "strategies": list(names),
            "seed": seed,
            "level": level,
            "actuators": list(ids),
            "n_measurements": len(measurements),
            "options": options,
            "parameters": {
                name: recorded_parameters(
                    make_strategy(name, base, seed=seed, **options.get(name, {}))
                )
                for name in names
            },
            "calibrated": list(nested_names),
            "baseline": BASELINE_STRATEGY if BASELINE_STRATEGY in names else None,
            "mape_floor_deg": floor,
            "failed": [
                {"strategy": task[3], "actuator_id": task[1], "error": _reason(error)}
                for task, error in failed
            ],
            "failed_other_fits": sum(
                "error" in out
                for task, out in zip(tasks, results, strict=True)
                if task[0] != "loco"
            ),
            "fits": len(tasks),
            "wall_time_s": time.perf_counter() - start,
        },
    )


def _check_two_actuators(ids: Sequence[str]) -> None:
    """Refuse measurements of fewer than 2 actuators (key ``measurements``)."""
    if len(ids) < 2:
        raise InputError(
            f"must cover at least 2 actuators; got {len(ids)} ({', '.join(ids)})",
            key="measurements",
        )


def check_calibration(actuators: Sequence[str], strategies: Sequence[str]) -> None:
    """Refuse a nested calibration that :func:`leave_one_configuration_out` cannot make.

    The calibrated interval of a held-out actuator comes from the leave-one-out
    errors of the other actuators, each predicted by a model fitted without it
    and without the held-out one: with two actuators that model would have no
    data at all, so the interval would be missing. The two slowest strategies
    (``experimental``, ``refined-ensemble``) are never calibrated.

    Parameters
    ----------
    actuators : sequence of str
        The measured actuators.
    strategies : sequence of str
        The strategies to score.

    Raises
    ------
    InputError
        Key ``calibrated`` (the parameter of :func:`leave_one_configuration_out`):
        fewer than :data:`MIN_CALIBRATION_ACTUATORS` actuators, or no strategy
        that is calibrated.
    """
    if len(actuators) < MIN_CALIBRATION_ACTUATORS:
        raise InputError(
            f"needs measurements of at least {MIN_CALIBRATION_ACTUATORS} actuators (the "
            "held-out one and two others, each predicted by a model fitted without it, to "
            f"calibrate its interval on); got {len(actuators)} ({'; '.join(actuators)})",
            key="calibrated",
        )
    if all(name in _SLOW for name in strategies):
        raise InputError(
            f"calibrates strategies other than {' and '.join(_SLOW)} (their training would "
            f"dominate the time); got only {', '.join(strategies)}",
            key="calibrated",
        )


def held_out_residuals(
    measurements: Measurements | ActuatorMeasurements,
    base: Surrogate | None,
    strategy: str,
    *,
    seed: int = 0,
    options: dict[str, Any] | None = None,
) -> dict[str, np.ndarray]:
    """Each actuator's absolute errors from ``strategy`` fitted on the other actuators.

    The leave-one-out errors that :func:`softbend.transfer.conformal.calibrate`
    turns into a calibrated interval (one fit per actuator, batched where the
    strategy can).

    Parameters
    ----------
    measurements : Measurements
        At least two actuators.
    base : estimator
        The simulation-trained surrogate the strategy starts from.
    strategy : str
        A registered strategy.
    seed : int, default 0
        Seed of the strategy.
    options : dict, optional
        Parameters of the strategy.

    Returns
    -------
    dict of str to ndarray
        Actuator id → ``|prediction − reading|`` on its readings, degrees.

    Raises
    ------
    InputError, ConvergenceError
        The first fit (without one actuator) that failed: the errors are those of every
        actuator or none.
    """
    with keyed("strategy"):
        cls = STRATEGIES.get(strategy)
    ids = measurements.actuator_ids
    _check_two_actuators(ids)
    with keyed("options"):
        values = check_parameters(cls, dict(options or {}))
    X, y, groups = measurements.features, measurements.angle_deg, measurements.groups
    tests = [np.flatnonzero(groups == a) for a in ids]
    trains = [np.flatnonzero(groups != a) for a in ids]
    actuator = getattr(measurements, "actuator", None)  # paper B's Measurements: None
    models, _ = _fit_all(strategy, base, values, seed, X, y, trains, actuator)
    for model in models:
        if isinstance(model, BaseException):  # no calibration without every actuator's errors
            raise model
    return {
        a: np.abs(np.asarray(m.predict(X[t]), dtype=np.float64) - y[t])
        for a, m, t in zip(ids, models, tests, strict=True)
    }


def _calibration(
    errors: dict[str, np.ndarray] | None, level: float, seen: np.ndarray, fallback: str
) -> Calibration | None:
    """The calibration from leave-one-out errors; None without any, or with an actuator
    whose errors are all non-finite."""
    if not errors or not all(np.isfinite(e).any() for e in errors.values()):
        return None
    return calibrate(errors, level, floor_deg=angle_floor(seen), fallback=fallback)


def _score_calibrated(cal: Calibration | None, y: np.ndarray, pred: np.ndarray) -> dict[str, Any]:
    if cal is None:
        return {
            "calibrated_coverage": np.nan,
            "calibrated_width_deg": np.nan,
            "calibration_half_width_deg": np.nan,
            "calibration_guaranteed": None,
        }
    lo, hi = cal.interval(pred)
    return {
        "calibrated_coverage": float(np.mean((y >= lo) & (y <= hi))),
        "calibrated_width_deg": float(np.mean(hi - lo)),
        "calibration_half_width_deg": cal.half_width_deg,
        "calibration_guaranteed": cal.guaranteed,
    }


def _weighted(part: pd.DataFrame, column: str) -> float:
    """The mean of ``column`` weighted by readings; NaN unless every actuator has one."""
    if part.empty or not part[column].notna().all():
        return np.nan
    return float((part[column] * part["n_points"]).sum() / part["n_points"].sum())


def _coverage_reason(name: str, calibrated: bool, coverage: float) -> str | None:
    """Why a strategy's summary has no calibrated coverage; None when it has one."""
    if coverage == coverage:
        return None
    if not calibrated:
        return "not calibrated: the calibration was not asked for (--calibrate; calibrated=True)"
    if name in _SLOW:
        return (
            f"not calibrated: {' and '.join(_SLOW)} never are (their training would "
            "dominate the time)"
        )
    return (
        "not calibrated on every held-out actuator: the leave-one-out errors of an "
        "actuator were not finite, or a fit without it failed"
    )


def _summarize(
    per_actuator: pd.DataFrame, names: Sequence[str], *, calibrated: bool = False
) -> pd.DataFrame:
    rows = []
    for name in names:
        mine = per_actuator[per_actuator["strategy"] == name]
        part = mine[mine["status"] == "ok"]  # a failed fit has no score to average
        worst = part.loc[part["rmse_deg"].idxmax()] if part["rmse_deg"].notna().any() else None
        mean_rmse = float(part["rmse_deg"].mean())
        calibrated_coverage = _weighted(part, "calibrated_coverage")
        rows.append(
            {
                "strategy": name,
                "rmse_deg": mean_rmse,
                "rmse_deg_mean": mean_rmse,
                "rmse_vs_baseline_pct": np.nan,
                "mape_pct": float(part["mape_pct"].mean()),
                "n_mape_used": int(part["n_mape_used"].sum()),
                "max_error_deg": float(part["max_error_deg"].max()),
                "coverage": _weighted(part, "coverage"),
                "calibrated_coverage": calibrated_coverage,
                "calibrated_coverage_reason": _coverage_reason(
                    name, calibrated, calibrated_coverage
                ),
                "calibrated_width_deg": _weighted(part, "calibrated_width_deg"),
                "worst_actuator": None if worst is None else worst["actuator_id"],
                "worst_rmse_deg": np.nan if worst is None else float(worst["rmse_deg"]),
                "worst_mape_pct": np.nan if worst is None else float(worst["mape_pct"]),
                "fit_s": float(mine["fit_s"].mean()),
                "n_failed": int(len(mine) - len(part)),
            }
        )
    summary = pd.DataFrame(rows)
    baseline = summary.loc[summary["strategy"] == BASELINE_STRATEGY, "rmse_deg_mean"]
    if len(baseline) and np.isfinite(baseline.iloc[0]) and baseline.iloc[0] > 0:
        summary["rmse_vs_baseline_pct"] = 100.0 * (
            summary["rmse_deg_mean"] / float(baseline.iloc[0]) - 1.0
        )
    return summary


def strategy_options(
    strategies: Sequence[str], settings: Mapping[str, str]
) -> dict[str, dict[str, Any]]:
    """Text settings of a run of several strategies as the ``options`` of the run.

    Parameters
    ----------
    strategies : sequence of str
        The strategies of the run.
    settings : mapping of str to str
        ``{"refined.epochs": "500"}`` sets a parameter of one strategy;
        ``{"epochs": "500"}`` sets it on every strategy of the run that takes it.

    Returns
    -------
    dict
        ``{strategy: {parameter: value}}``, typed by each parameter's default.

    Raises
    ------
    UnknownNameError
        A strategy that is not registered (key ``strategies``), or in
        ``settings`` (key ``settings``) a strategy that is not, a parameter it
        does not take, or a parameter no strategy of the run takes (the known
        ones listed).
    ValueError
        Key ``settings``: a value that is not of the parameter's kind or out of its range.
    """
    with keyed("strategies"):
        names = [STRATEGIES.check(name) for name in strategies]
    options: dict[str, dict[str, Any]] = {}
    with keyed("settings"):
        for key, text in settings.items():
            target, dot, parameter = key.rpartition(".")
            if dot:
                targets = [STRATEGIES.check(target)]
            else:
                targets = [n for n in names if parameter in strategy_parameters(n)]
                if not targets:
                    known = sorted({p for n in names for p in strategy_parameters(n)})
                    raise UnknownNameError(
                        f"is not a parameter of any strategy of the run ({', '.join(names)}); "
                        f"known: {', '.join(known) or 'none'}",
                        key=parameter,
                    )
            for name in targets:
                value = check_parameters(STRATEGIES.get(name), {parameter: text}, from_text=True)
                options.setdefault(name, {}).update(value)
    return options
