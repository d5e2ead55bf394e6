"""Figures of the PneuNet section: the reference's θ(p) and V(p), the main effects."""

from __future__ import annotations

from pathlib import Path
from typing import TYPE_CHECKING

import numpy as np

from softbend.reports.analysis_figures import _save

if TYPE_CHECKING:
    from numpy.typing import ArrayLike

    from softbend.analysis.effects import MainEffects

__all__ = ["main_effects_figure", "reference_curves"]


def _figure(rows: int, cols: int, size: tuple[float, float], *, share_rows: bool = False):
    """A figure of ``rows`` × ``cols`` axes (the y axis shared along each row if asked),
    drawn by the Agg canvas outside pyplot."""
    from matplotlib.backends.backend_agg import FigureCanvasAgg
    from matplotlib.figure import Figure

    fig = Figure(figsize=size, layout="constrained")
    FigureCanvasAgg(fig)
    return fig, fig.subplots(rows, cols, squeeze=False, sharey="row" if share_rows else False)


def reference_curves(
    pressure_mpa: ArrayLike,
    angle_deg: ArrayLike,
    volume_mm3: ArrayLike,
    path: str | Path,
    *,
    stop: str,
    title: str,
    contact_force_n: ArrayLike | None = None,
) -> Path:
    """Bending angle, cavity volume (and contact force) of one sweep against pressure.

    Parameters
    ----------
    pressure_mpa, angle_deg, volume_mm3 : array_like
        The converged steps: pressure (MPa), bending angle (degrees) and the
        cavity's volume (both halves, mm³).
    path : path
        The PNG written.
    stop : str
        Why the sweep stopped (the figure's footnote).
    title : str
        The figure's title (the design).
    contact_force_n : array_like, optional
        The force between the walls of the whole actuator at the same steps, N: a
        third panel, and the pressure where the walls first press on each other
        marked on every panel. None or empty: a sweep without contact, two panels.
    """
    p_kpa = np.asarray(pressure_mpa, dtype=np.float64) * 1e3
    contact = None if contact_force_n is None else np.asarray(contact_force_n, dtype=np.float64)
    if contact is not None and contact.size == 0:
        contact = None
    fig, axes = _figure(1, 2 if contact is None else 3, (10.0 if contact is None else 13.5, 3.8))
    row = list(axes[0])
    row[0].plot(p_kpa, np.asarray(angle_deg), "o-", ms=3, color="C0")
    row[0].set(xlabel="pressure (kPa)", ylabel="bending angle (°)", title="θ(p)")
    row[1].plot(p_kpa, np.asarray(volume_mm3) / 1e3, "o-", ms=3, color="C1")
    row[1].set(xlabel="pressure (kPa)", ylabel="cavity volume (mL)", title="V(p)")
    if contact is not None:
        row[2].plot(p_kpa, contact, "o-", ms=3, color="C2")
        row[2].set(
            xlabel="pressure (kPa)",
            ylabel="contact force (N)",
            title="walls pressing on each other",
        )
        pressing = np.flatnonzero(contact > 0.0)
        if pressing.size:  # the first step with the walls pressing on each other
            touch = p_kpa[pressing[0]]
            for ax in row:
                ax.axvline(touch, color="0.5", ls="--", lw=0.8)
            row[0].annotate(
                f" walls press from {touch:.1f} kPa",
                (touch, 0.05),
                xycoords=("data", "axes fraction"),
                fontsize=8,
                color="0.3",
            )
    for ax in row:
        ax.grid(alpha=0.3)
        ax.set_xlim(left=0.0)
    fig.suptitle(title, fontsize=9)
    fig.text(0.5, -0.04, f"stop: {stop}", ha="center", fontsize=8)
    return _save(fig, path)


def main_effects_figure(effects: MainEffects, path: str | Path, *, title: str = "") -> Path:
    """Main-effects plot: one row per response, one panel per parameter, shared y per row.

    Each panel marks the response's mean over each group of the parameter's
    values (at the group's mean value), the dashed line the response's mean over
    all designs.
    """
    table = effects.table
    parameters = list(effects.effects.index)
    responses = list(effects.effects.columns)
    fig, axes = _figure(
        len(responses),
        len(parameters),
        (1.9 * len(parameters), 2.0 * len(responses)),
        share_rows=True,
    )
    for i, response in enumerate(responses):
        rows = table[table["response"] == response]
        overall = np.average(
            rows[rows["parameter"] == parameters[0]]["mean"].fillna(0.0),
            weights=rows[rows["parameter"] == parameters[0]]["n"],
        )
        for j, parameter in enumerate(parameters):
            ax = axes[i][j]
            own = rows[rows["parameter"] == parameter]
            ax.plot(own["centre"], own["mean"], "o-", ms=3, color=f"C{i}")
            ax.axhline(overall, ls="--", lw=0.8, color="0.5")
            ax.grid(alpha=0.3)
            ax.tick_params(labelsize=7)
            if i == len(responses) - 1:
                ax.set_xlabel(parameter, fontsize=8)
            if j == 0:
                ax.set_ylabel(response, fontsize=8)
    if title:
        fig.suptitle(title, fontsize=9)
    return _save(fig, path)
