"""Files a user opens: the sweep as CSV, deformed states as VTK, side silhouettes."""

from __future__ import annotations

import os
from pathlib import Path

import numpy as np

from softbend._io import write_text_atomic
from softbend.fem._ngsolve import require_ngsolve
from softbend.fem.actuator import ActuatorModel
from softbend.models import SweepResult

require_ngsolve()  # NGSolve after PyTorch, or one line naming softbend[fem]

__all__ = ["silhouette_mm", "sweep_csv", "write_sweep_csv", "write_vtk"]


def sweep_csv(result: SweepResult) -> str:
    """The sweep as CSV text: pressure, angle, tip, converged flag, Newton iterations."""
    lines = ["pressure_mpa,angle_deg,tip_x_mm,tip_z_mm,converged,newton_iterations"]
    for row in zip(
        result.pressure_mpa,
        result.angle_deg,
        result.tip_x_mm,
        result.tip_z_mm,
        result.converged,
        result.newton_iterations,
        strict=True,
    ):
        p, a, x, z, ok, it = row
        lines.append(f"{p:.6g},{a:.6f},{x:.6f},{z:.6f},{int(ok)},{int(it)}")
    return "\n".join(lines) + "\n"


def write_sweep_csv(result: SweepResult, path: str | os.PathLike[str]) -> Path:
    """Write :func:`sweep_csv` atomically."""
    return write_text_atomic(path, sweep_csv(result))


def write_vtk(model: ActuatorModel, path: str | os.PathLike[str]) -> Path:
    """Write the current state of ``model`` as a VTK unstructured grid (``.vtu``).

    The file holds the undeformed half mesh with the displacement (mm) as a point
    field ``displacement``: in ParaView apply *Warp By Vector* to see the
    deformed actuator (and *Reflect* about ``y = 0`` for the whole one).
    """
    from ngsolve import VTKOutput

    path = Path(path)
    path.parent.mkdir(parents=True, exist_ok=True)
    stem = str(path)[: -len(".vtu")] if str(path).endswith(".vtu") else str(path)
    VTKOutput(
        model.mesh, coefs=[model.gfu], names=["displacement"], filename=stem, subdivision=0
    ).Do()
    return Path(stem + ".vtu")


def silhouette_mm(model: ActuatorModel, n: int = 80) -> np.ndarray:
    """Closed outline of the deformed actuator in the bending plane, shape (m, 2).

    The bottom line (strain-limiting layer) and the top line of the symmetry
    plane, from base to tip and back, in the measurement frame (x along the
    undeformed axis, z towards the bending side).
    """
    geo = model.geometry
    top = geo.design.b_mm + geo.outer_radius_mm
    xs = np.linspace(0.0, geo.length_mm, n)
    outline = []
    for height, order in ((0.0, xs), (top, xs[::-1])):
        for x in order:
            u = model.gfu(model.mesh(float(x), 0.0, float(height)))
            outline.append((x + u[0], -(height + u[2])))
    outline.append(outline[0])
    return np.array(outline)
