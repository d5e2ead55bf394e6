"""Figures of an FEM sweep: the angle–pressure curve and the deformed shapes (paper B Fig. 2b)."""

from __future__ import annotations

from collections.abc import Callable, Sequence
from dataclasses import dataclass, field
from pathlib import Path
from typing import TYPE_CHECKING, Any

import numpy as np

from softbend.actuators import Design
from softbend.fem.stats import fem_stats
from softbend.models import SweepResult
from softbend.reports.analysis_figures import _figure, _save

if TYPE_CHECKING:
    from numpy.typing import ArrayLike

    from softbend.fem.families import FEMFamily
    from softbend.fem.options import FEMOptions

__all__ = [
    "FEMSweepFiles",
    "angle_pressure_curve",
    "deformed_shapes",
    "family_sweep_with_files",
    "sweep_with_files",
]


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


@dataclass(frozen=True)
class FEMSweepFiles:
    """One FEM sweep of :func:`sweep_with_files`, what it was compared with and its files.

    Attributes
    ----------
    result, analytical : SweepResult
        The FEM sweep and the analytical model's on the same grid.
    shape_pressures_mpa : list of float
        Pressures of the converged steps whose shapes were drawn (and exported).
    steps : int
        Load steps of the sweep (the gravity step not counted).
    files : dict
        ``{"csv", "curve", "shapes"}`` paths, and ``"vtk"`` paths when exported.
    """

    result: SweepResult
    analytical: SweepResult
    shape_pressures_mpa: list[float]
    steps: int
    files: dict[str, Any] = field(default_factory=dict)


def sweep_with_files(
    design: Design,
    pressures_mpa: ArrayLike,
    options: FEMOptions | None,
    out_dir: str | Path,
    *,
    shape_pressures_mpa: Sequence[float] | int,
    prefix: str = "",
    vtk: bool = False,
    progress: Callable[[float, float, float], None] | None = None,
) -> FEMSweepFiles:
    """Sweep one design with the FEM and write what a person looks at.

    Writes ``<prefix>sweep.csv`` (pressure, angle, tip, converged, Newton
    iterations), ``<prefix>angle_pressure.png`` (with the analytical model) and
    ``<prefix>shapes.png`` (the deformed actuator at the converged steps nearest
    to ``shape_pressures_mpa``, paper B Fig. 2b), and with ``vtk`` the same
    shapes as ``vtk/shape_p<MPa>MPa.vtu`` for ParaView.

    Parameters
    ----------
    design : Design
    pressures_mpa : array_like
        Output pressures, MPa, increasing.
    options : FEMOptions or None
    out_dir : path
        Folder of the files (created).
    shape_pressures_mpa : sequence of float or int
        Where to draw the shape, MPa; an integer ``n`` draws ``n`` shapes evenly
        spaced from 0 to the last converged step.
    prefix : str
        Start of every file name.
    vtk : bool
        Also export the shapes as VTK.
    progress : callable, optional
        ``progress(pressure_mpa, angle_deg, target_mpa)`` after each load step.
    """
    from softbend.pipeline.paper_b_fem import sweep_with_shapes

    out = Path(out_dir)
    sweep = sweep_with_shapes(
        design,
        pressures_mpa,
        options,
        out,
        shape_pressures_mpa=shape_pressures_mpa,
        prefix=prefix,
        vtk=vtk,
        progress=progress,
    )
    files = {
        "csv": sweep.files["csv"],
        "curve": angle_pressure_curve(
            sweep.result, out / f"{prefix}angle_pressure.png", analytical=sweep.analytical
        ),
        "shapes": deformed_shapes(
            sweep.outlines, out / f"{prefix}shapes.png", title=f"Design ({design}), FEM"
        ),
    }
    if vtk:
        files["vtk"] = sweep.files["vtk"]
    return FEMSweepFiles(
        sweep.result, sweep.analytical, sweep.shape_pressures_mpa, sweep.steps, files
    )


def family_sweep_with_files(
    family: FEMFamily,
    design: Any,
    pressures_mpa: ArrayLike,
    options: FEMOptions,
    out_dir: str | Path,
    *,
    shape_pressures_mpa: int,
    vtk: bool = True,
    progress: Callable[[float, float, float], None] | None = None,
) -> FEMSweepFiles:
    """Sweep one design of an FEM family other than paper B's and write its files.

    Writes ``sweep.csv`` (pressure, angle, tip, converged, Newton iterations),
    ``angle_pressure.png`` and with ``vtk`` the whole actuator (the half model
    mirrored) at ``shape_pressures_mpa`` converged steps evenly spaced from 0 to
    the last reported pressure as ``vtk/shape_p<MPa>MPa.vtu``. There is no analytical model to
    compare with: ``analytical`` is the FEM sweep itself.

    Parameters
    ----------
    family : FEMFamily
        The family (:func:`softbend.fem.families.get_family`).
    design
        A checked design of the family.
    pressures_mpa : array_like
        Output pressures, MPa, increasing.
    options : FEMOptions
    out_dir : path
        Folder of the files (created).
    shape_pressures_mpa : int
        How many shapes to export.
    vtk : bool
        Export the shapes as VTK.
    progress : callable, optional
        ``progress(pressure_mpa, angle_deg, target_mpa)`` after each load step.
    """
    from softbend.fem.export import vtk_file_name, write_sweep_csv, write_vtk

    out = Path(out_dir)
    out.mkdir(parents=True, exist_ok=True)
    result, model, history = family.sweep(
        design, pressures_mpa, options, progress=progress, keep_states=True
    )
    files: dict[str, Any] = {"csv": write_sweep_csv(result, out / "sweep.csv")}
    files["curve"] = angle_pressure_curve(
        result, out / "angle_pressure.png", title=f"{family.title}\n({design})"
    )
    last = float(result.pressure_mpa[result.converged][-1]) if result.converged.any() else 0.0
    # The converged steps inside the reported range (not a step past touching walls).
    inside = [step for step in history.steps if step.pressure_mpa <= last + 1e-12]
    at = np.array([step.pressure_mpa for step in inside])
    picked = {int(np.abs(at - q).argmin()) for q in np.linspace(0.0, last, shape_pressures_mpa)}
    chosen_steps = [inside[i] for i in sorted(picked)]
    if vtk:
        vtk_files = []
        for chosen in chosen_steps:
            model.set_state(chosen.state)
            p = float(chosen.pressure_mpa)
            vtk_files.append(write_vtk(model, out / "vtk" / vtk_file_name(p), pressure_mpa=p))
        files["vtk"] = vtk_files
    return FEMSweepFiles(
        result,
        result,
        [float(s.pressure_mpa) for s in chosen_steps],
        len(history.steps) - 1,
        files,
    )
