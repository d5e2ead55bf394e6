"""The surrogate that transfer learning starts from: paper B's MLP on the FEM dataset.

:func:`train_base_mlp` trains the normalized MLP of paper B §4.1 (hidden sizes
(63, 65), 1000 epochs, Adam 6e-4, batches of 1024) on every converged sample of
the shipped Table 1 FEM dataset (:func:`softbend.datasets.table1_fem`).
softbend ships the result (``softbend transfer base`` makes it again), so that a
refinement, ``softbend reproduce`` and the tests do not train it each time;
:func:`load_base` reads it (or any saved surrogate) back.
"""

from __future__ import annotations

import os
from collections.abc import Callable
from importlib import resources
from pathlib import Path
from typing import TYPE_CHECKING, Any, cast

import numpy as np

from softbend.design import FEATURES
from softbend.errors import DatasetError
from softbend.references import SURROGATE_TRAINING

if TYPE_CHECKING:
    import pandas as pd

    from softbend.surrogates.mlp import NormalizedMLPRegressor
    from softbend.surrogates.persistence import SavedSurrogate

__all__ = [
    "BASE_HIDDEN_SIZES",
    "base_metadata",
    "fem_rows",
    "load_base",
    "shipped_base_path",
    "train_base_mlp",
]

#: Paper B's MLP (§4.1, Fig. 5): hidden layers of 63 and 65 units.
BASE_HIDDEN_SIZES: tuple[int, int] = cast(
    tuple[int, int], tuple(SURROGATE_TRAINING["mlp_hidden"].value)
)

_SHIPPED = "table1_fem_mlp.json"


def shipped_base_path() -> Path:
    """Path of the shipped FEM-trained MLP (``softbend/data/transfer/table1_fem_mlp.json``)."""
    return Path(str(resources.files("softbend") / "data" / "transfer" / _SHIPPED))


def fem_rows(samples: pd.DataFrame | None = None) -> np.ndarray:
    """The converged rows of :data:`FEATURES` of FEM samples (default: the shipped dataset)."""
    from softbend.datasets import table1_fem

    frame = table1_fem() if samples is None else samples
    frame = frame[frame["converged"].astype(bool)]
    return frame[list(FEATURES)].to_numpy(dtype=np.float64)


def train_base_mlp(
    samples: pd.DataFrame | None = None,
    *,
    hidden_sizes: tuple[int, int] = BASE_HIDDEN_SIZES,
    epochs: int = 1000,
    seed: int = 0,
    progress: Callable[[int, int], object] | None = None,
) -> NormalizedMLPRegressor:
    """Train paper B's MLP on FEM samples.

    Parameters
    ----------
    samples : DataFrame, optional
        Rows with :data:`FEATURES`, ``angle_deg`` and ``converged`` (the table of
        :func:`softbend.datasets.table1_fem` or of
        :func:`softbend.campaign.load_samples`); default the shipped dataset.
    hidden_sizes : (int, int), default (63, 65)
    epochs : int, default 1000
    seed : int, default 0
    progress : callable, optional
        ``progress(done_epochs, total_epochs)``.

    Returns
    -------
    NormalizedMLPRegressor
        Fitted on the converged samples (CPU, one thread).
    """
    from softbend.datasets import table1_fem
    from softbend.surrogates.batched import train_mlp_grid
    from softbend.surrogates.mlp import NormalizedMLPRegressor

    frame = table1_fem() if samples is None else samples
    missing = [c for c in (*FEATURES, "angle_deg", "converged") if c not in frame.columns]
    if missing:
        raise DatasetError(
            f"The 'samples' of train_base_mlp must have the columns {', '.join(FEATURES)}, "
            f"angle_deg and converged. Missing: {', '.join(missing)}."
        )
    frame = frame[frame["converged"].astype(bool)]
    X = frame[list(FEATURES)].to_numpy(dtype=np.float64)
    y = frame["angle_deg"].to_numpy(dtype=np.float64)
    rows = np.arange(len(y))
    grid = train_mlp_grid(
        X,
        y,
        [(rows, rows[:0])],
        [cast(tuple[int, int], tuple(hidden_sizes))],
        epochs=epochs,
        seed=seed,
        device="cpu",
        progress=progress,
        num_threads=1,
    )
    return NormalizedMLPRegressor.from_grid(grid, 0, 0)


def base_metadata(
    model: NormalizedMLPRegressor, *, epochs: int, seed: int, command: str
) -> dict[str, Any]:
    """The record saved with a base MLP that :func:`train_base_mlp` trained on the shipped data.

    Parameters
    ----------
    model : NormalizedMLPRegressor
        The trained MLP.
    epochs, seed : int
        As given to :func:`train_base_mlp`.
    command : str
        The command that made it, as a user would type it again.

    Returns
    -------
    dict
        Purpose, dataset (and the SHA-256 of its samples), hidden sizes, epochs,
        seed, command, final training MSE (deg²), the training ranges (mm,
        deg, MPa) and the support (each design's largest converged pressure and
        the largest angle: :class:`softbend.surrogates.support.Support`).
    """
    from softbend.datasets import table1_fem, table1_fem_provenance
    from softbend.surrogates.features import training_ranges
    from softbend.surrogates.support import support_from_rows

    provenance = table1_fem_provenance()
    samples = table1_fem()
    samples = samples[samples["converged"].astype(bool)]
    return {
        "purpose": "the FEM-trained MLP that transfer learning starts from",
        "trained_on": "softbend.datasets.table1_fem(), converged samples",
        "dataset_samples_sha256": provenance.get("files", {})
        .get("samples.parquet", {})
        .get("sha256"),
        "hidden_sizes": list(BASE_HIDDEN_SIZES),
        "epochs": epochs,
        "seed": seed,
        "command": command,
        "final_training_mse_deg2": float(model.loss_curve_[-1]) * model.y_scale_**2,
        "training_ranges": training_ranges(fem_rows()),
        "support": support_from_rows(
            samples[list(FEATURES)].to_numpy(dtype=np.float64),
            samples["angle_deg"].to_numpy(dtype=np.float64),
        ).to_dict(),
    }


def load_base(path: str | os.PathLike[str] | None = None) -> Any:
    """A saved surrogate to start from; default the shipped FEM-trained MLP.

    Raises
    ------
    DatasetError
        The shipped file is missing (``softbend transfer base`` writes it).
    FileNotFoundError, softbend.errors.SchemaError
        As :func:`softbend.surrogates.load_surrogate` for a given path.
    """
    return load_base_saved(path).model


def load_base_saved(path: str | os.PathLike[str] | None = None) -> SavedSurrogate:
    """:func:`load_base`, with the file's record: a :class:`~softbend.surrogates.SavedSurrogate`.

    Raises
    ------
    DatasetError, FileNotFoundError, softbend.errors.SchemaError
        As :func:`load_base`.
    """
    from softbend.surrogates.persistence import load_surrogate

    if path is None:
        target = shipped_base_path()
        if not target.is_file():
            raise DatasetError(
                f"The shipped FEM-trained MLP {target} is missing; "
                "'softbend transfer base --out PATH' trains it again."
            )
        return load_surrogate(target)
    return load_surrogate(path)
