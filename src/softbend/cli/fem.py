"""``softbend fem``: one FEM sweep with its files, and the mesh-convergence study."""

from __future__ import annotations

from pathlib import Path
from typing import TYPE_CHECKING, Annotated, Any

import typer

from softbend._validation import must_be
from softbend.cli import _common
from softbend.errors import InputError, keyed

if TYPE_CHECKING:
    import numpy as np

    from softbend.actuators import Design
    from softbend.fem import FEMOptions
    from softbend.fem.families import FEMFamily
    from softbend.fem.run import FamilySweep
    from softbend.fem.verification import MeshStudyRow

app = typer.Typer(
    help="Nonlinear 3D finite-element model of the actuator.\n\n"
    "The fiber-reinforced bending actuator of paper B (--family sfrba, the default) "
    "or a PneuNet (--family pneunet): pressure sweeps of one design and the "
    "mesh-convergence study.",
    no_args_is_help=True,
)

#: Solver statistics written by ``fem run`` beside the files of
#: :func:`softbend.fem.run.sweep_with_files`; the marker of its folder.
SWEEP_JSON = "sweep.json"

#: Everything ``fem run`` writes into its ``--out`` folder (the last: the folder of VTK files).
RUN_FILES: tuple[str, ...] = ("sweep.csv", SWEEP_JSON, "angle_pressure.png", "shapes.png", "vtk")

DesignOption = Annotated[
    str | None,
    typer.Option(
        "--design",
        help=_common.DESIGN_HELP
        + " For another --family: NAME=VALUE pairs separated by commas (n_chambers=6,wall_mm=1.5); "
        "parameters left out take the family's reference values (default: the reference).",
    ),
]
FamilyOption = Annotated[
    str,
    typer.Option(
        "--family",
        help="FEM actuator family: sfrba (paper B's fiber-reinforced actuator) or pneunet "
        "(a row of chambers on a strain-limiting layer).",
    ),
]
MaxhOption = Annotated[
    float | None,
    typer.Option("--maxh", help="Largest element size, mm (default: the family's, sfrba 5)."),
]
GravityOption = Annotated[
    str | None,
    typer.Option(
        "--gravity",
        help="Direction of gravity: bending (towards the strain-limiting layer, as paper B's "
        "experiments), against (the opposite), axial (base to tip) or none (default: the "
        "family's, sfrba bending, pneunet none).",
    ),
]

ContactOption = Annotated[
    str | None,
    typer.Option(
        "--contact",
        help="Contact between the facing walls of neighbouring PneuNet chambers: on (the "
        "default for --family pneunet: the sweep goes on to --pmax or 180° with the walls "
        "pressing on each other, the contact force and pressure reported per step) or off "
        "(the sweep stops where the walls first touch). sfrba: off only (no faces touch).",
    ),
]


MaterialOption = Annotated[
    str | None,
    typer.Option(
        "--material",
        help="Elastomer: a preset (dragon-skin-30) or the fit.json of 'softbend materials fit', "
        "optionally with its model after # (fit.json#yeoh; default the best fit). Default: "
        "the family's (sfrba dragon-skin-30, pneunet Elastosil M4601).",
    ),
]


PmaxOption = Annotated[
    float | None,
    typer.Option(
        "--pmax", help="Largest pressure of the sweep's grid, MPa (default: the family's)."
    ),
]
PstepOption = Annotated[
    float | None,
    typer.Option(
        "--pstep", help="Pressure step of the sweep's grid (outputs), MPa (default: the family's)."
    ),
]
OutOption = Annotated[
    Path,
    typer.Option(
        "--out",
        "-o",
        help="Folder for the CSV, JSON, figures and VTK files (replaced as a whole: a new "
        "or empty folder, or an earlier result of this command).",
    ),
]
ShapesOption = Annotated[int, typer.Option("--shapes", help="Deformed shapes drawn and saved.")]
SolveEveryOption = Annotated[
    bool, typer.Option("--solve-every", help="Solve every output pressure (no interpolation).")
]
SizesOption = Annotated[
    str | None,
    typer.Option(
        "--maxh",
        help="Comma-separated element sizes, mm, coarse to fine (default sfrba 6,5,4,3; "
        "pneunet 3,2.5,2).",
    ),
]
PressuresOption = Annotated[
    str | None,
    typer.Option(
        "--pressures",
        help="Comma-separated pressures, MPa (default sfrba 0,0.05,0.1; pneunet "
        "0,0.002,0.004,0.006: below the reference's touching walls).",
    ),
]


def _family_options(
    family: FEMFamily,
    maxh: float | None,
    gravity: str | None,
    material: str | None,
    *,
    solve_every: bool = False,
    contact: str | None = None,
) -> FEMOptions:
    """The options of ``family``, from its defaults and the given flags.

    ``contact`` None: the family's default, "on" for the PneuNet, "off" for paper
    B's actuator (which has no faces that touch: "on" is refused for it).
    """
    from softbend.materials.choice import material_from_spec

    changes: dict[str, object] = {"maxh_mm": family.maxh_mm if maxh is None else maxh}
    changes.update(family.contact_options(contact))
    if gravity is not None:
        changes["gravity"] = gravity
    if material is not None:
        with keyed("material"):
            changes["elastomer"] = material_from_spec(material)
    changes["output"] = "solve" if solve_every else "interpolate"
    return family.options(**changes)


def steps_reached(grid: np.ndarray, pressure_mpa: float) -> int:
    """How many pressures of the sweep's sorted ``grid`` (MPa) a sweep at ``pressure_mpa``
    has reached: the unit of ``fem run``'s progress (a load step may be cut into sub-steps,
    which count when they reach the next pressure of the grid)."""
    import numpy as np

    return int(np.searchsorted(grid, pressure_mpa * (1 + 1e-9) + 1e-12, side="right"))


@app.command("run")
def run(
    design: DesignOption = None,
    family: FamilyOption = "sfrba",
    pmax: PmaxOption = None,
    pstep: PstepOption = None,
    out: OutOption = Path("results/fem"),
    maxh: MaxhOption = None,
    gravity: GravityOption = None,
    material: MaterialOption = None,
    shapes: ShapesOption = 5,
    solve_every: SolveEveryOption = False,
    contact: ContactOption = None,
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

    With --family pneunet: a PneuNet, --design NAME=VALUE pairs (the reference
    PneuNet without). With --contact on (its default) the facing walls of
    neighbouring chambers press on each other (frictionless penalty contact)
    and the sweep goes on to --pmax or 180°; the table adds the contact force
    and mean contact pressure, and --json the cavity volume, contact force and
    contact pressure of every converged step. With --contact off the sweep
    stops where the walls first touch (the reason names the pressure). Its
    folder holds sweep.csv, sweep.json, angle_pressure.png and vtk/ (no
    shapes.png, and no analytical model on the curve).

    Example:

    \b
        softbend fem run --design 100,6,2,2,5,10 --pmax 0.2 --out fem
        softbend fem run --family pneunet --design n_chambers=6,wall_mm=1.5 --out pneunet
        softbend fem run --family pneunet --contact off --out pneunet-to-touch
    """
    from softbend._validation import check_int
    from softbend.fem.families import get_family
    from softbend.models import default_pressures_mpa

    with keyed("family"):
        chosen = get_family(family)
    actuator = chosen.parse(design)
    options = _family_options(
        chosen, maxh, gravity, material, solve_every=solve_every, contact=contact
    )
    pstep = chosen.pstep_mpa if pstep is None else pstep
    pressures = default_pressures_mpa(chosen.pmax_mpa if pmax is None else pmax, pstep)
    chosen.check_mesh(actuator, options)  # before NGSolve loads: a too fine --maxh is one line
    check_int(shapes, "shapes", low=1)
    out = Path(out)
    _common.check_output_dir(out, "--out", files=RUN_FILES[:-1])
    _common.check_replaceable_dir(out, "--out")
    sweep = _sweep_into(out, chosen, actuator, pressures, options, shapes, quiet=json_output)
    _print_sweep(sweep, pstep, out, json_output=json_output)


def _sweep_into(
    out: Path,
    family: FEMFamily,
    design: Design,
    pressures: np.ndarray,
    options: FEMOptions,
    shapes: int,
    *,
    quiet: bool,
) -> FamilySweep:
    """Sweep ``design`` into a stage swapped in as ``out``: files, figures and sweep.json."""
    import numpy as np

    from softbend._io import write_text_atomic
    from softbend._outdir import staged_dir
    from softbend.fem.run import sweep_summary, sweep_with_files
    from softbend.reports.fem_figures import sweep_figures

    grid = np.sort(np.asarray(pressures, dtype=float))
    with (
        _common.output_errors(out, "--out"),
        staged_dir(out) as stage,
        _common.as_written(stage, out),
    ):
        with _common.progress_bar(
            "FEM sweep (pressure steps)", int(grid.size), enabled=not quiet
        ) as advance:
            state = {"done": 0}

            def on_step(pressure: float, angle: float, target: float) -> None:
                done = steps_reached(grid, pressure)
                advance(
                    max(done - state["done"], 0), p=f"{pressure:.4f} MPa", angle=f"{angle:.1f}°"
                )
                state["done"] = max(done, state["done"])

            sweep = sweep_with_files(
                family,
                design,
                pressures,
                options,
                stage,
                shape_pressures_mpa=shapes,
                vtk=True,
                progress=on_step,
            )
        sweep_figures(sweep, stage)
        write_text_atomic(stage / SWEEP_JSON, _common.json_text(sweep_summary(sweep)))
    return sweep


def _print_sweep(sweep: FamilySweep, pstep: float, out: Path, *, json_output: bool) -> None:
    """The sweep as JSON, or its table (about ten rows) and one line of solver statistics."""
    from softbend.fem.run import sweep_summary
    from softbend.fem.stats import fem_stats

    result = sweep.result
    if json_output:
        extra = {"pressure_mpa": result.pressure_mpa, "angle_deg": result.angle_deg}
        _common.print_json({**sweep_summary(sweep), **extra})
        return
    import numpy as np

    stats = fem_stats(result)
    every = max(1, len(result.pressure_mpa) // 10)
    columns = ["pressure MPa", "angle °", "tip x mm", "tip z mm", "Newton its"]
    contact: list[np.ndarray] = []
    if "step_contact_force_n" in stats:  # per step: read at the table's pressures
        columns += ["contact N", "contact kPa"]
        steps = np.asarray(stats["steps_mpa"])
        for key in ("step_contact_force_n", "step_contact_pressure_kpa"):
            contact.append(np.interp(result.pressure_mpa, steps, stats[key]))  # type: ignore[literal-required]
    rows = [
        [f"{p:.3f}", f"{a:.2f}", f"{x:.1f}", f"{z:.1f}", int(i)] + [f"{c[k]:.3g}" for c in contact]
        for k, (p, a, x, z, i) in enumerate(
            zip(
                result.pressure_mpa,
                result.angle_deg,
                result.tip_x_mm,
                result.tip_z_mm,
                result.newton_iterations,
                strict=True,
            )
        )
        if round(p / pstep) % every == 0
    ]
    _common.print_table(
        f"FEM sweep of the {sweep.family.name} ({sweep.design.as_text()})", columns, rows
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
    design: DesignOption = None,
    family: FamilyOption = "sfrba",
    maxh: SizesOption = None,
    pressures: PressuresOption = None,
    gravity: GravityOption = None,
    material: MaterialOption = None,
    contact: ContactOption = None,
    json_output: Annotated[bool, typer.Option("--json", help="Print the table as JSON.")] = False,
) -> None:
    """Bending angle at --pressures for each element size.

    One row per element size of --maxh, coarse to fine, with the change of
    each angle relative to the previous size, in %.

    Example:

    \b
        softbend fem mesh-study --maxh 6,5,4,3 --pressures 0,0.05,0.1
    """
    from softbend.fem.families import get_family
    from softbend.fem.verification import mesh_study as study

    with keyed("family"):
        chosen = get_family(family)
    default_maxh, default_pressures = chosen.mesh_study_defaults()
    sizes = _floats(maxh, "maxh") if maxh else list(default_maxh)
    grid = _floats(pressures, "pressures") if pressures else list(default_pressures)
    actuator = chosen.parse(design)
    options = _family_options(chosen, None, gravity, material, contact=contact)
    for h in sizes:  # a too fine size is one line before any sweep
        chosen.check_mesh(actuator, options.replace(maxh_mm=h))
    with _common.progress_bar("mesh sizes", len(sizes), enabled=not json_output) as advance:
        rows = study(actuator, sizes, grid, options, progress=lambda d, n: advance())
    table = _mesh_table(rows, len(grid))
    if json_output:
        _common.print_json({"design": actuator.as_text(), "pressures_mpa": grid, "rows": table})
        return
    columns = ["maxh mm", "elements", "dofs", "s"]
    columns += [f"θ at {p:g} MPa" for p in grid] + [f"Δ% at {p:g}" for p in grid]
    _common.print_table(
        f"Mesh convergence of ({actuator.as_text()})",
        columns,
        [
            [r["maxh_mm"], r["elements"], r["ndof"], f"{r['wall_time_s']:.0f}"]
            + [f"{a:.3f}" for a in r["angles_deg"]]
            + [f"{c:.2f}" for c in r["change_pct"]]
            for r in table
        ],
    )


def _mesh_table(rows: list[MeshStudyRow], n_pressures: int) -> list[dict[str, Any]]:
    """The study's rows with the change of each angle from the previous size, %."""
    table = []
    for i, row in enumerate(rows):
        change = (
            [
                abs(a - b) / abs(b) * 100 if b else float("nan")
                for a, b in zip(row.angles_deg, rows[i - 1].angles_deg, strict=True)
            ]
            if i
            else [float("nan")] * n_pressures
        )
        table.append({**row.__dict__, "change_pct": change})
    return table


def _floats(text: str, key: str) -> list[float]:
    """The comma-separated numbers of ``text`` (at least one), errors keyed ``key``."""
    try:
        values = [float(v) for v in text.split(",") if v.strip()]
    except ValueError:
        raise InputError(must_be("comma-separated numbers", text), key=key) from None
    if not values:
        raise InputError(must_be("at least one number", text), key=key)
    return values
