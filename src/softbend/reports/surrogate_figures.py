"""Figures of the surrogate search (paper B Fig. 5).

* :func:`parity_and_errors` — per model family, the cross-validated (out-of-fold)
  prediction against the true angle, and the distribution of the error;
* :func:`mlp_loss_curve` — training loss per epoch of a refitted network (the
  MLP, or any family whose model records a ``loss_curve_``).

Families are titled by :data:`softbend.surrogates.families.FAMILIES`.

Matplotlib is imported inside the functions (Agg canvas, no pyplot state).
"""

from __future__ import annotations

from pathlib import Path
from typing import TYPE_CHECKING

import numpy as np

if TYPE_CHECKING:
    from softbend.surrogates.search import SearchResult

_DPI = 150


def _mape_label(cv: dict[str, float]) -> str:
    """``MAPE 1.23 % (|θ| ≥ 5°)``, or that it is undefined (no reading above the floor)."""
    floor = cv.get("mape_floor_deg")
    over = "" if floor is None else f" (|θ| ≥ {floor:.3g}°)"
    mape = cv["mape_pct"]
    return f"MAPE {mape:.2f} %{over}" if np.isfinite(mape) else f"MAPE undefined{over}"


def parity_and_errors(result: SearchResult, path: Path) -> Path:
    """Paper B Fig. 5: parity plot and error histogram for each family's best model.

    The predictions are out-of-fold: each sample is predicted by the model of
    the fold that held its design out.
    """
    from matplotlib.figure import Figure

    from softbend.surrogates.families import FAMILIES
    from softbend.surrogates.search import describe

    names = list(result.families)
    fig = Figure(figsize=(10, 3.6 * max(1, len(names))))
    axes = fig.subplots(max(1, len(names)), 2, squeeze=False)
    y = result.data.y
    lo, hi = float(np.min(y)), float(np.max(y))
    for row, name in enumerate(names):
        fam = result.families[name]
        ax_parity, ax_error = axes[row]
        ax_parity.hexbin(y, fam.oof_pred, gridsize=80, bins="log", mincnt=1, cmap="viridis")
        ax_parity.plot([lo, hi], [lo, hi], color="crimson", lw=1.0, label="y = x")
        ax_parity.set_xlabel("true bending angle (°)")
        ax_parity.set_ylabel("predicted (°), held-out designs")
        ax_parity.set_title(
            f"{FAMILIES.get(name).title} ({describe(fam.params)})\n"
            f"R² {fam.cv['r2']:.6f}, RMSE {fam.cv['rmse_deg']:.2f}°, "
            f"{_mape_label(fam.cv)}",
            fontsize=9,
        )
        ax_parity.legend(loc="upper left", fontsize=8)
        ax_parity.set_aspect("equal", adjustable="box")
        error = fam.oof_pred - y
        ax_error.hist(error, bins=120, color="steelblue", log=True)
        ax_error.axvline(0.0, color="crimson", lw=1.0)
        ax_error.set_xlabel("prediction error (°)")
        ax_error.set_ylabel("samples")
        ax_error.set_title(
            f"error: max |e| {fam.cv['max_abs_error_deg']:.2f}°, "
            f"95 % within ±{np.quantile(np.abs(error), 0.95):.2f}°",
            fontsize=9,
        )
        ax_error.grid(alpha=0.3)
    fig.suptitle(
        f"Surrogates, grouped {result.settings.get('folds', '?')}-fold cross-validation "
        f"({result.data.n_samples} samples, {result.data.n_groups} designs)"
    )
    fig.tight_layout()
    path.parent.mkdir(parents=True, exist_ok=True)
    fig.savefig(path, dpi=_DPI)
    return path


def mlp_loss_curve(
    loss_curve: list[float] | np.ndarray, path: Path, title: str = "normalized MLP"
) -> Path:
    """Training loss (standardized MSE) of a refitted network against the epoch.

    ``title`` is the family's (:attr:`~softbend.surrogates.families.Family.title`).
    """
    from matplotlib.figure import Figure

    fig = Figure(figsize=(6, 4))
    ax = fig.subplots()
    epochs = np.arange(1, len(loss_curve) + 1)
    ax.semilogy(epochs, loss_curve, color="navy")
    ax.set_xlabel("epoch")
    ax.set_ylabel("training MSE (standardized angle)")
    ax.set_title(f"{title[:1].upper()}{title[1:]}, refit on all designs")
    ax.grid(alpha=0.3, which="both")
    fig.tight_layout()
    path.parent.mkdir(parents=True, exist_ok=True)
    fig.savefig(path, dpi=_DPI)
    return path


def training_figures(result: SearchResult, out_dir: str | Path) -> dict[str, str]:
    """Paper B Fig. 5 and the loss curves of the refitted networks of a surrogate search.

    Parameters
    ----------
    result : SearchResult
        What :func:`softbend.surrogates.workflow.train_surrogates` (or
        :func:`~softbend.surrogates.search.search`) returned.
    out_dir : path
        Folder of ``fig5_parity_errors.png`` and ``<family>_loss.png`` (created).

    Returns
    -------
    dict
        ``{"fig5": path, "mlp_loss": path, ...}``, the figures drawn: Fig. 5 if
        any family was searched, and ``<family>_loss`` for each family whose
        refitted model records a ``loss_curve_`` (the MLP).
    """
    from softbend.surrogates.families import FAMILIES

    out = Path(out_dir)
    out.mkdir(parents=True, exist_ok=True)
    files: dict[str, str] = {}
    if result.families:
        files["fig5"] = str(parity_and_errors(result, out / "fig5_parity_errors.png"))
    for name, fam in result.families.items():
        curve = getattr(fam.model, "loss_curve_", None)
        if curve is not None and len(curve):
            title = FAMILIES.get(name).title
            path = out / f"{name}_loss.png"
            files[f"{name}_loss"] = str(mlp_loss_curve(curve, path, title))
    return files
