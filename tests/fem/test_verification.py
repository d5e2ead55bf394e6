"""Closed-form cases and mesh convergence, solved with the actuator's solver core."""

import math

import pytest

from softbend.fem.verification import (
    cantilever_sag,
    elastica_tip_deflection,
    mesh_study,
    tube_closed_form_pressure,
    tube_inflation,
)

from .conftest import COARSE, REFERENCE


def test_closed_form_tube_pressure_is_zero_at_rest_and_increasing():
    assert tube_closed_form_pressure(0.2, 5.0, 10.0, 5.0) == pytest.approx(0.0, abs=1e-15)
    pressures = [tube_closed_form_pressure(0.2, 5.0, 10.0, a) for a in (5.5, 6.0, 7.0)]
    assert pressures == sorted(pressures)


def test_elastica_reference_tends_to_the_linear_cantilever():
    # Small load: w L^4 / (8 EI) = alpha L / 8.
    _, z = elastica_tip_deflection(0.01, 100.0)
    assert z == pytest.approx(0.01 * 100.0 / 8.0, rel=1e-3)
    x, z = elastica_tip_deflection(4.0, 100.0)
    assert z < 4.0 * 100.0 / 8.0  # large deflection is stiffer than the linear estimate
    assert x < 100.0


def test_thick_walled_tube_matches_the_closed_form_within_2_percent():
    case = tube_inflation()
    assert case.reference > 1.0  # a large inflation, not the linear range
    assert case.relative_error < 0.02


@pytest.mark.slow
def test_cantilever_under_its_own_weight_matches_the_elastica_within_2_percent():
    case = cantilever_sag()
    assert case.reference > 30.0  # tip deflection over 30 % of the length
    assert case.relative_error < 0.02


@pytest.mark.slow
def test_mesh_refinement_changes_the_angle_by_less_than_3_percent():
    rows = mesh_study(REFERENCE, [6.0, 4.0, 3.0], [0.0, 0.05, 0.1], COARSE)
    middle, finest = rows[1].angles_deg, rows[2].angles_deg
    for a, b in zip(middle, finest, strict=True):
        assert abs(a - b) / abs(b) < 0.03
    assert rows[2].elements > rows[0].elements
    assert all(math.isfinite(a) for a in finest)
