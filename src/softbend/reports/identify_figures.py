"""Figures of a model selection: the candidates' free-run errors, and held-out free runs."""

from __future__ import annotations

from pathlib import Path
from typing import TYPE_CHECKING

if TYPE_CHECKING:
    from softbend.identification.selection import Selection
    from softbend.identification.timeseries import TimeSeriesSet

import numpy as np

__all__ = ["freerun_overlays", "selection_figure"]

_DPI = 120
_COLORS = {"arx": "C0", "poly2": "C2", "gg-svr": "C3"}


def selection_figure(selection: Selection, path: str | Path) -> Path:
    """Each candidate's cross-validated free-run NRMSE (bars, by family), its one-step NRMSE
    (dots) and, with validation experiments, its validation free-run NRMSE (crosses)."""
    from matplotlib.figure import Figure

    table = selection.table
    n = len(table)
    fig = Figure(figsize=(8, 0.28 * n + 1.6))
    ax = fig.subplots()
    y = np.arange(n)[::-1]
    colors = [_COLORS.get(f, "0.5") for f in table["family"]]
    ax.barh(y, table["cv_freerun_nrmse"], color=colors, alpha=0.75)
    ax.plot(table["cv_onestep_nrmse"], y, "k.", ms=4, label="one-step (not used to choose)")
    validation = table["validation_freerun_nrmse"].to_numpy(dtype=float)
    if np.isfinite(validation).any():
        ax.plot(validation, y, "x", color="k", label="validation experiments, free run")
    labels = [f"{c}{'  ◀ selected' if c == selection.best else ''}" for c in table["candidate"]]
    ax.set_yticks(y, labels, fontsize=7)
    ax.set_xlabel("NRMSE (RMSE / range of the output), mean over outputs")
    from matplotlib.patches import Patch

    handles = [
        Patch(color=c, alpha=0.75, label=f"{f}: cross-validated free run")
        for f, c in _COLORS.items()
        if f in set(table["family"])
    ]
    ax.legend(fontsize=7, loc="lower right", handles=[*handles, *ax.get_lines()])
    ax.grid(True, axis="x", alpha=0.3)
    ax.set_title("Model selection by held-out free-run error", fontsize=9)
    fig.tight_layout()
    fig.savefig(path, dpi=_DPI)
    return Path(path)


def freerun_overlays(
    data: TimeSeriesSet,
    outputs: dict[str, np.ndarray],
    path: str | Path,
    *,
    title: str,
    count: int = 6,
    bands: dict[str, tuple[np.ndarray, np.ndarray]] | None = None,
    band_label: str = "band",
) -> Path:
    """Measured and free-run outputs of up to ``count`` held-out experiments (rows) per
    output (columns), the free run's band (``bands``: experiment → ``(low, high)``,
    each shaped like its run) shaded behind it and named ``band_label`` in the legend."""
    from matplotlib.figure import Figure

    shown = [e for e in data.experiments if e.name in outputs][:count]
    m = len(data.output_names)
    fig = Figure(figsize=(4.2 * m, 2.1 * max(len(shown), 1) + 0.6))
    axes = fig.subplots(max(len(shown), 1), m, squeeze=False)
    for i, e in enumerate(shown):
        simulated = outputs[e.name]
        for j, name in enumerate(data.output_names):
            ax = axes[i, j]
            if bands and e.name in bands:
                low, high = bands[e.name]
                ax.fill_between(
                    e.time, low[:, j], high[:, j], color="C3", alpha=0.2, lw=0, label=band_label
                )
            ax.plot(e.time, e.outputs[:, j], color="0.3", lw=0.8, label="measured")
            ax.plot(e.time, simulated[:, j], color="C3", lw=0.8, label="free run")
            ax.set_title(f"{e.name}: {name}", fontsize=8)
            ax.tick_params(labelsize=7)
            if i == len(shown) - 1:
                ax.set_xlabel(data.time_name, fontsize=8)
    axes[0, 0].legend(fontsize=7)
    fig.suptitle(title, fontsize=9)
    fig.tight_layout()
    fig.savefig(path, dpi=_DPI)
    return Path(path)
