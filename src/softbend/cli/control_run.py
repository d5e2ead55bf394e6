"""``softbend control run``: a controller in the fixed-period loop on a rig, with its tick log."""

from __future__ import annotations

import signal
import threading
from collections.abc import Iterator
from contextlib import contextmanager
from pathlib import Path
from types import FrameType
from typing import TYPE_CHECKING, Any

import typer

from softbend.cli import _common
from softbend.cli import control_options as opt

if TYPE_CHECKING:
    from softbend.control.runs import LoopPlan, LoopResult, Simulation
    from softbend.control.setup import ControlSetup

_LOG_FORMATS = ("csv", "parquet")


def run_cmd(
    out: Path = opt.RUN_OUT,
    rig: str = opt.RIG,
    config: Path = opt.CONFIG,
    reference: str = opt.REFERENCE,
    controller: str = opt.CONTROLLER,
    assignments: list[str] = opt.SET,
    design: str = opt.DESIGN,
    model: Path = opt.MODEL,
    plant: str = opt.PLANT,
    duration_s: float = opt.RUN_DURATION,
    period_s: float = opt.PERIOD,
    sensor_period_s: float = opt.SENSOR_PERIOD,
    supply_mpa: str = opt.SUPPLY,
    rig_assignments: list[str] = opt.RIG_PARAM,
    rig_from: Path = opt.RIG_FROM,
    seed: int = typer.Option(0, help="Seed of a simulated rig's sensor and camera noise."),
    log_format: str = opt.LOG_FORMAT,
    strict: bool = opt.STRICT,
    as_json: bool = typer.Option(False, "--json", help="Print the summary as JSON."),
) -> None:
    """Run a controller in the fixed-period loop on a rig (help: control_help.RUN)."""
    from softbend._validation import check_choice
    from softbend.control.plants import parse_plant
    from softbend.control.pressures import run_supply_mpa
    from softbend.control.runs import plan_loop

    check_choice(log_format, "log_format", _LOG_FORMATS)
    files = [out / name for name in (f"ticks.{log_format}", "run.json", "run.png")]
    _common.check_output_dir(out, "--out", files=tuple(f.name for f in files))
    _common.check_replaceable_dir(out, "--out")
    with _common.library_progress():  # an FEM plant's sweep, if any
        plant_choice = parse_plant(plant)
        plan = plan_loop(
            rig=rig, config=config, reference=reference, controller=controller,
            assignments=assignments or (), design=design, model=model, plant=plant_choice,
            duration_s=duration_s, period_s=period_s, sensor_period_s=sensor_period_s,
            supply_mpa=run_supply_mpa(supply_mpa, model, plant_choice),
            rig_assignments=rig_assignments or (), seed=seed,
            strict=strict, rig_from=rig_from,
        )  # fmt: skip
    title = f"{reference}, rig {rig}"
    result = _run_loop(plan, out, files, title, as_json)
    _print_loop(plan, result, files, title, as_json)
    if result.loop.fault_kind == "interrupted":
        _common.error_line(result.loop.stop_reason)
        raise typer.Exit(130)
    if not result.loop.completed or not result.loop.vented:  # a fault, or a rig left unvented
        _common.error_line(result.loop.stop_reason)
        raise typer.Exit(1)


def _run_loop(
    plan: LoopPlan, out: Path, files: list[Path], title: str, as_json: bool
) -> LoopResult:
    """Run the loop into a folder beside ``out`` (its tick log, run.json, run.png), swapped
    in whole at the end; SIGTERM ends it as Ctrl-C does."""
    from softbend._outdir import staged_dir
    from softbend.reports import control_figures

    done = [0]

    def report(n: int, _total: int) -> None:
        advance(n - done[0])
        done[0] = n

    device = plan.make_rig()
    with (
        sigterm_as_interrupt(),
        _common.output_errors(out, "--out"),  # a full disk is one line
        staged_dir(out) as stage,  # built beside --out, swapped in whole at the end
        _common.as_written(stage, out),
    ):
        with _common.progress_bar("control loop", plan.ticks, enabled=not as_json) as advance:
            result = plan.run(stage / files[0].name, progress=report, device=device)
        payload = result.summary
        text = _common.json_text(payload) + "\n"
        (stage / files[1].name).write_text(text, encoding="utf-8")
        tick, sensor = plan.period_s * 1e3, plan.sensor_period_s * 1e3
        control_figures.run_figure(
            result.control_run().decimated(),
            stage / files[2].name,
            f"{payload['controller']} on {actuator_of(payload)}, {title} "
            f"(tick {tick:g} ms, sensor {sensor:g} ms)",
        )
    return result


def _print_loop(
    plan: LoopPlan, result: LoopResult, files: list[Path], title: str, as_json: bool
) -> None:
    """Print a loop run's summary: as JSON, or its models, scores and jitter as a table."""
    payload = {**result.summary, "files": [str(f) for f in files]}
    if as_json:
        _common.print_json(payload)
        return
    note, named = model_lines(plan.setup)
    named += rig_from_rows(payload.get("rig_from"))
    rows = named + metric_rows(payload["metrics"], payload["undefined_metrics"])
    rows += [[k, v] for k, v in payload["jitter"].items()]
    name = f"{payload['controller']} on {actuator_of(payload)}, {title}{note}"
    _common.print_table(name, ["metric", "value"], rows)
    _common.console.print(f"run written to {files[0].parent}")


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


@contextmanager
def sigterm_as_interrupt() -> Iterator[None]:
    """Within the block, SIGTERM ends a run as Ctrl-C does (:func:`terminate_as_interrupt`);
    the previous handler is put back after it."""
    previous = terminate_as_interrupt()
    try:
        yield
    finally:
        if previous is not None:
            signal.signal(signal.SIGTERM, previous)


def write_simulation(
    result: Simulation, out: Path, files: tuple[str, str, str], reference: str
) -> None:
    """Write a simulated run into ``out``: its log, its summary and its figure (``files``).

    The files are written beside ``out`` and swapped in at the end: an error, Ctrl-C
    or kill leaves the previous results (or none).
    """
    from softbend._outdir import staged_dir
    from softbend.reports import control_figures

    payload = result.summary
    with (
        _common.output_errors(out, "--out"),
        staged_dir(out) as stage,
        _common.as_written(stage, out),
    ):
        result.run.frame().to_csv(stage / files[0], index=False)
        (stage / files[1]).write_text(_common.json_text(payload) + "\n", encoding="utf-8")
        title = f"{payload['controller']} on {actuator_of(payload)}, {reference} (simulated)"
        control_figures.run_figure(result.run.decimated(), stage / files[2], title)


def print_simulation(result: Simulation, files: list[Path], reference: str, as_json: bool) -> None:
    """Print a simulated run's summary: as JSON, or its models and scores as a table."""
    payload = {**result.summary, "files": [str(f) for f in files]}
    if as_json:
        _common.print_json(payload)
        return
    note, named = model_lines(result.setup)
    named += rig_from_rows(payload.get("rig_from"))
    _common.print_table(
        f"{payload['controller']} on {actuator_of(payload)}, {reference}: simulated rig "
        f"(SYNTHETIC){note}",
        ["metric", "value"],
        named + metric_rows(payload["metrics"], payload["undefined_metrics"]),
    )
    _common.console.print(f"run written to {files[0].parent}")


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
    "print_simulation",
    "rig_from_rows",
    "run_cmd",
    "sigterm_as_interrupt",
    "terminate_as_interrupt",
    "write_simulation",
]
