"""The model-predictive pulse controller: its pneumatic model, observer and closed loop."""

import math

import numpy as np
import pytest

from softbend.control.controllers import BangBang, PressureRelay
from softbend.control.experiments import run_metrics, simulate
from softbend.control.predictive import PneumaticCurves, PredictivePulse
from softbend.control.rig import RigParams, SimulatedRig


@pytest.fixture(scope="module")
def curves():
    return PneumaticCurves(RigParams())


def test_fill_and_vent_curves_match_the_simulated_rig(table, curves):
    """The tabulated responses are the rig's own ODE (integrated differently)."""
    quiet = RigParams(valve_delay_s=0.0, sensor_noise_mpa=0.0, sensor_bits=0, step_s=0.0002)
    rig = SimulatedRig(table, quiet)
    rig.command(True, False)
    for t in (0.01, 0.03, 0.1, 0.3):
        rig.advance(round((t - rig.t_s) / rig.step_s))
        assert rig.pressure_mpa == pytest.approx(curves.after(0.0, t, (True, False)), abs=2e-4)
    start = rig.pressure_mpa
    rig.command(False, True)
    rig.advance(round(0.05 / rig.step_s))
    assert rig.pressure_mpa == pytest.approx(curves.after(start, 0.05, (False, True)), abs=2e-4)


def test_curves_compose_and_respect_their_bounds(curves):
    fill, vent, shut = (True, False), (False, True), (False, False)
    p = curves.after(0.0, 0.02, fill)
    assert curves.after(p, 0.03, fill) == pytest.approx(curves.after(0.0, 0.05, fill), abs=1e-6)
    assert 0.0 < p < curves.after(p, 0.01, fill) <= 0.2
    assert curves.after(0.15, 0.01, vent) < 0.15 and curves.after(0.15, 10.0, vent) >= 0.0
    assert curves.after(0.123, 5.0, shut) == 0.123
    assert curves.after(0.0, 100.0, fill) == pytest.approx(0.2, abs=1e-3)


def test_one_noisy_sample_does_not_fire_a_pulse(table):
    ctrl = PredictivePulse(table)
    target = ctrl.target_mpa(90.0)
    commands = []
    for k in range(200):
        measured = target + (0.002 if k == 100 else 0.0)  # one 4σ sample, 10 ms long
        for j in range(10):
            commands.append(ctrl.step(measured, 90.0, (10 * k + j) * 0.001))
    assert all(c == (False, False) for c in commands)


def test_a_persistent_error_is_corrected(table):
    ctrl = PredictivePulse(table)
    target = ctrl.target_mpa(90.0)
    seen = set()
    for k in range(50):
        for j in range(10):
            seen.add(ctrl.step(target - 0.01, 90.0, (10 * k + j) * 0.001))
    assert (True, False) in seen


@pytest.mark.parametrize("reference", ["step:90", "square:90:4", "triangle:0.2:90:20"])
def test_predictive_halves_paper_b_bang_bang_with_far_fewer_switches(table, reference):
    def score(controller):
        run = simulate(SimulatedRig(table, RigParams()), controller, reference, 10.0, seed=0)
        return run_metrics(run)

    best = score(PredictivePulse(table))
    paper_b = score(BangBang(table))
    relay = score(PressureRelay(table))
    if reference.startswith("square"):
        # each 0 -> 90° edge costs the fill time at full flow (~0.09 s of a 2 s plateau):
        # no controller of these valves goes below ~3 %, so only "better" is asked here
        assert best["mape_pct"] < paper_b["mape_pct"]
    else:
        assert best["mape_pct"] <= 0.5 * paper_b["mape_pct"]
    assert best["switches"] <= 0.5 * paper_b["switches"]
    assert best["mape_pct"] <= relay["mape_pct"] + 0.1
    assert best["switches"] <= relay["switches"]


def test_on_a_step_it_lands_with_one_pulse(table):
    run = simulate(SimulatedRig(table, RigParams()), PredictivePulse(table), "step:90", 3.0, seed=0)
    m = run_metrics(run)
    assert m["switches"] <= 4 and m["overshoot_pct"] < 3.0 and m["unsettled_edges"] == 0


@pytest.mark.parametrize(
    ("kwargs", "field"),
    [({"observer_gain": 0.0}, "observer_gain"), ({"deadband": -1}, "deadband")],
)
def test_bad_settings_are_one_error(table, kwargs, field):
    with pytest.raises(ValueError, match=f"^{field}: must be a number in "):
        PredictivePulse(table, **kwargs)


def test_predicted_angle_is_the_model_of_the_estimate(table):
    ctrl = PredictivePulse(table)
    ctrl.step(0.05, 90.0, 0.0)
    assert ctrl.predicted_deg == pytest.approx(table(0.05))
    assert not math.isnan(ctrl.predicted_deg)
    assert np.isfinite(ctrl.target_mpa(90.0))
