"""``softbend lab``: the virtual lab's labelled-synthetic measurements of paper B's actuators."""

from __future__ import annotations

from pathlib import Path

import typer

from softbend.cli import _common

lab_app = typer.Typer(
    help="Virtual lab: synthetic measurements of paper B's actuators.\n\n"
    "Labelled-synthetic readings of the actuators of paper B, Figure 7, as built "
    "(fabrication errors, hysteresis, camera noise).",
    no_args_is_help=True,
)


@lab_app.command("measure")
def measure(
    out: Path = typer.Option(..., "--out", "-o", help="CSV file to write the measurements to."),
    plant: str = typer.Option(
        "fem", help="Model of the actuators as built: a lab plant (fem or analytical)."
    ),
    seed: int = typer.Option(0, help="Seed of the fabrication errors and the camera noise."),
    fabrication_error: float = typer.Option(
        0.2, help="Half-width of the uniform error of the wall t and layer b, mm."
    ),
    hysteresis: float = typer.Option(
        0.02, help="Half the largest loading/unloading gap, fraction of the angle."
    ),
    camera_noise: float = typer.Option(1.0, help="Standard deviation of the angle reading, deg."),
    elastomer_max_stretch: float = typer.Option(
        3.0, help="Largest stretch of the shipped Dragon Skin 30 test used by the lab's fit."
    ),
    pmax: float = typer.Option(0.25, help="Largest pressure set, MPa."),
    pstep: float = typer.Option(0.01, help="Pressure step between readings, MPa."),
    max_angle: float = typer.Option(270.0, help="Stop raising the pressure past this angle, deg."),
    unloading: bool = typer.Option(False, "--unloading", help="Also read the unloading branch."),
    cycles: int = typer.Option(
        1, help="Inflation cycles per actuator (at most SOFTBEND_MAX_CYCLES, default 1000)."
    ),
    designs: list[str] | None = typer.Option(
        None,
        "--design",
        help="Measure this design instead of paper B's seven (l,r,t,b,phi,lc in mm and deg); "
        "repeat for several.",
    ),
    elastomer: str = typer.Option(
        "dragon-skin-30", help="Shipped tensile test the lab's silicone is fitted to (Yeoh)."
    ),
    material: str | None = typer.Option(
        None,
        help="The lab's silicone whole, instead of --elastomer: a preset or the fit.json of "
        "'softbend materials fit' (fit.json#yeoh for one of its models).",
    ),
    as_json: bool = typer.Option(False, "--json", help="Print a JSON summary."),
) -> None:
    """Measure actuators in the virtual lab.

    The actuators of paper B, Figure 7 (or those of --design), measured as built
    (synthetic data).
    Writes the CSV and its figure (the same name with .png) together: a run
    that fails leaves both as they were.

    Example:

    \b
        softbend lab measure --out lab.csv --plant analytical
        softbend lab measure --out own.csv --design 130,7,2.5,3,10,9 --plant analytical
        softbend lab measure --out own.csv --design 130,7,2.5,3,10,9 --material fit.json
    """
    from softbend._io import atomic_files
    from softbend.limits import check_limit
    from softbend.reports.transfer_figures import lab_measurements
    from softbend.transfer.lab import VirtualLab
    from softbend.transfer.measurements import format_measurements

    check_limit("cycles", cycles, "--cycles")
    out = Path(out)
    figure = out.with_suffix(".png")
    if out.suffix.lower() == ".png":
        raise ValueError(
            f"The '--out' must name the CSV file; its figure is written beside it with "
            f"'.png'. Got {out}, which the figure would replace."
        )
    _common.check_output_file(out, "--out", kind="csv")
    _common.check_output_file(figure, "--out", kind="png")
    from softbend.design import SFRBADesign
    from softbend.transfer.lab import LAB_ACTUATORS

    actuators = tuple(SFRBADesign.parse(d) for d in designs) if designs else LAB_ACTUATORS
    if material is not None:
        from softbend.materials.choice import material_from_spec

        material_from_spec(material, field="--material")
    lab = VirtualLab(
        actuators=actuators,
        elastomer=elastomer,
        material=material,
        plant=plant,
        seed=seed,
        fabrication_error_mm=fabrication_error,
        hysteresis=hysteresis,
        camera_noise_deg=camera_noise,
        elastomer_max_stretch=elastomer_max_stretch,
        pmax_mpa=pmax,
        pressure_step_mpa=pstep,
        max_angle_deg=max_angle,
        unloading=unloading,
        cycles=cycles,
    )
    total = len(lab.actuators)
    with _common.progress_bar("virtual lab", total, enabled=not as_json) as advance:
        measurements = lab.measure(progress=lambda done, n, name: advance(actuator=name))
    text = format_measurements(measurements)
    with _common.output_errors(out, "--out"), atomic_files(out, figure) as (csv_file, png):
        with (
            _common.output_errors(out, "--out"),
            _common.as_written(csv_file, out),
            open(csv_file, "w", encoding="utf-8", newline="") as handle,
        ):
            handle.write(text)
        with _common.output_errors(figure, "--out"), _common.as_written(png, figure):
            lab_measurements(measurements, png)
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
        f"Virtual lab (SYNTHETIC, {plant}, seed {seed}): {len(measurements)} readings",
        ["actuator (l,r,t,b,φ,lc)", "readings", "top pressure (MPa)", "largest angle (°)"],
        [[str(k), int(r.points), float(r.pmax), float(r.angle_max)] for k, r in per.iterrows()],
    )
    _common.console.print(f"measurements written to {out}, figure {figure}")
