"""``--rig-param NAME=VALUE`` of ``softbend control simulate``, ``run`` and ``serve``."""

import json

import pytest

from softbend.cli import main

from .conftest import one_error_line


def _simulate(out, *extra):
    return main(["control", "simulate", "--out", str(out), "--duration", "1.5", *extra])


def test_simulate_records_the_rig_parameters_in_effect(tmp_path, capsys):
    out = tmp_path / "run"
    args = ["--rig-param", "valve_delay_s=0.02", "--rig-param", "tubing_mm3=0", "--json"]
    assert _simulate(out, *args) == 0
    capsys.readouterr()
    metrics = json.loads((out / "metrics.json").read_text())
    rig = metrics["rig"]
    assert rig["valve_delay_s"] == 0.02 and rig["supply_gauge_mpa"] == 0.2
    assert rig["volume_mm3"] == pytest.approx(5654.87, abs=0.01)  # the cavity alone, no tubing
    assert rig["sensor_bits"] == 12 and rig["camera_noise_deg"] == 0.2  # defaults filled in
    assert metrics["rig_settings"] == {"valve_delay_s": 0.02, "tubing_mm3": 0.0}


def test_a_valve_delay_changes_the_simulated_run(tmp_path, capsys):
    assert _simulate(tmp_path / "a", "--json") == 0
    assert _simulate(tmp_path / "b", "--json", "--rig-param", "valve_delay_s=0.05") == 0
    capsys.readouterr()
    a = json.loads((tmp_path / "a" / "metrics.json").read_text())["metrics"]
    b = json.loads((tmp_path / "b" / "metrics.json").read_text())["metrics"]
    # valves that switch 45 ms later: bang-bang closes the inlet too late, the angle overshoots
    assert b["overshoot_pct"] > a["overshoot_pct"] + 10.0 and b["mape_pct"] > a["mape_pct"]


@pytest.mark.parametrize(
    ("args", "needles"),
    [
        (
            ["--rig-param", "valve_dealy_s=0.02"],
            ["--rig-param: valve_dealy_s: is not a parameter", "valve_delay_s, "],
        ),
        (["--rig-param", "sensor_bits=high"], ["--rig-param: sensor_bits: must be an integer"]),
        (
            ["--rig-param", "critical_ratio=1.5"],
            ["--rig-param: critical_ratio: must be in [0, 0.95]"],
        ),
        (
            ["--supply", "0.2", "--rig-param", "supply_gauge_mpa=0.3"],
            ["--supply: must equal the rig setting supply_gauge_mpa", "0.2 and 0.3"],
        ),
        (
            ["--rig-param", "supply_gauge_mpa=5"],
            ["--rig-param: supply_gauge_mpa: must be in (0, 2] MPa"],
        ),
    ],
)
def test_bad_rig_parameters_exit_2_with_one_line(tmp_path, capsys, args, needles):
    assert _simulate(tmp_path / "o", *args) == 2
    line = one_error_line(capsys)
    for needle in needles:
        assert needle in line
    assert not (tmp_path / "o").exists()


@pytest.mark.parametrize(
    ("args", "needles"),
    [
        (
            ["--rig-param", "supply_gauge_mpa=400psi"],
            ["--rig-param: supply_gauge_mpa: must be in (0, 2] MPa", "(given as '400psi')"],
        ),
        (
            ["--rig-param", "sensor_noise_mpa=1bars"],
            ["--rig-param: sensor_noise_mpa: unknown pressure unit 'bars'; allowed: Pa, kPa"],
        ),
        (["--rig-param", "tubing_mm3=5kPa"], ["--rig-param: tubing_mm3: must be a number"]),
        (
            ["--supply", "20bars"],
            ["--supply: must be a pressure: a number, optionally with a unit (Pa, kPa, MPa"],
        ),
        (
            ["--supply", "400psi"],
            ["--supply: must be a gauge pressure in (0, 2] MPa", "got 400psi (2.7579 MPa)"],
        ),
        (
            ["--supply", "20psi", "--rig-param", "supply_gauge_mpa=0.2"],
            ["--supply: must equal the rig setting supply_gauge_mpa"],
        ),
    ],
)
def test_bad_pressures_with_units_exit_2_with_one_line(tmp_path, capsys, args, needles):
    assert _simulate(tmp_path / "o", *args) == 2
    line = one_error_line(capsys)
    for needle in needles:
        assert needle in line, line
    assert not (tmp_path / "o").exists()


@pytest.mark.parametrize(
    ("args", "supply_mpa", "noise_mpa"),
    [
        (["--supply", "20psi"], 20 * 6.894757293168e-3, 0.0005),
        (["--supply", "200kPa", "--rig-param", "supply_gauge_mpa=0.2"], 0.2, 0.0005),
        (["--rig-param", "supply_gauge_mpa=3bar", "--rig-param", "sensor_noise_mpa=1kPa"],
         0.3, 0.001),
        (["--supply", "0.15"], 0.15, 0.0005),  # paper B's model is in MPa: a bare number too
    ],
)  # fmt: skip
def test_supply_and_rig_pressures_take_a_unit(tmp_path, capsys, args, supply_mpa, noise_mpa):
    assert _simulate(tmp_path / "o", *args, "--json") == 0
    rig = json.loads(capsys.readouterr().out)["rig"]
    assert rig["supply_gauge_mpa"] == pytest.approx(supply_mpa, rel=1e-12)
    assert rig["sensor_noise_mpa"] == pytest.approx(noise_mpa, rel=1e-12)


def test_the_same_supply_twice_is_accepted(tmp_path, capsys):
    args = ["--supply", "0.25", "--rig-param", "supply_gauge_mpa=0.25", "--json"]
    assert _simulate(tmp_path / "o", *args) == 0
    assert json.loads(capsys.readouterr().out)["rig"]["supply_gauge_mpa"] == 0.25


def test_run_takes_the_simulation_table_and_rig_param_overrides_it(tmp_path, capsys):
    config = tmp_path / "rig.toml"
    assert main(["control", "rig-config", "--out", str(config)]) == 0
    with config.open("a", encoding="utf-8") as f:
        f.write("\n[simulation]\nvalve_delay_s = 0.01\ncamera_noise_deg = 0.5\n")
    out = tmp_path / "run"
    args = ["control", "run", "--config", str(config), "--duration", "0.3", "--out", str(out)]
    assert main([*args, "--rig-param", "valve_delay_s=0.02", "--json"]) == 0
    capsys.readouterr()
    summary = json.loads((out / "run.json").read_text())
    assert summary["rig_params"]["valve_delay_s"] == 0.02  # --rig-param over the table
    assert summary["rig_params"]["camera_noise_deg"] == 0.5  # the table's
    assert summary["rig_settings"] == {"valve_delay_s": 0.02, "camera_noise_deg": 0.5}


def test_run_refuses_rig_param_with_a_hardware_rig(tmp_path, capsys):
    config = tmp_path / "rig.toml"
    assert main(["control", "rig-config", "--out", str(config)]) == 0
    capsys.readouterr()
    args = ["control", "run", "--rig", "modbus", "--config", str(config), "--out", "o"]
    assert main([*args, "--rig-param", "valve_delay_s=0.02"]) == 2
    line = one_error_line(capsys)
    assert line.startswith("softbend: error: --rig-param: set the simulated rig")
    assert "the rig modbus is hardware" in line


def test_rig_parameters_lists_every_name(capsys):
    assert main(["control", "rig-parameters", "--json"]) == 0
    rows = json.loads(capsys.readouterr().out)
    names = {r["name"] for r in rows}
    assert {"valve_delay_s", "tubing_mm3", "critical_ratio", "sensor_noise_mpa"} <= names
    assert main(["control", "simulate", "--help"]) == 0
    assert "'controlrig-parameters'" in "".join(capsys.readouterr().out.split())
