"""Figures of an FEM sweep: the angle–pressure curve and the deformed shapes (paper B Fig. 2b)."""

from __future__ import annotations

from collections.abc import Sequence
from pathlib import Path

import numpy as np

from softbend.campaign.backends import SweepResult
from softbend.reports.analysis_figures import _figure, _save

__all__ = ["angle_pressure_curve", "deformed_shapes"]


def angle_pressure_curve(
    result: SweepResult,
    path: str | Path,
    *,
    analytical: SweepResult | None = None,
) -> Path:
    """Bending angle against pressure; the converged steps marked, the analytical model dashed."""
    fig, ax = _figure((6.0, 4.2))
    ok = result.converged
    ax.plot(result.pressure_mpa[ok], result.angle_deg[ok], color="C0", label="FEM (outputs)")
    steps = result.stats.get("steps_mpa")
    if steps:
        ax.plot(
            steps,
            result.stats["step_angles_deg"],
            "o",
            ms=3,
            color="C0",
            label="FEM converged steps",
        )
    if analytical is not None:
        good = analytical.converged
        ax.plot(
            analytical.pressure_mpa[good],
            analytical.angle_deg[good],
            "--",
            color="C3",
            label="analytical (Polygerinos et al.)",
        )
    ax.set_xlabel("pressure (MPa)")
    ax.set_ylabel("bending angle θ (°)")
    ax.set_title(f"Design (l, r, t, b, φ, lc) = ({result.design})", fontsize=10)
    ax.grid(alpha=0.3)
    ax.legend(fontsize=8)
    return _save(fig, path)


def deformed_shapes(
    outlines: Sequence[tuple[float, np.ndarray]], path: str | Path, *, title: str = ""
) -> Path:
    """Side silhouettes of the deformed actuator at several pressures (paper B Fig. 2b).

    Parameters
    ----------
    outlines : sequence of (pressure MPa, array (m, 2))
        Closed outlines in the bending plane, mm (x along the undeformed axis,
        z towards the bending side), from :func:`softbend.fem.export.silhouette_mm`.
    """
    from matplotlib import colormaps

    fig, ax = _figure((6.4, 5.0))
    cmap = colormaps["viridis"]
    n = max(len(outlines) - 1, 1)
    for i, (pressure, outline) in enumerate(outlines):
        label = f"{pressure:.3f} MPa"
        ax.plot(outline[:, 0], outline[:, 1], color=cmap(i / n), lw=1.2, label=label)
    ax.axvline(0.0, color="0.3", lw=3)  # the fixed base
    ax.set_aspect("equal")
    ax.set_xlabel("x (mm)")
    ax.set_ylabel("z, towards the bending side (mm)")
    ax.invert_yaxis()
    ax.set_title(title or "Deformed actuator, bending plane", fontsize=10)
    ax.grid(alpha=0.3)
    ax.legend(fontsize=8, loc="best")
    return _save(fig, path)
