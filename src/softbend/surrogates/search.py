"""Grid search with design-grouped K-fold cross-validation (paper B §4.1).

Every configuration of every model family (a :class:`~softbend.surrogates.families.Family`
of :data:`~softbend.surrogates.families.FAMILIES`, by name) is fitted on K−1 folds and scored
on the held-out fold, where the folds are groups of whole designs: a pressure
sweep is never split between training and validation, so the score is that of
an unseen actuator, not of an unseen pressure of a seen one. The best
configuration of each family (lowest mean validation RMSE) is refitted on all
the data. The MLP configurations are trained together in one batched tensor
program (:func:`softbend.surrogates.batched.train_mlp_grid`).

Grids (``grid="paper"`` is paper B's; each family holds its own; ``small`` is a
family's own small-data grid where it has one, the MLP's :data:`SMALL_DATA_MLP_GRID`
and the polynomial's degrees 1 to 4 each with ridge strengths 1e-8 to 1
(:data:`~softbend.surrogates.families.PLR_SMALL_ALPHAS`), else its ``quick`` one;
the table base, :mod:`softbend.surrogates.table`, has one configuration):

========  ==================================  ====================================
family    ``quick``                           ``paper``
========  ==================================  ====================================
``plr``   degree 2, 4, 6                      degree 2 … 10
``xgb``   max depth 6, 9 x learning rate      max depth 1 … 20 x learning rate
          0.2, 0.4                            0.1, 0.2 … 1.0
``mlp``   hidden (63, 65), paper B's pick     hidden 55 … 65 x 55 … 65
========  ==================================  ====================================

The ``small`` grid is for tables of fewer than :data:`SMALL_DATA_DESIGNS` designs
(``softbend train`` picks it for them unless ``--grid`` is given). Paper B's
(63, 65) network has about 4 700 weights, tuned on 972 designs; a table of 30
designs holds about 300 rows, and with mini-batches of 1024 rows an epoch is one
Adam step, so the quick grid's 200 epochs at paper B's step size (6e-4) leave it
far from trained. The small grid trains two smaller networks, (16, 16) and
(32, 32), for 1000 epochs with Adam's step at 3e-3, and keeps the one of lower
held-out RMSE. On the first 30 designs of ``examples/pneunet/simulations.csv``
(grouped 5-fold CV, seed 0) the quick grid's (63, 65) scored R² 0.9215, RMSE
15.75°; the small grid's (32, 32) R² 0.9952, RMSE 3.91° and (16, 16) R² 0.9946,
RMSE 4.13°, for about three times the quick grid's CPU time (11.8 s against
3.7 s, one torch thread). The trainer has no weight decay: the small networks
and the design-grouped choice between them are what keep the fit from
following noise.

The quick grid is what ``softbend reproduce`` trains within its time budget.
Its MLP is paper B's configuration alone: a second size, (55, 55), was padded
to (63, 65) in the batched training, cost as much to train and never won; the
largest configuration of a batched training is not padded and keeps its own
random streams, so (63, 65) scores bitwise the same alone as beside (55, 55)
(``tests/surrogates/test_batched.py``). The ``paper`` grid searches the
sizes; with successive halving (``halving=3`` and five rungs) the whole paper
MLP grid on the FEM data took 34 min on 2 cores (docs/results.md has the command).

XGBoost uses 300 trees (paper B does not give the number), histogram tree
method. The MLP trains with batch 1024 and Adam lr 6e-4 (paper B) for 1000
epochs in the ``paper`` grid (paper B) and 200 in the ``quick`` grid (about a
tenth of the time on a laptop CPU, at some cost in accuracy), unless ``epochs``
is given.

Resume: given a :class:`~softbend.surrogates.checkpoint.SearchCheckpoint`, the
search appends every finished (family, configuration, fold) to it durably and,
run again with the same data and settings, loads the folds it holds instead of
refitting them, so a killed search resumes where it stopped and ends with the
same results. The MLP configurations train together, so their folds are saved
together when a training (a rung of successive halving) ends.
"""

from __future__ import annotations

import hashlib
import logging
import math
import time
from collections.abc import Callable, Iterator, Sequence
from contextlib import AbstractContextManager, contextmanager, nullcontext
from dataclasses import dataclass, field
from typing import TYPE_CHECKING, Any

import numpy as np
import pandas as pd

from softbend._validation import check_choice, check_int, check_range, must_be
from softbend.errors import InputError, keyed
from softbend.references import SURROGATE_TRAINING
from softbend.surrogates.families import (
    FAMILIES,
    GRID_NAMES,
    MODEL_NAMES,
    MODEL_TITLES,
    OPTIONAL_GRIDS,
    SMALL_DATA_MLP_GRID,
    XGB_TREES,
    FitSettings,
    family_names,
)
from softbend.surrogates.features import TrainingData
from softbend.surrogates.metrics import (
    MAPE_THRESHOLD_DEG,
    accuracy,
    inference_time,
    mape_floor_deg,
)

if TYPE_CHECKING:
    from softbend.surrogates.checkpoint import SearchCheckpoint

logger = logging.getLogger(__name__)

__all__ = [
    "CV_PROTOCOLS",
    "GRID_NAMES",
    "MLP_EPOCHS",
    "MODEL_NAMES",
    "MODEL_TITLES",
    "SEARCH_GRIDS",
    "SMALL_DATA_DESIGNS",
    "SMALL_DATA_MLP_GRID",
    "SMALL_DATA_MODELS",
    "XGB_TREES",
    "FamilyResult",
    "Progress",
    "SearchResult",
    "describe",
    "grid",
    "grouped_splits",
    "halving_rungs",
    "random_splits",
    "search",
    "search_fingerprint",
]

#: MLP epochs per grid (paper B: 1000).
MLP_EPOCHS: dict[str, int] = {
    "quick": 200,
    "paper": int(SURROGATE_TRAINING["mlp_epochs"].value),
    "small": 1000,
}

#: Adam step size of the MLP unless a configuration names its own (paper B: 6e-4).
MLP_LEARNING_RATE = 6e-4

#: Below this many designs, ``softbend train`` searches the ``small`` grid unless told a grid,
#: and the table base among its default families (:data:`SMALL_DATA_MODELS`).
SMALL_DATA_DESIGNS = 100

#: The default families below :data:`SMALL_DATA_DESIGNS` designs: paper B's three and the
#: table base (:mod:`softbend.surrogates.table`).
SMALL_DATA_MODELS: tuple[str, ...] = (*MODEL_NAMES, "table")


#: Every grid name: the families' own (:data:`GRID_NAMES`) and ``small`` (:data:`OPTIONAL_GRIDS`).
SEARCH_GRIDS: tuple[str, ...] = (*GRID_NAMES, *OPTIONAL_GRIDS)


def grid(name: str, model: str) -> list[dict[str, Any]]:
    """The configurations of the family ``model`` in the grid ``name`` (module docstring).

    ``small`` is a family's own small-data grid where it gives one (the MLP's
    :data:`SMALL_DATA_MLP_GRID`, the polynomial's degrees × ridge strengths), else
    its ``quick`` grid.

    Raises
    ------
    ValueError
        An unknown grid; :class:`~softbend.registry.UnknownNameError` an unknown family.
    """
    check_choice(name, "grid", SEARCH_GRIDS)
    with keyed("model"):
        family = FAMILIES.get(model)
    return family.configs(name)


def describe(params: dict[str, Any]) -> str:
    """Short text of a configuration, e.g. ``"max_depth=9, learning_rate=0.2"``."""
    return ", ".join(f"{k}={v}" for k, v in params.items())


def grouped_splits(
    groups: np.ndarray, n_splits: int = 5, seed: int = 0
) -> list[tuple[np.ndarray, np.ndarray]]:
    """K folds of whole groups (designs), shuffled with ``seed``.

    Returns
    -------
    list of (train_idx, val_idx)
        Row indices; every group's rows are in exactly one ``val_idx``.
    """
    # each group as the rank of its name: the same folds as the names give, found by integer
    # comparisons (names as text cost minutes on a table of a million rows); the rows hashed
    # to their distinct names first, so that only those are sorted (np.unique's ranks)
    import pandas as pd
    from sklearn.model_selection import GroupKFold

    codes, names = pd.factorize(np.asarray(groups).ravel(), sort=True, use_na_sentinel=False)
    ranks = codes
    n_groups = len(names)
    n_splits = int(
        check_range(
            n_splits,
            "folds",
            low=2,
            low_inclusive=True,
            high=max(2, n_groups),
            high_inclusive=True,
        )
    )
    if n_groups < n_splits:
        raise ValueError(
            f"Grouped {n_splits}-fold cross-validation needs at least {n_splits} designs. "
            f"Got {n_groups}."
        )
    splitter = GroupKFold(n_splits=n_splits, shuffle=True, random_state=seed)
    dummy = np.zeros((groups.size, 1))
    return [(train, val) for train, val in splitter.split(dummy, groups=ranks.ravel())]


#: Cross-validation protocols: folds of whole designs (the honest one), or of
#: samples shuffled across designs (paper B's, for comparison).
CV_PROTOCOLS: tuple[str, ...] = ("grouped", "random")


def random_splits(
    n_samples: int, n_splits: int = 5, seed: int = 0
) -> list[tuple[np.ndarray, np.ndarray]]:
    """K folds of samples shuffled with ``seed``, ignoring designs (paper B's protocol).

    A design's pressures then fall into several folds, so a model is scored on
    pressures between ones it was trained on: an interpolation score, optimistic
    for a new actuator. Offered to compare with paper B, not to choose models.
    """
    from sklearn.model_selection import KFold

    n_splits = int(
        check_range(
            n_splits,
            "folds",
            low=2,
            low_inclusive=True,
            high=max(2, n_samples),
            high_inclusive=True,
        )
    )
    splitter = KFold(n_splits=n_splits, shuffle=True, random_state=seed)
    return list(splitter.split(np.zeros((n_samples, 1))))


@dataclass
class FamilyResult:
    """The search over one model family.

    Attributes
    ----------
    name : str
        The family's name (``"plr"``, ``"xgb"``, ``"mlp"``, ...).
    params : dict
        Best configuration.
    cv : dict
        Accuracy of the best configuration on the pooled out-of-fold
        predictions (:func:`softbend.surrogates.metrics.accuracy`), plus
        ``r2_fold_mean``, ``r2_fold_std``, ``rmse_fold_mean``, ``rmse_fold_std``.
    oof_pred : ndarray
        Out-of-fold predictions of the best configuration, degrees (each row
        predicted by the model that did not see its design).
    model : estimator or None
        The best configuration refitted on all rows (None with ``refit=False``).
    timing : dict
        :func:`softbend.surrogates.metrics.inference_time` of ``model``.
    fit_s : float
        Wall time of the refit, s.
    search_s : float
        Wall time of the cross-validated search of this family, s.
    """

    name: str
    params: dict[str, Any]
    cv: dict[str, float]
    oof_pred: np.ndarray
    model: Any
    timing: dict[str, float]
    fit_s: float
    search_s: float


@dataclass
class SearchResult:
    """Outcome of :func:`search`.

    Attributes
    ----------
    cv_results : pandas.DataFrame
        One row per (family, configuration): mean and std over folds of R²,
        RMSE, MAPE, the pooled figures, fit seconds, and a ``status`` (``ok``
        or why it was skipped).
    families : dict
        ``{name: FamilyResult}`` for each family searched.
    data : TrainingData
        The data used.
    settings : dict
        Grid, folds, seed, device, epochs.
    resumed : int
        Configuration-folds loaded from a checkpoint instead of fitted (0 for a
        search that started afresh).
    """

    cv_results: pd.DataFrame
    families: dict[str, FamilyResult]
    data: TrainingData
    settings: dict[str, Any] = field(default_factory=dict)
    resumed: int = 0

    def summary(self) -> pd.DataFrame:
        """One row per family: best configuration, CV accuracy (the MAPE with its floor and
        the readings it used), inference time."""
        rows = []
        for name, fam in self.families.items():
            rows.append(
                {
                    "model": name,
                    "params": describe(fam.params),
                    "r2": fam.cv["r2"],
                    "rmse_deg": fam.cv["rmse_deg"],
                    "mape_pct": fam.cv["mape_pct"],
                    "mape_floor_deg": fam.cv["mape_floor_deg"],
                    "n_mape_used": fam.cv["n_mape_used"],
                    "max_abs_error_deg": fam.cv["max_abs_error_deg"],
                    "single_us": fam.timing["single_us"],
                    "batch_10k_ms": fam.timing["batch_ms"],
                    "fit_s": fam.fit_s,
                    "search_s": fam.search_s,
                }
            )
        return pd.DataFrame(rows)


Progress = Callable[[str, int, int], None]


def _mlp_precision(model: str, device: str, tf32: bool) -> AbstractContextManager[None]:
    """TF32 products while the MLP family trains on CUDA, if asked; else nothing."""
    if model != "mlp" or not tf32:
        return nullcontext()
    from softbend.surrogates.batched import tf32_matmul
    from softbend.surrogates.mlp_core import resolve_device

    return tf32_matmul(resolve_device(device), True)


#: Up to this many rows, the MLP trains on one CPU thread (:func:`_mlp_threads`).
ONE_THREAD_ROWS = 10_000


@contextmanager
def _mlp_threads(model: str, device: str, n_rows: int) -> Iterator[None]:
    """One torch thread while the MLP family of a small table trains on the CPU.

    The networks of a table of a few thousand rows are too small for OpenMP's
    threads to share their work, and on a busy machine their spinning costs
    more than the training: ``softbend train`` of the first 30 designs of
    ``examples/pneunet/simulations.csv`` (small grid) took 3 min 46 s of CPU
    time with torch's default threads and 45 s with one, with the same scores
    (2 cores under load).
    """
    if model != "mlp" or n_rows > ONE_THREAD_ROWS:
        yield
        return
    from softbend.surrogates.mlp_core import resolve_device

    if resolve_device(device) != "cpu":
        yield
        return
    import torch

    before = torch.get_num_threads()
    torch.set_num_threads(1)
    try:
        yield
    finally:
        torch.set_num_threads(before)


def _make(
    model: str, params: dict[str, Any], *, seed: int, n_jobs: int | None, device: str, epochs: int
) -> Any:
    """A new, unfitted estimator of the family ``model`` in the configuration ``params``."""
    settings = FitSettings(seed=seed, n_jobs=n_jobs, device=device, epochs=epochs)
    with keyed("models"):
        family = FAMILIES.get(model)
    return family.make(dict(params), settings)


def _fold_scores(
    y: np.ndarray, pred: np.ndarray, splits: list[tuple[np.ndarray, np.ndarray]], threshold: float
) -> dict[str, float]:
    per_fold = [accuracy(y[val], pred[val], mape_threshold_deg=threshold) for _, val in splits]
    pooled = accuracy(y, pred, mape_threshold_deg=threshold)
    r2s = np.array([f["r2"] for f in per_fold])
    rmses = np.array([f["rmse_deg"] for f in per_fold])
    mapes = np.array([f["mape_pct"] for f in per_fold])
    mapes = mapes[np.isfinite(mapes)]  # a fold with no reading above the floor has none
    return {
        **pooled,
        "r2_fold_mean": float(r2s.mean()),
        "r2_fold_std": float(r2s.std(ddof=1)),
        "rmse_fold_mean": float(rmses.mean()),
        "rmse_fold_std": float(rmses.std(ddof=1)),
        "mape_fold_mean": float(mapes.mean()) if mapes.size else math.nan,
    }


def _cv_sequential(
    model: str,
    configs: list[dict[str, Any]],
    data: TrainingData,
    splits: list[tuple[np.ndarray, np.ndarray]],
    make: Callable[[dict[str, Any]], Any],
    tick: Callable[[], None],
    checkpoint: SearchCheckpoint | None = None,
    stop: Callable[
        [list[tuple[dict[str, Any], np.ndarray | None, float, str]], dict[str, Any]], str | None
    ]
    | None = None,
) -> tuple[list[tuple[dict[str, Any], np.ndarray | None, float, str]], int]:
    """(params, oof predictions or None, fit seconds, status) per configuration.

    Also returns the number of folds loaded from ``checkpoint``; every fold
    fitted is added to it before ``tick`` reports it. ``stop(outcomes, params)``,
    asked before each configuration after the first (``params``: the next one),
    returns why the remaining ones are not fitted (they are listed as skipped for
    that reason), or None to go on.
    """
    out: list[tuple[dict[str, Any], np.ndarray | None, float, str]] = []
    resumed = 0
    for index, params in enumerate(configs):
        reason = stop(out, params) if stop is not None and out else None
        if reason is not None:
            logger.info("%s: %s", model, reason)
            for rest in configs[index:]:
                out.append((rest, None, 0.0, f"skipped: {reason}"))
                for _ in splits:
                    tick()
            break
        pred = np.empty_like(data.y)
        seconds = 0.0
        fitted = 0
        try:
            for fold, (train, val) in enumerate(splits):
                start = time.perf_counter()
                saved = (
                    checkpoint.get(model, params, fold, size=val.size)
                    if checkpoint is not None
                    else None
                )
                if saved is not None:
                    pred[val], spent = saved
                    resumed += 1
                else:
                    estimator = make(params).fit(data.X[train], data.y[train])
                    pred[val] = estimator.predict(data.X[val])
                    spent = time.perf_counter() - start
                    if checkpoint is not None:
                        checkpoint.add(model, params, fold, pred[val], spent)
                seconds += spent
                fitted += 1
                tick()
        except ValueError as exc:
            # Only the polynomial's memory guard is a reason to skip a configuration.
            if model != "plr" or "max_memory_mb" not in str(exc):
                raise
            logger.warning("%s %s skipped: %s", model, describe(params), exc)
            for _ in range(len(splits) - fitted):
                tick()
            seconds += time.perf_counter() - start
            out.append((params, None, seconds, f"skipped: {exc}"))
            continue
        out.append((params, pred, seconds, "ok"))
    return out, resumed


def _patience_stop(
    splits: list[tuple[np.ndarray, np.ndarray]], y: np.ndarray, patience: int
) -> Callable[
    [list[tuple[dict[str, Any], np.ndarray | None, float, str]], dict[str, Any]], str | None
]:
    """A ``stop`` for :func:`_cv_sequential`: the last ``patience`` degrees did not improve.

    Improvement is the mean held-out RMSE over the folds (``rmse_fold_mean`` of
    :func:`_fold_scores`), by which the search ranks; a degree's score is the best
    of its configurations (one per degree in the ``quick`` and ``paper`` grids,
    one per ridge strength in the ``small`` grid), and a degree is judged once all
    its configurations are fitted (consecutive in the grid).
    """

    def stop(
        outcomes: list[tuple[dict[str, Any], np.ndarray | None, float, str]],
        upcoming: dict[str, Any],
    ) -> str | None:
        if outcomes and outcomes[-1][0].get("degree") == upcoming.get("degree"):
            return None  # the degree's other configurations first
        best: dict[Any, float] = {}
        for params, pred, _, status in outcomes:
            if pred is None or status != "ok":
                continue
            score = _fold_scores(y, pred, splits, MAPE_THRESHOLD_DEG)["rmse_fold_mean"]
            degree = params.get("degree")
            best[degree] = min(score, best.get(degree, math.inf))
        scores = list(best.values())
        if len(scores) <= patience:
            return None
        best_before = min(scores[:-patience])
        if min(scores[-patience:]) < best_before:
            return None
        return (
            f"the last {patience} degree(s) did not improve on the best cross-validated "
            f"RMSE {best_before:.4g} deg (patience {patience})"
        )

    return stop


def halving_rungs(
    n_configs: int, epochs: int, eta: int, rungs: int | None = None
) -> list[tuple[int, int]]:
    """(configurations kept, epochs) of each rung of successive halving.

    Every configuration trains ``epochs / eta^k`` epochs first; after each rung
    the best ``1/eta`` (rounded up) go on to ``eta`` times as many epochs, until
    the survivors train the full ``epochs``. By default the number of rungs is
    chosen so that the last rung keeps at least ``eta`` configurations and the
    first rung trains at least 1/27 of the epochs (at most four rungs): a short
    first rung ranks configurations by their early loss, which only loosely
    predicts the final one. ``rungs`` sets the number instead (>= 1; one more
    rung than the default about halves the configuration-epochs of paper B's
    grid, with a first rung of 1/81 of the epochs and two configurations in the
    last).
    """
    if rungs is None:
        rungs = 1
        while rungs < 4 and math.ceil(n_configs / eta**rungs) >= eta:
            rungs += 1
    else:
        rungs = check_int(rungs, "rungs", low=1)
        most = _most_rungs(n_configs, epochs, eta)
        if rungs > most:
            raise InputError(
                f"must be at most {most} for {n_configs} configurations, {epochs} epochs and "
                f"factor {eta} (the first rung trains at least one epoch, the one before the "
                f"last races at least two configurations); got {rungs}",
                key="rungs",
            )
    out = []
    kept = n_configs
    for k in range(rungs):
        out.append((kept, max(1, round(epochs / eta ** (rungs - 1 - k)))))
        kept = max(1, math.ceil(kept / eta))
    return out


_halving_rungs = halving_rungs  # (search's argument of the same name hides the function)


def _most_rungs(n_configs: int, epochs: int, eta: int) -> int:
    """Rungs that still make sense: >= 1 epoch first, >= 2 configurations before the last."""
    rungs, kept = 1, n_configs
    while kept >= 2 and epochs / eta**rungs >= 1:
        rungs += 1
        kept = math.ceil(kept / eta)
    return rungs


def _load_training(
    checkpoint: SearchCheckpoint | None,
    configs: list[dict[str, Any]],
    splits: list[tuple[np.ndarray, np.ndarray]],
    y: np.ndarray,
    epochs: int,
    group: str,
) -> list[tuple[np.ndarray, float]] | None:
    """Each configuration's (out-of-fold predictions, seconds) of a saved MLP training.

    None unless ``checkpoint`` holds every fold of every configuration trained
    together for ``epochs`` in the batch ``group``.
    """
    if checkpoint is None:
        return None
    out = []
    for params in configs:
        pred = np.empty_like(y)
        seconds = 0.0
        for fold, (_, val) in enumerate(splits):
            saved = checkpoint.get("mlp", params, fold, size=val.size, epochs=epochs, group=group)
            if saved is None:
                return None
            pred[val] = saved[0]
            seconds += saved[1]
        out.append((pred, seconds))
    return out


def _cv_mlp_batched(
    configs: list[dict[str, Any]],
    data: TrainingData,
    splits: list[tuple[np.ndarray, np.ndarray]],
    *,
    epochs: int,
    seed: int,
    device: str,
    progress: Callable[[int, int], None] | None,
    halving: int | None = None,
    n_rungs: int | None = None,
    checkpoint: SearchCheckpoint | None = None,
) -> tuple[list[tuple[dict[str, Any], np.ndarray | None, float, str]], int]:
    """Cross-validated predictions of every MLP configuration, all trained at once.

    With ``halving=eta`` the configurations race by successive halving
    (:func:`halving_rungs`): every rung retrains its survivors from their
    initial weights for the rung's epochs, which gives exactly the first epochs
    of the full training (each model has its own random stream), so a
    configuration that reaches the last rung is the model the exhaustive search
    would have trained. A configuration that stops earlier keeps the scores of
    its last rung and says so in its status.

    With a ``checkpoint``, the folds of each training (each rung) are saved
    when it ends, and a training whose every fold the checkpoint holds (same
    configurations trained together, same epochs) is loaded, not repeated. Also
    returns the number of folds loaded.
    """
    from softbend.surrogates.batched import train_mlp_grid
    from softbend.surrogates.checkpoint import group_id

    rates = {float(c.get("learning_rate", MLP_LEARNING_RATE)) for c in configs}
    if len(rates) > 1:
        raise InputError(
            must_be("one learning_rate for every MLP configuration (they train together)", rates),
            key="param_grid",
        )
    learning_rate = rates.pop()
    rungs = (
        [(len(configs), epochs)]
        if not halving
        else halving_rungs(len(configs), epochs, halving, n_rungs)
    )
    total = sum(epochs_k for _, epochs_k in rungs)
    done_before = 0
    alive = list(range(len(configs)))
    out: dict[int, tuple[dict[str, Any], np.ndarray, float, str]] = {}
    resumed = 0
    for rung, (_, rung_epochs) in enumerate(rungs):
        sizes = [tuple(configs[i]["hidden_sizes"]) for i in alive]

        def forward(done: int, _total: int, offset: int = done_before) -> None:
            if progress is not None:
                progress(offset + done, total)

        # The configurations trained together share padded tensors: a fold is only
        # reused from a training of the same configurations (its group) and epochs.
        group = group_id(sizes)
        loaded = _load_training(
            checkpoint, [configs[i] for i in alive], splits, data.y, rung_epochs, group
        )
        if loaded is not None:
            preds = [pred for pred, _ in loaded]
            seconds_each = [spent for _, spent in loaded]
            resumed += len(alive) * len(splits)
            forward(rung_epochs, rung_epochs)
        else:
            start = time.perf_counter()
            result = train_mlp_grid(
                data.X,
                data.y,
                splits,
                sizes,
                epochs=rung_epochs,
                learning_rate=learning_rate,
                seed=seed,
                device=device,
                progress=forward,
            )
            seconds = (time.perf_counter() - start) / max(1, len(alive))
            seconds_each = [seconds] * len(alive)
            preds = []
            for k in range(len(alive)):
                pred = np.empty_like(data.y)
                for j in range(len(splits)):
                    trained = result.model(k, j)
                    pred[trained.val_index] = trained.val_pred_deg
                preds.append(pred)
            if checkpoint is not None:
                checkpoint.add_many(
                    ("mlp", configs[i], j, pred[val], seconds / len(splits), rung_epochs, group)
                    for i, pred in zip(alive, preds, strict=True)
                    for j, (_, val) in enumerate(splits)
                )
        done_before += rung_epochs
        scores = []
        last = rung == len(rungs) - 1
        for k, i in enumerate(alive):
            pred, seconds = preds[k], seconds_each[k]
            status = "ok" if last else f"stopped after {rung_epochs} epochs (successive halving)"
            previous = out.get(i, (None, None, 0.0, ""))[2]
            out[i] = (configs[i], pred, previous + seconds, status)
            fold_rmse = [
                float(np.sqrt(np.mean((pred[val] - data.y[val]) ** 2))) for _, val in splits
            ]
            scores.append((float(np.mean(fold_rmse)), i))
        if not last:
            keep = rungs[rung + 1][0]
            alive = sorted(i for _, i in sorted(scores)[:keep])
            logger.info("successive halving: %d of %d configurations go on", keep, len(scores))
    return [out[i] for i in range(len(configs))], resumed


def search(
    data: TrainingData,
    *,
    models: str | Sequence[str] = MODEL_NAMES,
    grid_name: str = "quick",
    folds: int = 5,
    seed: int = 0,
    device: str = "auto",
    n_jobs: int | None = None,
    epochs: int | None = None,
    mape_threshold_deg: float | None = None,
    param_grid: dict[str, list[dict[str, Any]]] | None = None,
    progress: Progress | None = None,
    cv: str = "grouped",
    halving: int | None = None,
    halving_rungs: int | None = None,
    plr_patience: int | None = None,
    checkpoint: SearchCheckpoint | None = None,
    refit: bool = True,
    tf32: bool = False,
    on_start: Callable[[], None] | None = None,
) -> SearchResult:
    """Grouped K-fold grid search of each model family, then a refit of the best.

    Parameters
    ----------
    data : TrainingData
        From :func:`softbend.surrogates.features.training_data`.
    models : sequence of str or str
        Names of registered families (:data:`~softbend.surrogates.families.FAMILIES`:
        ``"plr"``, ``"xgb"``, ``"mlp"``, ...), or one comma-separated text of them.
    grid_name : {"quick", "paper", "small"}
        Hyperparameter grid (module docstring).
    folds : int
        Number of design-grouped folds (default 5, as paper B).
    seed : int
        Seed of the fold assignment, XGBoost and the MLP.
    device : {"auto", "cpu", "cuda"}
        Where the MLP trains.
    n_jobs : int, optional
        XGBoost threads (default: all cores).
    epochs : int, optional
        MLP epochs (default :data:`MLP_EPOCHS` of the grid: 200 quick, 1000 paper,
        1000 small).
    mape_threshold_deg : float, optional
        The MAPE floor, smallest ``|θ|`` in the MAPE, degrees; default
        :func:`~softbend.surrogates.metrics.mape_floor_deg` of all the data's
        angles (1° for paper B's actuator, as paper B; else max(5°, 5 % of the
        largest ``|θ|``)), the same for every fold.
    param_grid : dict, optional
        Own configurations for some families, replacing the named grid for
        them, e.g. ``{"plr": [{"degree": 3}, {"degree": 5}]}``.
    progress : callable, optional
        ``progress(phase, done, total)``.
    cv : {"grouped", "random"}
        Folds of whole designs (default), or of samples shuffled across designs
        as paper B did (:func:`random_splits`; optimistic, for comparison only).
    halving : int, optional
        Race the MLP configurations by successive halving with this factor
        (e.g. 3; :func:`halving_rungs`) instead of training each for all the
        epochs: the paper grid then costs a fraction of the exhaustive search.
        The best configuration is chosen among those that reach the full epochs.
    halving_rungs : int, optional
        Number of rungs of the halving, >= 1 (default: :func:`halving_rungs`'
        choice).
    plr_patience : int, optional
        Stop raising the polynomial's degree (its configurations in grid order,
        ascending in the named grids) once this many in a row have not lowered
        the best cross-validated RMSE, >= 1; the higher degrees are listed as
        skipped. The fit's cost grows steeply with the degree (paper grid on the
        FEM data: degree 9 takes 20 times as long as degree 7), and past the
        best degree the held-out error only grows. Default: every degree.
    checkpoint : SearchCheckpoint, optional
        Durable record of the finished configuration-folds
        (:mod:`softbend.surrogates.checkpoint`): started with the fingerprint of
        this search, it hands back the folds of an interrupted run of the same
        search, which are loaded instead of fitted, and receives every fold
        fitted. The caller removes it when the results are safe.
    refit : bool, default True
        Refit each family's best configuration on all rows (``model``,
        ``timing``, ``fit_s`` of its :class:`FamilyResult`); ``False`` scores
        only (``model`` None, timings NaN), e.g. for a second CV protocol.
    tf32 : bool, default False
        Allow TF32 matrix products while the MLPs train on a CUDA device, the
        refit included (:func:`~softbend.surrogates.batched.tf32_matmul`); no
        effect on the CPU.
    on_start : callable, optional
        Called once every setting is checked, before the first fit (e.g. to
        print a line that a bad setting's error should not follow).

    Returns
    -------
    SearchResult
        With ``resumed``, the configuration-folds loaded from ``checkpoint``.
    """
    models = list(family_names(models))
    check_choice(grid_name, "grid", SEARCH_GRIDS)
    if mape_threshold_deg is None:
        mape_threshold_deg = mape_floor_deg(data.y, data.actuator)
    else:
        mape_threshold_deg = check_range(
            mape_threshold_deg, "mape_threshold_deg", low=0.0, low_inclusive=True
        )
    check_choice(device, "device", ("auto", "cpu", "cuda"))
    epochs = (
        MLP_EPOCHS[grid_name]
        if epochs is None
        else int(check_range(epochs, "epochs", low=1, low_inclusive=True))
    )
    check_choice(cv, "cv", CV_PROTOCOLS)
    if not isinstance(tf32, bool):
        raise InputError(must_be("True or False", tf32), key="tf32")
    if halving is not None:
        halving = check_int(halving, "halving", low=2)
    n_rungs = None if halving_rungs is None else check_int(halving_rungs, "halving_rungs", low=1)
    patience = None if plr_patience is None else check_int(plr_patience, "plr_patience", low=1)
    if n_rungs is not None and halving is None:
        raise InputError(
            f"needs 'halving' (the factor, e.g. 3); got halving_rungs={n_rungs} without it",
            key="halving_rungs",
        )
    splits = (
        grouped_splits(data.groups, folds, seed)
        if cv == "grouped"
        else random_splits(data.n_samples, folds, seed)
    )
    rows: list[dict[str, Any]] = []
    families: dict[str, FamilyResult] = {}
    param_grid = dict(param_grid or {})
    for name in param_grid:
        with keyed("param_grid"):
            FAMILIES.check(name)
    plan = {model: list(param_grid.get(model) or grid(grid_name, model)) for model in models}
    if halving is not None and "mlp" in plan:
        with keyed("halving_rungs"):  # bad rungs: before any fit
            _halving_rungs(len(plan["mlp"]), epochs, halving, n_rungs)
    if on_start is not None:
        on_start()
    if checkpoint is not None:
        checkpoint.start(
            search_fingerprint(
                data,
                splits,
                plan,
                grid_name=grid_name,
                cv=cv,
                seed=seed,
                epochs=epochs,
                halving=halving,
                n_rungs=n_rungs,
                device=device,
                n_jobs=n_jobs,
                tf32=tf32,
            )  # (no plr_patience: it decides which folds are fitted, not their scores)
        )
    resumed = 0
    for model, configs in plan.items():
        with _mlp_precision(model, device, tf32), _mlp_threads(model, device, data.n_samples):
            noun = "configuration" if len(configs) == 1 else "configurations"
            phase = f"{model}: {len(configs)} {noun} x {len(splits)} folds"
            started = time.perf_counter()

            def make(params: dict[str, Any], model: str = model) -> Any:
                return _make(model, params, seed=seed, n_jobs=n_jobs, device=device, epochs=epochs)

            if model == "mlp":
                # the batched search counts epochs (all configurations and folds train together)
                epoch_phase = f"{phase}, training epochs"

                def on_epoch(done: int, total_epochs: int, phase: str = epoch_phase) -> None:
                    if progress is not None:
                        progress(phase, done, total_epochs)

                outcomes, loaded = _cv_mlp_batched(
                    configs,
                    data,
                    splits,
                    epochs=epochs,
                    seed=seed,
                    device=device,
                    progress=on_epoch,
                    halving=halving,
                    n_rungs=n_rungs,
                    checkpoint=checkpoint,
                )
            else:
                total = len(configs) * len(splits)
                done = 0

                def tick(phase: str = phase, total: int = total) -> None:
                    nonlocal done
                    done += 1
                    if progress is not None:
                        progress(phase, done, total)

                if progress is not None:
                    progress(phase, 0, total)
                stop = (
                    _patience_stop(splits, data.y, patience)
                    if model == "plr" and patience is not None
                    else None
                )
                outcomes, loaded = _cv_sequential(
                    model, configs, data, splits, make, tick, checkpoint, stop
                )
            resumed += loaded
            best: tuple[float, dict[str, Any], np.ndarray, dict[str, float]] | None = None
            for params, pred, seconds, status in outcomes:
                row: dict[str, Any] = {
                    "model": model,
                    "params": describe(params),
                    "status": status,
                    "fit_s_per_config": seconds,
                }
                if pred is not None:
                    scores = _fold_scores(data.y, pred, splits, mape_threshold_deg)
                    row.update(scores)
                    # A configuration stopped early by successive halving is no candidate.
                    if status == "ok" and (best is None or scores["rmse_fold_mean"] < best[0]):
                        best = (scores["rmse_fold_mean"], params, pred, scores)
                rows.append(row)
            search_s = time.perf_counter() - started
            if best is None:
                logger.warning("no configuration of %s could be fitted", model)
                continue
            _, params, pred, scores = best
            final, timing, fit_s = None, {"single_us": math.nan, "batch_ms": math.nan}, 0.0
            if refit:
                start = time.perf_counter()
                final = _refit(make(params), data, f"{model}: refit on all designs", progress)
                fit_s = time.perf_counter() - start
                timing = inference_time(final, data.X, seed=seed)
            families[model] = FamilyResult(
                name=model,
                params=params,
                cv=scores,
                oof_pred=pred,
                model=final,
                timing=timing,
                fit_s=fit_s,
                search_s=search_s,
            )
    settings = {
        "grid": grid_name
        if not param_grid
        else f"{grid_name} (own grid for {', '.join(param_grid)})",
        "folds": len(splits),
        "cv": cv,
        "mlp_halving": halving,
        "mlp_halving_rungs": n_rungs if halving else None,
        "plr_patience": patience,
        "seed": seed,
        "device": device,
        "mlp_epochs": epochs,
        "mlp_tf32": tf32,
        "xgb_trees": XGB_TREES,
        "mape_threshold_deg": mape_threshold_deg,
        "mape_floor_deg": mape_threshold_deg,
        "n_samples": data.n_samples,
        "n_designs": data.n_groups,
        "data_hash": data.data_hash,
    }
    return SearchResult(
        cv_results=pd.DataFrame(rows),
        families=families,
        data=data,
        settings=settings,
        resumed=resumed,
    )


def _refit(estimator: Any, data: TrainingData, phase: str, progress: Progress | None) -> Any:
    """``estimator`` fitted on every row, told as its own phase: the MLP counts its
    training epochs, every other family counts one fit."""
    from softbend.surrogates.mlp import NormalizedMLPRegressor

    if progress is None:
        return estimator.fit(data.X, data.y)
    if isinstance(estimator, NormalizedMLPRegressor):
        epochs_phase = f"{phase}, training epochs"

        def on_epoch(done: int, total: int) -> None:
            progress(epochs_phase, done, total)

        return estimator.fit(data.X, data.y, progress=on_epoch)
    progress(phase, 0, 1)
    fitted = estimator.fit(data.X, data.y)
    progress(phase, 1, 1)
    return fitted


def search_fingerprint(
    data: TrainingData,
    splits: list[tuple[np.ndarray, np.ndarray]],
    plan: dict[str, list[dict[str, Any]]],
    *,
    grid_name: str,
    cv: str,
    seed: int,
    epochs: int,
    halving: int | None,
    device: str,
    n_jobs: int | None,
    n_rungs: int | None = None,
    tf32: bool = False,
) -> dict[str, Any]:
    """Everything that determines the scores of a search, for its checkpoint.

    The data hash, the folds (the hash of their validation rows, which follows
    from the data, ``cv``, the number of folds and the seed), the seed, the
    configurations of each family, the MLP epochs, halving and resolved device,
    the XGBoost trees and threads, and the versions of softbend and the
    libraries that fit the models. A checkpoint written under any other value
    is not reused.
    """
    from importlib.metadata import PackageNotFoundError, version

    import softbend

    digest = hashlib.sha256()
    for _, val in splits:
        digest.update(np.ascontiguousarray(val, dtype="<i8").tobytes())
        digest.update(b"|")
    versions: dict[str, str | None] = {"softbend": softbend.__version__}
    for package in ("numpy", "scikit-learn", "xgboost", "torch"):
        try:
            versions[package] = version(package)
        except PackageNotFoundError:
            versions[package] = None
    fingerprint: dict[str, Any] = {
        "data_hash": data.data_hash,
        "n_samples": data.n_samples,
        "cv": cv,
        "folds": len(splits),
        "splits": digest.hexdigest()[:16],
        "seed": seed,
        "grid": grid_name,
        "families": list(plan),
        "configs": plan,
        "versions": versions,
    }
    if "xgb" in plan:
        fingerprint["xgb"] = {"trees": XGB_TREES, "threads": n_jobs}
    if "mlp" in plan:
        from softbend.surrogates.mlp_core import resolve_device

        fingerprint["mlp"] = {
            "epochs": epochs,
            "halving": halving,
            "device": resolve_device(device),
        }
        if halving and n_rungs is not None:  # (absent: older checkpoints stay valid)
            fingerprint["mlp"]["halving_rungs"] = n_rungs
        if tf32:  # (absent: older checkpoints stay valid)
            fingerprint["mlp"]["tf32"] = True
    return fingerprint
