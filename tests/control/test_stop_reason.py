"""How a run ended is told once, and truly: "vented and stopped" only when the vent got through."""

import json
import threading
import time

import pytest

from softbend.cli import main
from softbend.control.controllers import ValveCommand
from softbend.control.loop import run_loop
from softbend.control.rig import RigParams, SimulatedRig
from softbend.errors import RigError

from ..stand_ins import StuckOpen


class Rig:
    """A simulated rig whose valves stop answering from ``t_fail`` on (reads may fail too)."""

    def __init__(self, table, t_fail, *, reads_fail=False):
        self.rig = SimulatedRig(table, RigParams())
        self.t_fail = t_fail
        self.reads_fail = reads_fail

    def clock_s(self):
        return self.rig.clock_s()

    def sleep_until(self, t):
        self.rig.sleep_until(t)

    def read_pressure_mpa(self):
        if self.reads_fail and self.rig.t_s >= self.t_fail:
            raise RigError("Lost the rig at test:// while reading.", kind="connection")
        return self.rig.read_pressure_mpa()

    def read_angle_deg(self):
        return self.rig.read_angle_deg()

    def command(self, inlet, outlet):
        if self.rig.t_s >= self.t_fail:
            raise RigError("Lost the rig at test:// while setting the valves.")
        self.rig.command(inlet, outlet)


class Open:
    """Keeps the inlet open: every tick sends a command while the link lasts."""

    predicted_deg = float("nan")

    def reset(self):
        pass

    def step(self, measurement_mpa, reference_deg, t_s):
        return ValveCommand(True, False) if t_s < 0.2 else ValveCommand(False, False)


def test_a_failed_vent_is_never_called_vented(table):
    run = run_loop(Rig(table, 0.5, reads_fail=True), Open(), "step:90", 2.0)
    assert not run.completed and not run.vented
    assert "vented and stopped" not in run.stop_reason
    assert (
        "could not vent the rig" in run.stop_reason
        and "the vent command did not reach it" in run.stop_reason
    )
    assert "watchdog must vent it" in run.stop_reason
    assert run.stop_reason.count("Lost the rig at test://") == 2  # the fault, then the vent


def test_a_completed_run_whose_vent_fails_says_so(table):
    run = run_loop(Rig(table, 0.99), Open(), "step:90", 1.0)  # no command after 0.2 s
    assert run.completed and not run.vented
    assert run.stop_reason.startswith("Completed, but could not vent the rig (Lost the rig")
    assert (
        "the vent command did not reach it" in run.stop_reason
        and "vented and stopped" not in run.stop_reason
    )


def test_a_fault_whose_vent_succeeds_says_vented_once(table):
    rig = Rig(table, 99.0)
    run = run_loop(rig, Open(), "step:90", 1.0, limits=None)
    assert run.completed and run.vented and run.stop_reason == "completed"
    from softbend.control.rigconfig import SafetyLimits

    run = run_loop(Rig(table, 99.0), Open(), "step:90", 1.0, limits=SafetyLimits(0.01))
    assert run.fault_kind == "over-pressure" and run.vented
    assert run.stop_reason.endswith("; vented and stopped.")
    assert run.stop_reason.count("vented") == 1 and "could not vent" not in run.stop_reason


pymodbus = pytest.importorskip("pymodbus")


@pytest.mark.parametrize("end", ["disconnect", "stop"])
def test_a_modbus_server_that_dies_mid_run_gives_one_true_ending(server, end):
    from softbend.control.modbus import ModbusRig

    timer = threading.Timer(0.6, getattr(server, end))
    with ModbusRig(server.config) as rig:
        timer.start()
        run = run_loop(rig, StuckOpen(), "step:90", 5.0)
    timer.join()
    assert not run.completed and not run.vented
    assert server.config.connection.where in run.stop_reason
    assert "vented and stopped" not in run.stop_reason and "(vented" not in run.stop_reason
    assert "stopped, but could not vent the rig" in run.stop_reason
    assert "the vent command did not reach it" in run.stop_reason


def test_the_cli_prints_one_true_line_when_the_modbus_server_dies(server, tmp_path, capsys):
    config = tmp_path / "rig.toml"
    config.write_text(server.config.to_toml())
    args = ["control", "run", "--rig", "modbus", "--config", str(config), "--json"]

    def disconnect_once_running():
        end = time.monotonic() + 60.0
        while not server.valves[0] and time.monotonic() < end:  # the loop opened the inlet
            time.sleep(0.01)
        time.sleep(0.2)
        server.disconnect()

    watcher = threading.Thread(target=disconnect_once_running)
    watcher.start()
    code = main(
        [*args, "--out", str(tmp_path / "o"), "--duration", "20", "--reference", "step:90:0"]
    )
    watcher.join()
    assert code == 1
    captured = capsys.readouterr()
    err = captured.err.strip().splitlines()
    assert len(err) == 1 and err[0].startswith("softbend: error: ")
    assert "vented and stopped" not in err[0] and "the vent command did not reach it" in err[0]
    assert json.loads(captured.out)["vented"] is False
    assert (tmp_path / "o" / "ticks.csv").exists()
