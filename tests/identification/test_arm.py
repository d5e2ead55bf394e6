import math
from dataclasses import replace

import numpy as np
import pytest

from softbend.identification.arm import (
    ARM_EXCITATIONS,
    ARM_VALIDATION,
    SoftArm,
    arm_excitation,
    arm_experiments,
    stiffening_drive,
    tip_from_curvature,
)

RATE_HZ = 12.0
QUIET = SoftArm(noise_std_mm=0.0)


def _step(chambers, level_kpa, duration_s=12.0, at_s=1.0):
    """Time and a pressure step from 0 to ``level_kpa`` in ``chambers`` at ``at_s``."""
    time = np.arange(round(duration_s * RATE_HZ)) / RATE_HZ
    pressures = np.zeros((time.size, 3))
    pressures[np.ix_(time >= at_s - 1e-12, list(chambers))] = level_kpa
    return time, pressures


def _constant(levels_kpa, duration_s=4.0):
    time = np.arange(round(duration_s * RATE_HZ)) / RATE_HZ
    return time, np.tile(np.asarray(levels_kpa, dtype=float), (time.size, 1))


@pytest.fixture(scope="module")
def default_set():
    return arm_experiments()


# ------------------------------------------------------------- pure functions
def test_tip_from_curvature_matches_closed_form_and_small_curvature_limit():
    kappa, length = 0.01, 150.0
    x, y = tip_from_curvature(kappa * math.cos(0.3), kappa * math.sin(0.3), length)
    radial = (1.0 - math.cos(kappa * length)) / kappa
    assert float(x) == pytest.approx(radial * math.cos(0.3), rel=1e-12)
    assert float(y) == pytest.approx(radial * math.sin(0.3), rel=1e-12)
    # |kappa| -> 0: no jump, the tip moves as kappa L^2 / 2.
    x0, y0 = tip_from_curvature(0.0, 0.0, length)
    assert float(x0) == 0.0 and float(y0) == 0.0
    tiny = 1e-12
    assert float(tip_from_curvature(tiny, 0.0, length)[0]) == pytest.approx(tiny * length**2 / 2)


def test_stiffening_drive_is_linear_at_first_and_bounded():
    assert float(stiffening_drive(1e-6, 40.0)) == pytest.approx(1e-6, rel=1e-6)
    assert float(stiffening_drive(40.0, 40.0)) == pytest.approx(20.0)
    assert float(stiffening_drive(1e9, 40.0)) < 40.0


# -------------------------------------------------------------------- physics
def test_zero_pressure_leaves_the_tip_at_the_origin_up_to_noise():
    time, pressures = _constant([0.0, 0.0, 0.0], duration_s=200.0)
    x, y = QUIET.simulate(time, pressures)
    assert np.all(x == 0.0) and np.all(y == 0.0)
    x, y = SoftArm().simulate(time, pressures, seed=3)
    for values in (x, y):
        assert abs(values.mean()) < 0.05
        assert values.std() == pytest.approx(0.3, rel=0.1)


@pytest.mark.parametrize("chamber", [0, 1, 2])
def test_one_chamber_bends_the_tip_towards_its_own_direction(chamber):
    time, pressures = _step([chamber], 40.0)
    x, y = QUIET.simulate(time, pressures)
    angle = math.degrees(math.atan2(y[-1], x[-1]))
    expected = QUIET.chamber_angles_deg[chamber]
    assert abs((angle - expected + 180.0) % 360.0 - 180.0) < 1.0
    assert math.hypot(x[-1], y[-1]) > 50.0


def test_equal_pressures_in_all_chambers_do_not_bend():
    x, y = QUIET.simulate(*_constant([45.0, 45.0, 45.0]))
    assert np.max(np.hypot(x, y)) < 1e-9
    # A common step: the chambers' different lags bend the arm on the way, and it
    # comes back straight, up to what the play operator may hold.
    x, y = QUIET.simulate(*_step([0, 1, 2], 45.0))
    assert np.max(np.hypot(x, y)) > 1.0
    held = QUIET.play_radius_per_mm * QUIET.length_mm**2 / 2
    assert math.hypot(x[-1], y[-1]) <= held + 1e-9
    no_play = replace(QUIET, play_radius_per_mm=0.0)
    x, y = no_play.simulate(*_step([0, 1, 2], 45.0))
    assert math.hypot(x[-1], y[-1]) < 1e-3


def test_small_pressures_act_linearly_and_large_ones_saturate():
    def reach(level):
        x, y = QUIET.simulate(*_constant([level, 0.0, 0.0]))
        steady = QUIET.steady_tip([level, 0.0, 0.0])
        assert x[-1] == pytest.approx(float(steady[0]), rel=1e-9)
        return math.hypot(x[-1], y[-1])

    assert 1.9 < reach(2.0) / reach(1.0) <= 2.0
    assert reach(60.0) / reach(30.0) < 1.4


def test_a_step_overshoots_when_underdamped_and_settles():
    no_play = replace(QUIET, play_radius_per_mm=0.0)
    time, pressures = _step([0], 30.0)
    final = float(no_play.steady_tip([30.0, 0.0, 0.0])[0])
    x, _ = no_play.simulate(time, pressures)
    assert x.max() > 1.02 * final
    assert np.allclose(x[time > 9.0], final, rtol=1e-3)
    overdamped = replace(no_play, damping_ratio=1.5)
    x, _ = overdamped.simulate(time, pressures)
    assert x.max() <= final * (1 + 1e-9)
    assert x[-1] == pytest.approx(final, rel=1e-3)


def test_hysteresis_keeps_the_tip_short_of_the_static_map_after_a_rise():
    x, _ = QUIET.simulate(*_step([0], 30.0))
    final = float(QUIET.steady_tip([30.0, 0.0, 0.0])[0])
    assert 0.3 < final - x[-1] < QUIET.play_radius_per_mm * QUIET.length_mm**2


def test_transport_delay_holds_the_tip_still():
    time, pressures = _step([0], 30.0, duration_s=3.0)
    x, _ = QUIET.simulate(time, pressures)  # step at sample 12, delay 0.1 s
    assert x[13] == 0.0 and x[14] > 0.0
    x, _ = replace(QUIET, delay_s=0.0).simulate(time, pressures)
    assert x[13] > 0.0


def test_rate_limit_slows_a_large_step():
    time, pressures = _step([0], 60.0, duration_s=6.0)
    free, _ = QUIET.simulate(time, pressures)
    limited, _ = replace(QUIET, rate_limit_kpa_per_s=40.0).simulate(time, pressures)
    assert limited[18] < 0.8 * free[18]
    assert limited[-1] == pytest.approx(free[-1], rel=1e-3)


def test_samples_off_the_internal_grid_are_interpolated_consistently():
    regular, pressures = _step([1], 35.0, duration_s=5.0)
    extra = np.sort(np.concatenate([regular, regular[:-1] + 0.037]))
    dense = np.zeros((extra.size, 3))
    dense[extra >= 1.0 - 1e-12, 1] = 35.0
    x_reg, y_reg = QUIET.simulate(regular, pressures)
    x_all, y_all = QUIET.simulate(extra, dense)
    shared = np.isin(extra, regular)
    np.testing.assert_allclose(x_all[shared], x_reg, atol=1e-9)
    np.testing.assert_allclose(y_all[shared], y_reg, atol=1e-9)
    # Between samples the tip lies between its neighbours (smooth, no jump).
    between = x_all[~shared]
    low = np.minimum(x_all[shared][:-1], x_all[shared][1:])
    high = np.maximum(x_all[shared][:-1], x_all[shared][1:])
    assert np.all((between >= low - 0.5) & (between <= high + 0.5))


def test_drift_wanders_slowly():
    time, pressures = _constant([0.0, 0.0, 0.0], duration_s=100.0)
    x, _ = replace(QUIET, drift_mm_per_sqrt_s=0.1).simulate(time, pressures, seed=1)
    assert x[0] == 0.0 and 0.05 < np.abs(x).max() < 10.0


# ---------------------------------------------------------------- reproducible
def test_seeds_reproduce_bit_for_bit():
    time, pressures = _step([0, 2], 25.0, duration_s=4.0)
    a = SoftArm().simulate(time, pressures, seed=7)
    b = SoftArm().simulate(time, pressures, seed=7)
    c = SoftArm().simulate(time, pressures, seed=8)
    assert np.array_equal(a[0], b[0]) and np.array_equal(a[1], b[1])
    assert not np.array_equal(a[0], c[0])
    one = arm_experiments(2, 1, duration_s=6.0, seed=4)
    two = arm_experiments(2, 1, duration_s=6.0, seed=4)
    other = arm_experiments(2, 1, duration_s=6.0, seed=5)
    for e, f, g in zip(one.experiments, two.experiments, other.experiments, strict=True):
        assert np.array_equal(e.inputs, f.inputs) and np.array_equal(e.outputs, f.outputs)
        assert not np.array_equal(e.outputs, g.outputs)


def test_an_experiment_does_not_change_with_the_counts():
    small = arm_experiments(1, 1, duration_s=6.0)
    large = arm_experiments(3, 2, duration_s=6.0)
    for name in ("train01-steps", "val01-steps"):
        a, b = small.subset([name]).experiments[0], large.subset([name]).experiments[0]
        assert np.array_equal(a.outputs, b.outputs)


@pytest.mark.parametrize("kind", ARM_EXCITATIONS)
def test_excitations_stay_in_range_and_start_at_rest(kind):
    pressures = arm_excitation(kind, 1200, RATE_HZ, 60.0, seed=2)
    assert pressures.shape == (1200, 3)
    assert np.all(pressures >= 0.0) and np.all(pressures <= 60.0)
    assert np.all(pressures[:12] == 0.0)
    assert pressures.max() > 30.0
    for column in pressures.T:  # every chamber is excited
        assert np.ptp(column) > 20.0


# ---------------------------------------------------------------- default set
def test_default_set_size_names_and_columns(default_set):
    assert len(default_set.experiments) == 17
    rows = sum(e.n_samples for e in default_set.experiments)
    assert rows == pytest.approx(45_000, rel=0.03)
    assert default_set.input_names == ("p1_kpa", "p2_kpa", "p3_kpa")
    assert default_set.output_names == ("x_mm", "y_mm")
    assert default_set.time_name == "time_s"
    assert default_set.names[:2] == ("train01-steps", "train02-ramps")
    assert default_set.names[-4:] == ARM_VALIDATION
    assert sum(n.startswith("train") for n in default_set.names) == 13
    dt = np.diff(default_set.experiments[0].time)
    assert np.allclose(dt, 1.0 / RATE_HZ)
    assert all("SYNTHETIC" in e.source for e in default_set.experiments)
    validation = default_set.subset(ARM_VALIDATION)
    assert {n.split("-")[1] for n in validation.names} == set(ARM_EXCITATIONS)


def test_default_set_covers_the_workspace(default_set):
    U, Y, _ = default_set.stacked()
    assert U.min() == 0.0 and U.max() <= 60.0
    radius = np.hypot(Y[:, 0], Y[:, 1])
    angle = np.degrees(np.arctan2(Y[:, 1], Y[:, 0]))
    assert radius.max() > 80.0
    counts, _ = np.histogram(angle[radius > 20.0], bins=6, range=(-180, 180))
    assert counts.min() > 0.05 * counts.sum()


# ----------------------------------------------------------------- bad input
@pytest.mark.parametrize(
    ("field", "value"),
    [
        ("length_mm", 0.0),
        ("damping_ratio", -0.1),
        ("noise_std_mm", -1.0),
        ("tau_s", (0.1, 0.2)),
        ("tau_s", (0.1, 0.0, 0.2)),
        ("chamber_angles_deg", ()),
        ("substep_s", float("nan")),
    ],
)
def test_bad_parameters_are_refused_with_their_name(field, value):
    with pytest.raises(ValueError, match=rf"^{field}: must") as info:
        SoftArm(**{field: value})
    assert info.value.key == field


def test_bad_simulation_input_is_refused():
    time, pressures = _constant([10.0, 0.0, 0.0])
    with pytest.raises(ValueError, match=r"^pressures_kpa: must be finite and >= 0"):
        QUIET.simulate(time, -pressures)
    with pytest.raises(ValueError, match=r"^pressures_kpa: must have one column per chamber"):
        QUIET.simulate(time, pressures[:, :2])
    with pytest.raises(ValueError, match=r"^pressures_kpa: .*one row per time sample"):
        QUIET.simulate(time, pressures[:-1])
    with pytest.raises(
        ValueError, match=r"^time_s: .* does not increase after .*\(sample 0\); it must increase"
    ):
        QUIET.simulate(time[::-1], pressures)
    with pytest.raises(ValueError, match=r"^seed: must be an integer"):
        QUIET.simulate(time, pressures, seed=1.5)


def test_bad_experiment_options_are_refused():
    with pytest.raises(ValueError, match=r"^n_train: must be an integer"):
        arm_experiments(0)
    with pytest.raises(ValueError, match=r"^duration_s: must be long enough for at least 2"):
        arm_experiments(1, 0, duration_s=0.05)
    with pytest.raises(ValueError, match=r"^arm: must be a SoftArm or None"):
        arm_experiments(1, 0, duration_s=2.0, arm="soft")  # type: ignore[arg-type]
    with pytest.raises(ValueError, match=r"^kind: must be one of"):
        arm_excitation("chirp", 100)  # type: ignore[arg-type]
