import math

import numpy as np
import pytest

from softbend.control.experiments import (
    ControlRun,
    cross_correlation_delay_s,
    parse_reference,
    rise_time_s,
    run_metrics,
)


def test_parse_references():
    step = parse_reference("step:90")
    assert step.values(np.array([0.0, 0.49, 0.5, 3.0])).tolist() == [0, 0, 90, 90]
    square = parse_reference("square:80:2:10")
    assert square.values(np.array([0.5, 1.5, 2.5])).tolist() == [10, 80, 10]
    tri = parse_reference("triangle:0.2:90")
    assert tri.values(np.array([0.0, 1.25, 2.5, 5.0])) == pytest.approx([0, 45, 90, 0])


def test_a_sine_swings_from_its_offset_at_rest_to_its_amplitude_at_half_a_period():
    sine = parse_reference("sine:60:4:20")
    t = np.array([0.0, 1.0, 2.0, 3.0, 4.0, 0.5])
    expected = [20, 40, 60, 40, 20, 20 + 40 * (1 - np.cos(np.pi / 4)) / 2]
    assert sine.values(t) == pytest.approx(expected)
    assert str(sine) == "sine:60:4:20" and sine.kind == "sine"
    assert parse_reference("sine:30:2").values(np.array([0.0, 1.0])) == pytest.approx([0, 30])


@pytest.mark.parametrize(
    ("spec", "message"),
    [
        ("ramp:90", "reference: kind must be one of 'step', 'square', 'triangle'"),
        ("90", "reference: must be one of"),
        ("step:abc", "reference: amplitude_deg of the step must be a number"),
        ("step:-5", "reference: amplitude_deg of the step must be a number in \\(0, 720\\]"),
        ("square:90", "reference: square takes 2–3 values"),
        ("triangle:0:90", "reference: freq_hz of the triangle must be a number in \\(0, 50\\]"),
        ("square:90:2:95", "reference: low_deg of the square must be below its amplitude_deg"),
        ("sine:60", r"reference: sine takes 2–3 values \(sine:AMP:PERIOD_S\[:OFFSET\]\)"),
        (
            "sine:60:x",
            r"period_s of the sine must be a number in \(0, 3600\]; got \"x\" "
            r"\(sine:AMP:PERIOD_S\[:OFFSET\]\)",
        ),
        ("sine:60:4:70", "reference: offset_deg of the sine must be below its amplitude_deg"),
        ("sine:60:4:-1", r"offset_deg of the sine must be a number in \[0, 720\]"),
        ("cos:60:4", "reference: kind must be one of 'step', 'square', 'triangle', 'sine'"),
    ],
)
def test_parse_reference_errors_name_the_field(spec, message):
    with pytest.raises(ValueError, match=message):
        parse_reference(spec)


def test_rise_time_of_known_ramp():
    t = np.linspace(0, 2, 2001)
    y = np.clip((t - 0.5) / 1.0, 0, 1) * 50.0  # 0 -> 50 from 0.5 s to 1.5 s
    assert rise_time_s(t, y, 0.0, 50.0) == pytest.approx(0.8, abs=1e-9)
    assert math.isnan(rise_time_s(t, y * 0.5, 0.0, 50.0))


def test_delay_of_shifted_triangle():
    t = np.arange(0, 10, 0.001)
    ref = parse_reference("triangle:0.2:90:20")
    for delay in (0.0, 0.0875, 0.25):
        found = cross_correlation_delay_s(t, ref.values(t), ref.values(t - delay))
        assert found == pytest.approx(delay, abs=1e-3)


def _run(t, r, y, reference):
    n = len(t)
    zeros = np.zeros(n)
    off = np.zeros(n, dtype=bool)
    return ControlRun(t, r, y, y, y, zeros, zeros, off, off, 0.0, 0, 1.0, reference=reference)


def test_metrics_of_synthetic_step():
    t = np.arange(1, 3001) * 0.001
    ref = parse_reference("step:100:0.5")
    r = ref.values(t)
    # first-order response, τ = 0.1 s, from the edge
    y = np.where(t >= 0.5, 100.0 * (1 - np.exp(-(t - 0.5) / 0.1)), 0.0)
    m = run_metrics(_run(t, r, y, ref))
    assert m["rise_s"] == pytest.approx(0.1 * math.log(9), abs=2e-3)
    assert m["settling_s"] == pytest.approx(0.1 * math.log(20), abs=2e-3)
    assert m["overshoot_pct"] == 0.0
    ok = r >= 5
    assert m["mape_pct"] == pytest.approx(np.mean(np.abs(y[ok] - 100) / 100) * 100)
