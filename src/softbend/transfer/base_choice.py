"""Choosing the base for transfer: every base × strategy scored by leaving one actuator out.

Grouped cross-validation across simulated designs says how a surrogate family
generalises to unseen designs; it does not say how well the family transfers to
measured actuators. :func:`score_bases` runs
:func:`~softbend.transfer.loco.leave_one_configuration_out` once per candidate
base on the same measurements and puts every (base, strategy) pair in one table
(:class:`BaseChoice`); :func:`best_pair` names the pair of the lowest mean
leave-one-actuator-out RMSE (degrees).

The rules of the choice, recorded with it:

- A pair is a candidate when its mean RMSE is finite and every held-out actuator
  could be fitted (``n_failed`` 0): a mean over fewer actuators is not comparable.
  When no pair qualifies, the pairs with some failed fits compete (said in
  ``best["note"]``).
- A base whose whole evaluation failed (every fit of every strategy) is a row of
  status ``failed`` with the reason; the others go on. Every base failing raises
  the first one's error.
- Pairs within :data:`TIE_DEG` of the lowest RMSE tie: the first in the order
  given (bases as listed, strategies in the table's order) is named, the others
  are listed in ``best["tied_with"]``.

``softbend transfer loco --base a.json,b.json`` and ``softbend train
--measurements`` (:func:`family_by_transfer`) both choose through here.
"""

from __future__ import annotations

import os
from collections.abc import Callable, Mapping, Sequence
from dataclasses import dataclass, field
from pathlib import Path
from typing import TYPE_CHECKING, Any

import numpy as np
import pandas as pd

from softbend.errors import InputError
from softbend.transfer.loco import LocoResult, leave_one_configuration_out
from softbend.transfer.strategies import FIT_ERRORS

if TYPE_CHECKING:
    from softbend.surrogates.protocol import Surrogate
    from softbend.transfer.measurements import ActuatorMeasurements, Measurements

__all__ = [
    "CHEAP_EXCLUDED",
    "TIE_DEG",
    "BaseChoice",
    "Candidate",
    "base_labels",
    "best_pair",
    "check_same_actuator",
    "family_by_transfer",
    "parse_bases",
    "score_bases",
]

#: Mean RMSEs (degrees) closer than this to the lowest tie with it.
TIE_DEG = 1e-9

#: Strategies a family's transfer score leaves out (``softbend train --measurements``):
#: ``experimental`` learns from the measurements alone (the same score for every base)
#: and ``refined-ensemble`` repeats ``refined`` several times over (the longest fit).
CHEAP_EXCLUDED: tuple[str, ...] = ("experimental", "refined-ensemble")

#: The columns of :attr:`BaseChoice.table`, in order.
TABLE_COLUMNS: tuple[str, ...] = (
    "base",
    "base_file",
    "strategy",
    "status",
    "rmse_deg",
    "rmse_vs_baseline_pct",
    "mape_pct",
    "max_error_deg",
    "coverage",
    "worst_actuator",
    "worst_rmse_deg",
    "n_failed",
    "rank",
    "best",
    "error",
)


@dataclass(frozen=True)
class Candidate:
    """One base of a choice: its label, file, model, and the run it gets.

    Attributes
    ----------
    label : str
        The base's name in the table and its results' folder (:func:`base_labels`).
    path : str
        The saved surrogate's file, as given.
    model : Surrogate
        The loaded surrogate.
    measurements : Measurements or ActuatorMeasurements
        The readings, as read for this base (:func:`~softbend.transfer.against_base.load_for_base`).
    strategies : sequence of str
        The strategies scored on this base (those that apply to it).
    options : dict
        Parameters per strategy (:func:`~softbend.transfer.loco.strategy_options`).
    """

    label: str
    path: str
    model: Surrogate
    measurements: Measurements | ActuatorMeasurements
    strategies: Sequence[str]
    options: dict[str, dict[str, Any]] = field(default_factory=dict)


@dataclass(frozen=True)
class BaseChoice:
    """Every base × strategy scored by leaving one actuator out, and the pair chosen.

    Attributes
    ----------
    results : dict of str to LocoResult
        Each base's own evaluation, by label (the bases whose evaluation failed absent).
    errors : dict of str to str
        Why a base's whole evaluation failed, by label.
    files : dict of str to str
        Each base's file, by label, in the order given.
    table : DataFrame
        One row per (base, strategy) (:data:`TABLE_COLUMNS`; a failed base one row, its
        strategy empty): the mean leave-one-actuator-out RMSE (degrees) and the other
        means of the base's summary, ``rank`` (1 the lowest RMSE among the candidates,
        NaN for a pair that is none) and ``best``.
    best : dict or None
        :func:`best_pair` of the table.
    """

    results: dict[str, LocoResult]
    errors: dict[str, str]
    files: dict[str, str]
    table: pd.DataFrame
    best: dict[str, Any] | None

    def to_dict(self) -> dict[str, Any]:
        """JSON-friendly: the table, the pair chosen, each base's file, error and result."""
        bases = {}
        for label, path in self.files.items():
            entry: dict[str, Any] = {"file": path, "status": "ok", "error": None}
            if label in self.errors:
                entry.update(status="failed", error=self.errors[label])
            else:
                entry["result"] = self.results[label].to_dict()
            bases[label] = entry
        return {
            "criterion": "lowest mean leave-one-actuator-out RMSE (degrees)",
            "tie_deg": TIE_DEG,
            "best": self.best,
            "table": self.table.to_dict(orient="records"),
            "bases": bases,
        }


def parse_bases(text: str | None) -> list[Path] | None:
    """The base files of a comma-separated ``--base`` text (None: the default base).

    Raises
    ------
    InputError
        Key ``base``: an empty name in the list, or a file named twice.
    """
    if text is None:
        return None
    names = [part.strip() for part in text.split(",")]
    if any(not name for name in names):
        raise InputError(
            f"must be one saved surrogate or several separated by commas (a.json,b.json); "
            f"got {text!r}, with an empty name",
            key="base",
        )
    seen: dict[str, str] = {}
    for name in names:
        real = os.path.realpath(name)
        if real in seen:
            raise InputError(
                f"names {name} twice (also as {seen[real]}); each base once", key="base"
            )
        seen[real] = name
    return [Path(name) for name in names]


def base_labels(paths: Sequence[str | os.PathLike[str]]) -> list[str]:
    """A short, unique label per base file: its stem (``models/xgb.json`` → ``xgb``), or,
    where stems repeat, the stem with its parent folder (``run1-xgb``), then a number."""
    stems = [Path(p).stem or "base" for p in paths]
    labels = []
    for path, stem in zip(paths, stems, strict=True):
        label = stem
        if stems.count(stem) > 1:
            parent = Path(path).resolve().parent
            above = parent.parent.name if parent.name == "models" else parent.name
            label = f"{above}-{stem}" if above else stem
        labels.append(label)
    unique: list[str] = []
    for label in labels:
        candidate, n = label, 2
        while candidate in unique:
            candidate, n = f"{label}-{n}", n + 1
        unique.append(candidate)
    return unique


def score_bases(
    candidates: Sequence[Candidate],
    *,
    level: float = 0.9,
    learning_curve: bool = True,
    calibrated: bool = False,
    seed: int = 0,
    progress: Callable[[str, int, int], None] | None = None,
) -> BaseChoice:
    """Leave one actuator out with every candidate base, and choose the best (base, strategy).

    Parameters
    ----------
    candidates : sequence of Candidate
        The bases, in the order ties are broken by; unique labels.
    level, learning_curve, calibrated, seed
        As :func:`~softbend.transfer.loco.leave_one_configuration_out`, the same for every base.
    progress : callable, optional
        ``progress(label, done, total)`` after each strategy's fits of base ``label``.

    Returns
    -------
    BaseChoice

    Raises
    ------
    InputError
        Key ``base``: no candidate, or a label twice.
    SoftbendError, ValueError, ArithmeticError
        Every base's evaluation failing: the first one's error.
    """
    if not candidates:
        raise InputError("must name at least one saved surrogate", key="base")
    labels = [c.label for c in candidates]
    if len(set(labels)) != len(labels):
        raise InputError(f"labels must be unique; got {', '.join(labels)}", key="base")
    results: dict[str, LocoResult] = {}
    errors: dict[str, str] = {}
    first: BaseException | None = None
    for candidate in candidates:

        def told(done: int, total: int, _name: str, label: str = candidate.label) -> None:
            if progress is not None:
                progress(label, done, total)

        try:
            results[candidate.label] = leave_one_configuration_out(
                candidate.measurements,
                candidate.model,
                list(candidate.strategies),
                level=level,
                learning_curve=learning_curve,
                calibrated=calibrated,
                seed=seed,
                options=dict(candidate.options),
                progress=told,
            )
        except FIT_ERRORS as error:  # every fit of this base failed: the others go on
            if isinstance(error, InputError) and error.key != "base":
                raise  # bad input is not a base's failure
            errors[candidate.label] = " ".join(str(error).split())
            first = first or error
    if not results:
        assert first is not None
        raise first
    files = {c.label: c.path for c in candidates}
    table = _table(results, errors, files)
    best = best_pair(table)
    if best is not None:
        table["best"] = (table["base"] == best["base"]) & (table["strategy"] == best["strategy"])
    return BaseChoice(results, errors, files, table, best)


def _table(
    results: Mapping[str, LocoResult], errors: Mapping[str, str], files: Mapping[str, str]
) -> pd.DataFrame:
    """One row per (base, strategy) in the order given; a failed base one row."""
    rows: list[dict[str, Any]] = []
    for label, path in files.items():
        if label in errors:
            rows.append(
                {
                    "base": label,
                    "base_file": path,
                    "strategy": None,
                    "status": "failed",
                    "error": errors[label],
                }
            )
            continue
        for _, r in results[label].summary.iterrows():
            n_failed = int(r.get("n_failed", 0))
            rows.append(
                {
                    "base": label,
                    "base_file": path,
                    "strategy": str(r["strategy"]),
                    "status": "ok" if n_failed == 0 else "some fits failed",
                    "rmse_deg": float(r["rmse_deg"]),
                    "rmse_vs_baseline_pct": float(r.get("rmse_vs_baseline_pct", np.nan)),
                    "mape_pct": float(r["mape_pct"]),
                    "max_error_deg": float(r["max_error_deg"]),
                    "coverage": float(r["coverage"]),
                    "worst_actuator": r["worst_actuator"],
                    "worst_rmse_deg": float(r["worst_rmse_deg"]),
                    "n_failed": n_failed,
                    "error": None,
                }
            )
    table = pd.DataFrame(rows).reindex(columns=list(TABLE_COLUMNS))
    table["best"] = False
    return _ranked(table)


def _eligible(table: pd.DataFrame) -> tuple[pd.Series, str | None]:
    """The rows that compete for best, and a note when the failed-fit rule was relaxed."""
    finite = table["rmse_deg"].apply(lambda v: v is not None and bool(np.isfinite(v)))
    complete = finite & (table["n_failed"].fillna(0) == 0)
    if complete.any():
        return complete, None
    if finite.any():
        return finite, (
            "every pair had some held-out actuators it could not be fitted without; "
            "its mean is over the others"
        )
    return finite, None


def _ranked(table: pd.DataFrame) -> pd.DataFrame:
    """``rank``: 1 for the lowest RMSE among the candidates, ties broken by order."""
    eligible, _ = _eligible(table)
    table["rank"] = np.nan
    order = table.loc[eligible, "rmse_deg"].astype(float).sort_values(kind="stable").index
    table.loc[order, "rank"] = np.arange(1, len(order) + 1, dtype=float)
    return table


def best_pair(table: pd.DataFrame) -> dict[str, Any] | None:
    """The (base, strategy) of the lowest mean leave-one-actuator-out RMSE in ``table``.

    Parameters
    ----------
    table : DataFrame
        Rows of ``base``, ``strategy``, ``rmse_deg`` (degrees) and ``n_failed``, in the
        order ties are broken by.

    Returns
    -------
    dict or None
        ``base``, ``base_file``, ``strategy``, ``rmse_deg``, ``tied_with`` (the other
        pairs within :data:`TIE_DEG`, as ``base/strategy``) and ``note`` (None, or why a
        pair with failed fits was allowed); None when no pair has a finite RMSE.
    """
    eligible, note = _eligible(table)
    if not eligible.any():
        return None
    rmses = table.loc[eligible, "rmse_deg"].astype(float)
    low = float(rmses.min())
    tied = rmses[rmses <= low + TIE_DEG].index  # in the order given
    chosen = table.loc[tied[0]]
    return {
        "base": str(chosen["base"]),
        "base_file": str(chosen["base_file"]),
        "strategy": str(chosen["strategy"]),
        "rmse_deg": float(chosen["rmse_deg"]),
        "tied_with": [f"{table.loc[i, 'base']}/{table.loc[i, 'strategy']}" for i in tied[1:]],
        "note": note,
    }


def family_by_transfer(choice: BaseChoice) -> dict[str, dict[str, Any]]:
    """Each base's best strategy and its mean leave-one-actuator-out RMSE (degrees).

    Returns
    -------
    dict
        ``{label: {"transfer_rmse_deg", "transfer_strategy", "transfer_error"}}``: NaN,
        None and the reason for a base whose evaluation failed or had no candidate pair.
    """
    out: dict[str, dict[str, Any]] = {}
    for label in choice.files:
        mine = choice.table[(choice.table["base"] == label) & choice.table["rank"].notna()]
        if len(mine):
            top = mine.sort_values("rank").iloc[0]
            out[label] = {
                "transfer_rmse_deg": float(top["rmse_deg"]),
                "transfer_strategy": str(top["strategy"]),
                "transfer_error": None,
            }
        else:
            reason = choice.errors.get(label, "no strategy was fitted on every actuator")
            out[label] = {
                "transfer_rmse_deg": float("nan"),
                "transfer_strategy": None,
                "transfer_error": reason,
            }
    return out


def check_same_actuator(candidates: Sequence[tuple[str, Any]]) -> None:
    """Refuse bases of different actuators: one measurement file fits one actuator.

    Parameters
    ----------
    candidates : sequence of (path, Actuator)
        Each base's file and the actuator it models.

    Raises
    ------
    InputError
        Key ``base``, naming each file's actuator.
    """
    names = {(a.name, tuple(a.names), a.pressure_column) for _, a in candidates}
    if len(names) > 1:
        said = "; ".join(f"{path} models {a.name}" for path, a in candidates)
        raise InputError(f"every base must model the measurements' actuator; {said}", key="base")


def transfer_strategies(saved: Any) -> tuple[list[str], dict[str, str]]:
    """The strategies a family's transfer score is the best of: transfer loco's defaults that
    apply to the family's saved model, but :data:`CHEAP_EXCLUDED`; and the others, with why."""
    from softbend.transfer.loco import DEFAULT_STRATEGIES
    from softbend.transfer.strategies import applicable_strategies

    names = [n for n in DEFAULT_STRATEGIES if n not in CHEAP_EXCLUDED]
    kept, left_out = applicable_strategies(names, saved.model, saved.actuator)
    left_out.update({n: "left out of the family's transfer score" for n in CHEAP_EXCLUDED})
    return kept, left_out


def choose_family(
    summary: dict[str, Any],
    models: Mapping[str, str | os.PathLike[str]],
    measurements: Sequence[str | os.PathLike[str]],
    *,
    seed: int = 0,
    progress: Callable[[str, int, int], None] | None = None,
) -> BaseChoice:
    """Select the family of a training by leave-one-actuator-out transfer error.

    Each family's refit model is the base of :func:`score_bases` on ``measurements``
    (:func:`transfer_strategies`: transfer loco's default strategies but the two of
    :data:`CHEAP_EXCLUDED`; no learning curve, no calibration); a family's transfer
    RMSE is the mean leave-one-actuator-out RMSE (degrees) of its best strategy.

    Parameters
    ----------
    summary : dict
        The summary of :func:`softbend.surrogates.workflow.train_surrogates`, updated in
        place: each family's entry gains ``transfer_rmse_deg``, ``transfer_strategy`` and
        ``transfer_error``; ``best_by_cv`` is the family grouped cross-validation named,
        ``best`` the family of the lowest transfer RMSE and ``selected_by``
        ``"transfer"`` (unchanged when no family has a transfer score); ``selection``
        records the criterion, both choices, the figures per family and the strategies.
    models : mapping of str to path
        Each family's saved model (a family without one gets no transfer score).
    measurements : sequence of path
        The measurement CSV files, joined, in the format of the family's actuator.
    seed : int, default 0
        Seed of the strategies.
    progress : callable, optional
        As :func:`score_bases`.

    Returns
    -------
    BaseChoice
        Every family × strategy.

    Raises
    ------
    DatasetError, InputError
        Key ``measurements``: files that cannot be read for the models' actuator, or
        readings past a model's range (:func:`~softbend.transfer.against_base.load_for_base`).
    """
    from softbend.errors import keyed
    from softbend.surrogates.persistence import load_surrogate
    from softbend.transfer.against_base import load_for_base
    from softbend.transfer.measurements import files_record

    candidates, left_out, files = [], {}, []
    for name, path in models.items():
        saved = load_surrogate(path)
        with keyed("measurements"):
            data, _ = load_for_base(list(measurements), saved)
        names, left_out[name] = transfer_strategies(saved)
        candidates.append(Candidate(name, str(path), saved.model, data, names))
        files = files_record(list(measurements), data)  # type: ignore[arg-type]
    choice = score_bases(candidates, learning_curve=False, seed=seed, progress=progress)
    scores = family_by_transfer(choice)
    by_cv = summary.get("best")
    by_transfer = None if choice.best is None else choice.best["base"]
    families = {}
    for name, entry in summary["models"].items():
        score = scores.get(name) or {
            "transfer_rmse_deg": float("nan"),
            "transfer_strategy": None,
            "transfer_error": "no saved model to transfer from",
        }
        entry.update(score)
        families[name] = {"cv_rmse_deg": float(entry["rmse_deg"]), **score}
    summary["best_by_cv"] = by_cv
    summary["selection"] = {
        "criterion": "transfer" if by_transfer is not None else summary.get("selected_by"),
        "by_transfer": by_transfer,
        "by_cv": by_cv,
        "cv_metric": summary.get("selected_by"),
        "transfer_metric": "mean leave-one-actuator-out RMSE (degrees) of the family's best "
        "strategy",
        "families": families,
        "best_pair": choice.best,
        "strategies_left_out": left_out,
        "measurement_files": files,
    }
    if by_transfer is not None:
        summary["best"], summary["selected_by"] = by_transfer, "transfer"
    return choice
