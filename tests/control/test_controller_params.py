"""Controller parameters by name: ``make_controller(**params)``, ``--set``, TOML [controller]."""

import json

import pytest

from softbend.cli import main
from softbend.control import CONTROLLERS, PLANTS, RIGS
from softbend.control.experiments import run_metrics, simulate
from softbend.control.factory import controller_parameters, make_controller
from softbend.control.rig import RigParams, SimulatedRig
from softbend.control.rigconfig import ControllerConfig, RigConfig, load_rig_config
from softbend.control.study import control_study
from softbend.design import sfrba_design
from softbend.parameters import parse_assignments
from softbend.registry import Registry, UnknownNameError

BANG_BANG = "known: deadzone, period"
UNKNOWN = "deadzon: is not a parameter"


def _line(capsys):
    err = capsys.readouterr().err.strip().splitlines()
    assert len(err) == 1, err
    assert err[0].startswith("softbend: error: ")
    return err[0]


def test_the_extension_points_are_registries():
    assert isinstance(CONTROLLERS, Registry) and isinstance(PLANTS, Registry)
    assert isinstance(RIGS, Registry)
    assert CONTROLLERS.names() == (
        "bang-bang", "bang-bang-closed", "pressure-pi", "pressure-relay", "predictive",
    )  # fmt: skip
    assert PLANTS.names() == ("surrogate", "fem", "lab")
    assert RIGS.names() == ("sim", "sim-realtime", "modbus")


def test_make_controller_passes_the_parameters(table):
    controller = make_controller("bang-bang", table, deadzone=0.02)
    assert controller.deadzone == 0.02 and controller.mode == "hold"
    assert make_controller("bang-bang-closed", table).mode == "closed"
    pi = make_controller("pressure-pi", table, kp=20, ki=1.5, deadband=0.001, pwm_period=0.05)
    assert (pi.kp, pi.ki, pi.deadband, pi.pwm_period) == (20.0, 1.5, 0.001, 0.05)
    relay = make_controller("pressure-relay", table, hysteresis=0.003, lead=0.02, min_on=0.01)
    assert (relay.hysteresis, relay.lead, relay.min_on) == (0.003, 0.02, 0.01)
    rig = RigParams()
    predictive = make_controller("predictive", table, None, rig, observer_gain=0.5, preview=0.1)
    assert (predictive.observer_gain, predictive.preview, predictive.params) == (0.5, 0.1, rig)


def test_the_registry_holds_the_classes_under_their_own_parameter_names():
    from softbend.control.controllers import BangBang, BangBangClosed, PressurePI, PressureRelay
    from softbend.control.predictive import PredictivePulse

    assert dict(CONTROLLERS.items()) == {
        "bang-bang": BangBang, "bang-bang-closed": BangBangClosed, "pressure-pi": PressurePI,
        "pressure-relay": PressureRelay, "predictive": PredictivePulse,
    }  # fmt: skip


def test_defaults_give_the_same_run_as_the_classes(table):
    from softbend.control.controllers import BangBang
    from softbend.control.predictive import PredictivePulse

    def score(controller):
        run = simulate(SimulatedRig(table, RigParams(), seed=0), controller, "step:90", 1.0)
        metrics = run_metrics(run)
        del metrics["realtime_factor"]  # wall-clock speed
        return metrics, run.frame().to_dict(orient="list")

    assert score(make_controller("bang-bang", table)) == score(BangBang(table, mode="hold"))
    rig = RigParams()
    assert score(make_controller("predictive", table, None, rig)) == score(
        PredictivePulse(table, rig)
    )


@pytest.mark.parametrize(
    ("values", "needle"),
    [
        ({"deadzon": 0.1}, f"deadzon: is not a parameter; {BANG_BANG}"),
        ({"deadzone": "a lot"}, "deadzone: must be a number; got 'a lot'"),
        ({"deadzone": True}, "deadzone: must be a number; got True"),
    ],
)  # fmt: skip
def test_bad_parameters_are_one_error(values, needle):
    with pytest.raises(ValueError) as caught:
        controller_parameters("bang-bang", values)
    assert needle in str(caught.value)


def test_text_values_are_parsed_by_kind():
    assert controller_parameters("bang-bang", {"deadzone": "0.02"}, from_text=True) == {
        "deadzone": 0.02, "period": 0.01,
    }  # fmt: skip
    assert controller_parameters("pressure-pi", {"kp": "30"}, from_text=True)["kp"] == 30.0
    with pytest.raises(ValueError, match=r"deadzone: must be a finite number; got 'nan'"):
        controller_parameters("bang-bang", {"deadzone": "nan"}, from_text=True)
    assert parse_assignments(["a=1", " b = x "]) == {"a": "1", "b": "x"}
    with pytest.raises(ValueError, match="must be NAME=VALUE"):
        parse_assignments(["deadzone"])
    with pytest.raises(ValueError, match="'deadzone' is given twice"):
        parse_assignments(["deadzone=1", "deadzone=2"])


def test_set_deadzone_changes_the_run_and_is_recorded(tmp_path, capsys):
    def run(*extra):
        out = tmp_path / f"run{len(extra)}"
        args = ["control", "simulate", "--out", str(out), "--duration", "1.5", "--json"]
        assert main([*args, "--controller", "bang-bang", *extra]) == 0
        payload = json.loads(capsys.readouterr().out)
        assert (
            json.loads((out / "metrics.json").read_text())["controller_params"]
            == (payload["controller_params"])
        )
        return payload

    default, narrow = run(), run("--set", "deadzone=0.02")
    assert default["controller_params"] == {"deadzone": 0.05, "period": 0.01}
    assert narrow["controller_params"] == {"deadzone": 0.02, "period": 0.01}
    assert narrow["metrics"] != default["metrics"]
    assert narrow["metrics"]["switches"] > default["metrics"]["switches"]


@pytest.mark.parametrize(
    ("args", "needles"),
    [
        (["--set", "deadzon=0.02"], [f"--set: {UNKNOWN}", BANG_BANG]),
        (
            ["--controller", "pressure-pi", "--set", "kd=1"],
            ["--set: kd: is not a parameter; known: kp, ki, deadband, pwm_period, period"],
        ),
        (["--set", "deadzone=wide"], ["--set: deadzone: must be a number; got 'wide'"]),
        (["--set", "deadzone=2"], ["--set: deadzone: must be in [0, 0.5] fraction of"]),
        (["--set", "deadzone"], ["--set: ", "must be NAME=VALUE"]),
        (["--controller", "pid"], ["--controller: Unknown controller 'pid'; known: bang"]),
        (["--plant", "camera"], ["--plant: Unknown plant 'camera'; known: surrogate, fem"]),
    ],
)  # fmt: skip
@pytest.mark.parametrize("command", ["simulate", "run"])
def test_bad_names_and_parameters_are_one_line(tmp_path, capsys, command, args, needles):
    assert main(["control", command, "--out", str(tmp_path / "o"), *args]) == 2
    line = _line(capsys)
    for needle in needles:
        assert needle in line
    assert not (tmp_path / "o").exists()


def test_an_unknown_rig_is_one_line(tmp_path, capsys):
    assert main(["control", "run", "--out", str(tmp_path / "o"), "--rig", "usb"]) == 2
    assert "--rig: Unknown rig 'usb'; known: sim, sim-realtime, modbus." in _line(capsys)


def _toml(tmp_path, table):
    path = tmp_path / "rig.toml"
    path.write_text(f"[pressure]\naddress = 0\nscale = 1e-4\n\n[controller]\n{table}")
    return path


def test_a_controller_table_is_applied_and_set_overrides_it(tmp_path, capsys):
    config = _toml(tmp_path, 'name = "pressure-relay"\nhysteresis = 0.004\nmin_on = 0.01\n')
    loaded = load_rig_config(config)
    assert loaded.controller == ControllerConfig(
        "pressure-relay", {"hysteresis": 0.004, "min_on": 0.01}
    )
    assert load_rig_config(_write(tmp_path, loaded.to_toml())) == loaded  # written back whole
    base = ["control", "run", "--config", str(config), "--duration", "0.5", "--json"]
    assert main([*base, "--out", str(tmp_path / "a"), "--set", "min_on=0.02"]) == 0
    payload = json.loads(capsys.readouterr().out)
    assert payload["controller"] == "pressure-relay"
    assert payload["controller_params"] == {
        "hysteresis": 0.004, "lead": 0.012, "min_on": 0.02, "period": 0.01,
    }  # fmt: skip
    assert '[controller]\nname = "pressure-relay"' in payload["rig_config"]
    # another controller on the command line: the table's parameters are not its own
    assert main([*base, "--out", str(tmp_path / "b"), "--controller", "bang-bang"]) == 0
    captured = capsys.readouterr()
    assert json.loads(captured.out)["controller_params"] == {
        "deadzone": 0.05, "period": 0.01,
    }  # fmt: skip
    # ... and saying so, not silently
    assert "sets parameters of 'pressure-relay', but --controller is 'bang-bang'" in captured.err


def _write(tmp_path, text):
    path = tmp_path / "again.toml"
    path.write_text(text)
    return path


@pytest.mark.parametrize(
    ("table", "needles"),
    [
        ('name = "pid"\n', [":6: controller.name: Unknown controller 'pid'", "known: bang-bang,"]),
        ('name = "bang-bang"\ndeadzon = 0.1\n', [":7: controller.deadzon: is not a", BANG_BANG]),
        ('name = "bang-bang"\ndeadzone = "5 %"\n', [":7: controller.deadzone: must be a number"]),
        ("deadzone = 0.1\n", [":5: [controller]: must give 'name'"]),
        ("name = 3\n", [":6: controller.name: must be a string"]),
    ],
)  # fmt: skip
def test_a_bad_controller_table_is_one_line_naming_its_line(tmp_path, capsys, table, needles):
    config = _toml(tmp_path, table)
    assert main(["control", "run", "--config", str(config), "--out", str(tmp_path / "o")]) == 2
    line = _line(capsys)
    assert str(config) in line
    for needle in needles:
        assert needle in line


def test_a_controller_table_out_of_range_is_refused_with_its_line(tmp_path, capsys):
    config = _toml(tmp_path, 'name = "bang-bang"\ndeadzone = 1.5\n')
    assert main(["control", "run", "--config", str(config), "--out", str(tmp_path / "o")]) == 2
    line = _line(capsys)
    assert f"{config}:7: controller.deadzone: must be in [0, 0.5]" in line


def test_the_config_dataclass_checks_its_controller():
    with pytest.raises(UnknownNameError, match="Unknown controller 'pid'"):
        RigConfig(controller=ControllerConfig("pid"))
    assert RigConfig().controller is None


class Linear:
    def predict(self, rows):
        return 6.0 + 1200.0 * rows[:, -1]


def test_the_study_takes_controller_parameters():
    design = sfrba_design(100, 6, 2, 2, 5, 8)
    kwargs = {"controllers": ("bang-bang",), "references": ("step:90",), "duration_s": 1.5}
    default = control_study(Linear(), design, **kwargs)
    narrow = control_study(
        Linear(), design, controller_params={"bang-bang": {"deadzone": 0.02}}, **kwargs
    )
    assert default.settings["controllers"] == {"bang-bang": {"deadzone": 0.05, "period": 0.01}}
    assert narrow.settings["controllers"]["bang-bang"]["deadzone"] == 0.02
    assert narrow.metric("bang-bang", "step:90", "switches") > default.metric(
        "bang-bang", "step:90", "switches"
    )
    with pytest.raises(ValueError, match="controller_params: name 'predictive', which is not"):
        control_study(Linear(), design, controller_params={"predictive": {}}, **kwargs)
