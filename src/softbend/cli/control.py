"""``softbend control``: closed-loop control of an actuator on the simulated rig (paper B §5)."""

from __future__ import annotations

import signal
import threading
from pathlib import Path
from typing import Any

import typer

from softbend.cli import _common

app = typer.Typer(
    help="Closed-loop control (paper B §5): valves, pressure sensor, virtual angle sensor.",
    no_args_is_help=True,
)

_FILES = ("run.csv", "metrics.json", "run.png")

# Options shared by simulate, run and serve.
_REFERENCE = typer.Option(
    "step:90",
    help="step:AMP[:T0_S], square:AMP:PERIOD_S[:LOW] or triangle:FREQ_HZ:AMP[:LOW] (degrees).",
)
_CONTROLLER = typer.Option(
    "bang-bang",
    help="bang-bang, bang-bang-closed, pressure-pi, pressure-relay or predictive.",
)
_DESIGN = typer.Option("100,6,2,2,5,8", help="Actuator l,r,t,b,phi,lc (mm, deg).")
_MODEL = typer.Option(
    None, "--model", help="Saved surrogate for θ(p) (default: the shipped FEM-trained MLP)."
)
_PLANT = typer.Option(
    "surrogate",
    help="θ(p) of the actuator: surrogate (the controller's own model), fem (the design's "
    "FEM sweep) or lab (its virtual-lab readings: model mismatch).",
)


def _setup(
    command: str,
    controller: str,
    design: str,
    model: Path | None,
    supply: float,
    plant: str = "surrogate",
):
    """Design, rig parameters, plant θ(p) table and controller of a run (checked first).

    The controller's virtual sensor and inverse come from ``model``; the plant's
    θ(p) from the same model (``surrogate``), the design's FEM sweep in the
    shipped dataset (``fem``) or its virtual-lab readings (``lab``: the reality
    gap the controller meets on a real actuator).
    """
    from softbend._validation import check_choice
    from softbend.control.controllers import CONTROLLERS, mlp_virtual_sensor
    from softbend.control.factory import make_controller
    from softbend.control.plants import PLANTS, plant_table
    from softbend.control.rig import AngleTable, RigParams
    from softbend.design import SFRBADesign
    from softbend.transfer.base import load_base

    check_choice(controller, "controller", command, CONTROLLERS)
    check_choice(plant, "plant", command, PLANTS)
    _check_supply(supply, command)
    actuator = SFRBADesign.parse(design)
    params = RigParams.for_design(actuator, supply_gauge_mpa=supply)
    surrogate = load_base(model)
    table = AngleTable.from_surrogate(surrogate, actuator)
    sensor = mlp_virtual_sensor(surrogate, actuator) if hasattr(surrogate, "predictor") else table
    actuator_table = plant_table(plant, actuator, table)
    return actuator, params, actuator_table, make_controller(controller, table, sensor, params)


def _check_supply(supply: float, command: str) -> None:
    """Refuse a supply pressure that is not a positive, plausible gauge pressure (MPa)."""
    from softbend.plausibility import RANGES

    high = RANGES["pressure_mpa"].high
    if not 0.0 < supply <= high:
        raise ValueError(
            f"The '--supply' of {command} must be a gauge pressure in (0, {high:g}] MPa "
            f"({high:g} MPa bursts any silicone actuator; a value in kPa must be divided by "
            f"1000). Got {supply!r} instead."
        )


@app.command("simulate")
def simulate_cmd(
    out: Path = typer.Option(..., "--out", help="Folder for run.csv, metrics.json and run.png."),
    reference: str = _REFERENCE,
    controller: str = _CONTROLLER,
    design: str = _DESIGN,
    model: Path = _MODEL,
    plant: str = _PLANT,
    duration: float = typer.Option(10.0, help="Simulated time, s."),
    supply: float = typer.Option(0.2, help="Supply pressure, MPa gauge."),
    seed: int = typer.Option(0, help="Seed of the sensor and camera noise."),
    as_json: bool = typer.Option(False, "--json", help="Print the metrics as JSON."),
) -> None:
    """Run a controller on the simulated rig and score it as paper B's Fig. 9 (synthetic)."""
    from softbend.control.experiments import parse_reference, run_metrics, simulate
    from softbend.control.rig import SimulatedRig
    from softbend.reports import control_figures

    ref = parse_reference(reference)
    actuator, params, table, ctrl = _setup(
        "softbend control simulate", controller, design, model, supply, plant
    )
    _common.check_output_dir(out, "--out", files=_FILES)
    rig = SimulatedRig(table, params, seed=seed)
    run = simulate(rig, ctrl, ref, duration, seed=seed)
    metrics = run_metrics(run)
    payload = {
        "synthetic": True,
        "reference": reference,
        "controller": controller,
        "plant": plant,
        "design": str(actuator),
        "duration_s": duration,
        "seed": seed,
        "rig": params.as_dict(),
        "metrics": metrics,
    }
    from softbend._io import atomic_files

    targets = (out / "run.csv", out / "metrics.json", out / "run.png")
    with _common.output_errors(out, "--out"), atomic_files(*targets) as (table, summary, png):
        run.frame().to_csv(table, index=False)  # all three files new, or all as they were
        summary.write_text(_common.json_text(payload) + "\n", encoding="utf-8")
        title = f"{controller} on {actuator}, {reference} (simulated)"
        control_figures.run_figure(run, png, title)
    payload["files"] = [str(target) for target in targets]
    if as_json:
        _common.print_json(payload)
        return
    _common.print_table(
        f"{controller} on {actuator}, {reference}: simulated rig (SYNTHETIC)",
        ["metric", "value"],
        [[k, v] for k, v in metrics.items()],
    )
    _common.console.print(f"run written to {out}")


RIGS: tuple[str, ...] = ("sim", "sim-realtime", "modbus")
_LOG_FORMATS = ("csv", "parquet")


@app.command("run")
def run_cmd(
    out: Path = typer.Option(
        ..., "--out", help="Folder for ticks.csv|parquet, run.json and run.png."
    ),
    rig: str = typer.Option(
        "sim",
        help="sim (simulated time), sim-realtime (simulated, on the wall clock) or modbus.",
    ),
    config: Path = typer.Option(
        None,
        "--config",
        help="Rig TOML: connection, register map, scaling, safety, period "
        "(required for --rig modbus; its [safety] and [loop] apply to every rig).",
    ),
    reference: str = _REFERENCE,
    controller: str = _CONTROLLER,
    design: str = _DESIGN,
    model: Path = _MODEL,
    plant: str = _PLANT,
    duration: float = typer.Option(10.0, help="Run time, s."),
    period: float = typer.Option(
        None, help="Loop tick (controller, valves), s (default: the config's period_s, 0.001)."
    ),
    sensor_period: float = typer.Option(
        None,
        help="Pressure reading period, s (default: the config's sensor_period_s, 0.01: 100 Hz).",
    ),
    supply: float = typer.Option(0.2, help="Supply pressure of a simulated rig, MPa gauge."),
    seed: int = typer.Option(0, help="Seed of a simulated rig's sensor and camera noise."),
    log_format: str = typer.Option("csv", help="Tick log format: csv (streamed) or parquet."),
    as_json: bool = typer.Option(False, "--json", help="Print the summary as JSON."),
) -> None:
    """Run a controller in the fixed-period loop on a rig, with its safety limits and tick log.

    The same controller object as `control simulate`, called every tick (1 ms) with
    the latest pressure reading (read every 10 ms: paper B's 100 Hz). Over-pressure,
    missed or stale readings vent the actuator and stop the run; so do Ctrl-C and SIGTERM. Exit 0
    when the run completed and the rig was vented, 1 when a fault stopped it or the
    final vent did not reach the rig (the log keeps every tick up to the fault; the
    one error line says whether the rig was vented), 130 on Ctrl-C.
    """
    from softbend._validation import check_choice, check_range
    from softbend.control.experiments import parse_reference
    from softbend.control.loop import run_loop
    from softbend.control.rigconfig import RigConfig, load_rig_config
    from softbend.reports import control_figures

    command = "softbend control run"
    check_choice(rig, "rig", command, RIGS)
    check_choice(log_format, "log_format", command, _LOG_FORMATS)
    ref = parse_reference(reference)
    if rig == "modbus" and config is None:
        raise ValueError(
            "The '--config' of softbend control run must name a rig TOML file with --rig "
            "modbus (write a template with 'softbend control rig-config --out rig.toml')."
        )
    settings = load_rig_config(config) if config is not None else RigConfig()
    loop_period = settings.period_s if period is None else period
    sensor_every = settings.sensor_period_s if sensor_period is None else sensor_period
    actuator, params, table, ctrl = _setup(command, controller, design, model, supply, plant)
    log_name = f"ticks.{log_format}"
    _common.check_output_dir(out, "--out", files=(log_name, "run.json", "run.png"))
    with _common.output_errors(out, "--out"):
        out.mkdir(parents=True, exist_ok=True)
    check_range(duration, "duration", command, low=0.0, high=86400.0, high_inclusive=True)
    check_range(loop_period, "period", command, low=0.0, high=1.0, high_inclusive=True)
    check_range(
        sensor_every, "sensor_period", command, low=loop_period, high=10.0,
        low_inclusive=True, high_inclusive=True,
    )  # fmt: skip
    ticks = max(1, round(duration / loop_period))
    device = _make_rig(rig, settings, table, params, seed)
    done = [0]

    def report(n: int, _total: int) -> None:
        advance(n - done[0])
        done[0] = n

    previous = _terminate_as_interrupt()
    try:
        with (
            _common.output_errors(out, "--out"),  # the tick log: a full disk is one line
            _common.progress_bar("control loop", ticks, enabled=not as_json) as advance,
        ):
            result = run_loop(
                device,
                ctrl,
                ref,
                duration,
                period_s=loop_period,
                sensor_period_s=sensor_every,
                limits=settings.safety,
                log_path=out / log_name,
                progress=report,
            )
    finally:
        device.close()
        if previous is not None:
            signal.signal(signal.SIGTERM, previous)
    jitter = result.jitter()
    metrics = result.metrics()
    payload = {
        "synthetic": rig != "modbus",
        "rig": rig,
        "where": settings.connection.where if rig == "modbus" else "simulated",
        "reference": reference,
        "controller": controller,
        "plant": plant if rig != "modbus" else "the rig",
        "design": str(actuator),
        "duration_s": duration,
        "period_s": loop_period,
        "sensor_period_s": sensor_every,
        "seed": seed,
        "completed": result.completed,
        "stop_reason": result.stop_reason,
        "fault_kind": result.fault_kind,
        "vented": result.vented,
        "jitter": jitter,
        "metrics": metrics,
        "rig_config": settings.to_toml(),
        "rig_params": params.as_dict() if rig != "modbus" else None,
    }
    if rig == "modbus":
        trips = device.round_trips_s
        payload["round_trip_ms"] = _percentiles_ms(trips)
    from softbend._io import atomic_files

    targets = (out / "run.json", out / "run.png")
    with _common.output_errors(out, "--out"), atomic_files(*targets) as (summary, png):
        summary.write_text(_common.json_text(payload) + "\n", encoding="utf-8")
        title = (
            f"{controller} on {actuator}, {reference}, rig {rig} "
            f"(tick {loop_period * 1e3:g} ms, sensor {sensor_every * 1e3:g} ms)"
        )
        control_figures.run_figure(result.control_run(), png, title)
    figure = targets[1]
    payload["files"] = [str(out / log_name), str(out / "run.json"), str(figure)]
    if as_json:
        _common.print_json(payload)
    else:
        rows = [[k, v] for k, v in {**metrics, **jitter}.items()]
        _common.print_table(
            f"{controller} on {actuator}, {reference}, rig {rig}", ["metric", "value"], rows
        )
        _common.console.print(f"run written to {out}")
    if result.fault_kind == "interrupted":
        _common.error_line(result.stop_reason)
        raise typer.Exit(130)
    if not result.completed or not result.vented:  # a fault, or a rig left unvented
        _common.error_line(result.stop_reason)
        raise typer.Exit(1)


def _terminate_as_interrupt() -> Any:
    """Make SIGTERM (``kill``, a service stop) end the loop as Ctrl-C does: vented.

    Returns the previous handler (None off the main thread, where signals
    cannot be set).
    """
    if threading.current_thread() is not threading.main_thread():
        return None

    def interrupt(signum: int, frame: Any) -> None:
        raise KeyboardInterrupt

    return signal.signal(signal.SIGTERM, interrupt)


def _percentiles_ms(values: list[float]) -> dict[str, float]:
    import numpy as np

    if not values:
        return {}
    ms = np.asarray(values) * 1e3
    return {"p50": float(np.percentile(ms, 50)), "p99": float(np.percentile(ms, 99))}


def _make_rig(kind: str, settings, table, params, seed: int):
    from softbend.control.rig import SimulatedRig

    if kind == "modbus":
        from softbend.control.modbus import ModbusRig

        return ModbusRig(settings).connect()
    simulated = SimulatedRig(table, params, seed=seed)
    if kind == "sim":
        return simulated
    from softbend.control.realtime import WallClockRig

    return WallClockRig(simulated)


@app.command("serve")
def serve_cmd(
    config: Path = typer.Option(
        None, "--config", help="Rig TOML whose register map to serve (default: the built-in map)."
    ),
    host: str = typer.Option("127.0.0.1", help="Address to listen on."),
    port: int = typer.Option(None, help="TCP port (default: the config's, else 5020)."),
    design: str = _DESIGN,
    model: Path = _MODEL,
    plant: str = _PLANT,
    supply: float = typer.Option(0.2, help="Supply pressure, MPa gauge."),
    seed: int = typer.Option(0, help="Seed of the sensor and camera noise."),
    duration: float = typer.Option(0.0, help="Serve for this long, s (0: until Ctrl-C)."),
) -> None:
    """Serve the simulated rig as a Modbus TCP device, to rehearse `control run --rig modbus`.

    Registers as in the config; the actuator is vented when no request came for 0.25 s.
    """
    import time

    from softbend._validation import check_range
    from softbend.control.modbus_server import SimulatedModbusServer
    from softbend.control.rig import SimulatedRig
    from softbend.control.rigconfig import RigConfig, load_rig_config

    settings = load_rig_config(config) if config is not None else RigConfig()
    listen = (
        port if port is not None else (settings.connection.port if config is not None else 5020)
    )
    check_range(duration, "duration", "softbend control serve", low=0.0, low_inclusive=True)
    if not host.strip():
        raise ValueError(
            "The '--host' of softbend control serve must be an address to listen on "
            "(e.g. 127.0.0.1 or 0.0.0.0). Got an empty string instead."
        )
    if not 0 <= listen <= 65535:
        raise ValueError(
            f"The '--port' of softbend control serve must be an integer in [0, 65535]. "
            f"Got {listen} instead."
        )
    _, params, table, _ = _setup(
        "softbend control serve", "bang-bang", design, model, supply, plant
    )
    server = SimulatedModbusServer(
        SimulatedRig(table, params, seed=seed), settings, host=host, port=listen
    )
    server.start()
    _common.console.print(
        f"simulated rig {design} serving on {server.config.connection.where} "
        f"({'Ctrl-C to stop' if duration == 0 else f'for {duration:g} s'})"
    )
    try:
        end = time.monotonic() + (duration if duration > 0 else float("inf"))
        while time.monotonic() < end:
            time.sleep(min(0.2, max(0.0, end - time.monotonic())))
    except KeyboardInterrupt:
        pass
    finally:
        server.stop()
    _common.console.print(f"served {server.requests} requests; valves left vented")


@app.command("rig-config")
def rig_config_cmd(
    out: Path = typer.Option(..., "--out", help="The TOML file to write."),
    host: str = typer.Option("127.0.0.1", help="Modbus TCP host."),
    port: int = typer.Option(5020, help="Modbus TCP port."),
    force: bool = typer.Option(
        False, "--force", help="Replace an existing --out file (a rig TOML may be hand-edited)."
    ),
) -> None:
    """Write a rig TOML template (the built-in register map of `control serve`) to edit.

    An existing file is kept unless --force is given; the file is written atomically
    (a reader sees the old file or the whole new one).
    """
    from dataclasses import replace

    from softbend._io import write_text_atomic
    from softbend.control.rigconfig import RigConfig

    if not 0 <= port <= 65535:
        raise ValueError(
            f"The '--port' of softbend control rig-config must be an integer in [0, 65535]. "
            f"Got {port} instead."
        )
    if not host.strip():
        raise ValueError("The '--host' of softbend control rig-config must not be empty.")
    settings = RigConfig()
    settings = replace(settings, connection=replace(settings.connection, host=host, port=port))
    _common.check_output_file(out, "--out")
    if out.exists() and not force:
        raise ValueError(
            f"The '--out' {out} already exists (perhaps a hand-edited rig config); "
            "give --force to replace it, or choose another file."
        )
    header = (
        "# softbend rig: connection, register map, scaling (value = offset + scale*count),\n"
        "# safety limits and loop period. Units: MPa gauge, degrees, seconds.\n\n"
    )
    with _common.output_errors(out, "--out"):
        write_text_atomic(out, header + settings.to_toml())
    _common.console.print(f"rig config written to {out}")


__all__ = ["RIGS", "app"]
