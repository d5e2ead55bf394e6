"""Physics of the actuator sweep (coarse mesh, low pressures so it stays fast)."""

import math

import numpy as np
import pytest

from softbend.campaign.backends import default_pressures_mpa, get_backend
from softbend.design import parse_sfrba, sfrba_design
from softbend.fem import FEMModel, FEMOptions, simulate

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
    thick = simulate(sfrba_design(100, 6, 3, 2, 5, 10), GRID, COARSE)
    assert thick.angle_deg[-1] < reference.angle_deg[-1] - 2.0


def test_longer_chamber_bends_more(reference):
    longer = simulate(sfrba_design(120, 6, 2, 2, 5, 10), GRID, COARSE)
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
    with pytest.raises(ValueError, match=r"^pressures_mpa: must be strictly increasing"):
        simulate(REFERENCE, [0.0, 0.02, 0.01], COARSE)
    with pytest.raises(ValueError, match=r"^pressures_mpa: must be finite"):
        simulate(REFERENCE, [0.0, float("nan")], COARSE)
    with pytest.raises(ValueError, match=r"^options: must be FEMOptions"):
        simulate(REFERENCE, [0.0], {"maxh_mm": 4})


def test_campaign_backend_builds_options_from_keywords():
    backend = get_backend("fem", maxh_mm=6.0, gravity="none")
    assert isinstance(backend, FEMModel)
    assert backend.options == FEMOptions(maxh_mm=6.0, gravity="none")
    assert backend.preferred_chunk_size == 1
    with pytest.raises(ValueError, match=r"^gravity: must be one of"):
        get_backend("fem", gravity="sideways")


def test_predictor_extrapolates_a_cubic_path_exactly():
    from softbend.fem.sweep import _predict

    def path(p):  # a cubic load path of two "dofs" and its derivative
        u = np.array([1.0 + 2.0 * p - 3.0 * p**2 + 5.0 * p**3, -p + 4.0 * p**3])
        du = np.array([2.0 - 6.0 * p + 15.0 * p**2, -1.0 + 12.0 * p**2])
        return u, du

    u0, t0 = path(0.1)
    u1, t1 = path(0.13)
    for target in (0.14, 0.16, 0.175):
        guess = _predict(u1, t1, 0.13, target, (0.1, u0, t0))
        np.testing.assert_allclose(guess, path(target)[0], rtol=1e-12)
    # Without an earlier state the predictor is the tangent line.
    np.testing.assert_allclose(_predict(u1, t1, 0.13, 0.15, None), u1 + 0.02 * t1)


def test_step_is_sized_for_the_target_predictor_error():
    from softbend.fem.sweep import _next_step

    options = FEMOptions(predictor_error_mm=0.3, min_step_mpa=1e-4, max_step_mpa=0.02)
    # On target: keep the step; 16x the target: half the step (error ~ step⁴).
    assert _next_step(0.01, 0.3, options) == pytest.approx(0.01)
    assert _next_step(0.01, 4.8, options) == pytest.approx(0.005)
    assert _next_step(0.01, 0.3 / 1.2**4, options) == pytest.approx(0.012)
    # Never more than 1.5x up or 2x down, and within the step bounds.
    assert _next_step(0.01, 0.0, options) == pytest.approx(0.015)
    assert _next_step(0.01, 1e3, options) == pytest.approx(0.005)
    assert _next_step(0.018, 1e-6, options) == pytest.approx(0.02)
    assert _next_step(1.5e-4, 1e3, options) == pytest.approx(1e-4)


def test_gravity_followed_in_fractions_matches_one_plain_newton_solve():
    from softbend.fem.actuator import ActuatorModel
    from softbend.fem.sweep import _apply_gravity

    followed = ActuatorModel(REFERENCE, COARSE)
    _apply_gravity(followed)
    direct = ActuatorModel(REFERENCE, COARSE)
    direct.set_load(0.0, 1.0)
    direct.solver.max_iterations = 40
    direct.solver.stall_iteration = direct.solver.progress_iteration = 10**6
    direct.solver.first_contraction = math.inf  # a plain Newton solve: no give-up rules
    direct.solver.solve(direct.force_scale_n(0.0))
    assert followed.gravity_factor.Get() == 1.0
    np.testing.assert_allclose(
        followed.measure().as_array(), direct.measure().as_array(), rtol=1e-6, atol=1e-6
    )


def test_interpolated_outputs_match_solving_every_output_pressure(reference):
    solved = simulate(REFERENCE, GRID, COARSE.replace(output="solve"))
    assert len(solved.stats["steps_mpa"]) >= len(GRID)  # every output is a step
    assert len(reference.stats["steps_mpa"]) < len(GRID)  # interpolation skips some
    np.testing.assert_allclose(reference.angle_deg, solved.angle_deg, atol=0.02)
    np.testing.assert_allclose(reference.tip_z_mm, solved.tip_z_mm, atol=0.01)


def test_stretch_beyond_the_material_model_stops_the_sweep(reference):
    stretches = reference.stats["step_max_stretch"]
    assert np.all(np.diff(stretches) >= -1e-9)
    limit = 0.5 * (1.0 + stretches[-1])  # reached part-way through the sweep
    stopped = simulate(REFERENCE, GRID, COARSE.replace(max_stretch=limit))
    reason = stopped.stats["stop_reason"]
    assert reason.startswith("stretch") and "beyond the material model" in reason
    assert stopped.stats["step_max_stretch"][-1] > limit
    assert stopped.stats["step_max_stretch"][-2] <= limit
    # Outputs end at the last step inside the limit, and all of them converged.
    assert stopped.pressure_mpa[-1] <= stopped.stats["steps_mpa"][-2] + 1e-12
    assert stopped.converged.all()
    n = len(stopped.pressure_mpa)
    np.testing.assert_allclose(stopped.angle_deg, reference.angle_deg[:n], atol=0.05)


def test_undeformed_state_has_unit_stretch():
    from softbend.fem.actuator import ActuatorModel

    model = ActuatorModel(REFERENCE, COARSE)
    stretch, where = model.max_stretch()
    assert stretch == pytest.approx(1.0, abs=1e-12)
    assert model.region_of(1.0) == "proximal cap"
    assert model.region_of(50.0) == "chamber wall"
    assert model.region_of(REFERENCE.l_mm + COARSE.base_cap_mm + 1.0) == "distal cap"
    assert where.shape == (3,)


def test_nearest_steps_are_unique_and_in_pressure_order():
    from softbend.fem.sweep import Step, StepHistory

    def step(p):
        return Step(p, np.zeros(3), np.zeros(3), 1)

    history = StepHistory([step(p) for p in (0.0, 0.01, 0.025, 0.04)])
    picked = history.nearest_steps([0.04, 0.012, 0.0, 0.009, 0.1])
    assert [s.pressure_mpa for s in picked] == [0.0, 0.01, 0.04]


def _balloon_steps(volumes):
    """Steps on the pressure–volume curve p = V − V²/2 (a maximum of 0.5 at V = 1)."""
    from softbend.fem.sweep import Step

    return [
        Step(v - v * v / 2.0, np.zeros(3), np.zeros(3), 4, volume_rate=1.0 / (1.0 - v))
        for v in volumes
    ]


def test_a_flattening_pressure_volume_curve_is_told_apart_from_a_stall():
    from softbend.fem.sweep import Step, _pressure_maximum

    close = _pressure_maximum(_balloon_steps([0.2, 0.5, 0.8, 0.9, 0.95]))
    assert close is not None
    assert close[0] == pytest.approx(0.5, abs=0.005)
    assert close[1] > 1.0  # dp/dV fell
    # Still far from the maximum, or stiffening, or too few steps: no signature.
    assert _pressure_maximum(_balloon_steps([0.1, 0.3, 0.5])) is None
    stiffening = [
        Step(v + v * v, np.zeros(3), np.zeros(3), 4, volume_rate=1.0 / (1.0 + 2.0 * v))
        for v in (0.2, 0.5, 0.8)
    ]
    assert _pressure_maximum(stiffening) is None
    assert _pressure_maximum(_balloon_steps([0.9, 0.95])) is None


@pytest.mark.slow
def test_a_ballooning_end_cap_stops_as_an_inflation_instability():
    """(100, 10, 4, 4, 15, 8): its unreinforced 8 mm distal cap balloons near 0.49 MPa."""
    result = simulate(parse_sfrba("100,10,4,4,15,8"), default_pressures_mpa(), FEMOptions())
    reason = result.stats["stop_reason"]
    assert reason.startswith(("inflation instability", "stretch")), reason
    assert "distal cap" in reason
    assert result.converged[:-1].all()
