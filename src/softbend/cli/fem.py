"""``softbend fem``: one FEM sweep with its files, and the mesh-convergence study."""

from __future__ import annotations

from pathlib import Path
from typing import TYPE_CHECKING, Annotated

import typer

from softbend._validation import must_be
from softbend.cli import _common
from softbend.errors import InputError, keyed

if TYPE_CHECKING:
    import numpy as np

    from softbend.fem import FEMOptions

app = typer.Typer(
    help="Nonlinear 3D finite-element model of the actuator.\n\n"
    "The fiber-reinforced bending actuator of paper B: pressure sweeps of one "
    "design and the mesh-convergence study.",
    no_args_is_help=True,
)

#: Solver statistics written by ``fem run`` beside the files of
#: :func:`softbend.reports.fem_figures.sweep_with_files`; the marker of its folder.
SWEEP_JSON = "sweep.json"

#: Everything ``fem run`` writes into its ``--out`` folder (the last: the folder of VTK files).
RUN_FILES: tuple[str, ...] = ("sweep.csv", SWEEP_JSON, "angle_pressure.png", "shapes.png", "vtk")

DesignOption = Annotated[
    str,
    typer.Option("--design", help=_common.DESIGN_HELP),
]
MaxhOption = Annotated[float, typer.Option("--maxh", help="Largest element size, mm.")]
GravityOption = Annotated[
    str,
    typer.Option(
        "--gravity",
        help="Direction of gravity: bending (towards the strain-limiting layer, as paper B's "
        "experiments), against (the opposite), axial (base to tip) or none.",
    ),
]


MaterialOption = Annotated[
    str,
    typer.Option(
        "--material",
        help="Elastomer: a preset (dragon-skin-30) or the fit.json of 'softbend materials fit', "
        "optionally with its model after # (fit.json#yeoh; default the best fit).",
    ),
]


def _options(
    maxh: float, gravity: str, material: str = "dragon-skin-30", output: str = "interpolate"
) -> FEMOptions:
    from softbend.fem import FEMOptions
    from softbend.materials.choice import material_from_spec

    with keyed("material"):
        elastomer = material_from_spec(material)
    return FEMOptions(maxh_mm=maxh, gravity=gravity, elastomer=elastomer, output=output)


def steps_reached(grid: np.ndarray, pressure_mpa: float) -> int:
    """How many pressures of the sweep's sorted ``grid`` (MPa) a sweep at ``pressure_mpa``
    has reached: the unit of ``fem run``'s progress (a load step may be cut into sub-steps,
    which count when they reach the next pressure of the grid)."""
    import numpy as np

    return int(np.searchsorted(grid, pressure_mpa * (1 + 1e-9) + 1e-12, side="right"))


@app.command("run")
def run(
    design: DesignOption = "100,6,2,2,5,10",
    pmax: Annotated[
        float, typer.Option("--pmax", help="Largest pressure of the sweep's grid, MPa.")
    ] = 0.2,
    pstep: Annotated[
        float, typer.Option("--pstep", help="Pressure step of the sweep's grid (outputs), MPa.")
    ] = 0.005,
    out: Annotated[
        Path,
        typer.Option(
            "--out",
            "-o",
            help="Folder for the CSV, JSON, figures and VTK files (replaced as a whole: a new "
            "or empty folder, or an earlier result of this command).",
        ),
    ] = Path("results/fem"),
    maxh: MaxhOption = 5.0,
    gravity: GravityOption = "bending",
    material: MaterialOption = "dragon-skin-30",
    shapes: Annotated[int, typer.Option("--shapes", help="Deformed shapes drawn and saved.")] = 5,
    solve_every: Annotated[
        bool,
        typer.Option("--solve-every", help="Solve every output pressure (no interpolation)."),
    ] = False,
    json_output: Annotated[bool, typer.Option("--json", help="Print the sweep as JSON.")] = False,
) -> None:
    """Sweep one design from 0 MPa to --pmax with the FEM.

    Writes into the folder --out: sweep.csv (pressure, angle, tip, converged,
    Newton iterations), sweep.json (solver statistics and options),
    angle_pressure.png (with the analytical model), shapes.png (deformed
    shapes, paper B, Figure 2b) and vtk/shape_p<MPa>MPa.vtu (such as
    shape_p0.050MPa.vtu: the whole actuator with the displacement, mm, the
    largest principal stretch and the strain-energy density, MPa) for
    ParaView (apply Warp By Vector). The folder is written as a whole: built
    beside --out and swapped in when every file is complete, so a run that
    fails leaves the previous results as they were and a rerun never mixes two
    runs. An existing --out may hold only what this command writes.

    Example:

    \b
        softbend fem run --design 100,6,2,2,5,10 --pmax 0.2 --out fem
    """
    import numpy as np

    from softbend._io import staged_dir, write_text_atomic
    from softbend._validation import check_int
    from softbend.design import SFRBADesign
    from softbend.fem.stats import fem_stats
    from softbend.models import default_pressures_mpa
    from softbend.reports.fem_figures import sweep_with_files

    actuator = SFRBADesign.parse(design)
    pressures = default_pressures_mpa(pmax, pstep)
    options = _options(maxh, gravity, material, output="solve" if solve_every else "interpolate")
    options.check_mesh(actuator)  # before NGSolve loads: a too fine --maxh is one line at once
    check_int(shapes, "shapes", low=1)
    out = Path(out)
    _common.check_output_dir(out, "--out", files=RUN_FILES[:-1])
    _common.check_replaceable_dir(out, "--out", "fem run", files=RUN_FILES, marker=SWEEP_JSON)
    grid = np.sort(np.asarray(pressures, dtype=float))
    with (
        _common.output_errors(out, "--out"),
        staged_dir(out) as stage,
        _common.as_written(stage, out),
    ):
        with _common.progress_bar(
            "FEM sweep (pressure steps)", int(grid.size), enabled=not json_output
        ) as advance:
            state = {"done": 0}

            def on_step(pressure: float, angle: float, target: float) -> None:
                done = steps_reached(grid, pressure)
                advance(
                    max(done - state["done"], 0), p=f"{pressure:.4f} MPa", angle=f"{angle:.1f}°"
                )
                state["done"] = max(done, state["done"])

            sweep = sweep_with_files(
                actuator,
                pressures,
                options,
                stage,
                shape_pressures_mpa=shapes,
                vtk=True,
                progress=on_step,
            )
        result = sweep.result
        stats = fem_stats(result)
        summary = {
            "design": str(actuator),
            "stop_reason": stats["stop_reason"],
            "max_pressure_mpa": result.max_pressure_mpa,
            "max_angle_deg": result.max_angle_deg,
            "wall_time_s": result.wall_time_s,
            "elements": result.mesh_size,
            "stats": result.stats,
        }
        write_text_atomic(stage / SWEEP_JSON, _common.json_text(summary))
    if json_output:
        _common.print_json(
            {**summary, "pressure_mpa": result.pressure_mpa, "angle_deg": result.angle_deg}
        )
        return
    rows = [
        [f"{p:.3f}", f"{a:.2f}", f"{x:.1f}", f"{z:.1f}", int(i)]
        for p, a, x, z, i in zip(
            result.pressure_mpa,
            result.angle_deg,
            result.tip_x_mm,
            result.tip_z_mm,
            result.newton_iterations,
            strict=True,
        )
        if round(p / pstep) % max(1, round(0.02 / pstep)) == 0
    ]
    _common.print_table(
        f"FEM sweep of ({actuator})",
        ["pressure MPa", "angle °", "tip x mm", "tip z mm", "Newton its"],
        rows,
    )
    t = stats["timings"]
    _common.console.print(
        f"stop: {stats['stop_reason']}; {result.mesh_size} elements, "
        f"{stats['ndof']} dofs; {result.wall_time_s:.1f} s "
        f"(assembly {t['assembly_s'] + t['residual_s']:.1f} s, "
        f"factorisation {t['factorization_s']:.1f} s); files in {out}"
    )


@app.command("mesh-study")
def mesh_study(
    design: DesignOption = "100,6,2,2,5,10",
    maxh: Annotated[
        str, typer.Option("--maxh", help="Comma-separated element sizes, mm, coarse to fine.")
    ] = "6,5,4,3",
    pressures: Annotated[
        str, typer.Option("--pressures", help="Comma-separated pressures, MPa.")
    ] = "0,0.05,0.1",
    gravity: GravityOption = "bending",
    material: MaterialOption = "dragon-skin-30",
    json_output: Annotated[bool, typer.Option("--json", help="Print the table as JSON.")] = False,
) -> None:
    """Bending angle at --pressures for each element size.

    One row per element size of --maxh, coarse to fine, with the change of
    each angle relative to the previous size, in %.

    Example:

    \b
        softbend fem mesh-study --maxh 6,5,4,3 --pressures 0,0.05,0.1
    """
    from softbend.design import SFRBADesign
    from softbend.fem.verification import mesh_study as study

    actuator = SFRBADesign.parse(design)
    sizes = _floats(maxh, "maxh")
    grid = _floats(pressures, "pressures")
    with _common.progress_bar("mesh sizes", len(sizes), enabled=not json_output) as advance:
        rows = study(
            actuator, sizes, grid, _options(4.0, gravity, material), progress=lambda d, n: advance()
        )
    table = []
    for i, row in enumerate(rows):
        change = (
            [
                abs(a - b) / abs(b) * 100 if b else float("nan")
                for a, b in zip(row.angles_deg, rows[i - 1].angles_deg, strict=True)
            ]
            if i
            else [float("nan")] * len(grid)
        )
        table.append({**row.__dict__, "change_pct": change})
    if json_output:
        _common.print_json({"design": str(actuator), "pressures_mpa": grid, "rows": table})
        return
    columns = ["maxh mm", "elements", "dofs", "s"]
    columns += [f"θ at {p:g} MPa" for p in grid] + [f"Δ% at {p:g}" for p in grid]
    _common.print_table(
        f"Mesh convergence of ({actuator})",
        columns,
        [
            [r["maxh_mm"], r["elements"], r["ndof"], f"{r['wall_time_s']:.0f}"]
            + [f"{a:.3f}" for a in r["angles_deg"]]
            + [f"{c:.2f}" for c in r["change_pct"]]
            for r in table
        ],
    )


def _floats(text: str, key: str) -> list[float]:
    """The comma-separated numbers of ``text`` (at least one), errors keyed ``key``."""
    try:
        values = [float(v) for v in text.split(",") if v.strip()]
    except ValueError:
        raise InputError(must_be("comma-separated numbers", text), key=key) from None
    if not values:
        raise InputError(must_be("at least one number", text), key=key)
    return values
