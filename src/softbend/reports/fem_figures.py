"""Figures of an FEM sweep: the angle–pressure curve and the deformed shapes (paper B Fig. 2b)."""

from __future__ import annotations

from collections.abc import Sequence
from pathlib import Path
from typing import TYPE_CHECKING

import numpy as np

from softbend.fem.stats import fem_stats
from softbend.models import SweepResult
from softbend.reports.analysis_figures import _figure, _save

if TYPE_CHECKING:
    from softbend.fem.run import FamilySweep

__all__ = ["angle_pressure_curve", "deformed_shapes", "sweep_figures"]


def angle_pressure_curve(
    result: SweepResult,
    path: str | Path,
    *,
    analytical: SweepResult | None = None,
    title: str | None = None,
) -> Path:
    """Bending angle against pressure; the converged steps marked, the analytical model dashed.

    ``title``: the figure's title (default: paper B's design tuple).
    """
    fig, ax = _figure((6.0, 4.2))
    ok = result.converged
    ax.plot(result.pressure_mpa[ok], result.angle_deg[ok], color="C0", label="FEM (outputs)")
    stats = fem_stats(result)
    steps = stats.get("steps_mpa")
    if steps:
        ax.plot(
            steps,
            stats["step_angles_deg"],
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
    ax.set_title(title or f"Design (l, r, t, b, φ, lc) = ({result.design})", fontsize=10)
    ax.grid(alpha=0.3)
    if ax.get_legend_handles_labels()[0]:  # no legend without a label
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
    if ax.get_legend_handles_labels()[0]:  # no legend without a label
        ax.legend(fontsize=8, loc="best")
    return _save(fig, path)


def sweep_figures(sweep: FamilySweep, out_dir: str | Path, *, prefix: str = "") -> dict[str, Path]:
    """Draw one FEM sweep of :func:`softbend.fem.run.sweep_with_files` into ``out_dir``.

    ``<prefix>angle_pressure.png`` (with the family's analytical model when it
    has one) and, when the family draws outlines, ``<prefix>shapes.png`` (the
    deformed actuator at the kept steps, paper B Fig. 2b).

    Returns
    -------
    dict
        ``{"curve"}`` and, with outlines, ``{"shapes"}`` paths.
    """
    out = Path(out_dir)
    design = sweep.design
    files = {
        "curve": angle_pressure_curve(
            sweep.result,
            out / f"{prefix}angle_pressure.png",
            analytical=sweep.analytical,
            title=f"{sweep.family.title}\n({design})",
        )
    }
    if sweep.outlines:
        files["shapes"] = deformed_shapes(
            sweep.outlines, out / f"{prefix}shapes.png", title=f"Design ({design}), FEM"
        )
    return files
