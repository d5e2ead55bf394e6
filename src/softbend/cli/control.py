"""``softbend control``: closed-loop control of an actuator on the simulated rig (paper B §5).

Each command parses its options, calls one function of :mod:`softbend.control`
(:func:`~softbend.control.runs.simulate_control`, :func:`~softbend.control.runs.plan_loop`,
:func:`~softbend.control.runs.simulated_server`) and prints or writes what it returns.
"""

from __future__ import annotations

from pathlib import Path
from typing import TYPE_CHECKING

import typer

from softbend.cli import _common, control_help, control_run
from softbend.cli import control_options as opt

if TYPE_CHECKING:
    from softbend.control.plant_choice import PlantChoice

app = typer.Typer(
    help="Closed-loop control of an actuator (paper B §5).\n\n"
    "Valves, a pressure sensor and a virtual angle sensor, on a simulated rig or a "
    "Modbus TCP one.",
    no_args_is_help=True,
)

_FILES = ("run.csv", "metrics.json", "run.png")


@app.command("simulate", help=control_help.SIMULATE)
def simulate_cmd(
    out: Path = typer.Option(
        ...,
        "--out",
        "-o",
        help="Folder for run.csv, metrics.json and run.png (replaced as a whole: a new or "
        "empty folder, or an earlier result of this command).",
    ),
    reference: str = opt.REFERENCE,
    controller: str = opt.CONTROLLER,
    assignments: list[str] = opt.SET,
    design: str = opt.DESIGN,
    model: Path = opt.MODEL,
    plant: str = opt.PLANT,
    duration_s: float = typer.Option(
        10.0,
        "--duration",
        help="Simulated time, s: in (0, 86400] and at most SOFTBEND_MAX_LOOP_TICKS rig steps "
        "(default 10 000 000: 10 000 s at the default step_s of 1 ms), each logged in memory.",
    ),
    supply_mpa: str = opt.SUPPLY,
    rig_assignments: list[str] = opt.RIG_PARAM,
    rig_from: Path = opt.RIG_FROM,
    seed: int = typer.Option(0, help="Seed of the sensor and camera noise."),
    strict: bool = opt.STRICT,
    as_json: bool = typer.Option(False, "--json", help="Print the metrics as JSON."),
) -> None:
    """Run a controller on the simulated rig and score it (help: control_help.SIMULATE)."""
    from softbend.control.plants import parse_plant
    from softbend.control.pressures import run_supply_mpa
    from softbend.control.runs import simulate_control

    _common.check_output_dir(out, "--out", files=_FILES)
    _common.check_replaceable_dir(out, "--out")
    with control_run.sigterm_as_interrupt():  # `kill`: staged results removed
        with _common.library_progress(enabled=not as_json):  # an FEM plant's sweep, if any
            plant_choice = parse_plant(plant)
            result = simulate_control(
                reference=reference, controller=controller, assignments=assignments or (),
                design=design, model=model, plant=plant_choice, duration_s=duration_s,
                supply_mpa=run_supply_mpa(supply_mpa, model, plant_choice),
                rig_assignments=rig_assignments or (), seed=seed,
                strict=strict, rig_from=rig_from,
            )  # fmt: skip
        control_run.write_simulation(result, out, _FILES, reference)
    control_run.print_simulation(result, [out / name for name in _FILES], reference, as_json)


app.command("run", help=control_help.RUN)(control_run.run_cmd)


@app.command("controllers")
def controllers_cmd(
    as_json: bool = typer.Option(False, "--json", help="Print the list as JSON."),
) -> None:
    """List the controllers and their parameters.

    Each parameter is given to a run by --set NAME=VALUE (or a [controller]
    table of the rig TOML); a value outside its range is refused before the
    run starts.

    Example:

    \b
        softbend control controllers --json
    """
    from softbend.control.factory import controller_catalog

    rows = controller_catalog()
    if as_json:
        _common.print_json(rows)
        return
    _common.print_table(
        "controllers (--controller NAME --set PARAM=VALUE)",
        ["controller", "parameters (defaults, ranges)", "what"],
        [
            [
                r["name"],
                ", ".join(
                    f"{k}={v} in {r['ranges'][k]}" if k in r["ranges"] else f"{k}={v}"
                    for k, v in r["params"].items()
                ),
                r["summary"],
            ]
            for r in rows
        ],
    )


@app.command("rig-parameters")
def rig_parameters_cmd(
    as_json: bool = typer.Option(False, "--json", help="Print the list as JSON."),
) -> None:
    """List the simulated rig's parameters.

    Each is given to simulate, run and serve by --rig-param NAME=VALUE (or a
    [simulation] table of the rig TOML); the unit is in the name, and a value
    outside the range listed is refused before the run starts.

    Example:

    \b
        softbend control rig-parameters --json
    """
    from softbend.control.rigs import rig_parameter_catalog

    rows = rig_parameter_catalog()
    if as_json:
        _common.print_json(rows)
        return
    table = [[r["name"], f"{r['default']:g}", r["range"], r["what"]] for r in rows]
    _common.print_table(
        "simulated rig (--rig-param NAME=VALUE)", ["name", "default", "range", "what"], table
    )


@app.command("serve")
def serve_cmd(
    config: Path = typer.Option(
        None, "--config", help="Rig TOML whose register map to serve (default: the built-in map)."
    ),
    host: str = typer.Option("127.0.0.1", help="Address to listen on."),
    port: int = typer.Option(None, help="TCP port (default: the config's, else 5020)."),
    design: str = opt.DESIGN,
    model: Path = opt.MODEL,
    plant: str = opt.PLANT,
    supply_mpa: str = opt.SUPPLY,
    rig_assignments: list[str] = opt.RIG_PARAM,
    rig_from: Path = opt.RIG_FROM,
    seed: int = typer.Option(0, help="Seed of the sensor and camera noise."),
    duration_s: float = typer.Option(
        0.0, "--duration", help="Serve for this long, s (0: until Ctrl-C)."
    ),
) -> None:
    """Serve the simulated rig as a Modbus TCP device.

    A rehearsal of 'softbend control run --rig modbus': registers as in the
    config; the actuator is vented when no request came for 0.25 s. Ctrl-C or
    SIGTERM stops it with the valves vented (exit 0).

    Example:

    \b
        softbend control serve --config rig.toml --port 5020
    """
    import time

    from softbend._validation import check_range
    from softbend.control.plants import parse_plant
    from softbend.control.pressures import run_supply_mpa
    from softbend.control.runs import simulated_server

    duration = check_range(duration_s, "duration_s", low=0.0, low_inclusive=True)
    with _common.library_progress():  # an FEM plant's sweep, if any
        plant_choice = parse_plant(plant)
        server = simulated_server(
            config=config, host=host, port=port, design=design, model=model, plant=plant_choice,
            supply_mpa=run_supply_mpa(supply_mpa, model, plant_choice),
            rig_assignments=rig_assignments or (), seed=seed, rig_from=rig_from,
        )  # fmt: skip
    with control_run.sigterm_as_interrupt():  # `kill` stops it as Ctrl-C does
        try:
            server.start()
            _common.console.print(
                f"simulated rig {_served(design, plant_choice)} serving on "
                f"{server.config.connection.where} "
                f"({'Ctrl-C to stop' if duration == 0 else f'for {duration:g} s'})"
            )
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
    out: Path = typer.Option(..., "--out", "-o", help="The TOML file to write."),
    host: str = typer.Option("127.0.0.1", help="Modbus TCP host."),
    port: int = typer.Option(5020, help="Modbus TCP port."),
    force: bool = typer.Option(
        False, "--force", help="Replace an existing --out file (a rig TOML may be hand-edited)."
    ),
) -> None:
    """Write a rig TOML template to edit.

    The template holds the built-in register map of 'softbend control serve'.
    An existing file is kept unless --force is given; the file is written
    atomically (a reader sees the old file or the whole new one).

    Example:

    \b
        softbend control rig-config --out rig.toml --port 502
    """
    from softbend._io import write_text_atomic
    from softbend._validation import must_be
    from softbend.control.rigconfig import rig_config_template
    from softbend.errors import InputError

    if not 0 <= port <= 65535:
        raise InputError(must_be("an integer in [0, 65535]", port), key="port")
    if not host.strip():
        raise InputError(must_be("a host name or address", host), key="host")
    text = rig_config_template(host, port)
    _common.check_output_file(out, "--out")
    if out.exists() and not force:
        raise ValueError(
            f"The '--out' {out} already exists (perhaps a hand-edited rig config); "
            "give --force to replace it, or choose another file."
        )
    with _common.output_errors(out, "--out"):
        write_text_atomic(out, text)
    _common.console.print(f"rig config written to {out}")


def _served(design: str | None, plant: PlantChoice) -> str:
    """What ``control serve`` says it simulates: the design, or an identified plant."""
    from softbend.control.designs import DEFAULT_DESIGN

    if design is None and plant.kind == "identified":
        return f"of the identified model {plant}"
    return design or DEFAULT_DESIGN


__all__ = ["app"]
