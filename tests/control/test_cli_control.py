"""``softbend control simulate`` in-process."""

import json

import pytest

from softbend.cli import main


def test_bad_controller_is_one_line(capsys):
    code = main(["control", "simulate", "--out", "x", "--controller", "pid"])
    assert code == 2
    err = capsys.readouterr().err.strip().splitlines()
    assert len(err) == 1 and "--controller: Unknown controller 'pid'" in err[0]
    assert "known: bang-bang, bang-bang-closed, pressure-pi, pressure-relay, predictive" in err[0]


def test_bad_reference_is_one_line(capsys):
    assert main(["control", "simulate", "--out", "x", "--reference", "step:x"]) == 2
    assert "--reference: amplitude_deg of the step must be" in capsys.readouterr().err


@pytest.mark.parametrize("command", ["simulate", "run"])
def test_a_bad_sine_reference_is_one_line_with_the_expected_form(tmp_path, capsys, command):
    out = tmp_path / "o"
    assert main(["control", command, "--out", str(out), "--reference", "sine:60:4:x"]) == 2
    err = capsys.readouterr().err.strip().splitlines()
    assert len(err) == 1 and err[0].startswith("softbend: error: --reference: offset_deg of"), err
    assert "(sine:AMP:PERIOD_S[:OFFSET])" in err[0] and not out.exists()


@pytest.mark.parametrize("controller", ["bang-bang", "pressure-pi"])
def test_simulate_writes_run(tmp_path, capsys, controller):
    out = tmp_path / "run"
    code = main(
        [
            "control",
            "simulate",
            "--out",
            str(out),
            "--duration",
            "1.5",
            "--controller",
            controller,
            "--json",
        ]
    )
    assert code == 0
    payload = json.loads(capsys.readouterr().out)
    assert payload["synthetic"] is True and payload["metrics"]["rising_edges"] == 1
    assert (out / "run.csv").read_text().startswith("t_s,reference_deg,angle_deg")
    assert json.loads((out / "metrics.json").read_text())["controller"] == controller


@pytest.mark.parametrize(
    ("args", "needles"),
    [
        (
            ["run", "--rig", "usb"],
            ["--rig: Unknown rig 'usb'; known: sim, sim-realtime, modbus"],
        ),
        (["run", "--rig", "modbus"], ["--config: must name a rig TOML file"]),
        (["run", "--log-format", "xml"], ["--log-format:", "'parquet'"]),
        (["run", "--period", "0.02", "--sensor-period", "0.01"], ["--sensor-period:"]),
        (["run", "--duration", "-1"], ["--duration: must be a number in (0, 86400]"]),
        (["run", "--rig", "modbus", "--config", "nope.toml"], ["does not exist"]),
        (["serve", "--config", "nope.toml"], ["does not exist"]),
        (["serve", "--duration", "-2"], ["--duration: must be a number in [0, inf)"]),
        (["serve", "--port", "70000"], ["--port: must be an integer in [0, 65535]"]),
        (
            ["simulate", "--plant", "lab", "--design", "160,10,4,4,15,12"],
            ["--plant: ", "has no measured loading curve"],
        ),
        (["simulate", "--plant", "fem", "--design", "0,6,2,2,5,8"], ["--design: l_mm"]),
    ],
)
def test_bad_input_of_every_control_command_is_one_line(tmp_path, capsys, args, needles):
    out = [] if args[0] == "serve" else ["--out", str(tmp_path / "o")]
    code = main(["control", *args, *out])
    assert code == 2
    err = capsys.readouterr().err.strip().splitlines()
    assert len(err) == 1, err
    for needle in needles:
        assert needle in err[0]


def test_a_rig_config_with_an_unknown_key_is_one_line(tmp_path, capsys):
    config = tmp_path / "rig.toml"
    config.write_text("[pressure]\nadress = 3\n")
    code = main(["control", "run", "--rig", "modbus", "--config", str(config), "--out", "o"])
    assert code == 2
    assert f"{config}:2: pressure.adress: is not a key of [pressure]" in capsys.readouterr().err


def test_rig_config_writes_a_template_that_loads_and_refuses_a_folder(tmp_path, capsys):
    from softbend.control.rigconfig import load_rig_config

    path = tmp_path / "rig.toml"
    assert main(["control", "rig-config", "--out", str(path), "--port", "5099"]) == 0
    assert load_rig_config(path).connection.port == 5099
    assert main(["control", "rig-config", "--out", str(tmp_path)]) == 2
    assert "--out" in capsys.readouterr().err


def test_run_on_the_simulated_rig_writes_its_log(tmp_path, capsys):
    out = tmp_path / "run"
    args = ["control", "run", "--controller", "predictive", "--duration", "1", "--out", str(out)]
    assert main([*args, "--log-format", "parquet", "--json"]) == 0
    payload = json.loads(capsys.readouterr().out)
    assert payload["completed"] and payload["rig"] == "sim"
    assert (out / "ticks.parquet").is_file() and (out / "run.png").is_file()


def test_simulate_tracks_a_sine_reference_scored_by_its_delay(tmp_path, capsys):
    out = tmp_path / "run"
    args = ["control", "simulate", "--reference", "sine:60:1:10", "--duration", "1.5"]
    assert main([*args, "--out", str(out), "--json"]) == 0
    payload = json.loads(capsys.readouterr().out)
    assert payload["reference"] == "sine:60:1:10"
    assert payload["metrics"]["delay_s"] is not None and "rising_edges" not in payload["metrics"]
    lines = (out / "run.csv").read_text().splitlines()
    references = [float(line.split(",")[1]) for line in lines[1:]]
    assert min(references) == pytest.approx(10) and max(references) == pytest.approx(60, abs=0.1)
