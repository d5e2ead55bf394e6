"""An identified dynamic model as the rig's actuator, and the rig set from one."""

import numpy as np
import pytest

from softbend.control.identified_plant import (
    NARXAngle,
    identified_plant,
    pressure_unit,
    rig_settings_from,
)
from softbend.control.rig import AngleDynamics, RigParams, SimulatedRig
from softbend.control.runs import simulate_control
from softbend.errors import InputError

from .identified_models import DELAY_S, GAIN, PERIOD_S, TAU_S, fopdt_series, save_fopdt

#: A rig whose chamber fills within a step: its pressure is a step of the supply.
FAST = RigParams(
    inlet_conductance_m3_s_pa=1e-7, volume_mm3=10.0, compliance_mm3_per_mpa=0.0,
    valve_delay_s=0.0, sensor_noise_mpa=0.0, camera_noise_deg=0.0,
)  # fmt: skip


@pytest.fixture(scope="module")
def fopdt(tmp_path_factory):
    return save_fopdt(tmp_path_factory.mktemp("fopdt") / "model.json")


def step_through_rig(path, seconds=0.5):
    """Open the inlet of the fast rig at 0 and log (t, pressure, angle) every step."""
    plant = identified_plant(path)
    rig = SimulatedRig(plant.angle_table(0.2), FAST, dynamics=plant.dynamics())
    rig.command(True, False)
    log = []
    for _ in range(round(seconds / FAST.step_s)):
        rig.advance(1)
        log.append((rig.t_s, rig.pressure_mpa, rig.angle_deg))
    return np.array(log)


def test_fopdt_step_response_through_the_rig(fopdt):
    log = step_through_rig(fopdt)
    t, p, angle = log.T
    supply = FAST.supply_gauge_mpa
    assert p[10] == pytest.approx(supply, rel=1e-6)  # a step of the supply within 10 ms
    # at each sample instant: the FOPDT of the pressure the rig held there
    ratio = round(PERIOD_S / FAST.step_s)
    samples = np.concatenate(([0.0], p[ratio - 1 :: ratio]))
    expected = fopdt_series(samples)
    assert np.allclose(angle[ratio - 1 :: ratio], expected[1:], atol=1e-6 * GAIN * supply)
    # between samples the angle is held: it changes only on a sample instant
    changes = np.flatnonzero(np.diff(angle)) + 1  # the steps where the angle moved
    assert changes.size > 10 and np.all((changes + 1) % ratio == 0)
    # and the continuous FOPDT step within what it moves in one sample period
    final = GAIN * supply
    start = DELAY_S + PERIOD_S  # the pressure is sampled at the first sample after 0
    continuous = np.where(t > start, final * (1 - np.exp(-(t - start) / TAU_S)), 0.0)
    tolerance = final * (1 - np.exp(-PERIOD_S / TAU_S)) + 1e-4 * final  # + the fit's error
    assert np.max(np.abs(angle - continuous)) <= tolerance
    assert angle[-1] == pytest.approx(final, rel=1e-3)


def test_input_in_kpa_is_converted(tmp_path, fopdt):
    kpa = save_fopdt(tmp_path / "kpa.json", inputs=("p_kpa",), scale=1000.0)
    assert identified_plant(kpa).input_scale == 1000.0
    mpa_angle, kpa_angle = step_through_rig(fopdt)[:, 2], step_through_rig(kpa)[:, 2]
    assert np.allclose(kpa_angle, mpa_angle, atol=1e-6 * GAIN * 0.2)
    assert kpa_angle[-1] > 0.9 * GAIN * 0.2  # the same degrees, not 1000 times them


@pytest.mark.parametrize(
    ("name", "unit", "scale"),
    [("p_mpa", "MPa", 1.0), ("P_KPA", "kPa", 1e3), ("p_bar", "bar", 10.0),
     ("p_pa", "Pa", 1e6), ("p_psi", "psi", 145.0377)],
)  # fmt: skip
def test_pressure_units(name, unit, scale):
    got = pressure_unit(name)
    assert got is not None and got[0] == unit and got[1] == pytest.approx(scale, rel=1e-6)


def test_no_pressure_unit():
    assert pressure_unit("valve") is None and pressure_unit("p_mm") is None


def test_narx_angle_is_angle_dynamics(fopdt):
    dynamics = identified_plant(fopdt).dynamics()
    assert isinstance(dynamics, NARXAngle) and isinstance(dynamics, AngleDynamics)
    first = [dynamics.advance(0.1, 0.001) for _ in range(80)]
    assert dynamics.reset() == pytest.approx(0.0, abs=1e-3)
    assert [dynamics.advance(0.1, 0.001) for _ in range(80)] == first  # reset is a fresh start


def test_steady_state_table_is_the_gain(fopdt):
    table = identified_plant(fopdt).angle_table(0.2)
    assert table(0.1) == pytest.approx(GAIN * 0.1, rel=1e-4)
    assert table.inverse(60.0) == pytest.approx(60.0 / GAIN, rel=1e-4)


def test_rig_from_reads_tau_and_delay(fopdt):
    settings, record = rig_settings_from(fopdt)
    assert settings["angle_time_constant_s"] == pytest.approx(TAU_S, rel=1e-3)
    assert settings["valve_delay_s"] == pytest.approx(DELAY_S, rel=1e-6)
    assert record["reading"] == "pressure_mpa → angle_deg"
    assert record["gain"] == pytest.approx(GAIN, rel=1e-3)


def test_rig_from_sets_the_run_and_rig_param_wins(fopdt):
    run = simulate_control(
        rig_from=fopdt, rig_assignments=["valve_delay_s=0.01"], duration_s=0.3,
        reference="step:60",
    )  # fmt: skip
    rig = run.summary["rig"]
    assert rig["angle_time_constant_s"] == pytest.approx(TAU_S, rel=1e-3)
    assert rig["valve_delay_s"] == 0.01
    origin = run.summary["rig_from"]
    assert origin["used"] == ["angle_time_constant_s"] and origin["overridden"] == ["valve_delay_s"]
    assert origin["file"] == str(fopdt)


def test_rig_from_out_of_range(tmp_path):
    slow = save_fopdt(tmp_path / "slow.json", tau_s=2.0, period_s=0.1)
    with pytest.raises(InputError) as caught:
        rig_settings_from(slow)
    assert caught.value.key == "rig_from"
    assert "angle_time_constant_s range [0, 1] s" in str(caught.value)
    assert "pressure_mpa → angle_deg" in str(caught.value)


def test_rig_from_refuses_a_surrogate():
    with pytest.raises(InputError, match="must be a model saved by 'softbend identify'"):
        rig_settings_from("src/softbend/data/transfer/table1_fem_mlp.json")


@pytest.mark.parametrize(
    ("options", "words"),
    [
        ({"inputs": ("p1_mpa", "p2_mpa")}, "exactly one input, a pressure"),
        ({"inputs": ("valve",)}, "exactly one input, a pressure"),
        ({"outputs": ("x_mm",)}, "one output that is an angle in degrees"),
        ({"outputs": ("angle_deg", "theta_deg")}, "and 2 are"),
        ({"time": "t"}, "a time column of known unit"),
    ],
)
def test_refusals_are_one_clear_error(tmp_path, options, words):
    path = save_fopdt(tmp_path / "model.json", **options)
    with pytest.raises(InputError) as caught:
        identified_plant(path)
    assert caught.value.key == "plant"
    assert words in str(caught.value) and str(path) in str(caught.value)


def test_identified_plant_runs_the_loop(fopdt):
    run = simulate_control(plant=str(fopdt), reference="step:60:0", duration_s=1.0)
    summary = run.summary
    assert summary["design"] is None and summary["design_supported"] is None
    assert summary["plant_description"] == (
        f"identified model {fopdt} (arx na=1 nb=4), sample period 0.01 s"
    )
    # the bang-bang holds the identified actuator near 60°
    angle = run.run.angle_deg[run.run.t_s > 0.5]
    assert abs(np.mean(angle) - 60.0) < 6.0


def test_identified_plant_has_no_design(fopdt):
    with pytest.raises(InputError) as caught:
        simulate_control(plant=str(fopdt), design="100,6,2,2,5,8", duration_s=0.1)
    assert caught.value.key == "design" and "--model" in str(caught.value)


def test_paper_b_default_rig_is_the_lag(table):
    """Without dynamics, the angle follows θ(p) through the first-order lag, step by step."""
    params = RigParams(sensor_noise_mpa=0.0, camera_noise_deg=0.0)
    rig = SimulatedRig(table, params)
    assert rig.dynamics is None
    rig.command(True, False)
    lag = 1.0 - np.exp(-params.step_s / params.angle_time_constant_s)
    angle = rig.angle_deg
    for _ in range(200):
        rig.advance(1)
        angle += lag * (table(rig.pressure_mpa) - angle)
        assert rig.angle_deg == angle


@pytest.mark.parametrize(
    ("family", "params"),
    [("poly2", {}), ("poly2-sim", {"filter": True, "steps": 10, "tau_init": 4.0})],
    ids=["poly2", "poly2-sim-filter"],
)
def test_narx_angle_steps_as_the_model_runs_free(tmp_path, family, params):
    """Sampled every period, the rig's stepping equals the model's own free run, the learned
    input filter included."""
    from softbend.identification.dynamics import load_identified
    from softbend.identification.multi import MultiNARX, save_multi_narx

    rng = np.random.default_rng(1)
    p = np.repeat(rng.uniform(0.0, 0.2, 40), 25)
    angle = fopdt_series(p) ** 1.2 / 10.0  # a bend that stiffens: not linear in p
    model = MultiNARX(family, output_lags=2, input_lags=3, params=params)
    model.fit(p[:, None], angle[:, None])
    assert (getattr(model, "input_tau_", None) is not None) == bool(params)
    metadata = {"inputs": ["p_kpa"], "outputs": ["angle_deg"], "time": "t_ms", "sample_period": 10}
    path = save_multi_narx(model, tmp_path / f"{family}.json", metadata=metadata)
    plant = identified_plant(path)
    assert plant.sample_period_s == pytest.approx(0.01) and plant.input_scale == 1000.0
    dynamics = plant.dynamics()
    test = rng.uniform(0.0, 2e-4, 300)  # MPa: the model's 0–0.2 kPa
    stepped = [dynamics.advance(q, 0.01) for q in test]
    lag = model.max_lag
    inputs = np.concatenate([np.zeros(lag), test * 1000.0])[:, None]
    rest = np.tile(plant.rest_outputs, (lag, 1))
    free = load_identified(path).free_run(inputs, rest)[lag:, 0]
    assert np.allclose(stepped, free, rtol=1e-9, atol=1e-9 * np.ptp(free))


def test_loop_rig_steps_the_identified_plant(fopdt):
    from softbend.control.runs import plan_loop

    plan = plan_loop(plant=str(fopdt), rig_from=fopdt, reference="step:60:0", duration_s=0.5)
    rig = plan.make_rig()
    assert isinstance(rig.dynamics, NARXAngle)
    assert rig.params.valve_delay_s == pytest.approx(DELAY_S)
    result = plan.run(device=rig)
    assert result.summary["rig_from"]["used"] == ["angle_time_constant_s", "valve_delay_s"]
    assert result.summary["plant_description"].startswith("identified model")


def test_rig_from_refused_on_hardware(fopdt, tmp_path):
    from softbend.control.runs import plan_loop

    with pytest.raises(InputError) as caught:
        plan_loop(rig="modbus", rig_from=fopdt)
    assert caught.value.key == "rig_from" and "hardware" in str(caught.value)


def test_a_steady_state_that_never_rises_is_refused(tmp_path):
    """A model whose angle falls with pressure (its input read with the wrong sign)."""
    falling = save_fopdt(tmp_path / "falling.json", scale=-1.0)
    with pytest.raises(InputError) as caught:
        identified_plant(falling).angle_table(0.2)
    assert caught.value.key == "plant" and "must bend more as the pressure rises" in str(
        caught.value
    )
