"""Train the surrogates of a campaign and write everything a user keeps.

:func:`train_surrogates` runs the grouped cross-validated search
(:func:`softbend.surrogates.search.search`) on a campaign's samples and writes
into ``out_dir``:

- ``models/<model>.json`` — the refitted best model of each family with its
  metadata (feature order and units, data hash, CV metrics, softbend version);
- ``models/<model>.onnx`` — its ONNX export, checked against ``predict``;
- ``cv_results.csv`` — every configuration's cross-validated scores;
- ``summary.csv`` — the best of each family beside paper B's figures.

It draws nothing: :func:`softbend.reports.surrogate_figures.training_figures`
draws paper B Fig. 5 and the MLP's loss from what it returns.
"""

from __future__ import annotations

import os
from pathlib import Path
from typing import TYPE_CHECKING, Any

import numpy as np
import pandas as pd

from softbend._io import write_text_atomic
from softbend.surrogates.features import TrainingData, training_data
from softbend.surrogates.search import MODEL_NAMES, Progress, SearchResult, describe, search

if TYPE_CHECKING:
    from softbend.surrogates.checkpoint import SearchCheckpoint

#: Paper B §4.1 (Fig. 5): best configuration of each family, 5-fold CV on its FEM data.
PAPER_B_FIG5: dict[str, dict[str, Any]] = {
    "plr": {"params": "degree 4", "r2": 0.9986, "mape_pct": 1.8, "inference_ms": 22.39},
    "xgb": {
        "params": "max depth 9, learning rate 0.2",
        "r2": 0.9995,
        "mape_pct": 0.8,
        "inference_ms": 53.77,
    },
    "mlp": {"params": "hidden (63, 65)", "r2": 0.9991, "mape_pct": 0.89, "inference_ms": 12.99},
}


def _load_data(source: Any) -> TrainingData:
    if isinstance(source, TrainingData):
        return source
    if isinstance(source, pd.DataFrame):
        return training_data(source)
    from softbend.campaign.store import load_samples

    path = Path(os.fspath(source))
    if not path.exists():
        raise FileNotFoundError(f"Campaign database {str(path)!r} does not exist.")
    return training_data(load_samples(path))


def train_surrogates(
    source: Any,
    out_dir: str | os.PathLike[str],
    *,
    models: tuple[str, ...] | list[str] = MODEL_NAMES,
    grid_name: str = "quick",
    folds: int = 5,
    seed: int = 0,
    device: str = "auto",
    n_jobs: int | None = None,
    epochs: int | None = None,
    export_onnx: bool = True,
    progress: Progress | None = None,
    cv: str = "grouped",
    halving: int | None = None,
    halving_rungs: int | None = None,
    plr_patience: int | None = None,
    checkpoint: SearchCheckpoint | None = None,
    tf32: bool = False,
) -> tuple[SearchResult, dict[str, Any]]:
    """Search, refit, save and export the surrogates of a campaign.

    Parameters
    ----------
    source : path, pandas.DataFrame or TrainingData
        A campaign database (DuckDB), its samples table, or prepared data.
    out_dir : path
        Output folder (created).
    models, grid_name, folds, seed, device, n_jobs, epochs, progress
        As :func:`softbend.surrogates.search.search`.
    export_onnx : bool
        Also write and check ``models/<model>.onnx`` (default True).
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

    Returns
    -------
    result : SearchResult
    summary : dict
        JSON-friendly headline figures, per family and paper B's beside them,
        the files written, and ``resumed_config_folds`` (folds loaded from
        ``checkpoint``).
    """
    from softbend.surrogates.features import training_ranges
    from softbend.surrogates.persistence import save_surrogate

    data = _load_data(source)
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
    )
    out = Path(out_dir)
    (out / "models").mkdir(parents=True, exist_ok=True)
    files: dict[str, str] = {}
    families: dict[str, Any] = {}
    for name, fam in result.families.items():
        metadata = {
            "data_hash": data.data_hash,
            "n_samples": data.n_samples,
            "n_designs": data.n_groups,
            "cv": {k: float(v) for k, v in fam.cv.items()},
            "search": {**result.settings, "params": describe(fam.params)},
            "training_ranges": training_ranges(data.X),
        }
        files[f"{name}_model"] = str(
            save_surrogate(fam.model, out / "models" / f"{name}.json", metadata=metadata)
        )
        entry: dict[str, Any] = {
            "params": describe(fam.params),
            **{k: float(v) for k, v in fam.cv.items()},
            **{f"inference_{k}": v for k, v in fam.timing.items()},
            "fit_s": fam.fit_s,
            "search_s": fam.search_s,
            "paper_b": PAPER_B_FIG5[name],
        }
        if export_onnx:
            from softbend.surrogates.onnx_export import onnx_predict, save_onnx

            onnx_path = save_onnx(fam.model, out / "models" / f"{name}.onnx")
            rows = data.X[np.random.default_rng(seed).integers(0, data.n_samples, 2000)]
            expected = fam.model.predict(rows)
            entry["onnx_max_abs_diff_deg"] = float(
                np.max(np.abs(onnx_predict(onnx_path, rows) - expected))
            )
            files[f"{name}_onnx"] = str(onnx_path)
        families[name] = entry
    cv_path = out / "cv_results.csv"
    write_text_atomic(cv_path, result.cv_results.to_csv(index=False))
    summary_table = result.summary()
    summary_table["paper_b_params"] = [PAPER_B_FIG5[m]["params"] for m in summary_table["model"]]
    summary_table["paper_b_r2"] = [PAPER_B_FIG5[m]["r2"] for m in summary_table["model"]]
    summary_table["paper_b_mape_pct"] = [
        PAPER_B_FIG5[m]["mape_pct"] for m in summary_table["model"]
    ]
    summary_table["paper_b_inference_ms"] = [
        PAPER_B_FIG5[m]["inference_ms"] for m in summary_table["model"]
    ]
    write_text_atomic(out / "summary.csv", summary_table.to_csv(index=False))
    files["cv_results"] = str(cv_path)
    files["summary"] = str(out / "summary.csv")
    best = min(result.families, key=lambda m: result.families[m].cv["mape_pct"], default=None)
    summary = {
        "settings": result.settings,
        "models": families,
        "best_by_mape": best,
        "resumed_config_folds": result.resumed,
        "files": files,
    }
    return result, summary
