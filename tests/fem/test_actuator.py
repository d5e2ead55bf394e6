"""The actuator model's measurements against closed forms, without solving."""

from __future__ import annotations

import math

import numpy as np
import pytest

from softbend.fem.actuator import ActuatorModel

from .conftest import COARSE, REFERENCE

ngsolve = pytest.importorskip("ngsolve")


@pytest.fixture(scope="module")
def model():
    return ActuatorModel(REFERENCE, COARSE)


def test_at_rest_the_actuator_is_straight_and_the_cavity_is_a_half_cylinder(model):
    model.set_state(np.zeros_like(model.state()))
    rest = model.measure()
    assert rest.angle_deg == 0.0 and rest.tip_z_mm == 0.0
    base_cap = COARSE.base_cap_mm
    assert rest.tip_x_mm == pytest.approx(base_cap + REFERENCE.l_mm + REFERENCE.lc_mm)
    half_cylinder = 0.5 * math.pi * REFERENCE.r_mm**2 * REFERENCE.l_mm
    assert model.cavity_volume_mm3() == pytest.approx(half_cylinder, rel=5e-3)


@pytest.mark.parametrize("angle_deg", [30.0, 90.0, 200.0])
def test_an_imposed_arc_is_measured_as_its_angle(model, angle_deg):
    # Every section moved as if the axis were bent to constant curvature κ.
    kappa = math.radians(angle_deg) / REFERENCE.l_mm
    x = ngsolve.x - COARSE.base_cap_mm  # arc length from the start of the chamber
    model.gfu.Set(
        ngsolve.CF(
            (
                ngsolve.sin(kappa * x) / kappa - x,
                0,
                -(1 - ngsolve.cos(kappa * x)) / kappa,
            )
        )
    )
    assert model.measure().angle_deg == pytest.approx(angle_deg, abs=0.05)
    backbone = model.backbone_mm()
    s = np.linspace(0.0, REFERENCE.l_mm, len(backbone))  # backbone points, evenly spaced
    expected_x = COARSE.base_cap_mm + np.sin(kappa * s) / kappa
    expected_z = (1 - np.cos(kappa * s)) / kappa
    np.testing.assert_allclose(backbone[:, 0], expected_x, atol=0.05)
    np.testing.assert_allclose(backbone[:, 1], expected_z, atol=0.05)
    model.set_state(np.zeros_like(model.state()))


def test_the_state_round_trips_and_the_force_scale_grows_with_pressure(model):
    rng = np.random.default_rng(1)
    values = 1e-3 * rng.standard_normal(model.state().shape)
    model.set_state(values)
    np.testing.assert_array_equal(model.state(), values)
    model.set_state(np.zeros_like(values))
    # Pressure resultant on the half cavity plus the weight: linear in the pressure.
    weight = model.force_scale_n(0.0)
    assert weight > 0.0
    assert model.force_scale_n(0.2) - weight == pytest.approx(
        2 * (model.force_scale_n(0.1) - weight)
    )
    cap, length = COARSE.base_cap_mm, REFERENCE.l_mm
    assert model.region_of(cap / 2) == "proximal cap"
    assert model.region_of(cap + length / 2) == "chamber wall"
    assert model.region_of(cap + length + 1.0) == "distal cap"
