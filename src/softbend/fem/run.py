"""One FEM sweep of any family written to a folder: what ``softbend fem run`` computes.

:func:`sweep_with_files` sweeps one design of a family
(:class:`~softbend.fem.families.FEMFamily`), keeping every converged state,
writes ``sweep.csv`` and, with ``vtk``, the deformed actuator at a few
converged steps as ``vtk/shape_p<MPa>MPa.vtu``; it keeps the family's
analytical sweep on the same grid and the side outlines of those states when
the family has them. :func:`sweep_summary` is the record ``fem run`` writes to
``sweep.json``. The figures are drawn from the returned :class:`FamilySweep`
(:mod:`softbend.reports.fem_figures`). Importing this module never imports
NGSolve (the sweep does when it runs).
"""

from __future__ import annotations

from collections.abc import Callable, Sequence
from dataclasses import dataclass, field
from pathlib import Path
from typing import TYPE_CHECKING, Any

import numpy as np

if TYPE_CHECKING:
    from numpy.typing import ArrayLike

    from softbend.actuators import Design
    from softbend.fem.families import FEMFamily
    from softbend.fem.options import FEMOptions
    from softbend.models import SweepResult

__all__ = ["FamilySweep", "shape_steps", "sweep_summary", "sweep_with_files"]


@dataclass(frozen=True)
class FamilySweep:
    """One FEM sweep of :func:`sweep_with_files`, what it is compared with and its files.

    Attributes
    ----------
    family : FEMFamily
        The swept design's family.
    design
        The swept design.
    result : SweepResult
        The FEM sweep.
    analytical : SweepResult or None
        The family's analytical model on the same grid (None: the family has none).
    shape_pressures_mpa : list of float
        Pressures of the converged steps whose shapes were kept, MPa.
    outlines : list of (float, ndarray)
        ``(pressure MPa, closed outline (m, 2) in mm)`` in the bending plane at
        those steps (empty: the family draws no outline).
    steps : int
        Load steps of the sweep (the gravity step not counted).
    files : dict
        ``{"csv": path}``, and ``"vtk"`` (list of paths) when exported.
    """

    family: FEMFamily
    design: Design
    result: SweepResult
    analytical: SweepResult | None
    shape_pressures_mpa: list[float]
    outlines: list[tuple[float, np.ndarray]]
    steps: int
    files: dict[str, Any] = field(default_factory=dict)


def shape_steps(
    steps: Sequence[Any], result: SweepResult, shape_pressures_mpa: Sequence[float] | int
) -> list[Any]:
    """The converged steps nearest to ``shape_pressures_mpa``, each once, in order.

    Only steps inside the reported range count (not a step past touching walls or
    past the angle limit). An integer ``n`` asks for ``n`` pressures evenly spaced
    from 0 to the last converged output pressure, MPa.
    """
    ok = result.converged
    last = float(result.pressure_mpa[ok][-1]) if ok.any() else 0.0
    inside = [step for step in steps if step.pressure_mpa <= last + 1e-12] or list(steps[:1])
    wanted = (
        np.linspace(0.0, last, shape_pressures_mpa)
        if isinstance(shape_pressures_mpa, int)
        else np.atleast_1d(np.asarray(shape_pressures_mpa, dtype=float))
    )
    at = np.array([step.pressure_mpa for step in inside])
    picked = {int(np.abs(at - q).argmin()) for q in wanted}
    return [inside[i] for i in sorted(picked)]


def sweep_with_files(
    family: FEMFamily,
    design: Design,
    pressures_mpa: ArrayLike,
    options: FEMOptions,
    out_dir: str | Path,
    *,
    shape_pressures_mpa: Sequence[float] | int,
    prefix: str = "",
    vtk: bool = False,
    progress: Callable[[float, float, float], None] | None = None,
) -> FamilySweep:
    """Sweep one design of ``family`` and write ``<prefix>sweep.csv`` (and the VTK shapes).

    Parameters
    ----------
    family : FEMFamily
        The design's family (:func:`softbend.fem.families.get_family`).
    design
        A checked design of the family.
    pressures_mpa : array_like
        Output pressures, MPa, increasing.
    options : FEMOptions
        Modelling assumptions and solver settings.
    out_dir : path
        Folder of the files (created).
    shape_pressures_mpa : sequence of float or int
        Where to keep the shape, MPa (see :func:`shape_steps`).
    prefix : str
        Start of every file name.
    vtk : bool
        Also export the shapes as ``vtk/shape_p<MPa>MPa.vtu``.
    progress : callable, optional
        ``progress(pressure_mpa, angle_deg, target_mpa)`` after each load step.
    """
    from softbend.fem.export import vtk_file_name, write_sweep_csv, write_vtk

    out = Path(out_dir)
    out.mkdir(parents=True, exist_ok=True)
    result, model, history = family.sweep(
        design, pressures_mpa, options, progress=progress, keep_states=True
    )
    files: dict[str, Any] = {"csv": write_sweep_csv(result, out / f"{prefix}sweep.csv")}
    analytical = None if family.analytical is None else family.analytical(design, pressures_mpa)
    chosen = shape_steps(history.steps, result, shape_pressures_mpa)
    outlines, vtk_files = [], []
    for step in chosen:
        model.set_state(step.state)
        p = float(step.pressure_mpa)
        if family.outline is not None:
            outlines.append((p, family.outline(model)))
        if vtk:
            vtk_files.append(write_vtk(model, out / "vtk" / vtk_file_name(p), pressure_mpa=p))
    if vtk:
        files["vtk"] = vtk_files
    pressures = [float(step.pressure_mpa) for step in chosen]
    steps = len(history.steps) - 1
    return FamilySweep(family, design, result, analytical, pressures, outlines, steps, files)


def sweep_summary(sweep: FamilySweep) -> dict[str, Any]:
    """What ``fem run`` writes to ``sweep.json``: family, design, stop, extremes, statistics."""
    result = sweep.result
    return {
        "family": sweep.family.name,
        "design": sweep.design.as_text(),
        "stop_reason": result.stats["stop_reason"],
        "max_pressure_mpa": result.max_pressure_mpa,
        "max_angle_deg": result.max_angle_deg,
        "wall_time_s": result.wall_time_s,
        "elements": result.mesh_size,
        "stats": result.stats,
    }
