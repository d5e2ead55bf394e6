"""A plant and a rig added from outside the package, each one register call, used by the CLI."""

import json

import pytest

from softbend.cli import main
from softbend.control import PLANTS, RIGS
from softbend.control.rig import AngleTable, SimulatedRig


def stiff_plant(design, model_table):
    """An actuator half as compliant as the controllers' model (a test double)."""
    return AngleTable(model_table.pressures_mpa, 0.5 * model_table.angles_deg)


class CountingRig(SimulatedRig):
    """The simulated rig, counting the valve commands it receives (a test double)."""

    synthetic = True
    where = "counting"

    def command(self, inlet: bool, outlet: bool) -> None:
        self.commands = getattr(self, "commands", 0) + 1
        super().command(inlet, outlet)


made: list[CountingRig] = []


def counting_rig(setup):
    rig = CountingRig(setup.plant_table, setup.params, seed=setup.seed)
    made.append(rig)
    return rig


@pytest.fixture
def extensions():
    PLANTS.register("stiff", stiff_plant)
    RIGS.register("counting", counting_rig)
    try:
        yield
    finally:
        PLANTS.unregister("stiff")
        RIGS.unregister("counting")
        made.clear()


def test_a_registered_plant_and_rig_run_in_the_loop(tmp_path, capsys, extensions):
    out = tmp_path / "run"
    args = ["control", "run", "--rig", "counting", "--plant", "stiff", "--duration", "1"]
    assert main([*args, "--controller", "pressure-relay", "--out", str(out), "--json"]) == 0
    payload = json.loads(capsys.readouterr().out)
    assert (payload["rig"], payload["where"], payload["plant"]) == ("counting", "counting", "stiff")
    assert len(made) == 1 and made[0].commands > 0
    # the relay reaches the model's pressure for 90°: the stiffer actuator bends half as much
    assert payload["metrics"]["mape_pct"] > 40.0


def test_unregistered_names_are_one_line_listing_the_known(tmp_path, capsys):
    code = main(["control", "run", "--rig", "counting", "--out", str(tmp_path / "o")])
    assert code == 2
    err = capsys.readouterr().err.strip().splitlines()
    assert err == ["softbend: error: --rig: Unknown rig 'counting'; known: sim, sim-realtime, "
                   "modbus."]  # fmt: skip
