import math

import numpy as np
import pytest

from softbend.identification.data import load_experiments, save_experiments
from softbend.identification.synthetic import (
    ALL_PROFILE_KINDS,
    PROFILE_KINDS,
    CurlingActuator,
    pressure_profile,
    synthetic_dataset,
)

NO_HYSTERESIS = {"play_weights": (0.0, 0.0, 0.0)}


@pytest.fixture(scope="module")
def dataset():
    return synthetic_dataset()


# ---------------------------------------------------------------- static maps
def test_calibration_points_of_paper_a_are_exact():
    actuator = CurlingActuator()
    rho, length = actuator.steady_state([100.0, -80.0, 0.0])
    np.testing.assert_allclose(length, [18.25, 9.25, 15.25], rtol=0, atol=1e-12)
    np.testing.assert_allclose(rho, [0.45, -0.30, 0.0], rtol=0, atol=1e-12)
    # Paper A eqs. 18-19: +19.67 % elongation, -39.34 % shrinkage.
    assert round(100 * (length[0] - 15.25) / 15.25, 2) == 19.67
    assert round(100 * (15.25 - length[1]) / 15.25, 2) == 39.34


def test_other_calibrations_are_also_hit_exactly():
    actuator = CurlingActuator(
        max_pressure_kpa=150,
        min_pressure_kpa=-50,
        max_length_mm=17,
        min_length_mm=12,
        max_rho=0.6,
        min_rho=-0.1,
        rho_stiffening=3.0,
        length_stiffening=0.01,
    )
    rho, length = actuator.steady_state([150.0, -50.0])
    np.testing.assert_allclose(rho, [0.6, -0.1], atol=1e-12)
    np.testing.assert_allclose(length, [17.0, 12.0], atol=1e-12)
    # A nearly linear arc-length map (stiffening -> 0) is the straight line between them.
    assert actuator.steady_state(75.0)[1] == pytest.approx(16.125, rel=1e-4)


def test_static_maps_are_monotone_signed_and_saturating():
    actuator = CurlingActuator()
    pressure = np.linspace(-80.0, 100.0, 721)
    rho, length = actuator.steady_state(pressure)
    assert np.all(np.diff(rho) > 0) and np.all(np.diff(length) > 0)
    assert np.array_equal(np.sign(rho), np.sign(pressure))
    assert np.all((length > 15.25) == (pressure > 0))
    # Rubber stiffening: the slope falls with |p| on both sides (concave up, convex down).
    for values in (rho, length):
        positive = values[pressure >= 0]
        negative = values[pressure <= 0]
        assert np.all(np.diff(positive, 2) < 0)
        assert np.all(np.diff(negative, 2) > 0)


# ------------------------------------------------------------------- dynamics
def _step(actuator, level_kpa, *, hold_s=15.0, release_s=2.0, dt=0.02):
    n_lead = 10
    n_hold = round(hold_s / dt)
    n_release = round(release_s / dt)
    time = dt * np.arange(n_lead + n_hold + n_release)
    pressure = np.zeros(time.size)
    pressure[n_lead : n_lead + n_hold] = level_kpa
    return actuator.response(time, pressure), n_lead, n_hold


def test_chamber_pressure_is_an_exact_first_order_lag_slower_when_venting():
    actuator = CurlingActuator()
    response, lead, hold = _step(actuator, 60.0)
    t = response.time_s
    rise = slice(lead + 1, lead + hold + 1)  # the command is held from sample `lead` on
    expected = 60.0 * (1.0 - np.exp(-(t[rise] - t[lead]) / actuator.tau_charge_s))
    np.testing.assert_allclose(response.chamber_pressure_kpa[rise], expected, atol=1e-9)
    # One time constant after the step: 1 - 1/e of the way.
    k = lead + round(actuator.tau_charge_s / 0.02)
    assert response.chamber_pressure_kpa[k] == pytest.approx(60 * (1 - math.exp(-1)), rel=1e-9)
    start = lead + hold
    fall = slice(start + 1, None)
    vented = response.chamber_pressure_kpa[start] * np.exp(
        -(t[fall] - t[start]) / actuator.tau_discharge_s
    )
    np.testing.assert_allclose(response.chamber_pressure_kpa[fall], vented, atol=1e-9)
    assert actuator.tau_discharge_s > actuator.tau_charge_s


def test_step_response_settles_on_the_static_map_after_lag_and_creep():
    actuator = CurlingActuator(**NO_HYSTERESIS)
    response, lead, hold = _step(actuator, 60.0)
    end = lead + hold
    rho_s, length_s = actuator.steady_state(60.0)
    assert response.rho[end] == pytest.approx(rho_s, rel=1e-5)
    assert response.length_mm[end] == pytest.approx(length_s, rel=1e-6)
    # Creep: once the pressure has settled (t >> tau), the remaining gap closes as
    # c * (final change) * exp(-t / creep_time_s), a standard-linear-solid retardation.
    t = response.time_s - response.time_s[lead]
    window = (t > 1.0) & (t < 6.0)
    gap = rho_s - response.rho[window]
    slope, intercept = np.polyfit(t[window], np.log(gap), 1)
    assert -1.0 / slope == pytest.approx(actuator.creep_time_s, rel=1e-3)
    # Amplitude c * rho_s, delayed by the pneumatic lag: at most tau_c / (tau_c - tau) larger.
    amplitude = actuator.creep_fraction * rho_s
    delay = actuator.creep_time_s / (actuator.creep_time_s - actuator.tau_charge_s)
    assert amplitude < math.exp(intercept) < delay * amplitude
    # Five pneumatic time constants after the step the fast part is done but the creep is not.
    k = lead + round(5 * actuator.tau_charge_s / 0.02)
    creep = actuator.creep_fraction * rho_s
    assert 0.97 * (rho_s - creep) < response.rho[k] < rho_s - 0.5 * creep


def test_step_response_with_hysteresis_settles_on_the_loading_branch():
    actuator = CurlingActuator()
    response, lead, hold = _step(actuator, -50.0)
    end = lead + hold
    # Loading from rest leaves every play operator at p + r (vacuum side), so the
    # drive is short of the chamber pressure by the hysteresis half-width.
    drive = -50.0 + actuator.hysteresis_halfwidth_kpa
    assert response.drive_pressure_kpa[end] == pytest.approx(drive, abs=1e-6)
    rho_s, length_s = actuator.steady_state(drive)
    assert response.rho[end] == pytest.approx(rho_s, rel=1e-5)
    assert response.length_mm[end] == pytest.approx(length_s, rel=1e-6)
    assert actuator.steady_state(-50.0)[0] < response.rho[end] < 0


def _trapezoid_cycles(period_s, peak_kpa=100.0, cycles=2, dt=0.05):
    """Ramps 0 -> peak -> 0 with short holds at both ends, so the lagged chamber reaches both."""
    ramp = np.linspace(0.0, 1.0, round(0.5 * period_s / dt), endpoint=False)
    hold = round(2.0 / dt)
    cycle = np.concatenate([ramp, np.ones(hold), 1.0 - ramp, np.zeros(hold)])
    pressure = peak_kpa * np.concatenate([np.zeros(hold), np.tile(cycle, cycles)])
    return dt * np.arange(pressure.size), pressure, cycle.size


def _loop_area(x, y):
    """Signed area enclosed by the closed curve (x, y), positive counter-clockwise."""
    return 0.5 * float(np.sum(x * np.roll(y, -1) - np.roll(x, -1) * y))


@pytest.mark.parametrize("period_s", [4.0, 40.0])
def test_prandtl_ishlinskii_loop_has_the_closed_form_area_at_any_rate(period_s):
    actuator = CurlingActuator()
    time, pressure, n_cycle = _trapezoid_cycles(period_s, dt=0.01)
    response = actuator.response(time, pressure)
    last = slice(-n_cycle, None)  # second cycle: the periodic loop
    area = _loop_area(response.chamber_pressure_kpa[last], response.drive_pressure_kpa[last])
    peak = 100.0
    expected = sum(
        2 * w * r * (peak - 2 * r)
        for w, r in zip(actuator.play_weights, actuator.play_radii_kpa, strict=True)
    )
    # Counter-clockwise in (p_c, p_h): the drive lags on loading and leads on unloading.
    assert area == pytest.approx(expected, rel=1e-3)


def _rho_loop_area(actuator, period_s):
    time, pressure, n_cycle = _trapezoid_cycles(period_s, dt=0.1)
    response = actuator.response(time, pressure)
    last = slice(-n_cycle, None)
    return _loop_area(pressure[last], response.rho[last])


def test_hysteresis_loop_does_not_shrink_when_the_cycle_slows_down():
    # Coarse substeps are accurate here: the inputs change over minutes.
    actuator = CurlingActuator(substep_s=0.05)
    viscous = CurlingActuator(substep_s=0.05, **NO_HYSTERESIS)  # lag and creep only
    periods = (200.0, 800.0, 3200.0)
    total = [_rho_loop_area(actuator, period) for period in periods]
    rate_dependent = [_rho_loop_area(viscous, period) for period in periods]
    assert all(area > 0 for area in total)  # unloading branch above the loading branch
    # Lag and creep alone give a loop that vanishes as 1/period ...
    assert rate_dependent[1] == pytest.approx(rate_dependent[0] / 4, rel=0.05)
    assert rate_dependent[2] == pytest.approx(rate_dependent[1] / 4, rel=0.05)
    # ... while the hysteretic part stays the same however slow the cycle.
    hysteretic = [t - v for t, v in zip(total, rate_dependent, strict=True)]
    assert hysteretic[1] == pytest.approx(hysteretic[0], rel=0.01)
    assert hysteretic[2] == pytest.approx(hysteretic[1], rel=0.01)
    assert total[2] > 0.95 * total[1] > 0.8 * total[0]
    assert rate_dependent[2] < 0.02 * total[2]
    # Small: a few percent of (output range x pressure range).
    assert 0.005 < total[2] / (0.45 * 100.0) < 0.06


# ---------------------------------------------------------------------- noise
def test_camera_noise_has_the_stated_std_and_pixel_quantization():
    actuator = CurlingActuator()
    n = 20000
    experiment = actuator.simulate(0.02 * np.arange(n), np.zeros(n), seed=11)
    pixel = actuator.pixel_mm
    expected = math.sqrt(actuator.noise_std_mm**2 + pixel**2 / 12)  # Gaussian + rounding
    for values in (experiment.x_mm, experiment.y_mm):
        assert np.std(values) == pytest.approx(expected, rel=0.03)
        assert abs(np.mean(values)) < 4 * expected / math.sqrt(n)
        np.testing.assert_allclose(values / pixel, np.round(values / pixel), atol=1e-6)
    raw = CurlingActuator(noise_std_mm=0.03, pixel_mm=0.0).simulate(
        0.02 * np.arange(n), np.zeros(n), seed=11
    )
    assert np.std(raw.x_mm) == pytest.approx(0.03, rel=0.03)
    exact = CurlingActuator(noise_std_mm=0.0, pixel_mm=0.0).simulate(
        [0, 0.02, 0.04], [0.0, 0.0, 0.0]
    )
    np.testing.assert_array_equal(exact.x_mm, 0.0)
    np.testing.assert_array_equal(exact.length_mm, 15.25)


def test_noise_free_camera_recovers_the_model_through_the_kinematics():
    actuator = CurlingActuator(noise_std_mm=0.0, pixel_mm=0.0)
    time, pressure = pressure_profile("random_hold", 300, 0.02, -80.0, seed=2)
    experiment = actuator.simulate(time, pressure)
    response = actuator.response(time, pressure)
    np.testing.assert_allclose(experiment.rho, response.rho, atol=1e-12)
    np.testing.assert_allclose(experiment.length_mm, response.length_mm, rtol=1e-12)


# ------------------------------------------------------------------ determinism
def test_same_seed_same_arrays_other_seed_other_noise():
    a = synthetic_dataset(n_experiments=2, n_samples=64, seed=3)
    b = synthetic_dataset(n_experiments=2, n_samples=64, seed=3)
    c = synthetic_dataset(n_experiments=2, n_samples=64, seed=4)
    for sign in ("positive", "negative"):
        assert a[sign] == b[sign]
        assert not np.array_equal(a[sign][0].x_mm, c[sign][0].x_mm)
    actuator = CurlingActuator()
    time, pressure = pressure_profile("sine", 64, seed=5)
    assert actuator.simulate(time, pressure, seed=1) == actuator.simulate(time, pressure, seed=1)
    assert actuator.simulate(time, pressure, seed=1) != actuator.simulate(time, pressure, seed=2)


# ---------------------------------------------------------------------- profiles
@pytest.mark.parametrize("kind", ALL_PROFILE_KINDS)
@pytest.mark.parametrize("peak", [100.0, -80.0])
def test_every_profile_starts_at_rest_and_spans_the_range(kind, peak):
    time, pressure = pressure_profile(kind, 512, 0.02, peak, seed=9)
    np.testing.assert_allclose(time, 0.02 * np.arange(512))
    np.testing.assert_array_equal(pressure[:10], 0.0)
    assert np.any(pressure == peak)
    fraction = pressure / peak
    assert np.all((fraction >= 0) & (fraction <= 1))
    again = pressure_profile(kind, 512, 0.02, peak, seed=9)[1]
    np.testing.assert_array_equal(pressure, again)
    assert not np.array_equal(pressure, pressure_profile(kind, 512, 0.02, peak, seed=10)[1])


# ----------------------------------------------------------------------- dataset
def test_dataset_layout_of_paper_a(dataset):
    assert set(dataset) == {"positive", "negative"}
    for sign, experiments in dataset.items():
        assert len(experiments) == 6
        assert [e.name for e in experiments] == [f"{sign}-{i:02d}" for i in range(1, 7)]
        assert {e.metadata["profile"] for e in experiments} == set(PROFILE_KINDS)
        for e in experiments:
            assert e.n_samples == 512
            assert e.dt_s == pytest.approx(0.02)
            assert e.synthetic and "SYNTHETIC" in e.metadata["label"]
            assert e.sign == sign
            assert np.sign(np.median(e.rho[e.pressure_kpa != 0])) == (
                1 if sign == "positive" else -1
            )


def test_every_held_out_experiment_is_covered_by_the_others(dataset):
    margin = {"rho": 0.01, "length_mm": 0.15}  # a few noise standard deviations
    for experiments in dataset.values():
        for i, held in enumerate(experiments):
            others = [e for j, e in enumerate(experiments) if j != i]
            for name in ("pressure_kpa", "rho", "length_mm"):
                low = min(getattr(e, name).min() for e in others)
                high = max(getattr(e, name).max() for e in others)
                tol = margin.get(name, 0.0)
                values = getattr(held, name)
                assert low - tol <= values.min() and values.max() <= high + tol, (held.name, name)


def test_dataset_round_trips_through_csv_with_its_label(dataset, tmp_path):
    paths = save_experiments(dataset["negative"], tmp_path)
    assert "SYNTHETIC DATA" in paths[0].read_text().splitlines()[1]
    assert load_experiments(tmp_path) == dataset["negative"]


def _lagged(y, u):
    return np.column_stack([y[1:-1], y[:-2], u[2:], u[1:-1]]), y[2:]


def _free_run(predict, y, u):
    out = list(y[:2])
    for t in range(2, u.size):
        out.append(predict(np.array([[out[-1], out[-2], u[t], u[t - 1]]])))
    return np.array(out)


def _svr_step(svr, xs, ys):
    def predict(phi):
        return ys.inverse_transform(svr.predict(xs.transform(phi))[:, None])[0, 0]

    return predict


def test_narx_svr_identifies_the_actuator_on_a_held_out_experiment(dataset):
    """Paper A's model: phi = [y(t-1), y(t-2), u(t), u(t-1)], SVR C = 100, eps = 0.1."""
    from sklearn.preprocessing import StandardScaler
    from sklearn.svm import SVR

    for experiments in dataset.values():
        held, train = experiments[0], experiments[1:]
        for output in ("rho", "length_mm"):
            pairs = [_lagged(getattr(e, output), e.pressure_kpa) for e in train]
            X = np.vstack([p[0] for p in pairs])
            Y = np.concatenate([p[1] for p in pairs])
            xs = StandardScaler().fit(X)
            ys = StandardScaler().fit(Y[:, None])
            svr = SVR(kernel="rbf", C=100, epsilon=0.1).fit(
                xs.transform(X), ys.transform(Y[:, None]).ravel()
            )
            y, u = getattr(held, output), held.pressure_kpa
            simulated = _free_run(_svr_step(svr, xs, ys), y, u)
            nrmse = np.sqrt(np.mean((simulated[2:] - y[2:]) ** 2)) / np.ptp(y)
            assert nrmse < 0.10, (held.name, output, nrmse)
            # Not trivially linear: a linear ARX on the same regressors does clearly worse.
            coef = np.linalg.lstsq(np.column_stack([X, np.ones(len(X))]), Y, rcond=None)[0]
            linear = _free_run(lambda phi, c=coef: float(phi[0] @ c[:4] + c[4]), y, u)
            linear_nrmse = np.sqrt(np.mean((linear[2:] - y[2:]) ** 2)) / np.ptp(y)
            assert linear_nrmse > 1.3 * nrmse, (held.name, output, nrmse, linear_nrmse)


# ------------------------------------------------------------------- bad input
@pytest.mark.parametrize(
    ("kwargs", "field"),
    [
        ({"max_length_mm": 15.0}, "max_length_mm"),
        ({"min_length_mm": 16.0}, "min_length_mm"),
        ({"max_rho": -0.1}, "max_rho"),
        ({"min_rho": 0.2}, "min_rho"),
        ({"max_pressure_kpa": -10}, "max_pressure_kpa"),
        ({"min_pressure_kpa": 10}, "min_pressure_kpa"),
        ({"tau_charge_s": 0}, "tau_charge_s"),
        ({"creep_fraction": 1.0}, "creep_fraction"),
        ({"noise_std_mm": -0.01}, "noise_std_mm"),
        ({"play_radii_kpa": (1.0, -2.0)}, "play_radii_kpa"),
        ({"play_weights": (0.5, 0.6, 0.1)}, "play_weights"),
        ({"play_weights": (0.1,)}, "play_weights"),
        ({"rest_length_mm": float("nan")}, "rest_length_mm"),
    ],
)
def test_actuator_rejects_bad_parameters(kwargs, field):
    with pytest.raises(ValueError, match=rf"^{field}: must"):
        CurlingActuator(**kwargs)


def test_bad_profiles_and_datasets_are_refused():
    with pytest.raises(ValueError, match=r"^kind: must be one of"):
        pressure_profile("square")
    with pytest.raises(ValueError, match=r"^n_samples: must be"):
        pressure_profile("step", 8)
    with pytest.raises(ValueError, match=r"^peak_kpa: must be nonzero"):
        pressure_profile("step", peak_kpa=0.0)
    with pytest.raises(ValueError, match=r"^n_experiments: must be"):
        synthetic_dataset(n_experiments=0)
    with pytest.raises(ValueError, match=r"^actuator: must be a CurlingActuator"):
        synthetic_dataset(actuator="soft")
    with pytest.raises(ValueError, match=r"^excitation: must be one of"):
        synthetic_dataset(excitation="uniform")
    with pytest.raises(
        ValueError, match=r"^time_s: 0.1 does not increase after 0.1 \(sample 1\); it must increase"
    ):
        CurlingActuator().response([0.0, 0.1, 0.1], [0.0, 1.0, 2.0])
    with pytest.raises(
        ValueError, match=r"^pressure_kpa: must be a 1-D array of the length of 'time_s'"
    ):
        CurlingActuator().response([0.0, 0.1, 0.2], [0.0, 1.0])


# ------------------------------------------------------------ impulsive excitation
def _standardized_regressors(experiments, output="rho"):
    from softbend.identification.narx import lagged_matrix

    u = np.concatenate([e.pressure_kpa for e in experiments])
    y = np.concatenate([getattr(e, output) for e in experiments])
    groups = np.concatenate([np.full(e.n_samples, i) for i, e in enumerate(experiments)])
    X, _, _ = lagged_matrix((u - u.mean()) / u.std(), (y - y.mean()) / y.std(), groups)
    return X


def test_impulsive_excitation_gives_heavy_tailed_regressors_and_mixed_light_tailed(dataset):
    import warnings

    from softbend.identification.kernels import ShapeClippedWarning, estimate_kernel_shape

    impulsive = synthetic_dataset(n_experiments=3, seed=4, excitation="impulsive")
    for sign, experiments in impulsive.items():
        assert {e.metadata["profile"] for e in experiments} == {"impulsive"}
        assert all(e.metadata["excitation"] == "impulsive" for e in experiments)
        pressure = np.concatenate([e.pressure_kpa for e in experiments])
        peak = 100.0 if sign == "positive" else -80.0
        # Most samples near the operating point (20-34 % of the peak), a few pulses beyond.
        near = (pressure / peak > 0.15) & (pressure / peak < 0.35)
        assert 0.7 < near.mean() < 0.97
        estimate = estimate_kernel_shape(_standardized_regressors(experiments))
        assert estimate.relative_kurtosis > 1.5 and estimate.shape < 1.0
    with warnings.catch_warnings():
        warnings.simplefilter("ignore", ShapeClippedWarning)
        mixed = estimate_kernel_shape(_standardized_regressors(dataset["positive"]))
    assert mixed.clipped and mixed.shape == 2.0 and mixed.relative_kurtosis < 1.0
