"""The Modbus rig against the simulated rig served on 127.0.0.1, faults included."""

import json
import os
import signal
import socket
import subprocess
import sys
import threading
import time
from dataclasses import replace
from pathlib import Path

import pytest

from softbend.cli import main
from softbend.control.controllers import BangBang, PressureRelay
from softbend.control.experiments import run_metrics, simulate
from softbend.control.loop import run_loop
from softbend.control.modbus import ModbusRig
from softbend.control.rig import RigParams, SimulatedRig
from softbend.errors import RigError

from ..stand_ins import StuckOpen

pytest.importorskip("pymodbus")


def wait_for(predicate, timeout=2.0):
    end = time.monotonic() + timeout
    while time.monotonic() < end:
        if predicate():
            return True
        time.sleep(0.01)
    return predicate()


def test_readings_and_valves_go_through_the_registers(server, table):
    with ModbusRig(server.config) as rig:
        assert rig.read_pressure_mpa() == pytest.approx(0.0, abs=0.002)
        assert rig.read_angle_deg() == pytest.approx(table(0.0), abs=1.0)
        rig.command(True, False)
        assert wait_for(lambda: server.valves == (True, False))
        for _ in range(100):  # 1 s, polling faster than the 0.25 s watchdog
            time.sleep(0.01)
            p = rig.read_pressure_mpa()
        assert p == pytest.approx(0.2, abs=0.005)  # filled to the 0.2 MPa supply
        assert rig.read_angle_deg() == pytest.approx(table(p), abs=5.0)
        rig.command(False, True)
        assert wait_for(lambda: server.valves == (False, True))


def test_the_server_watchdog_vents_a_silent_master(server):
    with ModbusRig(server.config) as rig:
        rig.command(True, False)
        assert wait_for(lambda: server.valves == (True, False), timeout=0.2)
        time.sleep(0.4)  # no request for longer than watchdog_s = 0.25
    assert server.valves == (False, True) and server.watchdog_vents == 1


def direct_band(table, controller, seeds=(0, 1, 2)):
    """Direct simulations with the rig's 5 ms valve delay and with 3 ms more (the link's latency).

    The loop over Modbus adds its round trips to the valve delay: measured about
    1 ms on 127.0.0.1 (bang-bang MAPE 6.3 % against 5.3 % direct, 6.4 % direct
    with 1 ms more delay).
    """
    runs = []
    for delay in (0.005, 0.008):
        for s in seeds:
            rig = SimulatedRig(table, RigParams(valve_delay_s=delay))
            runs.append(run_metrics(simulate(rig, controller(table), "step:90:0.5", 2.5, seed=s)))
    return runs


@pytest.mark.parametrize("controller", [BangBang, PressureRelay])
def test_the_loop_through_modbus_matches_the_direct_simulation(server, table, controller):
    """Within the seed-to-seed noise of direct runs whose valve delay spans the link's latency."""
    with ModbusRig(server.config) as rig:
        run = run_loop(rig, controller(table), "step:90:0.5", 2.5)
    assert run.completed, run.stop_reason
    m = run.metrics()
    band = direct_band(table, controller)
    mape = [r["mape_pct"] for r in band]
    assert min(mape) - 0.5 <= m["mape_pct"] <= max(mape) + 0.5
    assert m["rise_s"] == pytest.approx(sum(r["rise_s"] for r in band) / len(band), abs=0.03)
    assert server.valves == (False, True) or wait_for(lambda: server.valves == (False, True))
    assert run.jitter()["ticks"] == 2500


def test_server_gone_mid_run_stops_clearly_and_the_watchdog_vents(server):
    timer = threading.Timer(0.8, server.disconnect)
    with ModbusRig(server.config) as rig:
        timer.start()
        run = run_loop(rig, StuckOpen(), "step:90", 5.0)
    timer.join()
    assert not run.completed and run.fault_kind in ("connection", "timeout")
    assert server.config.connection.where in run.stop_reason
    assert run.ticks["t_s"].iloc[-1] < 2.0
    assert not run.vented and "watchdog must vent it" in run.stop_reason
    assert wait_for(lambda: server.valves == (False, True), timeout=1.0)
    assert server.watchdog_vents == 1


@pytest.mark.parametrize(
    ("fault", "kind", "needle"),
    [
        ("garbage", "garbage", "65535 decodes to 6.554 MPa"),
        ("timeout", "timeout", "did not answer within 0.05 s"),
        ("frozen", "stale", "sample counter (register 2) has not changed"),
    ],
)
def test_register_faults_vent_and_stop_with_a_clear_message(server, table, fault, kind, needle):
    timer = threading.Timer(0.5, server.inject, args=(fault,))
    with ModbusRig(server.config) as rig:
        timer.start()
        run = run_loop(rig, BangBang(table), "step:90:0.1", 5.0)
    timer.join()
    server.inject(None)
    assert run.fault_kind == kind, run.stop_reason
    assert needle in run.stop_reason and "vented and stopped" in run.stop_reason
    assert run.ticks["t_s"].iloc[-1] < 2.5
    assert wait_for(lambda: server.valves == (False, True), timeout=1.0)


def test_no_rig_at_the_address_is_one_error(table):
    from softbend.control.modbus_server import free_tcp_port
    from softbend.control.rigconfig import RigConfig

    config = RigConfig()
    config = replace(config, connection=replace(config.connection, port=free_tcp_port()))
    with pytest.raises(RigError, match=r"Cannot connect to the rig at tcp://127\.0\.0\.1:"):
        ModbusRig(config).connect()


def test_cli_run_through_the_server_writes_log_and_jitter(server, tmp_path, capsys):
    config = tmp_path / "rig.toml"
    config.write_text(server.config.to_toml())
    out = tmp_path / "run"
    args = ["control", "run", "--rig", "modbus", "--config", str(config), "--out", str(out)]
    code = main([*args, "--duration", "1.5", "--reference", "step:90:0.3", "--json"])
    assert code == 0
    payload = json.loads(capsys.readouterr().out)
    assert payload["completed"] and payload["where"] == server.config.connection.where
    assert payload["jitter"]["ticks"] == 1500 and payload["round_trip_ms"]["p50"] > 0
    assert (out / "ticks.csv").exists() and (out / "run.json").exists()


def test_cli_run_stops_with_exit_1_on_a_fault(server, tmp_path, capsys):
    config = tmp_path / "rig.toml"
    config.write_text(server.config.to_toml())
    args = ["control", "run", "--rig", "modbus", "--config", str(config)]
    timer = threading.Timer(0.5, server.inject, args=("garbage",))
    timer.start()
    code = main([*args, "--out", str(tmp_path / "o"), "--duration", "5"])
    timer.join()
    server.inject(None)
    assert code == 1
    err = capsys.readouterr().err.strip().splitlines()
    assert "garbage" in err[-1] and "vented and stopped" in err[-1]
    assert (tmp_path / "o" / "ticks.csv").exists()


def test_cli_run_refuses_a_rig_whose_first_reading_is_garbage(server, tmp_path, capsys):
    config = tmp_path / "rig.toml"
    config.write_text(server.config.to_toml())
    server.inject("garbage")
    args = ["control", "run", "--rig", "modbus", "--config", str(config)]
    code = main([*args, "--out", str(tmp_path / "o"), "--duration", "2"])
    server.inject(None)
    assert code == 2
    err = capsys.readouterr().err.strip().splitlines()
    assert len(err) == 1 and "is garbage" in err[0]
    assert not (tmp_path / "o" / "ticks.csv").exists()
    assert server.valves == (False, False)  # no valve was ever opened


def _default_signals() -> None:
    """In the child: SIGINT as at a terminal, even when the test runs as a background job."""
    signal.signal(signal.SIGINT, signal.SIG_DFL)


@pytest.mark.skipif(sys.platform == "win32", reason="POSIX signals to a child")
@pytest.mark.parametrize("signum", [signal.SIGINT, signal.SIGTERM])
def test_ctrl_c_or_sigterm_leaves_the_valves_vented(server, tmp_path, signum):
    config = tmp_path / "rig.toml"
    config.write_text(replace(server.config).to_toml())
    server.watchdog_s = 0.0  # only the loop may vent: prove it does
    softbend = Path(sys.executable).with_name("softbend")  # the console script
    cmd = [str(softbend), "control", "run", "--rig", "modbus"]
    cmd += ["--config", str(config), "--out", str(tmp_path / "o"), "--duration", "30"]
    child = subprocess.Popen(
        cmd, stderr=subprocess.PIPE, text=True, env=os.environ.copy(),
        preexec_fn=_default_signals,
    )  # fmt: skip
    try:
        assert wait_for(lambda: server.valves[0], timeout=30.0), "the loop never opened the inlet"
        child.send_signal(signum)
        _, err = child.communicate(timeout=30)
    finally:
        child.kill()
    assert child.returncode == 130
    assert "Interrupted (Ctrl-C or SIGTERM)" in err.strip().splitlines()[-1]
    assert wait_for(lambda: server.valves == (False, True), timeout=1.0)
    assert (tmp_path / "o" / "ticks.csv").exists()


def test_serve_on_a_port_in_use_is_one_line(server, capsys):
    code = main(["control", "serve", "--port", str(server.port), "--duration", "0.2"])
    assert code == 2
    err = capsys.readouterr().err.strip().splitlines()
    assert len(err) == 1 and f"cannot listen on tcp://127.0.0.1:{server.port}" in err[0]


@pytest.mark.skipif(sys.platform == "win32", reason="POSIX signals to a child")
def test_kill_stops_the_served_rig_as_ctrl_c_does(tmp_path):
    port = _free_port()
    softbend = Path(sys.executable).with_name("softbend")  # the console script
    cmd = [str(softbend), "control", "serve", "--port", str(port)]
    child = subprocess.Popen(cmd, stdout=subprocess.PIPE, stderr=subprocess.PIPE, text=True)
    try:
        assert wait_for(lambda: _listening(port), timeout=60.0), "the rig never listened"
        child.send_signal(signal.SIGTERM)
        out, err = child.communicate(timeout=30)
    finally:
        child.kill()
    assert child.returncode == 0, err
    assert "valves left vented" in out.strip().splitlines()[-1]


def _free_port() -> int:
    with socket.socket() as probe:
        probe.bind(("127.0.0.1", 0))
        return probe.getsockname()[1]


def _listening(port: int) -> bool:
    with socket.socket() as probe:
        probe.settimeout(0.2)
        return probe.connect_ex(("127.0.0.1", port)) == 0
