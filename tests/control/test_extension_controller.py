"""A controller added from outside the package: one class, one register call, used by the CLI."""

import json
import math

import pytest

from softbend.cli import main
from softbend.control import CONTROLLERS, ControllerModel
from softbend.control.controllers import ValveCommand
from softbend.parameters import Range, declare_ranges


@declare_ranges(limit=Range(0.0, 0.5, "MPa", "the pressure to fill to: at most the supply"))
class HoldPressure:
    """Fill to a fixed pressure and hold it (a test double).

    Parameters
    ----------
    model : ControllerModel
        What the controller knows (unused: it watches the pressure only).
    limit : float, default 0.03
        Pressure to fill to, MPa gauge.
    """

    def __init__(self, model: ControllerModel, *, limit: float = 0.03) -> None:
        self.limit = limit
        self.reset()

    def reset(self) -> None:
        self.predicted_deg = math.nan

    def step(self, measurement_mpa: float, reference_deg: float, t_s: float) -> ValveCommand:
        return ValveCommand(measurement_mpa < self.limit, False)


@pytest.fixture
def toy():
    CONTROLLERS.register("toy", HoldPressure)
    try:
        yield "toy"
    finally:
        CONTROLLERS.unregister("toy")


def _simulate(tmp_path, capsys, name, *extra):
    out = tmp_path / name
    args = ["control", "simulate", "--out", str(out), "--duration", "1.5", "--json", *extra]
    assert main(args) == 0, capsys.readouterr().err
    payload = json.loads(capsys.readouterr().out)
    assert json.loads((out / "metrics.json").read_text()) == {
        k: v for k, v in payload.items() if k != "files"
    }
    return payload, out


def test_a_controller_registered_outside_runs_through_the_cli(tmp_path, capsys, toy):
    payload, out = _simulate(tmp_path, capsys, "default", "--controller", toy)
    assert payload["controller"] == "toy" and payload["controller_params"] == {"limit": 0.03}
    import pandas as pd

    run = pd.read_csv(out / "run.csv")
    assert run["outlet"].sum() == 0  # the toy never vents
    assert 0.03 <= run["pressure_mpa"].iloc[-1] < 0.05  # held (the valve shuts late)
    higher, _ = _simulate(tmp_path, capsys, "higher", "--controller", toy, "--set", "limit=0.06")
    assert higher["controller_params"] == {"limit": 0.06}
    assert higher["metrics"]["mape_pct"] < payload["metrics"]["mape_pct"]  # closer to 90°


def test_the_registry_lists_the_toy_and_forgets_it(tmp_path, capsys, toy):
    assert main(["control", "controllers", "--json"]) == 0
    rows = {r["name"]: r for r in json.loads(capsys.readouterr().out)}
    assert rows["toy"]["params"] == {"limit": 0.03}
    assert rows["toy"]["summary"] == "Fill to a fixed pressure and hold it (a test double)."
    assert rows["bang-bang"]["params"] == {"deadzone": 0.05, "period": 0.01}
    CONTROLLERS.unregister("toy")
    try:
        code = main(["control", "simulate", "--out", str(tmp_path / "o"), "--controller", "toy"])
        assert code == 2 and "Unknown controller 'toy'" in capsys.readouterr().err
    finally:
        CONTROLLERS.register("toy", HoldPressure)  # for the fixture's unregister


def test_a_toy_controller_from_a_rig_toml_runs_in_the_loop(tmp_path, capsys, toy):
    config = tmp_path / "rig.toml"
    config.write_text('[pressure]\naddress = 0\nscale = 1e-4\n[controller]\nname = "toy"\n')
    out = tmp_path / "run"
    args = ["control", "run", "--config", str(config), "--duration", "1", "--out", str(out)]
    assert main([*args, "--set", "limit=0.05", "--json"]) == 0, capsys.readouterr().err
    payload = json.loads(capsys.readouterr().out)
    assert payload["controller"] == "toy" and payload["controller_params"] == {"limit": 0.05}
    assert json.loads((out / "run.json").read_text())["controller_params"] == {"limit": 0.05}


def test_its_declared_range_holds_set_values(tmp_path, capsys, toy):
    args = ["control", "simulate", "--out", str(tmp_path / "o"), "--controller", toy]
    assert main([*args, "--set", "limit=5"]) == 2
    err = capsys.readouterr().err.strip()
    assert err == "softbend: error: --set: limit: must be in [0, 0.5] MPa; got '5'"
    assert main([*args, "--set", "limt=0.1"]) == 2
    assert "--set: limt: is not a parameter; known: limit" in capsys.readouterr().err


def test_a_factory_function_registers_the_same_way(tmp_path, capsys):
    def make_hold(model, *, limit: float = 0.04):
        """Fill to a fixed pressure (a factory)."""
        return HoldPressure(model, limit=limit)

    CONTROLLERS.register("toy-factory", make_hold)
    try:
        payload, _ = _simulate(tmp_path, capsys, "factory", "--controller", "toy-factory")
        assert payload["controller_params"] == {"limit": 0.04}
    finally:
        CONTROLLERS.unregister("toy-factory")
