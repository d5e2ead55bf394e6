import math

import pytest

from softbend.design import sfrba_design
from softbend.fem import FEMOptions
from softbend.fem.geometry import actuator_geometry, mesh_actuator


@pytest.mark.parametrize(
    ("field", "value", "needle"),
    [
        ("maxh_mm", -1.0, "maxh_mm: must be a number in (0, 20]"),
        ("maxh_mm", float("nan"), "maxh_mm: "),
        ("order", 1, "order: must be one of 2, 3"),
        ("fiber_law", "rope", "fiber_law: must be one of 'tension-compression'"),
        ("gravity", "down", "gravity: must be one of 'bending', 'against'"),
        ("output", "all", "output: must be one of 'interpolate', 'solve'"),
        ("max_angle_deg", 400.0, "max_angle_deg: must be a number in (0, 340]"),
        ("max_stretch", 0.9, "max_stretch: must be a number in (1, 50]"),
        (
            "predictor_error_mm",
            0.0,
            "predictor_error_mm: must be a number in (0, 10]",
        ),
        ("base_cap_mm", 0.0, "base_cap_mm: "),
        ("elastomer", "silicone", "elastomer: must be a Material"),
    ],
)
def test_bad_options_name_the_field(field, value, needle):
    with pytest.raises(ValueError) as info:
        FEMOptions(**{field: value})
    assert needle in str(info.value)


def test_step_bounds_are_ordered():
    with pytest.raises(ValueError, match="initial_step_mpa: "):
        FEMOptions(initial_step_mpa=0.1, max_step_mpa=0.05)
    with pytest.raises(ValueError, match="unknown"):
        FEMOptions().replace(mesh=3)


def test_impossible_geometry_is_refused_by_the_design():
    with pytest.raises(ValueError, match=r"t_mm.*\(0, 50\]"):
        sfrba_design(100, 6, -2, 2, 5, 10)


def test_a_mesh_too_fine_to_afford_is_refused_before_meshing():
    with pytest.raises(ValueError, match=r"^maxh_mm: must give at most"):
        mesh_actuator(sfrba_design(160, 10, 4, 4, 5, 12), maxh_mm=0.05)


def test_faces_are_named_and_the_mesh_has_the_solid_volume():
    import ngsolve as ngs

    design = sfrba_design(100, 6, 2, 2, 5, 10)
    shape, info = actuator_geometry(design, 3.0)
    assert {f.name for f in shape.faces} == {
        "base",
        "tip",
        "symmetry",
        "bottom",
        "outer",
        "cavity",
    }
    mesh, info = mesh_actuator(design, maxh_mm=6.0)
    volume = ngs.Integrate(ngs.CoefficientFunction(1.0), mesh)
    assert volume == pytest.approx(info.half_volume_mm3, rel=2e-3)
    assert info.length_mm == 113.0
    assert info.perimeter_mm == pytest.approx(math.pi * 8 + 16 + 4)


def test_options_digest_follows_every_setting():
    base = FEMOptions()
    assert base.digest() == FEMOptions().digest()
    assert len(base.digest()) == 64
    assert base.replace(maxh_mm=4.0).digest() != base.digest()
    assert base.replace(rtol=1e-8).digest() != base.digest()


@pytest.mark.parametrize(
    "values", [(100, 6, 2, 2, 5, 8), (160, 10, 4, 4, 15, 12), (37.5, 3.25, 1, 1, 0, 1)]
)
def test_one_cavity_volume_serves_the_fem_and_the_rig(values):
    from softbend.control.rig import RigParams
    from softbend.fem.geometry import ActuatorGeometry

    design = sfrba_design(*values)
    l_mm, r_mm = values[0], values[1]
    # Closed form: a half-disc of radius r extruded over l.
    assert design.cavity_volume_mm3 == pytest.approx(math.pi * r_mm**2 / 2.0 * l_mm, rel=1e-15)
    if values[:2] == (100, 6):
        assert design.cavity_volume_mm3 == pytest.approx(1800.0 * math.pi, rel=1e-15)
    # The FEM meshes exactly half of it; the rig's air volume is all of it plus the tubing.
    assert ActuatorGeometry(design, 3.0).half_cavity_volume_mm3 == design.cavity_volume_mm3 / 2
    rig = RigParams.for_design(design, tubing_mm3=2000.0)
    assert rig.volume_mm3 == design.cavity_volume_mm3 + 2000.0


def test_the_meshed_cavity_has_the_closed_form_volume():
    from softbend.fem.actuator import ActuatorModel

    design = sfrba_design(100, 6, 2, 2, 5, 10)
    model = ActuatorModel(design, FEMOptions(maxh_mm=6.0))
    assert model.cavity_volume_mm3() == pytest.approx(design.cavity_volume_mm3, rel=2e-3)
