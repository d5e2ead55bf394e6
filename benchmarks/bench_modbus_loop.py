"""Benchmark: the control loop through a Modbus TCP server (paper B §5 on a "rig").

Starts ``softbend control serve`` (the simulated rig behind a Modbus TCP server)
in a separate process on 127.0.0.1, runs the fixed-period loop (1 ms tick, pressure
read at 100 Hz as paper B)
through :class:`softbend.control.modbus.ModbusRig` for each controller on a
``step:90`` and a 0.2 Hz triangle, and prints the period jitter (|Δt − period|,
p50/p99/max), the lateness of ticks, the request round trip (p50/p99), and the
metrics beside the direct simulation of the same controller (simulated time, same
rig). The Modbus path adds its latency (about one round trip) to the valves'
delay, which shows in the bang-bang metrics. Run::

    .venv/bin/python benchmarks/bench_modbus_loop.py [--duration 20] [--json]
"""

from __future__ import annotations

import argparse
import json
import subprocess
import sys
import tempfile
import time
from dataclasses import replace
from pathlib import Path

import numpy as np
from _record import record, table_figures

from softbend.control.controllers import mlp_virtual_sensor
from softbend.control.experiments import run_metrics, simulate
from softbend.control.factory import make_controller
from softbend.control.loop import run_loop
from softbend.control.modbus import ModbusRig
from softbend.control.modbus_server import free_tcp_port
from softbend.control.rig import AngleTable, RigParams, SimulatedRig
from softbend.control.rigconfig import RigConfig
from softbend.design import sfrba_design
from softbend.errors import RigError
from softbend.transfer.base import load_base

REFERENCES = ("step:90", "triangle:0.2:90:20")


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--duration", type=float, default=20.0)
    parser.add_argument("--json", action="store_true")
    args = parser.parse_args()
    design = sfrba_design(100, 6, 2, 2, 5, 8)
    model = load_base()
    table = AngleTable.from_surrogate(model, design)
    sensor = mlp_virtual_sensor(model, design)
    params = RigParams.for_design(design)
    controllers = {
        name: (lambda name=name: make_controller(name, table, sensor, params))
        for name in ("bang-bang", "pressure-relay", "predictive")
    }
    config = RigConfig()
    config = replace(config, connection=replace(config.connection, port=free_tcp_port()))
    softbend = Path(sys.executable).with_name("softbend")
    rows = []
    with tempfile.TemporaryDirectory() as tmp:
        path = Path(tmp) / "rig.toml"
        path.write_text(config.to_toml())
        for name, make in controllers.items():
            for ref in REFERENCES:
                server = subprocess.Popen(
                    [str(softbend), "control", "serve", "--config", str(path)],
                    stdout=subprocess.DEVNULL,
                    stderr=subprocess.DEVNULL,
                )
                try:
                    rig = _connect(config)
                    run = run_loop(rig, make(), ref, args.duration)
                    trips = np.array(rig.round_trips_s) * 1e3
                    rig.close()
                finally:
                    server.terminate()
                    server.wait(10)
                direct = run_metrics(
                    simulate(SimulatedRig(table, params), make(), ref, args.duration, seed=0)
                )
                m, j = run.metrics(), run.jitter()
                rows.append(
                    {
                        "controller": name,
                        "reference": ref,
                        "completed": run.completed,
                        "ticks": j["ticks"],
                        "jitter_p50_ms": j["period_jitter_p50_ms"],
                        "jitter_p99_ms": j["period_jitter_p99_ms"],
                        "jitter_max_ms": j["period_jitter_max_ms"],
                        "lateness_p99_ms": j["lateness_p99_ms"],
                        "round_trip_p50_ms": float(np.percentile(trips, 50)),
                        "round_trip_p99_ms": float(np.percentile(trips, 99)),
                        "modbus_mape_pct": m["mape_pct"],
                        "direct_mape_pct": direct["mape_pct"],
                        "modbus_switches": m["switches"],
                        "direct_switches": direct["switches"],
                    }
                )
    columns = {
        "jitter_p99_ms": ("period jitter p99", "ms"),
        "lateness_p99_ms": ("lateness p99", "ms"),
        "round_trip_p50_ms": ("round trip p50", "ms"),
        "round_trip_p99_ms": ("round trip p99", "ms"),
        "modbus_mape_pct": ("MAPE through Modbus", "%"),
        "direct_mape_pct": ("MAPE simulated directly", "%"),
    }
    figures, units = table_figures(
        {f"{r['controller']}, {r['reference']}": r for r in rows}, columns
    )
    record("modbus_loop", figures, units=units, notes=f"{args.duration:g} s per run, 1 ms tick")
    if args.json:
        print(json.dumps(rows, indent=2))
        return
    print(
        f"loop ticking at 1 kHz, pressure read at 100 Hz, through Modbus TCP on 127.0.0.1 "
        f"(server in another process), {args.duration:g} s per run"
    )
    head = (
        f"{'controller':<15}{'reference':<20}{'jitter p50/p99/max ms':>24}"
        f"{'late p99':>9}{'rtt p50/p99 ms':>16}{'MAPE mb/direct':>16}{'switches':>12}"
    )
    print(head)
    for r in rows:
        print(
            f"{r['controller']:<15}{r['reference']:<20}"
            f"{r['jitter_p50_ms']:>8.3f}/{r['jitter_p99_ms']:.3f}/{r['jitter_max_ms']:.2f}"
            f"{r['lateness_p99_ms']:>9.3f}"
            f"{r['round_trip_p50_ms']:>9.2f}/{r['round_trip_p99_ms']:.2f}"
            f"{r['modbus_mape_pct']:>9.2f}/{r['direct_mape_pct']:.2f}"
            f"{r['modbus_switches']:>6}/{r['direct_switches']}"
        )


def _connect(config: RigConfig, attempts: int = 100) -> ModbusRig:
    for _ in range(attempts):  # the server process needs a moment to listen
        try:
            return ModbusRig(config).connect()
        except RigError:
            time.sleep(0.1)
    return ModbusRig(config).connect()


if __name__ == "__main__":
    main()
