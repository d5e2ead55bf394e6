"""``softbend lab``: the virtual lab's labelled-synthetic measurements of paper B's actuators.

Every setting is checked before the lab runs, and a message names the option
typed (``--pmax``), not the library's field (:mod:`softbend.cli._options`).
Options that contradict each other (``--material`` gives the silicone whole, so
``--elastomer`` and ``--elastomer-max-stretch`` would be dropped) are refused,
naming both. The CSV
and its figure are written together through temporary files beside them: a run
that fails, or is stopped by Ctrl-C or SIGTERM, leaves both as they were and no
temporary file.
"""

from __future__ import annotations

from pathlib import Path
from typing import TYPE_CHECKING, Any

import typer

from softbend.cli import _common
from softbend.errors import InputError, SoftbendError

if TYPE_CHECKING:
    from softbend.actuators import Design
    from softbend.transfer.lab import VirtualLab
    from softbend.transfer.measurements import Measurements

#: Options that ``--material`` makes pointless: the silicone is given whole.
_MATERIAL_REPLACES: dict[str, str] = {
    "elastomer": "--elastomer",
    "elastomer_max_stretch": "--elastomer-max-stretch",
}


def _typed(ctx: typer.Context, parameter: str) -> bool:
    """Whether the option of ``parameter`` was given (typed or from the environment)."""
    source = ctx.get_parameter_source(parameter)
    return getattr(source, "name", None) in ("COMMANDLINE", "ENVIRONMENT")


lab_app = typer.Typer(
    help="Virtual lab: synthetic measurements of paper B's actuators.\n\n"
    "Labelled-synthetic readings of the actuators of paper B, Figure 7, as built "
    "(fabrication errors, hysteresis, camera noise).",
    no_args_is_help=True,
)


_OUT = typer.Option(..., "--out", "-o", help="CSV file to write the measurements to.")
_PLANT = typer.Option(
    "fem", help="Model of the actuators as built: a lab model (fem or analytical)."
)
_SEED = typer.Option(0, help="Seed of the fabrication errors and the camera noise.")
_FABRICATION_ERROR = typer.Option(
    0.2, help="Half-width of the uniform error of the wall t and layer b, mm."
)
_HYSTERESIS = typer.Option(
    0.02, help="Half the largest loading/unloading gap, fraction of the angle."
)
_CAMERA_NOISE = typer.Option(1.0, help="Standard deviation of the angle reading, deg.")
_ELASTOMER_MAX_STRETCH = typer.Option(
    3.0, help="Largest stretch of the shipped Dragon Skin 30 test used by the lab's fit."
)
_PMAX = typer.Option(0.25, help="Largest pressure set, MPa.")
_PSTEP = typer.Option(0.01, help="Pressure step between readings, MPa.")
_MAX_ANGLE = typer.Option(270.0, help="Stop raising the pressure past this angle, deg.")
_UNLOADING = typer.Option(False, "--unloading", help="Also read the unloading branch.")
_CYCLES = typer.Option(
    1, help="Inflation cycles per actuator (at most SOFTBEND_MAX_CYCLES, default 1000)."
)
_DESIGNS = typer.Option(
    None,
    "--design",
    help="Measure this design instead of paper B's seven (l,r,t,b,phi,lc in mm and deg); "
    "repeat for several.",
)
_ELASTOMER = typer.Option(
    "dragon-skin-30", help="Shipped tensile test the lab's silicone is fitted to (Yeoh)."
)
_MATERIAL = typer.Option(
    None,
    help="The lab's silicone whole, instead of --elastomer and --elastomer-max-stretch "
    "(not with them): a preset or the fit.json of 'softbend materials fit' (fit.json#yeoh "
    "for one of its models).",
)
_JSON = typer.Option(False, "--json", help="Print a JSON summary.")


@lab_app.command("measure")
def measure(
    ctx: typer.Context,
    out: Path = _OUT,
    plant: str = _PLANT,
    seed: int = _SEED,
    fabrication_error: float = _FABRICATION_ERROR,
    hysteresis: float = _HYSTERESIS,
    camera_noise: float = _CAMERA_NOISE,
    elastomer_max_stretch: float = _ELASTOMER_MAX_STRETCH,
    pmax: float = _PMAX,
    pstep: float = _PSTEP,
    max_angle: float = _MAX_ANGLE,
    unloading: bool = _UNLOADING,
    cycles: int = _CYCLES,
    designs: list[str] | None = _DESIGNS,
    elastomer: str = _ELASTOMER,
    material: str | None = _MATERIAL,
    as_json: bool = _JSON,
) -> None:
    """Measure actuators in the virtual lab.

    The actuators of paper B, Figure 7 (or those of --design), measured as built
    (synthetic data).
    Writes the CSV and its figure (the same name with .png) together: a run
    that fails or is interrupted leaves both as they were.

    Example:

    \b
        softbend lab measure --out lab.csv --plant analytical
        softbend lab measure --out own.csv --design 130,7,2.5,3,10,9 --plant analytical
        softbend lab measure --out own.csv --design 130,7,2.5,3,10,9 --material fit.json
    """
    from softbend.transfer.lab import LAB_ACTUATORS, VirtualLab

    _check_material(ctx, material)
    out, figure = _outputs(out)
    silicone: dict[str, Any] = (
        {"material": material}
        if material is not None
        else {"elastomer": elastomer, "elastomer_max_stretch": elastomer_max_stretch}
    )
    lab = VirtualLab(
        actuators=tuple(_design(text) for text in designs) if designs else LAB_ACTUATORS,
        plant=plant,
        seed=seed,
        fabrication_error_mm=fabrication_error,
        hysteresis=hysteresis,
        camera_noise_deg=camera_noise,
        pmax_mpa=pmax,
        pressure_step_mpa=pstep,
        max_angle_deg=max_angle,
        unloading=unloading,
        cycles=cycles,
        **silicone,
    )
    measurements = _measure_and_write(lab, out, figure, quiet=as_json)
    _print_measurements(measurements, out, figure, f"{plant}, seed {seed}", as_json)


def _check_material(ctx: typer.Context, material: str | None) -> None:
    """Refuse ``--material`` beside an option it makes pointless, naming both."""
    if material is None:
        return
    for parameter, option in _MATERIAL_REPLACES.items():
        if _typed(ctx, parameter):
            raise ValueError(
                f"The '--material' gives the lab's silicone whole, so the '{option}' "
                f"would not be used; give one of '--material' and '{option}'."
            )


def _outputs(out: Path) -> tuple[Path, Path]:
    """The CSV ``out`` and its figure beside it, both checked writable before any work."""
    out = Path(out)
    figure = out.with_suffix(".png")
    if out.suffix.lower() == ".png":
        raise ValueError(
            f"The '--out' must name the CSV file; its figure is written beside it with "
            f"'.png'. Got {out}, which the figure would replace."
        )
    _common.check_output_file(out, "--out", kind="csv")
    _common.check_output_file(figure, "--out", kind="png")
    return out, figure


def _measure_and_write(lab: VirtualLab, out: Path, figure: Path, *, quiet: bool) -> Measurements:
    """Measure every actuator of ``lab`` and write the CSV and its figure together.

    Ctrl-C or SIGTERM leaves both files as they were, says so and exits with 130.
    """
    from softbend._io import atomic_files
    from softbend.cli.control_run import sigterm_as_interrupt
    from softbend.reports.transfer_figures import lab_measurements
    from softbend.transfer.measurements import format_measurements

    total = len(lab.actuators)
    try:
        with sigterm_as_interrupt():  # `kill` leaves both files as Ctrl-C does
            with _common.progress_bar("virtual lab", total, enabled=not quiet) as advance:
                measurements = lab.measure(progress=lambda done, n, name: advance(actuator=name))
            text = format_measurements(measurements)
            with (
                _common.output_errors(out, "--out"),
                atomic_files(out, figure) as (csv_file, png),
            ):
                with (
                    _common.output_errors(out, "--out"),
                    _common.as_written(csv_file, out),
                    open(csv_file, "w", encoding="utf-8", newline="") as handle,
                ):
                    handle.write(text)
                with _common.output_errors(figure, "--out"), _common.as_written(png, figure):
                    lab_measurements(measurements, png)
    except KeyboardInterrupt:
        _common.err_console.print(
            f"softbend: interrupted; {out} and {figure} are as they were",
            markup=False,
            highlight=False,
            soft_wrap=True,
        )
        raise typer.Exit(130) from None
    return measurements


def _print_measurements(
    measurements: Measurements, out: Path, figure: Path, run: str, as_json: bool
) -> None:
    """Each actuator's readings as a table (titled with ``run``), or the JSON summary."""
    per = measurements.per_actuator()
    if as_json:
        _common.print_json(
            {
                "out": str(out),
                "figure": str(figure),
                "synthetic": True,
                "n_measurements": len(measurements),
                "actuators": per.reset_index().to_dict(orient="records"),
                "metadata": dict(measurements.metadata),
            }
        )
        return
    _common.print_table(
        f"Virtual lab (SYNTHETIC, {run}): {len(measurements)} readings",
        ["actuator (l,r,t,b,φ,lc)", "readings", "top pressure (MPa)", "largest angle (°)"],
        [[str(k), int(r.points), float(r.pmax), float(r.angle_max)] for k, r in per.iterrows()],
    )
    _common.console.print(f"measurements written to {out}, figure {figure}")


def _design(text: str) -> Design:
    """One ``--design`` value as a design; a bad one is one error naming the option."""
    from softbend.design import parse_sfrba

    try:
        return parse_sfrba(text)
    except ValueError as exc:
        detail = exc.detail if isinstance(exc, SoftbendError) else str(exc)
        raise InputError(f"{text!r} is not a design: {detail}", key="designs") from None
