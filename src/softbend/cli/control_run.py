"""``softbend control run``: a controller in the fixed-period loop on a rig, with its tick log."""

from __future__ import annotations

import signal
import threading
from pathlib import Path
from types import FrameType
from typing import TYPE_CHECKING, Any

import typer

from softbend.cli import _common
from softbend.cli import control_options as opt

if TYPE_CHECKING:
    from softbend.control.setup import ControlSetup

_LOG_FORMATS = ("csv", "parquet")


def run_cmd(
    out: Path = typer.Option(
        ...,
        "--out",
        "-o",
        help="Folder for ticks.csv|parquet, run.json and run.png (replaced as a whole: a new "
        "or empty folder, or an earlier result of this command).",
    ),
    rig: str = typer.Option(
        "sim",
        help="A registered rig: sim (simulated time), sim-realtime (simulated, on the wall "
        "clock) or modbus.",
    ),
    config: Path = typer.Option(
        None,
        "--config",
        help="Rig TOML: connection, register map, scaling, safety, period, [controller], "
        "[simulation] (required for --rig modbus; its [safety] and [loop] apply to every rig).",
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
        help="Run time, s: in (0, 86400] and at most SOFTBEND_MAX_LOOP_TICKS ticks (default "
        "10 000 000: 10 000 s at the default 1 ms tick), each logged in memory.",
    ),
    period_s: float = typer.Option(
        None,
        "--period",
        help="Loop tick (controller, valves), s (default: the config's period_s, 0.001).",
    ),
    sensor_period_s: float = typer.Option(
        None,
        "--sensor-period",
        help="Pressure reading period, s (default: the config's sensor_period_s, 0.01: 100 Hz).",
    ),
    supply_mpa: str = opt.SUPPLY,
    rig_assignments: list[str] = opt.RIG_PARAM,
    rig_from: Path = opt.RIG_FROM,
    seed: int = typer.Option(0, help="Seed of a simulated rig's sensor and camera noise."),
    log_format: str = typer.Option("csv", help="Tick log format: csv (streamed) or parquet."),
    strict: bool = opt.STRICT,
    as_json: bool = typer.Option(False, "--json", help="Print the summary as JSON."),
) -> None:
    """Run a controller in the fixed-period loop on a rig.

    The loop keeps the rig's safety limits and a log of every tick. It calls the same
    controller object as 'softbend control simulate' every tick (1 ms) with the latest
    pressure reading (read every 10 ms: paper B's 100 Hz). The controller and its
    parameters come from --controller and --set, else the config's [controller] table
    (--set overrides its values); run.json records them. A simulated rig takes the
    config's [simulation] table and --rig-param (which overrides it). Over-pressure, missed or stale
    readings vent the actuator and stop the run; so do Ctrl-C and SIGTERM. Exit 0 when
    the run completed and the rig was vented, 1 when a fault stopped it or the final
    vent did not reach the rig (the log keeps every tick up to the fault; the one error
    line says whether the rig was vented), 130 on Ctrl-C.

    Every --set and --rig-param value is held to its declared range and the run to
    the memory it needs, before it starts. A score the run does not define (an angle
    that did not settle within the run, a rig without an angle sensor) is null in
    run.json and --json, with the reason under undefined_metrics, and 'null (the
    reason)' in the table; never NaN. The results are built beside --out and swapped
    in once written: a kill -9 leaves the previous results whole (the ticks of the
    killed run stay in the hidden folder .OUT.PID-*.new/ticks.csv.partial beside it
    until the next run into --out).

    Example:

    \b
        softbend control run --out loop --config rig.toml --set deadzone=0.02
    """
    from softbend._outdir import staged_dir
    from softbend._validation import check_choice
    from softbend.control.pressures import run_supply_mpa
    from softbend.control.runs import plan_loop
    from softbend.reports import control_figures

    check_choice(log_format, "log_format", _LOG_FORMATS)
    log_name = f"ticks.{log_format}"
    _common.check_output_dir(out, "--out", files=(log_name, "run.json", "run.png"))
    _common.check_replaceable_dir(out, "--out")
    with _common.library_progress():  # an FEM plant's sweep, if any
        plan = plan_loop(
            rig=rig, config=config, reference=reference, controller=controller,
            assignments=assignments or (), design=design, model=model, plant=plant,
            duration_s=duration_s, period_s=period_s, sensor_period_s=sensor_period_s,
            supply_mpa=run_supply_mpa(supply_mpa, model, plant),
            rig_assignments=rig_assignments or (), seed=seed,
            strict=strict, rig_from=rig_from,
        )  # fmt: skip
    done = [0]

    def report(n: int, _total: int) -> None:
        advance(n - done[0])
        done[0] = n

    device = plan.make_rig()
    previous = terminate_as_interrupt()
    try:
        with (
            _common.output_errors(out, "--out"),  # a full disk is one line
            staged_dir(out) as stage,  # built beside --out, swapped in whole at the end
            _common.as_written(stage, out),
        ):
            with _common.progress_bar("control loop", plan.ticks, enabled=not as_json) as advance:
                result = plan.run(stage / log_name, progress=report, device=device)
            payload = dict(result.summary)
            name, actuator = payload["controller"], actuator_of(payload)
            text = _common.json_text(payload) + "\n"
            (stage / "run.json").write_text(text, encoding="utf-8")
            title = (
                f"{name} on {actuator}, {reference}, rig {rig} "
                f"(tick {plan.period_s * 1e3:g} ms, sensor {plan.sensor_period_s * 1e3:g} ms)"
            )
            control_figures.run_figure(result.control_run().decimated(), stage / "run.png", title)
    finally:
        if previous is not None:
            signal.signal(signal.SIGTERM, previous)
    payload["files"] = [str(out / log_name), str(out / "run.json"), str(out / "run.png")]
    if as_json:
        _common.print_json(payload)
    else:
        note, named = model_lines(plan.setup)
        named += rig_from_rows(payload.get("rig_from"))
        rows = named + metric_rows(payload["metrics"], payload["undefined_metrics"])
        rows += [[k, v] for k, v in payload["jitter"].items()]
        _common.print_table(
            f"{name} on {actuator}, {reference}, rig {rig}{note}", ["metric", "value"], rows
        )
        _common.console.print(f"run written to {out}")
    if result.loop.fault_kind == "interrupted":
        _common.error_line(result.loop.stop_reason)
        raise typer.Exit(130)
    if not result.loop.completed or not result.loop.vented:  # a fault, or a rig left unvented
        _common.error_line(result.loop.stop_reason)
        raise typer.Exit(1)


def metric_rows(metrics: dict[str, Any], undefined: dict[str, str]) -> list[list[Any]]:
    """The rows of a run's score table: a score the run does not define as 'null (why)'."""
    return [
        [key, f"null ({undefined.get(key, 'not defined by this run')})" if value is None else value]
        for key, value in metrics.items()
    ]


def model_lines(setup: ControlSetup) -> tuple[str, list[list[Any]]]:
    """What a run's table says of its models: a note for the title and rows naming them.

    Nothing for the shipped MLP against a named plant (paper B's runs) with a design
    inside its training ranges; one row when the plant is the controller's model; a
    row each otherwise, and the title's note "model mismatch" when a saved model
    plays the plant and the controller uses another. An identified plant is named
    by its description; the row "design in the model's training data" says whether
    the design lies in the training ranges of the controller's model (as the
    summary's ``design_supported`` and the warning do).
    """
    plant, model = setup.plant, setup.model_path
    support = setup.design_support_text()
    design_row = [[DESIGN_ROW, support]] if support is not None else []
    if setup.identified is not None:
        rows = [["plant", setup.identified.describe()]]
        if not setup.has_design:
            top = setup.model.angle_table.pmax_mpa
            return "", [*rows, ["controller's model", f"its steady-state θ(p), 0–{top:g} MPa"]]
        return "; model mismatch", [*rows, ["controller's model", model], *design_row]
    if setup.model_from == "shipped" and setup.plant_choice.kind == "named":
        return "", design_row if setup.design_supported is False else []
    if setup.plant_is_model:
        return "", [["plant and controller's model", model], *design_row]
    rows = [["plant", plant], ["controller's model", model], *design_row]
    return ("; model mismatch" if setup.mismatch else ""), rows


def actuator_of(payload: dict[str, Any]) -> str:
    """What a run's title calls the actuator: its design, else the identified plant."""
    design = payload.get("design")
    return str(design) if design is not None else "the identified actuator"


def rig_from_rows(origin: dict[str, Any] | None) -> list[list[Any]]:
    """The row of a run's table naming the rig settings of an identified model (--rig-from)."""
    if not origin or not origin.get("used"):
        return []
    values = ", ".join(f"{name} {origin[name]:.3g} s" for name in origin["used"])
    return [["rig from", f"{origin['file']}: {values}"]]


#: The row of a run's table that says whether the design is in its model's training data.
DESIGN_ROW = "design in the model's training data"


def terminate_as_interrupt() -> Any:
    """Make SIGTERM (``kill``, a service stop) end a loop or a server as Ctrl-C does: vented.

    Returns the previous handler (None off the main thread, where signals
    cannot be set).
    """
    if threading.current_thread() is not threading.main_thread():
        return None

    def interrupt(signum: int, frame: FrameType | None) -> None:
        raise KeyboardInterrupt

    return signal.signal(signal.SIGTERM, interrupt)


__all__ = [
    "DESIGN_ROW",
    "actuator_of",
    "metric_rows",
    "model_lines",
    "rig_from_rows",
    "run_cmd",
    "terminate_as_interrupt",
]
