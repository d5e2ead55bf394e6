"""The VTK output: shared nodes, quadratic cells, the whole actuator, stretch and energy."""

from __future__ import annotations

import xml.etree.ElementTree as ET

import numpy as np
import pytest
from scipy.spatial import cKDTree

from softbend.fem import FEMOptions
from softbend.fem.export import (
    VTK_QUADRATIC_TETRA,
    VTK_TETRA,
    VTKGrid,
    actuator_grid,
    vtk_file_name,
    vtu_text,
    write_vtk,
)
from softbend.fem.sfrba.sweep import run_sweep

from .conftest import REFERENCE

#: The coarsest mesh allowed, no gravity: one small sweep of a few seconds.
PRESSURE_MPA = 0.01


@pytest.fixture(scope="module")
def swept():
    options = FEMOptions(maxh_mm=20.0, gravity="none")
    _, model, history = run_sweep(REFERENCE, [0.0, PRESSURE_MPA], options, keep_states=True)
    start, end = history.steps[0], history.steps[-1]
    assert end.pressure_mpa == pytest.approx(PRESSURE_MPA)
    return model, start.state, end.state


def _at(model, state):
    model.set_state(state)
    return model


def _half_counts(model) -> tuple[int, int, int, int]:
    """Vertices and edges of the half mesh, and those of them on the plane y = 0."""
    ys = np.array([v.point[1] for v in model.mesh.vertices])
    on_plane = np.abs(ys) < 1e-9
    edges = np.array([[v.nr for v in e.vertices] for e in model.mesh.edges])
    edges_on_plane = int(np.sum(on_plane[edges[:, 0]] & on_plane[edges[:, 1]]))
    return int(model.mesh.nv), len(edges), int(on_plane.sum()), edges_on_plane


def test_one_point_per_vertex_and_edge_of_the_whole_mirrored_mesh(swept):
    model, _, loaded = swept
    grid = actuator_grid(_at(model, loaded), pressure_mpa=PRESSURE_MPA)
    nv, nedge, nv_plane, nedge_plane = _half_counts(model)
    assert len(grid.points) == 2 * (nv + nedge) - (nv_plane + nedge_plane)
    assert grid.cells.shape == (2 * model.mesh.ne, 10)
    assert grid.cell_type == VTK_QUADRATIC_TETRA
    assert len(np.unique(grid.points.round(9), axis=0)) == len(grid.points)
    assert grid.points[:, 1].min() == pytest.approx(-grid.points[:, 1].max())
    half = actuator_grid(model, mirror=False)
    assert len(half.points) == nv + nedge and half.field_data == {"model_half": 1.0}
    assert grid.field_data == {"model_half": 0.0, "pressure_mpa": PRESSURE_MPA}


def test_cells_are_positively_oriented_and_edge_nodes_hold_the_exact_displacement(swept):
    model, _, loaded = swept
    grid = actuator_grid(_at(model, loaded))
    p = grid.points[grid.cells[:, :4]]
    volume = np.einsum(
        "ni,ni->n", np.cross(p[:, 1] - p[:, 0], p[:, 2] - p[:, 0]), p[:, 3] - p[:, 0]
    )
    assert volume.min() > 0.0
    u = grid.point_data["displacement"]
    edge_nodes = np.unique(grid.cells[:, 4:])
    upper = edge_nodes[grid.points[edge_nodes, 1] >= 0.0][::25]
    for k in upper:
        exact = model.gfu(model.mesh(*grid.points[k]))
        np.testing.assert_allclose(u[k], exact, rtol=0, atol=1e-9)


def test_the_mirrored_displacement_is_symmetric(swept):
    model, _, loaded = swept
    grid = actuator_grid(_at(model, loaded))
    points, u = grid.points, grid.point_data["displacement"]
    distance, image = cKDTree(points).query(points * [1.0, -1.0, 1.0])
    assert distance.max() < 1e-9
    np.testing.assert_allclose(u[image] * [1.0, -1.0, 1.0], u, rtol=0, atol=1e-12)
    assert np.abs(u[:, 1]).max() > 1e-3  # the check is not vacuous
    on_plane = np.abs(points[:, 1]) < 1e-9
    np.testing.assert_allclose(u[on_plane, 1], 0.0, atol=1e-12)


def test_no_stretch_and_no_energy_at_zero_pressure(swept):
    model, rest, loaded = swept
    grid = actuator_grid(_at(model, np.zeros_like(rest)), pressure_mpa=0.0)
    np.testing.assert_allclose(grid.cell_data["max_principal_stretch"], 1.0, rtol=0, atol=1e-9)
    np.testing.assert_allclose(grid.cell_data["strain_energy_density"], 0.0, rtol=0, atol=1e-9)
    grid = actuator_grid(_at(model, loaded))
    stretch = grid.cell_data["max_principal_stretch"]
    assert stretch.max() == pytest.approx(model.max_stretch()[0], rel=1e-12)
    assert stretch.min() >= 1.0 - 1e-9
    assert grid.cell_data["strain_energy_density"].max() > 0.0


def test_the_file_parses_back_with_its_cells_fields_and_pressure(swept, tmp_path):
    model, _, loaded = swept
    path = write_vtk(
        _at(model, loaded), tmp_path / "vtk" / vtk_file_name(PRESSURE_MPA), pressure_mpa=0.01
    )
    assert path.name == "shape_p0.010MPa.vtu"
    grid = actuator_grid(model, pressure_mpa=PRESSURE_MPA)
    root = ET.parse(path).getroot()
    piece = root.find("UnstructuredGrid/Piece")
    assert piece is not None
    n, m = int(piece.get("NumberOfPoints", -1)), int(piece.get("NumberOfCells", -1))
    assert (n, m) == (len(grid.points), len(grid.cells))
    arrays = {a.get("Name"): a for a in root.iter("DataArray")}

    def values(name: str) -> np.ndarray:
        return np.array((arrays[name].text or "").split(), dtype=float)

    assert set(np.unique(values("types"))) == {VTK_QUADRATIC_TETRA}
    assert len(values("types")) == m
    np.testing.assert_array_equal(values("offsets"), 10 * np.arange(1, m + 1))
    connectivity = values("connectivity").astype(int)
    assert len(connectivity) == 10 * m and connectivity.max() == n - 1
    assert values("Points").reshape(-1, 3).shape == (n, 3)
    np.testing.assert_allclose(
        values("displacement").reshape(-1, 3), grid.point_data["displacement"], atol=1e-8
    )
    for name in ("max_principal_stretch", "strain_energy_density"):
        assert arrays[name].get("Name") == name and len(values(name)) == m
    field_data = root.find("UnstructuredGrid/FieldData")
    assert field_data is not None
    assert {a.get("Name"): float(a.text or "nan") for a in field_data} == {
        "model_half": 0.0,
        "pressure_mpa": PRESSURE_MPA,
    }


def test_a_linear_grid_is_written_with_vtk_tetra_cells():
    grid = VTKGrid(
        points=np.array([[0.0, 0, 0], [1, 0, 0], [0, 1, 0], [0, 0, 1]]),
        cells=np.array([[0, 1, 2, 3]]),
        cell_type=VTK_TETRA,
        point_data={"displacement": np.zeros((4, 3))},
    )
    root = ET.fromstring(vtu_text(grid))
    arrays = {a.get("Name"): a.text for a in root.iter("DataArray")}
    assert arrays["types"] == "10" and arrays["offsets"] == "4"
    assert root.find("UnstructuredGrid/FieldData") is None


@pytest.mark.parametrize(
    ("pressure", "name"),
    [
        (0.0, "shape_p0.000MPa.vtu"),
        (0.15, "shape_p0.150MPa.vtu"),
        (0.2, "shape_p0.200MPa.vtu"),
        (0.0025, "shape_p0.0025MPa.vtu"),
        (1.5, "shape_p1.500MPa.vtu"),
    ],
)
def test_file_names_are_in_mpa(pressure, name):
    assert vtk_file_name(pressure) == name


@pytest.mark.parametrize("pressure", [-0.1, float("nan"), float("inf")])
def test_a_bad_pressure_in_the_file_name_is_one_value_error(pressure):
    with pytest.raises(ValueError, match=r"^pressure_mpa: must be a number"):
        vtk_file_name(pressure)
