"""Solid geometry and mesh of the half PneuNet (netgen.occ).

The half ``y ≥ 0`` of the PneuNet (the plane ``y = 0`` through its middle is a
plane of symmetry of geometry and loads). Along ``x`` from the fixed face at
``x = 0``: an inlet block of length ``end`` (the FEM option ``base_cap_mm``) and
full height, then ``n`` chambers of outer length ``Lc`` separated by gaps ``g``.
A base slab of thickness ``b`` runs under everything (``0 ≤ z ≤ b``, strain-
limiting layer at ``z = 0``); each chamber is a box ``b ≤ z ≤ b + H``,
``0 ≤ y ≤ W/2`` with a cavity ``Lc − 2w`` long, ``W/2 − wo`` wide (half) and
``H − wo`` high standing on the base. The first chamber's front wall is fused
with the inlet block.

Each chamber is its own closed cavity at the common pressure: the inlet
channel that links the chambers of a real PneuNet is left out (a few mm² of
section, it carries pressure, not load). Faces are named for the physics:
``base`` (``x = 0``, fixed), ``symmetry`` (``y = 0``), ``bottom`` (``z = 0``,
strain-limiting layer), ``cavity`` (pressure), ``facing_back`` and
``facing_front`` (the outer faces of the walls that face each other across a
gap: the back face of every chamber but the last and the front face of every
chamber but the first, which may touch: :data:`FACING_FACES`) and ``outer``
(the rest).
"""

from __future__ import annotations

from dataclasses import dataclass
from typing import Any

import numpy as np

from softbend.actuators import Design
from softbend.fem._ngsolve import require_ngsolve
from softbend.fem.geometry import check_element_count, curved_mesh, name_faces, tetrahedra_in_volume
from softbend.fem.pneunet.description import cavity_volume_mm3, length_mm

__all__ = [
    "FACING_FACES",
    "PneuNetGeometry",
    "check_pneunet_mesh",
    "element_size_mm",
    "estimated_pneunet_elements",
    "mesh_pneunet",
    "pneunet_solid",
]


#: Names of the faces that face each other across the gaps: (back faces, front faces).
FACING_FACES: tuple[str, str] = ("facing_back", "facing_front")


@dataclass(frozen=True)
class PneuNetGeometry:
    """Dimensions of the meshed half PneuNet, mm.

    Attributes
    ----------
    design : Design
        The PneuNet design.
    end_mm : float
        Length of the inlet block at the fixed end.
    """

    design: Design
    end_mm: float

    @property
    def n(self) -> int:
        """Number of chambers."""
        return int(self.design.n_chambers)

    @property
    def length_mm(self) -> float:
        """From the fixed face to the tip."""
        return length_mm(self.design, self.end_mm)

    @property
    def half_width_mm(self) -> float:
        return self.design.chamber_width_mm / 2.0

    @property
    def height_mm(self) -> float:
        """Base plus chamber height."""
        return self.design.base_mm + self.design.chamber_height_mm

    def chamber_x_mm(self, i: int) -> tuple[float, float]:
        """Outer axial extent ``(x0, x1)`` of chamber ``i`` (0 at the fixed end)."""
        d = self.design
        x0 = self.end_mm + i * (d.chamber_length_mm + d.gap_mm)
        return x0, x0 + d.chamber_length_mm

    @property
    def chambers_mm(self) -> tuple[float, float]:
        """Axial extent of the chambered part ``(end, length)``: the backbone."""
        return self.end_mm, self.length_mm

    @property
    def half_cavity_volume_mm3(self) -> float:
        """Undeformed volume of the half model's cavities, mm³."""
        return cavity_volume_mm3(self.design) / 2.0

    @property
    def half_volume_mm3(self) -> float:
        """Volume of the half body (elastomer), mm³."""
        d = self.design
        block = self.end_mm * self.half_width_mm * self.height_mm
        base = (self.length_mm - self.end_mm) * self.half_width_mm * d.base_mm
        boxes = self.n * d.chamber_length_mm * self.half_width_mm * d.chamber_height_mm
        return block + base + boxes - self.half_cavity_volume_mm3

    def facing_walls(self, ny: int = 6, nz: int = 10) -> list[tuple[np.ndarray, np.ndarray]]:
        """Sample points on the outer faces of the walls that face each other across a gap.

        For each gap ``k`` (between chambers ``k`` and ``k+1``), the points
        ``(x, y, z)`` on the back face of chamber ``k`` and, at the same ``y``
        and ``z``, on the front face of chamber ``k+1``: a grid over the whole
        faces, from the base to the roof (where bending brings them closest)
        and from the symmetry plane to the side, each shape ``(ny·nz, 3)``.
        """
        d = self.design
        y = np.linspace(0.0, self.half_width_mm, ny)
        z = np.linspace(d.base_mm, self.height_mm, nz)
        yy, zz = (a.ravel() for a in np.meshgrid(y, z, indexing="ij"))
        pairs = []
        for k in range(self.n - 1):
            back = self.chamber_x_mm(k)[1]
            front = self.chamber_x_mm(k + 1)[0]
            pairs.append(
                (
                    np.column_stack([np.full_like(yy, back), yy, zz]),
                    np.column_stack([np.full_like(yy, front), yy, zz]),
                )
            )
        return pairs


def pneunet_solid(design: Design, end_mm: float) -> tuple[Any, PneuNetGeometry]:
    """Build the half PneuNet as an OCC solid with named faces.

    Returns
    -------
    (netgen.occ.TopoDS_Shape, PneuNetGeometry)
    """
    require_ngsolve()
    from netgen.occ import Box, Glue, Pnt

    info = PneuNetGeometry(design, end_mm)
    d = design
    hw, top, b = info.half_width_mm, info.height_mm, d.base_mm
    body = Box(Pnt(0, 0, 0), Pnt(info.length_mm, hw, b)) + Box(Pnt(0, 0, 0), Pnt(end_mm, hw, top))
    cavities = []
    for i in range(info.n):
        x0, x1 = info.chamber_x_mm(i)
        body = body + Box(Pnt(x0, 0, b), Pnt(x1, hw, top))
        cavities.append(
            Box(
                Pnt(x0 + d.wall_mm, 0, b),
                Pnt(x1 - d.wall_mm, hw - d.outer_wall_mm, top - d.outer_wall_mm),
            )
        )
    cavity = Glue(cavities) if len(cavities) > 1 else cavities[0]
    cavity.faces.name = "cavity"
    solid = body - cavity
    name_faces(
        solid, info.length_mm, tip=False, what=f"the PneuNet geometry of design {design.as_text()}"
    )
    _name_facing(solid, info)
    return solid, info


def _name_facing(solid: Any, info: PneuNetGeometry) -> None:
    """Rename the ``outer`` faces across the gaps :data:`FACING_FACES` (by their centres)."""
    tol = 1e-7 * info.length_mm
    backs = [info.chamber_x_mm(k)[1] for k in range(info.n - 1)]
    fronts = [info.chamber_x_mm(k)[0] for k in range(1, info.n)]
    for face in solid.faces:
        if face.name != "outer" or face.center.z < info.design.base_mm + tol:
            continue
        x = face.center.x
        if any(abs(x - b) < tol for b in backs):
            face.name = FACING_FACES[0]
        elif any(abs(x - f) < tol for f in fronts):
            face.name = FACING_FACES[1]


#: The element size is at most this many times the thinnest chamber wall.
WALL_ELEMENT_RATIO = 2.5


def element_size_mm(design: Design, maxh_mm: float) -> float:
    """The largest element size the PneuNet is meshed with, mm: ``maxh_mm``, capped by its walls.

    At most :data:`WALL_ELEMENT_RATIO` times the thinnest chamber wall
    (``wall_mm``, ``outer_wall_mm``): with 3 mm elements on 0.8 mm walls (25 mm
    tall, 20 mm wide chambers) Newton stalled at the first pressure step
    however short, with 2 mm it converged. The reference's 1.2 mm walls cap it
    at 3 mm, its default.
    """
    return min(maxh_mm, WALL_ELEMENT_RATIO * min(design.wall_mm, design.outer_wall_mm))


def estimated_pneunet_elements(design: Design, maxh_mm: float, end_mm: float) -> float:
    """About how many tetrahedra the half PneuNet's mesh has (known before meshing).

    As :func:`softbend.fem.geometry.estimated_elements`: six times the half
    body's volume over that of a regular tetrahedron of edge ``maxh_mm``: an
    upper bound where ``maxh_mm`` is below the walls' thickness, the case it
    guards (the reference at 3 mm: estimate 6 800, mesh 1 345).
    """
    volume = PneuNetGeometry(design, end_mm).half_volume_mm3
    return tetrahedra_in_volume(volume, element_size_mm(design, maxh_mm))


def check_pneunet_mesh(design: Design, maxh_mm: float, end_mm: float) -> None:
    """Refuse a ``maxh_mm`` that would mesh ``design`` with too many elements.

    Raises
    ------
    InputError
        Keyed ``maxh_mm``: the estimate of :func:`estimated_pneunet_elements`
        exceeds :data:`softbend.fem.geometry.MAX_ELEMENTS`.
    """
    check_element_count(estimated_pneunet_elements(design, maxh_mm, end_mm), design, maxh_mm)


def mesh_pneunet(
    design: Design, *, maxh_mm: float, order: int = 2, end_mm: float = 3.0
) -> tuple[Any, PneuNetGeometry]:
    """Curved tetrahedral mesh of the half PneuNet, elements at most :func:`element_size_mm`.

    Raises
    ------
    InputError
        For a ``maxh_mm`` that gives too many elements (checked before meshing).
    SoftbendError
        If netgen fails to mesh the geometry.
    """
    require_ngsolve()
    check_pneunet_mesh(design, maxh_mm, end_mm)
    shape, info = pneunet_solid(design, end_mm)
    h = element_size_mm(design, maxh_mm)
    what = f"the PneuNet {design.as_text()} with maxh_mm={maxh_mm:g}"
    return curved_mesh(shape, h, order, what), info
