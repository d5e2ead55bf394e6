"""Files a user opens: the sweep as CSV, deformed states as VTK, side silhouettes."""

from __future__ import annotations

import math
import os
from dataclasses import dataclass, field
from pathlib import Path
from typing import TYPE_CHECKING

import numpy as np

from softbend._io import write_text_atomic
from softbend._validation import must_be
from softbend.errors import InputError
from softbend.fem._ngsolve import require_ngsolve
from softbend.fem.actuator import ActuatorModel
from softbend.models import SweepResult

if TYPE_CHECKING:
    from softbend.fem.pneunet.model import PneuNetModel

require_ngsolve()  # NGSolve after PyTorch, or one line naming softbend[fem]

__all__ = [
    "VTK_QUADRATIC_TETRA",
    "VTK_TETRA",
    "VTKGrid",
    "actuator_grid",
    "silhouette_mm",
    "sweep_csv",
    "vtk_file_name",
    "vtu_text",
    "write_sweep_csv",
    "write_vtk",
]

#: VTK cell types: linear and quadratic (10-node) tetrahedron.
VTK_TETRA: int = 10
VTK_QUADRATIC_TETRA: int = 24

#: NGSolve's reference tetrahedron (corners 0–3), then the midpoints of its
#: edges in VTK's order for the quadratic tetrahedron.
_EDGES = np.array([(0, 1), (1, 2), (0, 2), (0, 3), (1, 3), (2, 3)])
_CORNERS = np.array([(1.0, 0.0, 0.0), (0.0, 1.0, 0.0), (0.0, 0.0, 1.0), (0.0, 0.0, 0.0)])
_REFERENCE_TET = np.vstack([_CORNERS, 0.5 * (_CORNERS[_EDGES[:, 0]] + _CORNERS[_EDGES[:, 1]])])
#: Node order of a tetrahedron with corners 1 and 2 swapped (its orientation turned).
_SWAP = np.array([0, 2, 1, 3, 6, 5, 4, 7, 9, 8])


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


def vtk_file_name(pressure_mpa: float) -> str:
    """File name of the deformed state at ``pressure_mpa`` (MPa), e.g. ``shape_p0.150MPa.vtu``.

    Three decimals, more (up to six) where three would not tell the pressure.

    Raises
    ------
    ValueError
        If ``pressure_mpa`` is not a finite number ≥ 0.
    """
    p = float(pressure_mpa)
    if not math.isfinite(p) or p < 0.0:
        raise InputError(must_be("a number in [0, inf)", pressure_mpa), key="pressure_mpa")
    digits = next((d for d in range(3, 7) if abs(round(p, d) - p) <= 1e-12), 6)
    return f"shape_p{p:.{digits}f}MPa.vtu"


@dataclass(frozen=True)
class VTKGrid:
    """An unstructured grid of tetrahedra with its fields, as written to a ``.vtu`` file.

    Attributes
    ----------
    points : ndarray, shape (n, 3)
        Undeformed node positions, mm: one per mesh vertex and, for quadratic
        cells, one per edge (at the edge's midpoint on the curved element).
    cells : ndarray, shape (m, 4) or (m, 10)
        Node indices of each cell in VTK order (vertices, then the edges
        01, 12, 02, 03, 13, 23), positively oriented.
    cell_type : int
        :data:`VTK_TETRA` (10) or :data:`VTK_QUADRATIC_TETRA` (24).
    point_data : dict of str to ndarray
        Fields at the nodes, shape (n,) or (n, 3).
    cell_data : dict of str to ndarray
        Fields per cell, shape (m,) or (m, 3).
    field_data : dict of str to float
        Values of the whole grid.
    """

    points: np.ndarray
    cells: np.ndarray
    cell_type: int
    point_data: dict[str, np.ndarray] = field(default_factory=dict)
    cell_data: dict[str, np.ndarray] = field(default_factory=dict)
    field_data: dict[str, float] = field(default_factory=dict)


def actuator_grid(
    model: ActuatorModel | PneuNetModel, *, pressure_mpa: float | None = None, mirror: bool = True
) -> VTKGrid:
    """The current state of ``model`` as a grid of shared nodes, the whole actuator by default.

    The model (paper B's actuator or a PneuNet) is the half ``y ≥ 0``; with
    ``mirror`` its reflection about the symmetry plane ``y = 0`` (``y → −y``,
    ``u_y → −u_y``) completes it, the nodes on the plane kept once. Cells are
    quadratic tetrahedra (VTK type 24) where the displacement is of order 2 or
    more (the edge nodes take the exact value of the displacement at the edge
    midpoints; for order 3 that is a sample of the cubic field), linear ones
    (type 10) for order 1.

    Fields:

    * ``displacement`` (point data, mm);
    * ``max_principal_stretch`` (cell data, –) and ``strain_energy_density``
      (cell data, MPa = MJ/m³: the elastomer's energy per undeformed volume,
      the ``W(Ī1) + K/2 (J − 1)²`` of :func:`softbend.fem.mechanics.solid_energy`),
      both at the cell's centroid, from the deformation gradient of the solution;
    * field data ``pressure_mpa`` (where given, MPa) and ``model_half``
      (1 for the half model, 0 for the whole actuator).

    Parameters
    ----------
    model : ActuatorModel or PneuNetModel
        Its displacement ``gfu`` is the state written.
    pressure_mpa : float, optional
        Cavity pressure of the state, MPa (the state a sweep restores does not
        carry it).
    mirror : bool
        Reflect the half model into the whole actuator.
    """
    import ngsolve as ngs

    from softbend.fem.mechanics import solid_energy

    mesh = model.mesh
    quadratic = int(model.fes.globalorder) >= 2
    reference = _REFERENCE_TET[: 10 if quadratic else 4]
    rule = ngs.IntegrationRule(points=[tuple(p) for p in reference], weights=[0.0] * len(reference))
    at_nodes = mesh.MapToAllElements(rule, ngs.VOL)
    xyz = np.asarray(ngs.CoefficientFunction((ngs.x, ngs.y, ngs.z))(at_nodes))
    u = np.asarray(model.gfu(at_nodes))
    ne, k = int(mesh.ne), len(reference)
    xyz, u = xyz.reshape(ne, k, 3), u.reshape(ne, k, 3)
    corners = np.array([[v.nr for v in el.vertices] for el in mesh.Elements(ngs.VOL)], dtype=int)
    nv = int(mesh.nv)
    cells = np.empty((ne, k), dtype=int)
    cells[:, :4] = corners
    points = np.empty((nv, 3))
    disp = np.empty((nv, 3))
    points[corners.ravel()] = xyz[:, :4].reshape(-1, 3)
    disp[corners.ravel()] = u[:, :4].reshape(-1, 3)
    if quadratic:
        a, b = corners[:, _EDGES[:, 0]], corners[:, _EDGES[:, 1]]
        keys = np.minimum(a, b) * nv + np.maximum(a, b)
        _, first, inverse = np.unique(keys.ravel(), return_index=True, return_inverse=True)
        cells[:, 4:] = nv + inverse.reshape(ne, 6)
        points = np.vstack([points, xyz[:, 4:].reshape(-1, 3)[first]])
        disp = np.vstack([disp, u[:, 4:].reshape(-1, 3)[first]])

    centroid = ngs.IntegrationRule(points=[(0.25, 0.25, 0.25)], weights=[1.0 / 6.0])
    at_centroids = mesh.MapToAllElements(centroid, ngs.VOL)
    F = ngs.Id(3) + ngs.Grad(model.gfu)
    o = model.options
    bulk = o.bulk_ratio * o.elastomer_model.initial_shear_modulus_mpa
    energy = np.asarray(solid_energy(F, o.elastomer_model, bulk)(at_centroids)).reshape(ne)
    Fc = np.asarray(F(at_centroids)).reshape(ne, 3, 3)
    stretch = np.sqrt(np.linalg.eigvalsh(np.einsum("nki,nkj->nij", Fc, Fc))[:, -1])

    cells = _oriented(points, cells)
    if mirror:
        points, disp, cells = _mirrored(points, disp, cells, model.geometry.length_mm)
        energy, stretch = np.tile(energy, 2), np.tile(stretch, 2)
    field_data = {"model_half": 0.0 if mirror else 1.0}
    if pressure_mpa is not None:
        field_data["pressure_mpa"] = float(pressure_mpa)
    return VTKGrid(
        points=points,
        cells=cells,
        cell_type=VTK_QUADRATIC_TETRA if quadratic else VTK_TETRA,
        point_data={"displacement": disp},
        cell_data={"max_principal_stretch": stretch, "strain_energy_density": energy},
        field_data=field_data,
    )


def _oriented(points: np.ndarray, cells: np.ndarray) -> np.ndarray:
    """``cells`` with the corners of negatively oriented tetrahedra (and their edges) swapped."""
    p = points[cells[:, :4]]
    volume = np.einsum(
        "ni,ni->n", np.cross(p[:, 1] - p[:, 0], p[:, 2] - p[:, 0]), p[:, 3] - p[:, 0]
    )
    out = cells.copy()
    flip = volume < 0.0
    out[flip] = cells[flip][:, _SWAP[: cells.shape[1]]]
    return out


def _mirrored(
    points: np.ndarray, disp: np.ndarray, cells: np.ndarray, size_mm: float
) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
    """The half grid and its reflection about ``y = 0``, nodes on the plane shared."""
    off = np.abs(points[:, 1]) > 1e-9 * max(size_mm, 1.0)
    index = np.arange(len(points))
    index[off] = len(points) + np.arange(int(off.sum()))
    flip = np.array([1.0, -1.0, 1.0])
    reflected = index[cells][:, _SWAP[: cells.shape[1]]]  # a reflection turns the orientation
    return (
        np.vstack([points, points[off] * flip]),
        np.vstack([disp, disp[off] * flip]),
        np.vstack([cells, reflected]),
    )


def vtu_text(grid: VTKGrid) -> str:
    """``grid`` as the text of a VTK XML unstructured grid (``.vtu``, ASCII)."""

    def data_array(name: str | None, values: np.ndarray, kind: str = "Float64") -> str:
        values = np.asarray(values)
        components = values.shape[1] if values.ndim == 2 else 1
        fmt = "%d" if kind.startswith("Int") or kind.startswith("UInt") else "%.10g"
        body = " ".join(fmt % v for v in values.ravel())
        attrs = f' type="{kind}"'
        attrs += f' Name="{name}"' if name else ""
        attrs += f' NumberOfComponents="{components}"' if components > 1 else ""
        if name and kind == "Float64" and values.ndim == 1 and values.size == 1:
            attrs += ' NumberOfTuples="1"'
        return f'<DataArray{attrs} format="ascii">{body}</DataArray>'

    n, m = len(grid.points), len(grid.cells)
    k = grid.cells.shape[1]
    lines = [
        '<?xml version="1.0"?>',
        '<VTKFile type="UnstructuredGrid" version="1.0" byte_order="LittleEndian" '
        'header_type="UInt64">',
        "<UnstructuredGrid>",
    ]
    if grid.field_data:
        lines.append("<FieldData>")
        lines += [data_array(key, np.array([v])) for key, v in grid.field_data.items()]
        lines.append("</FieldData>")
    lines += [
        f'<Piece NumberOfPoints="{n}" NumberOfCells="{m}">',
        "<Points>",
        data_array("Points", grid.points),
        "</Points>",
        "<Cells>",
        data_array("connectivity", grid.cells.ravel(), "Int64"),
        data_array("offsets", k * np.arange(1, m + 1), "Int64"),
        data_array("types", np.full(m, grid.cell_type), "UInt8"),
        "</Cells>",
        "<PointData>",
        *(data_array(key, v) for key, v in grid.point_data.items()),
        "</PointData>",
        "<CellData>",
        *(data_array(key, v) for key, v in grid.cell_data.items()),
        "</CellData>",
        "</Piece>",
        "</UnstructuredGrid>",
        "</VTKFile>",
    ]
    return "\n".join(lines) + "\n"


def write_vtk(
    model: ActuatorModel | PneuNetModel,
    path: str | os.PathLike[str],
    *,
    pressure_mpa: float | None = None,
    mirror: bool = True,
) -> Path:
    """Write the current state of ``model`` as a VTK unstructured grid (``.vtu``).

    The whole actuator (the half model reflected about ``y = 0``) with shared
    nodes, the displacement (mm) and the stretch and energy density of
    :func:`actuator_grid`: in ParaView apply *Warp By Vector* to see the
    deformed actuator. ``.vtu`` is appended to ``path`` when missing; name the
    file with :func:`vtk_file_name`.

    Parameters
    ----------
    model : ActuatorModel or PneuNetModel
    path : path
        File to write (its folder is created).
    pressure_mpa : float, optional
        Cavity pressure of the state, MPa, written as field data.
    mirror : bool
        Write the whole actuator (else the half ``y ≥ 0``, marked ``model_half = 1``).
    """
    path = Path(path)
    if path.suffix != ".vtu":
        path = Path(str(path) + ".vtu")
    path.parent.mkdir(parents=True, exist_ok=True)
    grid = actuator_grid(model, pressure_mpa=pressure_mpa, mirror=mirror)
    return write_text_atomic(path, vtu_text(grid))


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
