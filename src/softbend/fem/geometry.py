"""Solid geometry and mesh of the fiber-reinforced actuator (netgen.occ).

The half actuator ``y ≥ 0`` (paper B §2.1, Fig. 1a): a body whose section is
a rectangle ``2(r+t) × b`` under a half-disc of radius ``r + t``, from ``x = 0``
to ``x = cap + l + lc``, minus the cavity: a half-disc of radius ``r`` standing
on the bottom wall (centre at height ``b``) from ``x = cap`` to ``x = cap + l``.
Faces are named for the physics: ``base`` (fixed), ``symmetry`` (``y = 0``),
``bottom`` (strain-limiting layer), ``outer`` (curved top and side, fibers),
``tip`` and ``cavity`` (pressure).
"""

from __future__ import annotations

import math
from collections.abc import Iterable
from dataclasses import dataclass
from typing import Any

from softbend.actuators import Design
from softbend.errors import InputError, SoftbendError
from softbend.fem._ngsolve import require_ngsolve

__all__ = [
    "ActuatorGeometry",
    "actuator_geometry",
    "check_element_count",
    "check_mesh_size",
    "curved_mesh",
    "estimated_elements",
    "mesh_actuator",
    "name_faces",
    "tetrahedra_in_volume",
]

#: Largest number of tetrahedra a mesh may have (guards against a tiny maxh).
MAX_ELEMENTS = 400_000


@dataclass(frozen=True)
class ActuatorGeometry:
    """Dimensions of the meshed half actuator, mm.

    Attributes
    ----------
    design : Design
    base_cap_mm : float
        Proximal end wall.
    length_mm : float
        Whole body, ``cap + l + lc``.
    outer_radius_mm : float
        ``r + t``.
    perimeter_mm : float
        Outer perimeter of the full section, ``π(r+t) + 2(r+t) + 2b``.
    """

    design: Design
    base_cap_mm: float

    @property
    def length_mm(self) -> float:
        d = self.design
        return self.base_cap_mm + d.l_mm + d.lc_mm

    @property
    def outer_radius_mm(self) -> float:
        return self.design.r_mm + self.design.t_mm

    @property
    def perimeter_mm(self) -> float:
        ro = self.outer_radius_mm
        return math.pi * ro + 2.0 * ro + 2.0 * self.design.b_mm

    @property
    def chamber_mm(self) -> tuple[float, float]:
        """Axial extent ``(x0, x1)`` of the cavity."""
        return self.base_cap_mm, self.base_cap_mm + self.design.l_mm

    @property
    def half_volume_mm3(self) -> float:
        """Volume of the half body (elastomer), mm³."""
        d = self.design
        ro = self.outer_radius_mm
        section = ro * d.b_mm + math.pi * ro**2 / 4.0
        return section * self.length_mm - self.half_cavity_volume_mm3

    @property
    def half_cavity_volume_mm3(self) -> float:
        """Undeformed volume of the half cavity, mm³: ``π·r²·l/4``.

        Exactly half of :attr:`~softbend.actuators.Design.cavity_volume_mm3` (the
        mesh is the half model ``y ≥ 0``).
        """
        return self.design.cavity_volume_mm3 / 2.0


def actuator_geometry(design: Design, base_cap_mm: float) -> tuple[Any, ActuatorGeometry]:
    """Build the half actuator as an OCC solid with named faces.

    Returns
    -------
    (netgen.occ.TopoDS_Shape, ActuatorGeometry)
    """
    require_ngsolve()
    from netgen.occ import Box, Cylinder, Pnt, X

    info = ActuatorGeometry(design, base_cap_mm)
    r, b = design.r_mm, design.b_mm
    ro, length = info.outer_radius_mm, info.length_mm
    x0, x1 = info.chamber_mm
    upper = Cylinder(Pnt(0, 0, b), X, ro, length) * Box(Pnt(0, 0, b), Pnt(length, ro, b + ro))
    body = upper + Box(Pnt(0, 0, 0), Pnt(length, ro, b))
    cavity = Cylinder(Pnt(x0, 0, b), X, r, x1 - x0) * Box(Pnt(x0, 0, b), Pnt(x1, r, b + r))
    cavity.faces.name = "cavity"
    solid = body - cavity
    name_faces(solid, length, tip=True, what=f"the actuator geometry of design {design}")
    return solid, info


def name_faces(solid: Any, length_mm: float, *, tip: bool, what: str) -> None:
    """Name the faces of a half model (its ``cavity`` faces named) for the physics.

    By where a face's centre lies: ``x = 0`` is ``base``, with ``tip`` the face
    ``x = length_mm`` is ``tip``, ``y = 0`` is ``symmetry``, ``z = 0`` is
    ``bottom``; every other face is ``outer``.

    Parameters
    ----------
    solid : netgen.occ.TopoDS_Shape
        The half model, ``0 ≤ x ≤ length_mm``, ``y ≥ 0``, ``z ≥ 0``; renamed in place.
    length_mm : float
        Its length along ``x``, mm.
    tip : bool
        Whether the face ``x = length_mm`` is named ``tip`` (else ``outer``).
    what : str
        The geometry, for the error message.

    Raises
    ------
    SoftbendError
        If the names found are not the expected ones (a netgen behaviour change).
    """
    tol = 1e-7 * length_mm
    for face in solid.faces:
        if face.name == "cavity":
            continue
        c = face.center
        if abs(c.x) < tol:
            face.name = "base"
        elif tip and abs(c.x - length_mm) < tol:
            face.name = "tip"
        elif abs(c.y) < tol:
            face.name = "symmetry"
        elif abs(c.z) < tol:
            face.name = "bottom"
        else:
            face.name = "outer"
    names = {f.name for f in solid.faces}
    expected = {"base", "symmetry", "bottom", "outer", "cavity"} | ({"tip"} if tip else set())
    if names != expected:  # pragma: no cover - a netgen behaviour change
        raise SoftbendError(
            f"{what} has faces {sorted(map(str, names))}, expected {sorted(expected)}"
        )


def mesh_actuator(
    design: Design, *, maxh_mm: float, order: int = 2, base_cap_mm: float = 3.0
) -> tuple[Any, ActuatorGeometry]:
    """Quadratic (curved) tetrahedral mesh of the half actuator.

    Parameters
    ----------
    design : Design
    maxh_mm : float
        Largest element size, mm.
    order : int
        Geometric order of the curved elements (the displacement order).
    base_cap_mm : float
        Proximal end wall, mm.

    Returns
    -------
    (ngsolve.Mesh, ActuatorGeometry)

    Raises
    ------
    ValueError
        If the mesh would exceed :data:`MAX_ELEMENTS` tetrahedra for this
        ``maxh_mm`` (estimated before meshing).
    SoftbendError
        If netgen fails to mesh the geometry.
    """
    require_ngsolve()
    check_mesh_size(design, maxh_mm, base_cap_mm)
    shape, info = actuator_geometry(design, base_cap_mm)
    return curved_mesh(shape, maxh_mm, order, f"design {design} with maxh_mm={maxh_mm:g}"), info


def curved_mesh(shape: Any, h_mm: float, order: int, what: str) -> Any:
    """Tetrahedral mesh of ``shape``, elements at most ``h_mm``, curved to ``order``.

    Parameters
    ----------
    shape : netgen.occ.TopoDS_Shape
        The solid, faces named.
    h_mm : float
        Largest element size, mm.
    order : int
        Geometric order of the curved elements.
    what : str
        What is meshed, for the error message.

    Returns
    -------
    ngsolve.Mesh

    Raises
    ------
    SoftbendError
        If netgen fails to mesh the geometry.
    """
    ngsolve = require_ngsolve()
    from netgen.occ import OCCGeometry

    try:
        mesh = ngsolve.Mesh(OCCGeometry(shape).GenerateMesh(maxh=h_mm))
    except Exception as exc:  # netgen raises its own exception types
        raise SoftbendError(f"netgen could not mesh {what}: {exc}") from exc
    mesh.Curve(order)
    return mesh


def estimated_elements(design: Design, maxh_mm: float, base_cap_mm: float = 3.0) -> float:
    """About how many tetrahedra the FEM's mesh of ``design`` has with ``maxh_mm``.

    Six times the half actuator's volume over that of a regular tetrahedron of
    edge ``maxh_mm``: the estimate of :func:`check_mesh_size`, known before
    meshing and without NGSolve.

    Parameters
    ----------
    design : Design
        The actuator.
    maxh_mm : float
        Largest element size, mm (> 0).
    base_cap_mm : float, default 3.0
        Proximal end wall, mm (:attr:`~softbend.fem.options.FEMOptions.base_cap_mm`).

    Returns
    -------
    float
        The estimated number of elements.
    """
    return tetrahedra_in_volume(ActuatorGeometry(design, base_cap_mm).half_volume_mm3, maxh_mm)


def tetrahedra_in_volume(volume_mm3: float, h_mm: float) -> float:
    """Six times ``volume_mm3`` over the volume of a regular tetrahedron of edge ``h_mm``.

    The element count the FEM's meshes are estimated by before meshing.

    Parameters
    ----------
    volume_mm3 : float
        The meshed volume, mm³.
    h_mm : float
        Element size, mm (> 0).

    Returns
    -------
    float
        The estimated number of elements.
    """
    return 6.0 * volume_mm3 / (h_mm**3 / (6.0 * math.sqrt(2.0)))


def check_mesh_size(
    designs: Design | Iterable[Design], maxh_mm: float, base_cap_mm: float = 3.0
) -> None:
    """Refuse a ``maxh_mm`` that would mesh a design with too many elements.

    The FEM's rule on the mesh size: at most
    :data:`MAX_ELEMENTS` tetrahedra, as estimated by
    :func:`estimated_elements` (:func:`mesh_actuator`
    applies it to the design it meshes). A command checks it on every design
    it will sweep, before any work.

    Parameters
    ----------
    designs : Design or iterable of Design
        The actuators to mesh.
    maxh_mm : float
        Largest element size, mm (> 0).
    base_cap_mm : float, default 3.0
        Proximal end wall, mm.

    Raises
    ------
    InputError
        Keyed ``maxh_mm``: a design's estimated mesh exceeds :data:`MAX_ELEMENTS`;
        the message names the design with the most elements, as the FEM would.
    """
    items = [designs] if isinstance(designs, Design) else list(designs)
    if not items:
        return
    estimates = [estimated_elements(d, maxh_mm, base_cap_mm) for d in items]
    largest = max(range(len(items)), key=estimates.__getitem__)
    check_element_count(estimates[largest], items[largest], maxh_mm)


def check_element_count(estimate: float, design: object, maxh_mm: float) -> None:
    """Refuse a mesh of about ``estimate`` elements above :data:`MAX_ELEMENTS`.

    Parameters
    ----------
    estimate : float
        The estimated number of elements of the mesh of ``design``.
    design : object
        The design, named in the message.
    maxh_mm : float
        The element size asked for, mm.

    Raises
    ------
    InputError
        Keyed ``maxh_mm``, naming the design, the size and the estimate.
    """
    if estimate > MAX_ELEMENTS:
        raise InputError(
            f"must give at most {MAX_ELEMENTS} elements for design {design}; got "
            f"{maxh_mm:g} mm (about {estimate:.0f} elements)",
            key="maxh_mm",
        )
