import numpy as np
import pytest

from softbend.control.controllers import BangBang, PressurePI, PressureRelay, ValveCommand
from softbend.control.experiments import run_metrics, simulate
from softbend.control.rig import SimulatedRig


def angle_sensor(p):
    return 1000.0 * p  # 0.1 MPa -> 100°


@pytest.mark.parametrize("mode", ["hold", "closed"])
def test_bang_bang_deadzone_rule(mode):
    c = BangBang(angle_sensor, mode=mode)
    # θr = 100: dz = 5°
    assert c.step(0.090, 100.0, 0.00) == ValveCommand(True, False)  # θd = 10 > 5
    assert c.predicted_deg == pytest.approx(90.0)
    assert c.step(0.110, 100.0, 0.01) == ValveCommand(False, True)  # θd = -10 < -5
    inside = c.step(0.097, 100.0, 0.02)  # θd = 3: in the deadzone
    expected = ValveCommand(False, True) if mode == "hold" else ValveCommand(False, False)
    assert inside == expected
    assert c.step(0.0955, 100.0, 0.03) == ValveCommand(False, mode == "hold")  # θd = 4.5
    assert c.step(0.0949, 100.0, 0.04) == ValveCommand(True, False)  # θd = 5.1


def test_bang_bang_samples_at_its_period_and_resets():
    c = BangBang(angle_sensor)
    assert c.step(0.0, 100.0, 0.0).inlet
    # between samples the decision is held even if the reading changes
    assert c.step(0.2, 100.0, 0.005).inlet
    assert c.step(0.2, 100.0, 0.01).outlet
    c.reset()
    assert c.step(0.0, 100.0, 0.011).inlet


def test_controller_validation():
    with pytest.raises(ValueError, match="mode: must be one of 'hold', 'closed'"):
        BangBang(angle_sensor, mode="open")
    with pytest.raises(ValueError, match=r"deadzone: must be a number in \[0, 0.5\]"):
        BangBang(angle_sensor, deadzone=-0.1)
    with pytest.raises(ValueError, match="angle_table: must be an AngleTable"):
        PressurePI(angle_sensor)
    with pytest.raises(ValueError, match="virtual_sensor: must be callable"):
        BangBang(0.5)


def test_pressure_pi_pwm_duty(table):
    c = PressurePI(table, kp=10.0, ki=0.0, pwm_period=0.02)
    target = table.inverse(90.0)
    # error 0.05 MPa -> u = 0.5 -> inlet open for 10 of 20 ms
    states = [c.step(target - 0.05, 90.0, i * 0.001).inlet for i in range(20)]
    assert sum(states) == 10 and all(states[:10])
    # inside the deadband: shut
    c.reset()
    assert c.step(target, 90.0, 0.0) == ValveCommand(False, False)


def _step_run(table, controller):
    rig = SimulatedRig(table, seed=1)
    run = simulate(rig, controller, "step:90", 3.0)
    return run_metrics(run)


def test_pi_beats_bang_bang_on_a_step(table):
    bang = _step_run(table, BangBang(table))
    pi = _step_run(table, PressurePI(table))
    assert pi["mape_pct"] < 0.7 * bang["mape_pct"]
    assert pi["switches"] * 5 < bang["switches"]
    assert pi["settling_s"] < 0.5
    assert pi["rise_s"] < 0.2


def test_relay_settles_a_step_with_few_switches(table):
    m = _step_run(table, PressureRelay(table))
    bang = _step_run(table, BangBang(table))
    assert m["switches"] <= 30 and m["switches"] * 4 < bang["switches"]
    assert m["mape_pct"] < 5.0
    assert m["settling_s"] < 0.5


def test_loop_settles_on_known_plant(table):
    """With θ linear in p, the PI holds the true angle within the 5 % band at the end."""
    rig = SimulatedRig(table, seed=2)
    run = simulate(rig, PressurePI(table), "step:120:0.2", 2.0)
    tail = run.angle_deg[run.t_s > 1.5]
    assert np.all(np.abs(tail - 120.0) < 6.0)
    # valves shut at rest: no air drawn in the last half second
    assert not run.inlet[run.t_s > 1.5].any()
