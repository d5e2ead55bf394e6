"""Train the surrogates of a campaign and write everything a user keeps.

:func:`train_surrogates` runs the grouped cross-validated search
(:func:`softbend.surrogates.search.search`) on a campaign's samples and writes
into ``out_dir``:

- ``models/<model>.json`` — the refitted best model of each family with its
  metadata (feature order and units, data hash, CV metrics, softbend version),
  for a family with a storage (:class:`~softbend.surrogates.families.Storage`);
- ``models/<model>.onnx`` — its ONNX export, checked against ``predict``, for a
  family with one;
- ``cv_results.csv`` — every configuration's cross-validated scores;
- ``summary.csv`` — the best of each family beside paper B's figures (empty for
  a family paper B does not have).

The summary names the best family by cross-validated RMSE (°) unless told
another metric (``select_by``: ``rmse``, ``mape`` or ``r2``; :data:`SELECT_BY`):
a MAPE weighs the readings near its floor most and can prefer a model several
times further off in degrees. ``best_by_mape`` stays, reported beside. On a
table of fewer than :data:`~softbend.surrogates.search.SMALL_DATA_DESIGNS`
designs the search uses the ``small`` grid unless a grid is named, and says so
(``advice``).

It draws nothing: :func:`softbend.reports.surrogate_figures.training_figures`
draws paper B Fig. 5 and the MLP's loss from what it returns.
:func:`train_into` is what ``softbend train`` runs: the same, into a folder that
is replaced as a whole, resuming an interrupted search from its checkpoint.
"""

from __future__ import annotations

import os
from collections.abc import Callable, Sequence
from pathlib import Path
from typing import TYPE_CHECKING, Any, TypeAlias

import numpy as np
import pandas as pd

from softbend._io import write_text_atomic
from softbend._validation import check_choice
from softbend.references import SURROGATES, values
from softbend.surrogates.families import FAMILIES, family_names
from softbend.surrogates.features import TrainingData, family_training_data, training_data
from softbend.surrogates.search import (
    MODEL_NAMES,
    SMALL_DATA_DESIGNS,
    SMALL_DATA_MODELS,
    Progress,
    SearchResult,
    describe,
    search,
)

if TYPE_CHECKING:
    from softbend.surrogates.checkpoint import SearchCheckpoint

#: What surrogates are trained from: a campaign database, its samples table, or prepared data.
Source: TypeAlias = TrainingData | pd.DataFrame | str | os.PathLike[str]

#: Paper B §4.1 (Fig. 5): best configuration of each family, 5-fold CV on its FEM data
#: (:data:`softbend.references.SURROGATES`).
PAPER_B_FIG5: dict[str, dict[str, Any]] = values(SURROGATES)


#: Metrics the best family may be chosen by: (key of the CV scores, True if higher is better).
SELECT_BY: dict[str, tuple[str, bool]] = {
    "rmse": ("rmse_deg", False),
    "mape": ("mape_pct", False),
    "r2": ("r2", True),
}

#: The progress phase of writing the models, after the last refit (its total: the families).
SAVING_PHASE = "saving the models"


def best_family(families: dict[str, Any], select_by: str = "rmse") -> str | None:
    """The family whose pooled cross-validated ``select_by`` score is best.

    Parameters
    ----------
    families : dict
        ``{name: FamilyResult}`` (anything with a ``cv`` dict of scores).
    select_by : {"rmse", "mape", "r2"}
        Lowest RMSE (°), lowest MAPE (%) or highest R². A family whose score is
        undefined (NaN: no reading above the MAPE floor) is no candidate.

    Returns
    -------
    str or None
        The family's name; None when no family has a defined score.
    """
    check_choice(select_by, "select_by", tuple(SELECT_BY))
    key, higher = SELECT_BY[select_by]
    scored = {
        name: float(fam.cv[key]) for name, fam in families.items() if np.isfinite(fam.cv[key])
    }
    if not scored:
        return None
    pick = max if higher else min
    return pick(scored, key=scored.__getitem__)


def small_data_advice(
    n_designs: int, grid_name: str | None, *, mlp: bool = True, table: bool = False
) -> str | None:
    """One line for a table of fewer than :data:`SMALL_DATA_DESIGNS` designs, else None.

    ``grid_name`` is the grid the caller named (None: none); ``mlp`` whether the
    MLP is among the families trained (the grid is said only then); ``table``
    whether the table base is (it is then said to be a candidate).
    """
    if n_designs >= SMALL_DATA_DESIGNS:
        return None
    grid = (
        "the MLP searches the small-data grid (networks of 16 and 32 units, 1000 epochs; "
        "--grid quick for paper B's network)"
        if grid_name is None
        else f"--grid {grid_name} was asked for (the small-data grid is the default here)"
    )
    said = f"; {grid}" if mlp else ""
    if table:
        said += (
            "; the table base (the simulated curves themselves, a Gaussian process between "
            "designs) is a candidate"
        )
    return (
        f"{n_designs} designs: fewer than {SMALL_DATA_DESIGNS}, so the held-out scores vary "
        f"from fold to fold and a flexible model can fit noise{said}. Compare the families "
        "by RMSE and add designs where the held-out error is largest."
    )


def default_models(n_designs: int) -> tuple[str, ...]:
    """The families ``softbend train`` searches unless told: paper B's three
    (:data:`~softbend.surrogates.search.MODEL_NAMES`), and for a table of fewer than
    :data:`~softbend.surrogates.search.SMALL_DATA_DESIGNS` designs the table base too
    (:data:`~softbend.surrogates.search.SMALL_DATA_MODELS`)."""
    return SMALL_DATA_MODELS if n_designs < SMALL_DATA_DESIGNS else MODEL_NAMES


def _telling(advise: Callable[[str], None] | None, line: str | None) -> Callable[[], None] | None:
    """``advise(line)`` as a call of no arguments; None when there is nothing to tell."""
    if advise is None or line is None:
        return None
    return lambda: advise(line)


def _mape_entry(cv: dict[str, float]) -> dict[str, Any]:
    """The MAPE fields of a summary entry: null and a reason when it is undefined."""
    floor = float(cv["mape_floor_deg"])
    used = int(cv["n_mape_used"])
    entry: dict[str, Any] = {"mape_floor_deg": floor, "n_mape_used": used}
    if not np.isfinite(cv["mape_pct"]):
        entry["mape_pct"] = None
        entry["mape_undefined"] = f"no reading has |angle| >= {floor:g} deg (the MAPE floor)"
    return entry


def _load_data(source: Source) -> TrainingData:
    if isinstance(source, TrainingData):
        return source
    if isinstance(source, pd.DataFrame):
        return training_data(source)
    from softbend.campaign.store import campaign_actuator, load_samples

    path = Path(os.fspath(source))
    if not path.exists():
        raise FileNotFoundError(f"Campaign database {str(path)!r} does not exist.")
    samples = load_samples(path)
    # A campaign of another FEM family than paper B's trains on its own design
    # columns and actuator, recorded in the database; paper B's records none.
    return family_training_data(samples, campaign_actuator(path))


def train_surrogates(
    source: Source,
    out_dir: str | os.PathLike[str],
    *,
    models: str | Sequence[str] | None = None,
    grid_name: str | None = "quick",
    folds: int = 5,
    seed: int = 0,
    device: str = "auto",
    n_jobs: int | None = None,
    epochs: int | None = None,
    export_onnx: bool = True,
    progress: Progress | None = None,
    select_by: str = "rmse",
    advise: Callable[[str], None] | None = None,
    cv: str = "grouped",
    halving: int | None = None,
    halving_rungs: int | None = None,
    plr_patience: int | None = None,
    checkpoint: SearchCheckpoint | None = None,
    tf32: bool = False,
    interpolation: bool | None = None,
) -> tuple[SearchResult, dict[str, Any]]:
    """Search, refit, save and export the surrogates of a campaign.

    Parameters
    ----------
    source : path, pandas.DataFrame or TrainingData
        A campaign database (DuckDB), its samples table, or prepared data.
    out_dir : path
        Output folder (created).
    models, grid_name, folds, seed, device, n_jobs, epochs, progress
        As :func:`softbend.surrogates.search.search` (``models``: registered family
        names, or one comma-separated text of them; None: :func:`default_models`,
        paper B's three and, under
        :data:`~softbend.surrogates.search.SMALL_DATA_DESIGNS` designs, the table
        base). ``grid_name`` None: ``small``
        for fewer than :data:`~softbend.surrogates.search.SMALL_DATA_DESIGNS`
        designs, else ``quick``.
    export_onnx : bool
        Also write and check ``models/<model>.onnx`` (default True) for the families
        that have an ONNX export.
    cv : {"grouped", "random"}, halving : int, optional, halving_rungs : int, plr_patience : int
        Cross-validation protocol, successive halving of the MLP grid and early
        stop of the polynomial's degrees (see :func:`softbend.surrogates.search.search`).
    checkpoint : SearchCheckpoint, optional
        Where the search saves its finished configuration-folds and from which
        an interrupted search resumes (see :func:`softbend.surrogates.search.search`);
        left in place: the caller removes it once ``out_dir`` is safe.
    tf32 : bool
        TF32 matrix products for the MLP on a CUDA device (see
        :func:`softbend.surrogates.search.search`).
    interpolation : bool, optional
        Also score each family's chosen configuration on held-out pressure points
        of the simulated designs (:func:`~softbend.surrogates.interpolation.interpolation_scores`:
        one more fit per family), reported as ``interpolation`` beside the
        grouped figures. None (the default): only for a table of fewer than
        :data:`~softbend.surrogates.search.SMALL_DATA_DESIGNS` designs, where the
        extra fit is cheap and the grouped figures alone vary most (a large
        table pays a whole fit per family for it).
    select_by : {"rmse", "mape", "r2"}
        The cross-validated metric that names the best family (default RMSE).
    advise : callable, optional
        Told :func:`small_data_advice`'s line, once the settings are checked and
        before the first fit, for a table of
        fewer than :data:`~softbend.surrogates.search.SMALL_DATA_DESIGNS` designs.

    Returns
    -------
    result : SearchResult
    summary : dict
        JSON-friendly headline figures, per family and paper B's beside them
        (``paper_b``, empty for a family paper B does not have; the MAPE with
        its floor ``mape_floor_deg`` and ``n_mape_used``, null with
        ``mape_undefined`` when no reading reaches the floor; with
        ``interpolation``, the family's ``interpolation`` figures), ``best`` and
        ``selected_by``, ``best_by_mape``, ``advice`` (None for 100 designs or
        more), the files written, and ``resumed_config_folds`` (folds loaded
        from ``checkpoint``).
    """
    from softbend.actuators import SFRBA
    from softbend.surrogates.features import training_ranges
    from softbend.surrogates.persistence import save_surrogate
    from softbend.surrogates.support import support_from_rows

    check_choice(select_by, "select_by", tuple(SELECT_BY))
    data = _load_data(source)
    if models is None:
        models = default_models(data.n_groups)
    names = [m.strip() for m in models.split(",")] if isinstance(models, str) else list(models)
    advice = small_data_advice(data.n_groups, grid_name, mlp="mlp" in names, table="table" in names)
    if grid_name is None:
        grid_name = "small" if advice is not None else "quick"
    actuator = data.actuator or SFRBA  # every check and file names this actuator
    published = actuator.published_cv
    result = search(
        data,
        models=models,
        grid_name=grid_name,
        folds=folds,
        seed=seed,
        device=device,
        n_jobs=n_jobs,
        epochs=epochs,
        progress=progress,
        cv=cv,
        halving=halving,
        halving_rungs=halving_rungs,
        plr_patience=plr_patience,
        checkpoint=checkpoint,
        tf32=tf32,
        on_start=_telling(advise, advice),
    )
    interpolated: dict[str, dict[str, float]] = {}
    if interpolation is None:
        interpolation = data.n_groups < SMALL_DATA_DESIGNS
    if interpolation:
        from softbend.surrogates.families import FitSettings
        from softbend.surrogates.interpolation import interpolation_scores

        settings = FitSettings(
            seed=seed, n_jobs=n_jobs, device=device, epochs=int(result.settings["mlp_epochs"])
        )
        phase = "interpolation: held-out pressures of the simulated designs"
        if progress is not None:
            progress(phase, 0, 1)
        interpolated = interpolation_scores(
            data,
            {name: fam.params for name, fam in result.families.items()},
            settings,
            mape_threshold_deg=float(result.settings["mape_floor_deg"]),
        )
        if progress is not None:
            progress(phase, 1, 1)
    out = Path(out_dir)
    (out / "models").mkdir(parents=True, exist_ok=True)
    files: dict[str, str] = {}
    families: dict[str, Any] = {}
    saving = SAVING_PHASE
    if progress is not None:  # the table's ranges and support: a second or more on 10^6 rows
        progress(saving, 0, len(result.families))
    # what every model records of the table, found once (not once per family)
    described = {
        "data_hash": data.data_hash,
        "n_samples": data.n_samples,
        "n_designs": data.n_groups,
        "training_ranges": training_ranges(data.X, actuator.features),
        "support": support_from_rows(
            data.X, data.y, parameters=actuator.names, pressure_unit=actuator.pressure_unit
        ).to_dict(),
    }
    for done, (name, fam) in enumerate(result.families.items(), start=1):
        metadata = {
            **{key: described[key] for key in ("data_hash", "n_samples", "n_designs")},
            "cv": {k: float(v) for k, v in fam.cv.items()},
            "search": {**result.settings, "params": describe(fam.params)},
            "training_ranges": described["training_ranges"],
            "support": described["support"],
        }
        metadata["actuator"] = actuator.to_dict()  # every model names its actuator
        family = FAMILIES.get(name)
        if family.storage is not None:
            files[f"{name}_model"] = str(
                save_surrogate(fam.model, out / "models" / f"{name}.json", metadata=metadata)
            )
        entry: dict[str, Any] = {
            "params": describe(fam.params),
            **{k: float(v) for k, v in fam.cv.items()},
            **_mape_entry(fam.cv),
            **{f"inference_{k}": v for k, v in fam.timing.items()},
            "fit_s": fam.fit_s,
            "search_s": fam.search_s,
            "paper_b": dict(published.get(name) or {}),
        }
        if name in interpolated:
            entry["interpolation"] = interpolated[name]
        if export_onnx and family.onnx is not None:
            from softbend.surrogates.onnx_export import onnx_predict, save_onnx

            onnx_path = save_onnx(fam.model, out / "models" / f"{name}.onnx", actuator=actuator)
            rows = data.X[np.random.default_rng(seed).integers(0, data.n_samples, 2000)]
            expected = fam.model.predict(rows)
            entry["onnx_max_abs_diff_deg"] = float(
                np.max(np.abs(onnx_predict(onnx_path, rows) - expected))
            )
            files[f"{name}_onnx"] = str(onnx_path)
        families[name] = entry
        if progress is not None:
            progress(saving, done, len(result.families))
    cv_path = out / "cv_results.csv"
    write_text_atomic(cv_path, result.cv_results.to_csv(index=False))
    summary_table = result.summary()
    if interpolated:
        for key in ("rmse_deg", "max_abs_error_deg", "r2"):
            summary_table[f"interp_{key}"] = [
                interpolated.get(m, {}).get(key) for m in summary_table["model"]
            ]
    for key in ("params", "r2", "mape_pct", "inference_ms"):
        summary_table[f"paper_b_{key}"] = [
            dict(published.get(m) or {}).get(key) for m in summary_table["model"]
        ]
    write_text_atomic(out / "summary.csv", summary_table.to_csv(index=False))
    files["cv_results"] = str(cv_path)
    files["summary"] = str(out / "summary.csv")
    summary = {
        **({"actuator": actuator.to_dict()} if actuator.named_in_outputs else {}),
        "settings": result.settings,
        "models": families,
        "best": best_family(result.families, select_by),
        "selected_by": select_by,
        "best_by_mape": best_family(result.families, "mape"),
        "mape_floor_deg": result.settings["mape_floor_deg"],
        "advice": advice,
        "resumed_config_folds": result.resumed,
        "files": files,
    }
    return result, summary


def train_into(
    source: Source,
    out_dir: str | os.PathLike[str],
    *,
    models: str | Sequence[str] | None = None,
    figures: Callable[[SearchResult, Path], dict[str, str]] | None = None,
    choose: Callable[[SearchResult, Path, dict[str, Any]], None] | None = None,
    on_resume: Callable[[str], None] | None = None,
    on_discard: Callable[[str], None] | None = None,
    **options: Any,
) -> tuple[SearchResult, dict[str, Any]]:
    """:func:`train_surrogates` into a folder replaced as a whole, resumable.

    The families are checked first. Everything is written into a staging folder
    beside ``out_dir`` (with ``figures(result, stage)``'s files, if given) that
    replaces ``out_dir`` only when complete: an interrupted run leaves the
    previous folder as it was, never old models beside new ones. Every finished
    configuration-fold is kept in the checkpoint beside ``out_dir``
    (:func:`~softbend.surrogates.checkpoint.checkpoint_path`); the same call run
    again after an interruption resumes from it, and it is removed once the new
    folder is in place.

    Parameters
    ----------
    source, out_dir, models
        As :func:`train_surrogates`.
    figures : callable, optional
        ``figures(result, folder) -> {name: path}``: more files drawn into the
        staging folder (e.g. :func:`softbend.reports.surrogate_figures.training_figures`).
    choose : callable, optional
        ``choose(result, folder, summary)``: the selection step, once every family is
        fitted and refit and saved into the staging folder, before the figures; it may
        name another ``best`` in ``summary`` (recording its criterion), rewrite the
        folder's tables and add files to ``summary["files"]`` (e.g.
        :func:`softbend.transfer.base_choice.choose_family`, by transfer error).
    on_resume, on_discard : callable, optional
        Told one line when a checkpoint is resumed, or discarded as that of other
        settings (:class:`~softbend.surrogates.checkpoint.SearchCheckpoint`).
    **options
        The other keyword arguments of :func:`train_surrogates` (``grid_name``,
        ``folds``, ``seed``, ``device``, ...), not ``checkpoint``.

    Returns
    -------
    result : SearchResult
    summary : dict
        As :func:`train_surrogates`, with ``files`` named where they are now, in
        ``out_dir``.

    Raises
    ------
    softbend.registry.UnknownNameError
        An unknown family, before anything is written.
    """
    from softbend._outdir import staged_dir
    from softbend.surrogates.checkpoint import SearchCheckpoint, checkpoint_path

    names = None if models is None else family_names(models)
    out = Path(out_dir)
    checkpoint = SearchCheckpoint(checkpoint_path(out), on_resume=on_resume, on_discard=on_discard)
    with checkpoint:
        with staged_dir(out, "train") as stage:
            result, summary = train_surrogates(
                source, stage, models=names, checkpoint=checkpoint, **options
            )
            if choose is not None:
                choose(result, stage, summary)
            if figures is not None:
                summary["files"].update(figures(result, stage))
        checkpoint.remove()  # the new folder is in place
    summary["files"] = {
        key: str(out / Path(value).relative_to(stage))
        if str(value).startswith(str(stage))
        else value
        for key, value in summary["files"].items()
    }
    return result, summary
