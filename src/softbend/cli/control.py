"""``softbend control``: closed-loop control of an actuator on the simulated rig (paper B §5).

Each command parses its options, calls one function of :mod:`softbend.control`
(:func:`~softbend.control.runs.simulate_control`, :func:`~softbend.control.runs.plan_loop`,
:func:`~softbend.control.runs.simulated_server`) and prints or writes what it returns.
"""

from __future__ import annotations

from pathlib import Path

import typer

from softbend.cli import _common, control_run
from softbend.cli import control_options as opt

app = typer.Typer(
    help="Closed-loop control of an actuator (paper B §5).\n\n"
    "Valves, a pressure sensor and a virtual angle sensor, on a simulated rig or a "
    "Modbus TCP one.",
    no_args_is_help=True,
)

_FILES = ("run.csv", "metrics.json", "run.png")


@app.command("simulate")
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
    """Run a controller on the simulated rig and score it.

    Scores the run as paper B, Figure 9 (synthetic data). metrics.json records
    the controller and the rig, with every one of their parameters as used, and
    the controller's model. That model (θ(p) and virtual angle sensor) is
    --model, else the --plant when it is a saved surrogate (a refined model is
    its own soft sensor, as in paper B), else the shipped FEM-trained MLP;
    --model with another --plant .json is a deliberate mismatch, and the table
    names both. A model of any actuator may be used: --design names its
    parameters (NAME=VALUE pairs), its pressures are converted from the rig's MPa
    (a bare --supply is in the model's pressure unit, a --rig-param pressure in
    MPa as its name says, both take a unit such as 20psi; the scores stay in
    MPa), and the chamber is its
    description's (else --rig-param volume_mm3). A design outside the model's
    training ranges is a warning naming the parameter, and the table's row
    "design in the model's training data" and design_supported in metrics.json
    say so; --strict refuses it. A model of 'softbend identify' (one pressure
    input, an angle output, a time column in s or ms) may play the plant: its
    dynamics replace θ(p) and the angle lag, and without --model its
    steady-state θ(p) is the controller's (such a plant has no --design).
    --rig-from such a model sets the rig's angle_time_constant_s and
    valve_delay_s from its step reading; --rig-param values win.
    A score the run does not define (an angle that did not settle within the
    run, a run without a rising edge) is null in metrics.json and --json, with
    the reason under undefined_metrics, and 'null (the reason)' in the table;
    never NaN. Every --set and --rig-param value is held to its declared range
    and the run to the memory it needs, before it starts. The results are
    written beside --out and swapped in at the end: an error, Ctrl-C or kill
    leaves the previous results (or none).

    Example:

    \b
        softbend control simulate --out bb --set deadzone=0.02 --rig-param valve_delay_s=0.02
    """
    import signal

    from softbend._outdir import staged_dir
    from softbend.control.pressures import run_supply_mpa
    from softbend.control.runs import simulate_control
    from softbend.reports import control_figures

    _common.check_output_dir(out, "--out", files=_FILES)
    _common.check_replaceable_dir(out, "--out")
    previous = control_run.terminate_as_interrupt()  # `kill`: staged results removed
    try:
        with _common.library_progress(enabled=not as_json):  # an FEM plant's sweep, if any
            result = simulate_control(
                reference=reference, controller=controller, assignments=assignments or (),
                design=design, model=model, plant=plant, duration_s=duration_s,
                supply_mpa=run_supply_mpa(supply_mpa, model, plant),
                rig_assignments=rig_assignments or (), seed=seed,
                strict=strict, rig_from=rig_from,
            )  # fmt: skip
        payload = dict(result.summary)
        name, actuator = payload["controller"], control_run.actuator_of(payload)
        with (
            _common.output_errors(out, "--out"),
            staged_dir(out) as stage,
            _common.as_written(stage, out),
        ):
            result.run.frame().to_csv(stage / _FILES[0], index=False)
            text = _common.json_text(payload) + "\n"
            (stage / _FILES[1]).write_text(text, encoding="utf-8")
            title = f"{name} on {actuator}, {reference} (simulated)"
            control_figures.run_figure(result.run.decimated(), stage / _FILES[2], title)
    finally:
        if previous is not None:
            signal.signal(signal.SIGTERM, previous)
    payload["files"] = [str(out / name) for name in _FILES]
    if as_json:
        _common.print_json(payload)
        return
    note, named = control_run.model_lines(result.setup)
    named += control_run.rig_from_rows(payload.get("rig_from"))
    _common.print_table(
        f"{name} on {actuator}, {reference}: simulated rig (SYNTHETIC){note}",
        ["metric", "value"],
        named + control_run.metric_rows(payload["metrics"], payload["undefined_metrics"]),
    )
    _common.console.print(f"run written to {out}")


app.command("run")(control_run.run_cmd)


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
    import signal
    import time

    from softbend._validation import check_range
    from softbend.control.pressures import run_supply_mpa
    from softbend.control.runs import simulated_server

    duration = check_range(duration_s, "duration_s", low=0.0, low_inclusive=True)
    with _common.library_progress():  # an FEM plant's sweep, if any
        server = simulated_server(
            config=config, host=host, port=port, design=design, model=model, plant=plant,
            supply_mpa=run_supply_mpa(supply_mpa, model, plant),
            rig_assignments=rig_assignments or (), seed=seed, rig_from=rig_from,
        )  # fmt: skip
    previous = control_run.terminate_as_interrupt()  # `kill` stops it as Ctrl-C does
    try:
        server.start()
        _common.console.print(
            f"simulated rig {_served(design, plant)} serving on "
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
        if previous is not None:
            signal.signal(signal.SIGTERM, previous)
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


def _served(design: str | None, plant: str) -> str:
    """What ``control serve`` says it simulates: the design, or an identified plant."""
    from softbend.control.designs import DEFAULT_DESIGN
    from softbend.control.plants import parse_plant

    if design is None and parse_plant(plant).kind == "identified":
        return f"of the identified model {plant}"
    return design or DEFAULT_DESIGN


__all__ = ["app"]
