"""The identified model read physically (gain, τ, delay) and run on a new input."""

from __future__ import annotations

import json
import math
import sys

import numpy as np
import pytest

from softbend.errors import InputError, SchemaError
from softbend.identification import dynamics
from softbend.identification.dynamics import (
    IdentifiedModel,
    is_identified_model,
    load_identified,
    seconds_per_unit,
    step_readings,
    unit_from_name,
)
from softbend.identification.multi import _FORMAT, MultiNARX, save_multi_narx
from softbend.identification.timeseries_io import SAMPLE_TIME_NAME

A, B, DELAY, DT = 0.9, 0.5, 3, 0.01  # y(t) = a·y(t−1) + b·u(t−d), sampled every 10 ms


def _first_order(n: int = 900, seed: int = 0) -> tuple[np.ndarray, np.ndarray]:
    """Random steps through a first-order system with dead time (noise-free)."""
    u = np.repeat(np.random.default_rng(seed).uniform(0.0, 10.0, n // 30), 30)
    y = np.zeros(n)
    for t in range(1, n):
        y[t] = A * y[t - 1] + (B * u[t - DELAY] if t >= DELAY else 0.0)
    return u, y


@pytest.fixture(scope="module")
def fopdt() -> IdentifiedModel:
    u, y = _first_order()
    model = MultiNARX("arx", output_lags=1, input_lags=DELAY + 1).fit(u[:, None], y[:, None])
    return IdentifiedModel(model, {}, ("p_kpa",), ("x_mm",), "time_s", DT, 1.0)


def test_the_step_reading_recovers_gain_time_constant_and_delay(fopdt):
    (reading,) = step_readings(fopdt)
    assert (reading.input, reading.output, reading.gain_unit) == ("p_kpa", "x_mm", "mm/kPa")
    assert reading.gain == pytest.approx(B / (1 - A), rel=1e-4)
    assert reading.note == ""
    tau = -DT / math.log(A)  # 94.9 ms
    assert reading.time_constant == pytest.approx(tau, rel=1e-3)
    assert abs(reading.delay - DELAY * DT) < DT
    assert reading.time_constant_s == reading.time_constant and reading.delay_s == reading.delay
    assert reading.step == pytest.approx(fopdt.model.u_std_[0])
    record = reading.to_dict()
    assert record["gain_unit"] == "mm/kPa" and record["delay_s"] == pytest.approx(DELAY * DT)


def test_times_without_a_known_unit_have_no_seconds(fopdt):
    samples = IdentifiedModel(fopdt.model, {}, ("u",), ("y",), SAMPLE_TIME_NAME, 1.0, None)
    (reading,) = step_readings(samples)
    assert abs(reading.delay - DELAY) < 1 and reading.delay_s is None
    assert reading.time_constant == pytest.approx(-1 / math.log(A), rel=1e-3)
    assert reading.time_constant_s is None
    assert samples.sample_period_s is None and reading.gain_unit == ""


def test_steady_state_is_the_closed_form_gain(fopdt):
    for u in (0.0, 2.0, 7.5):
        assert fopdt.steady_state([u]) == pytest.approx([B / (1 - A) * u], abs=1e-5)


def test_free_run_is_the_model_simulation(fopdt):
    u, y = _first_order(seed=1)
    lag = fopdt.max_lag
    from_measured = fopdt.free_run(u[:, None], y[:lag, None])
    np.testing.assert_array_equal(from_measured, fopdt.model.simulate(u[:, None], y[:, None]))
    assert np.max(np.abs(from_measured[:, 0] - y)) < 1e-6 * np.ptp(y) * 100  # the true system
    # from rest: the first input's steady state, held until the input changes
    at_rest = fopdt.free_run(u)
    np.testing.assert_allclose(at_rest[: lag + DELAY, 0], B / (1 - A) * u[0], atol=1e-5)


def test_bad_inputs_name_the_argument(fopdt):
    with pytest.raises(InputError) as err:
        fopdt.free_run(np.zeros((10, 2)))
    assert err.value.key == "inputs"
    with pytest.raises(InputError) as err:
        fopdt.free_run(np.zeros(10), np.zeros((1, 1)))
    assert err.value.key == "initial_outputs"
    with pytest.raises(InputError) as err:
        fopdt.free_run(np.zeros(2))
    assert err.value.key == "inputs" and "max_lag + 1" in str(err.value)


def test_a_response_that_never_settles_is_none_with_the_reason():
    # an integrator: y(t) = y(t−1) + 0.1·u(t−1), the output drifts (to the free-run bound)
    u = np.repeat(np.random.default_rng(3).uniform(-1.0, 1.0, 20), 30)
    y = np.concatenate(([0.0], np.cumsum(0.1 * u[:-1])))
    model = MultiNARX("arx", output_lags=1, input_lags=2).fit(u[:, None], y[:, None])
    identified = IdentifiedModel(model, {}, ("u",), ("y",), "t_ms", 2.0, 1e-3)
    (reading,) = step_readings(identified)
    assert math.isnan(reading.gain) and reading.time_constant is None and reading.delay is None
    assert reading.note in {"diverges", "does not settle", "no steady operating point"}
    assert reading.to_dict()["gain"] is None


def test_a_model_with_no_response_says_so():
    # two inputs, the second one has no effect on the output
    rng = np.random.default_rng(4)
    U = np.repeat(rng.uniform(0.0, 1.0, (20, 2)), 25, axis=0)
    y = np.zeros(len(U))
    for t in range(1, len(U)):
        y[t] = 0.5 * y[t - 1] + U[t - 1, 0]
    model = MultiNARX("arx", output_lags=1, input_lags=2).fit(U, y[:, None])
    identified = IdentifiedModel(model, {}, ("a", "b"), ("y",), "time_s", 1.0, 1.0)
    first, second = step_readings(identified)
    assert first.gain == pytest.approx(2.0, rel=1e-3) and first.note == ""
    assert first.time_constant == pytest.approx(-1 / math.log(0.5), rel=1e-3)
    assert first.delay == 1.0
    # a least-squares fit leaves a tiny coefficient: either no response or a tiny gain
    assert second.note == "no response" or abs(second.gain) < 1e-4


def test_units_from_column_names():
    assert [unit_from_name(n) for n in ("p1_kpa", "x_mm", "rho", "angle_DEG", "a_b")] == [
        "kPa",
        "mm",
        "",
        "deg",
        "",
    ]
    assert seconds_per_unit("time_s") == 1.0 and seconds_per_unit("t_ms") == 1e-3
    assert seconds_per_unit("clock_min") == 60.0
    assert seconds_per_unit("sample") is None and seconds_per_unit("t") is None
    assert seconds_per_unit("x_mm") is None


def test_saved_and_loaded_with_its_names_and_timing(fopdt, tmp_path):
    metadata = {"inputs": ["p_kpa"], "outputs": ["x_mm"], "time": "t_ms", "sample_period": 10.0,
                "time_unit_s": 1e-3}  # fmt: skip
    path = save_multi_narx(fopdt.model, tmp_path / "model.json", metadata=metadata)
    assert is_identified_model(path)
    again = load_identified(path)
    assert (again.input_names, again.output_names, again.time_name) == (
        ("p_kpa",),
        ("x_mm",),
        "t_ms",
    )
    assert again.sample_period == 10.0 and again.sample_period_s == pytest.approx(0.01)
    u, _ = _first_order(seed=2)
    np.testing.assert_array_equal(again.free_run(u), fopdt.free_run(u))
    (reading,) = step_readings(again)
    assert reading.delay == pytest.approx(DELAY * 10.0) and reading.delay_s == pytest.approx(0.03)


def test_a_model_saved_before_the_timing_was_recorded_loads(fopdt, tmp_path):
    path = save_multi_narx(fopdt.model, tmp_path / "old.json", metadata={"inputs": ["p"],
                           "outputs": ["x"]})  # fmt: skip
    old = load_identified(path)
    assert old.time_name == "sample" and old.sample_period == 1.0 and old.time_unit_s is None
    bare = load_identified(save_multi_narx(fopdt.model, tmp_path / "bare.json"))
    assert bare.input_names == ("u1",) and bare.output_names == ("y1",)


@pytest.mark.parametrize(
    ("metadata", "key"),
    [
        ({"inputs": ["a", "b"]}, "metadata.inputs"),
        ({"outputs": "x"}, "metadata.outputs"),
        ({"sample_period": 0}, "metadata.sample_period"),
        ({"sample_period": True}, "metadata.sample_period"),
        ({"time": "t_s", "time_unit_s": -1}, "metadata.time_unit_s"),
        ({"time": ""}, "metadata.time"),
    ],
)
def test_a_broken_entry_is_a_schema_error_naming_file_and_key(fopdt, tmp_path, metadata, key):
    path = save_multi_narx(fopdt.model, tmp_path / "broken.json", metadata=metadata)
    with pytest.raises(SchemaError) as err:
        load_identified(path)
    assert err.value.key == key and err.value.file == str(path)


def test_is_identified_model_reads_only_json_of_the_format(fopdt, tmp_path):
    assert not is_identified_model(tmp_path / "missing.json")
    other = tmp_path / "other.json"
    other.write_text(json.dumps({"format": "softbend-surrogate"}))
    assert not is_identified_model(other)
    other.write_text(json.dumps({"format": "softbend-surrogate", "note": _FORMAT}))
    assert not is_identified_model(other)
    (tmp_path / "broken.json").write_text("{")
    assert not is_identified_model(tmp_path / "broken.json")
    csv = tmp_path / "model.csv"
    csv.write_text(json.dumps({"format": _FORMAT}))
    assert not is_identified_model(csv)


def test_the_module_is_light_and_agrees_with_the_saved_format():
    assert dynamics._FORMAT == _FORMAT and dynamics.SAMPLE_TIME_NAME == SAMPLE_TIME_NAME
    import subprocess

    code = "import sys, softbend.identification.dynamics; print('sklearn' in sys.modules)"
    out = subprocess.run([sys.executable, "-c", code], capture_output=True, text=True, check=True)
    assert out.stdout.strip() == "False"
