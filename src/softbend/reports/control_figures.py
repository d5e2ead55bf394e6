"""Figures of closed-loop runs (paper B Fig. 9): angles, valve states, pressure.

Matplotlib is imported inside the functions (Agg canvas, no pyplot state).
"""

from __future__ import annotations

from collections.abc import Iterable
from pathlib import Path
from typing import TYPE_CHECKING

if TYPE_CHECKING:
    from matplotlib.axes import Axes

    from softbend.control.experiments import ControlRun

__all__ = ["run_figure", "runs_figure"]

_DPI = 120


def _panels(axes: Iterable[Axes], run: ControlRun, *, legend: bool = True) -> None:
    top, valves, pressure = axes
    top.plot(run.t_s, run.reference_deg, "k--", lw=1, label="reference θr")
    top.plot(run.t_s, run.camera_deg, lw=1.2, label="true angle θe (camera)")
    top.plot(run.t_s, run.predicted_deg, lw=0.8, alpha=0.8, label="predicted θp (model)")
    top.set_ylabel("angle (°)")
    valves.step(run.t_s, run.inlet.astype(float) + 1.6, where="post", lw=0.8, label="inlet")
    valves.step(run.t_s, run.outlet.astype(float), where="post", lw=0.8, label="outlet")
    valves.set_yticks([0, 1, 1.6, 2.6], ["shut", "open", "shut", "open"], fontsize=7)
    valves.set_ylim(-0.3, 2.9)
    pressure.plot(run.t_s, run.pressure_mpa, lw=1, label="true")
    pressure.plot(run.t_s, run.measured_mpa, lw=0.6, alpha=0.7, label="sensor")
    pressure.set_ylabel("pressure (MPa, gauge)")
    pressure.set_xlabel("time (s)")
    if legend:
        top.legend(loc="upper right", fontsize=7)
        valves.legend(loc="upper right", fontsize=7)
        pressure.legend(loc="upper right", fontsize=7)


def run_figure(run: ControlRun, path: str | Path, title: str) -> Path:
    """One run: reference, true and predicted angle; valve states; pressure (true, sensor)."""
    from matplotlib.figure import Figure

    fig = Figure(figsize=(8, 7))
    axes = fig.subplots(3, 1, sharex=True, height_ratios=(3, 1, 2))
    _panels(axes, run)
    axes[0].set_title(title, fontsize=9)
    fig.tight_layout()
    fig.savefig(path, dpi=_DPI)
    return Path(path)


def runs_figure(runs: dict[str, ControlRun], path: str | Path, title: str) -> Path:
    """Several runs side by side (one column each, titled by their keys)."""
    from matplotlib.figure import Figure

    n = len(runs)
    fig = Figure(figsize=(4.2 * n, 6.5))
    axes = fig.subplots(3, n, sharex="col", height_ratios=(3, 1, 2), squeeze=False)
    for j, (name, run) in enumerate(runs.items()):
        _panels(axes[:, j], run, legend=j == 0)
        axes[0, j].set_title(name, fontsize=9)
    fig.suptitle(title, fontsize=10)
    fig.tight_layout()
    fig.savefig(path, dpi=_DPI)
    return Path(path)
