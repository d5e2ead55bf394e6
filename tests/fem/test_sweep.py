"""Physics of the actuator sweep (coarse mesh, low pressures so it stays fast)."""

import numpy as np
import pytest

from softbend.campaign.backends import FEMBackend, default_pressures_mpa, get_backend
from softbend.design import SFRBADesign
from softbend.fem import FEMOptions, simulate

from .conftest import COARSE, REFERENCE

GRID = default_pressures_mpa(0.03)


@pytest.fixture(scope="module")
def reference():
    return simulate(REFERENCE, GRID, COARSE)


def test_zero_pressure_is_the_gravity_only_shape(reference):
    assert reference.pressure_mpa[0] == 0.0
    sag = reference.angle_deg[0]
    assert 3.0 < sag < 15.0  # gravity alone bends the soft actuator a few degrees
    no_gravity = simulate(REFERENCE, [0.0], COARSE.replace(gravity="none"))
    assert no_gravity.angle_deg[0] == pytest.approx(0.0, abs=1e-6)
    against = simulate(REFERENCE, [0.0], COARSE.replace(gravity="against"))
    assert against.angle_deg[0] == pytest.approx(-sag, rel=0.05)


def test_angle_rises_monotonically_and_the_result_is_complete(reference):
    assert reference.converged.all()
    assert len(reference.pressure_mpa) == len(GRID)
    assert np.all(np.diff(reference.angle_deg) > 0)
    assert reference.stats["stop_reason"] == "reached the last pressure"
    assert reference.mesh_size > 0 and reference.stats["ndof"] > 0
    assert np.all(np.isfinite(reference.tip_x_mm)) and np.all(reference.tip_z_mm > 0)


def test_thicker_top_wall_bends_less(reference):
    thick = simulate(SFRBADesign(100, 6, 3, 2, 5, 10), GRID, COARSE)
    assert thick.angle_deg[-1] < reference.angle_deg[-1] - 2.0


def test_longer_chamber_bends_more(reference):
    longer = simulate(SFRBADesign(120, 6, 2, 2, 5, 10), GRID, COARSE)
    assert longer.angle_deg[-1] > reference.angle_deg[-1] + 2.0


def test_a_step_that_cannot_converge_ends_the_sweep_with_a_reason():
    options = COARSE.replace(
        max_iterations=3, initial_step_mpa=0.04, min_step_mpa=0.03, max_step_mpa=0.04
    )
    result = simulate(REFERENCE, [0.0, 0.04, 0.08], options)
    assert list(result.converged) == [True, False]
    assert np.isnan(result.angle_deg[-1])
    assert result.stats["stop_reason"].startswith("no convergence above 0 MPa")
    assert "residual=" in result.stats["failure"]


def test_bad_pressures_and_options_are_clear_errors():
    with pytest.raises(ValueError, match="'pressures_mpa' of simulate must be strictly increasing"):
        simulate(REFERENCE, [0.0, 0.02, 0.01], COARSE)
    with pytest.raises(ValueError, match="'pressures_mpa' of simulate must be finite"):
        simulate(REFERENCE, [0.0, float("nan")], COARSE)
    with pytest.raises(ValueError, match="'options' of simulate must be FEMOptions"):
        simulate(REFERENCE, [0.0], {"maxh_mm": 4})


def test_campaign_backend_builds_options_from_keywords():
    backend = get_backend("fem", maxh_mm=6.0, gravity="none")
    assert isinstance(backend, FEMBackend)
    assert backend.options == FEMOptions(maxh_mm=6.0, gravity="none")
    assert backend.preferred_chunk_size == 1
    with pytest.raises(ValueError, match="'gravity' of FEMOptions"):
        get_backend("fem", gravity="sideways")
