"""``softbend design find``: the designs that meet a specification, verified by the FEM.

The search names the model's own parameters (its recorded actuator
description): paper B's ``l, r, t, b, phi, lc``, or another actuator's
(``--fix layer=paper --range wall_mm=1:2 --minimize n_chambers``), with
pressures in the model's pressure unit; ``--verify`` sweeps an actuator with
the FEM of its family (paper B's, or the ``fem_family`` its description names,
such as the PneuNet) and otherwise says so in one line; a sweep that stops
before the pressure checked (walls touching, no convergence) is shown as
stopped, with the FEM's reason.

Everything is checked before a design is scored: the output folder, every
number against its declared range (:data:`VERIFY`, :data:`WORKERS`,
:data:`softbend.design_search.search.TOP` and the target's), options that
contradict each other (a target, range or objective beside ``--spec``; a
verification option without ``--verify``), the material of the verification,
every spec of the file and the size of every search's grid. The verification's
campaign is kept beside ``--out`` (:func:`verification_db`) until the command
ends: a run stopped by Ctrl-C or a kill keeps the designs it swept, and the same
command resumes from them; a finished run removes it.
"""

from __future__ import annotations

import hashlib
import os
from pathlib import Path
from typing import TYPE_CHECKING, Any

import typer

from softbend._validation import check_choice, must_be
from softbend.cli import _common
from softbend.errors import InputError, SoftbendError
from softbend.parameters import Range

if TYPE_CHECKING:
    from softbend.campaign.backends import ResolvedMaterial
    from softbend.design_search.search import SearchResult

#: How many of the best candidates ``--verify`` sweeps.
VERIFY = Range(0, 100, "designs", "each is a sweep of the FEM, minutes long")

#: The processes of the verification (``--workers``).
WORKERS = Range(1, 4096, "processes", "the bound of a campaign's local workers")

#: Options a spec file gives itself (by parameter), and what of each spec they set.
_SPEC_GIVES: dict[str, str] = {
    "angle": "target",
    "at": "target",
    "max_pressure": "target",
    "max_angle_at": "target",
    "curve": "target",
    "tolerance": "tolerance",
    "margin": "margin",
    "minimize": "objectives",
    "maximize": "objectives",
    "fix": "ranges (fix, range)",
    "ranges": "ranges (fix, range)",
    "resolution": "resolution",
}

#: Options of the verification alone (by parameter).
_VERIFY_OPTIONS: tuple[str, ...] = ("backend", "workers", "material", "replace_stopped")


def _typed(ctx: typer.Context, parameter: str) -> bool:
    """Whether the option of ``parameter`` was given (typed or from the environment)."""
    source = ctx.get_parameter_source(parameter)
    return getattr(source, "name", None) in ("COMMANDLINE", "ENVIRONMENT")


def _check_count(value: int, key: str, allowed: Range) -> None:
    """Refuse an integer option outside ``allowed`` (keyed ``key``), with the range and why."""
    if not allowed.contains(value):
        raise InputError(
            must_be(f"an integer in {allowed.describe()} ({allowed.why})", value), key=key
        )


def _verification(
    ctx: typer.Context, verify: int, backend: str, workers: int | None, material: str | None
) -> ResolvedMaterial | None:
    """Check the options of ``--verify`` and read ``--material`` once; the material
    (None: the backend's own).

    Raises
    ------
    InputError
        A verification option without ``--verify``, a backend that is not public
        or takes no material, ``--workers`` outside :data:`WORKERS`.
    SoftbendError
        A material that is not a preset nor a valid ``fit.json`` (as ``fem run``).
    """
    _check_count(verify, "verify", VERIFY)
    if not verify:
        given = [name for name in _VERIFY_OPTIONS if _typed(ctx, name)]
        if given:
            raise InputError(
                "applies to the verification; give --verify N (the best N candidates "
                "swept), or leave it out",
                key=given[0],
            )
        return None
    from softbend.campaign.backends import public_backends, resolve_material, takes_material

    check_choice(backend, "backend", public_backends())
    if workers is not None:
        _check_count(workers, "workers", WORKERS)
    if material is None:
        return None
    if not takes_material(backend):
        takers = [n for n in public_backends() if takes_material(n)]
        raise InputError(
            f"applies to a backend that takes a material ({', '.join(takers)}); "
            f"got --backend {backend}",
            key="material",
        )
    return resolve_material(material)


app = typer.Typer(
    help="Design to a specification.\n\n"
    "Search the design space on a surrogate for the designs that meet a target "
    "bending, and verify the best with the FEM.",
    no_args_is_help=True,
)


@app.command("find")
def find(
    ctx: typer.Context,
    out: Path = typer.Option(..., "--out", "-o", help="Folder for the tables and figures."),
    model: Path = typer.Option(
        None,
        help="Saved surrogate to search (default: the shipped FEM-trained MLP); its actuator's "
        "parameters are the names of --fix, --range, --resolution and --minimize.",
    ),
    spec: Path = typer.Option(
        None, help="A TOML file of [[spec]] tables, one folder of results per spec."
    ),
    angle: float = typer.Option(None, help="Target angle, deg (with --at or --max-pressure)."),
    at: str = typer.Option(
        None,
        help="Pressure the target angle is read at: a number in the model's pressure unit "
        "(MPa for paper B's actuator) or with a unit (20psi, 138kPa, 0.1MPa, 1.5bar).",
    ),
    max_pressure: str = typer.Option(
        None,
        help="Reach --angle at no more than this pressure, as --at (then --minimize pressure).",
    ),
    max_angle_at: str = typer.Option(
        None, help="Bend as far as possible at this pressure, as --at."
    ),
    curve: str = typer.Option(
        None,
        help="Follow the points P:ANGLE, comma-separated (pressure in the model's unit:deg), "
        "e.g. 0.05:40,0.1:95.",
    ),
    tolerance: float = typer.Option(3.0, help="How far the angle may miss, deg, in (0, 90]."),
    margin: float = typer.Option(
        0.0, help="Degrees of the tolerance kept back on the surrogate (its own error)."
    ),
    minimize: list[str] = typer.Option(
        None,
        help="Objectives to minimise: a design parameter (l, r, t, b, phi, lc of paper B's "
        "actuator), pressure, volume (paper B's), sensitivity, angle, error (comma-separated "
        "or repeated; default error).",
    ),
    maximize: list[str] = typer.Option(None, help="Objectives to maximise (as --minimize)."),
    fix: list[str] = typer.Option(
        None, help="Fix a parameter, NAME=VALUE (repeatable; a categorical one by level name)."
    ),
    ranges: list[str] = typer.Option(
        None,
        "--range",
        help="Range of a parameter, NAME=LOW:HIGH (repeatable; whole ends for an integer one, "
        "none for a categorical one, whose levels are all searched unless fixed).",
    ),
    resolution: list[str] = typer.Option(
        None,
        help="Mould resolution: a number for every parameter or NAME=STEP (repeatable); "
        "0 searches continuously. Default 0.5 mm and 1° of phi; for another actuator each "
        "continuous parameter's declared resolution (else a round step, about 1/100 of its "
        "range), integers by 1.",
    ),
    top: int = typer.Option(
        10, help="Candidates listed, 1 to 1000 (to 25 with a continuous parameter)."
    ),
    neighbours: bool = typer.Option(
        False, "--neighbours", help="Also list designs one step from a better one."
    ),
    verify: int = typer.Option(
        0,
        help="Sweep the best N (at most 100) with --backend and compare (paper B's actuator, "
        "or another with the FEM of the family its description names; one that names none "
        "is not verified, and the output says so).",
    ),
    backend: str = typer.Option("fem", help="Backend of the verification: fem or analytical."),
    workers: int = typer.Option(
        None, help="Processes of the verification, 1 to 4096 (default: all cores)."
    ),
    material: str = typer.Option(None, help="Elastomer of the verification (as fem run)."),
    replace_stopped: bool = typer.Option(
        False,
        "--replace-stopped",
        help="Replace a verified candidate whose FEM sweep stops before the pressure "
        "(chamber walls touch, no convergence) by the next listed one, until N reach it "
        "or the --top list ends.",
    ),
    allow_extrapolation: bool = typer.Option(
        False, "--allow-extrapolation", help="Search outside the training data, answers flagged."
    ),
    as_json: bool = typer.Option(False, "--json", help="Print the results as JSON."),
) -> None:
    """Find the designs that meet a target bending.

    Every design of the grid of manufacturable values (--resolution) within the
    model's training ranges (or --range, --fix) is scored on the surrogate;
    those that meet the target within --tolerance are ranked by the
    objectives (several: the Pareto front), each listed design more than one
    step from a better one (--neighbours lists them all). Answers outside the model's
    training data are passed over unless --allow-extrapolation (which lists them
    with a "no" in the table's "trained there" column, "supported": false in the
    JSON and a warning on stderr, as softbend predict does). With --verify N
    the best N are swept by the FEM and set beside the surrogate.

    Every input is checked before a design is scored: each number against its
    range, the size of each grid (at most 20 million designs), the material,
    and every [[spec]] of --spec (a name is a plain folder name of --out; the
    target, range and objective options are the file's, not given beside it).
    The results are built beside --out and swapped in when complete; a run
    killed during the verification leaves a hidden .OUT.PID-*.new folder that
    the next run into --out removes. The verification's sweeps are kept beside
    --out (.OUT.verify-KEY.duckdb) until the command ends: after Ctrl-C or a
    kill the same command sweeps only the designs not yet swept.

    The names are the model's own: paper B's l, r, t, b, phi, lc (mm, deg;
    pressures in MPa), or the parameters of the actuator another model was
    trained on, searched within its training ranges and its description's
    (integers on whole numbers, a categorical parameter on every level unless
    --fix names one, a continuous one on its declared resolution, else on a
    round step of about a hundredth of its range), designs breaking the
    description's constraints left out, pressures in the model's unit.
    --verify sweeps another actuator with the FEM of the family its description
    names (such as pneunet; --backend fem); a sweep that stops before the
    pressure checked (chamber walls touching, no convergence) is "stopped", with
    the FEM's reason, not an angle; --replace-stopped then verifies the next
    listed design instead, until N reach the pressure. An actuator that names
    no FEM family is not verified, and the output says so (a warning, and
    "verify_skipped" in search.json).

    Example:

    \b
        softbend design find --angle 90 --at 0.08 --minimize l --fix phi=10 \\
            --range t=3:4 --verify 5 --out design
        softbend design find --model pneunet.json --angle 90 --at 30 \\
            --minimize n_chambers --fix layer=paper --range wall_mm=1:2 --out design
    """
    from softbend._outdir import staged_dir
    from softbend.design_search import spec as specs
    from softbend.design_search.search import TOP, LoadedModel, find_designs, searched_ranges
    from softbend.design_search.space import space_of
    from softbend.design_search.verify import verify_candidates, verify_family, verify_skipped
    from softbend.reports.design_outputs import FILES, write_search
    from softbend.transfer.base import shipped_base_path

    out = Path(out)
    model_path = shipped_base_path() if model is None else Path(model)
    inputs = tuple(p for p in (model, spec) if p is not None)
    _common.check_output_dir(out, "--out", inputs=inputs)
    _common.check_replaceable_dir(out, "--out", inputs=inputs)
    _check_count(top, "top", TOP)
    elastomer = _verification(ctx, verify, backend, workers, material)
    loaded = LoadedModel.load(model_path)  # read once; its actuator names the parameters
    space = space_of(loaded.actuator)
    if verify and space.verifiable:  # a family that cannot sweep its designs: before any search
        verify_family(space)
    actuator = None if space.paper_b else space.actuator
    if spec is not None:
        for name, what in _SPEC_GIVES.items():
            if _typed(ctx, name):
                raise InputError(
                    f"cannot be used with --spec: the spec file gives each spec's {what}",
                    key=name,
                )
        chosen = specs.load_specifications(
            spec,
            reserved=sorted({"search.json", *FILES}),
            actuator=actuator,
        )
    else:
        unit = space.pressure_unit
        target = specs.target_from_options(
            angle=angle, at=_pressure(at, unit, "--at"),
            max_pressure=_pressure(max_pressure, unit, "--max-pressure"),
            max_angle_at=_pressure(max_angle_at, unit, "--max-angle-at"),
            curve=curve, tolerance=tolerance, unit=unit,
        )  # fmt: skip
        if not 0 <= margin < tolerance:
            raise InputError(
                must_be(
                    f"in [0, {tolerance:g}) degrees (below --tolerance, the miss the "
                    "surrogate's own error may take)",
                    margin,
                ),
                key="margin",
            )
        numbers = [s for s in resolution or () if "=" not in s]
        if len(numbers) > 1:
            raise InputError(f"gives a number {len(numbers)} times; give it once", key="resolution")
        try:
            every = float(numbers[0]) if numbers else None
        except ValueError:
            raise InputError(
                must_be("a number or NAME=STEP", numbers[0]), key="resolution"
            ) from None
        given, steps = specs.build_ranges(
            fix or (),
            ranges or (),
            [s for s in resolution or () if "=" in s],
            step=every,
            space=space,
        )
        objectives = specs.parse_objectives(minimize or (), maximize or (), space)
        chosen = [specs.Specification(target, given, objectives, "spec", steps, margin, actuator)]
    training = loaded.metadata.get("training_ranges")
    for number, one in enumerate(chosen, start=1):  # every grid counted before any is built
        try:
            searched_ranges(one, training, allow_extrapolation=allow_extrapolation, top=top)
        except ValueError as exc:
            if spec is None:
                raise
            said = exc.detail if isinstance(exc, SoftbendError) else str(exc)
            raise InputError(f"[[spec]] {number} ({one.name!r}): {said}", file=str(spec)) from None
    with _common.library_progress(enabled=not as_json):
        results = [
            find_designs(
                loaded,
                one,
                top=top,
                allow_extrapolation=allow_extrapolation,
                distinct=not neighbours,
            )
            for one in chosen
        ]
    payload: list[dict[str, Any]] = []
    skipped = verify_skipped(results[0], backend) if verify else None
    if skipped is not None:  # another actuator: said once, and in each record
        for result in results:
            result.verify_skipped = skipped
    kept: list[Path] = []  # the verification's campaigns, removed once the command ends
    with _common.output_errors(out, "--out"), staged_dir(out) as stage:
        if verify and skipped is None:
            with _common.library_progress(enabled=not as_json):
                for result in results:
                    if result.candidates:
                        db = verification_db(out, result, backend, elastomer, verify)
                        kept.append(db)
                        verify_candidates(
                            result,
                            verify,
                            db_path=db,
                            backend=backend,
                            workers=workers,
                            material=elastomer,
                            scratch_dir=stage,
                            replace_stopped=replace_stopped,
                        )
        payload = [r.to_dict() for r in results]
        for result in results:
            folder = stage / result.spec.name if len(results) > 1 else stage
            write_search(result, loaded.predictor, folder)
        if len(results) > 1:  # the record of them all, and the folder's marker
            (stage / "search.json").write_text(
                _common.json_text({"specs": payload}) + "\n", encoding="utf-8"
            )
    for db in kept:
        for path in (db, db.with_name(db.name + ".wal")):
            path.unlink(missing_ok=True)
    for result in results:
        line = result.message()  # none meets the target (and the pressures outside, if any)
        if line is None and result.outside_pressures:
            line = f"{result.pressure_warning()}."
        if line is not None:
            _common.warning_line(line)
        line = _extrapolated(result, model_path, len(results) > 1)
        if line is not None:
            _common.warning_line(line)
    if skipped is not None:
        _common.warning_line(f"--verify skipped: {skipped}; the answers are the surrogate's.")
    if as_json:
        _common.print_json(payload[0] if len(payload) == 1 else {"specs": payload})
        return
    for result in results:
        _print_result(result)
    _common.console.print(f"{', '.join(FILES)} written to {out}")


def _pressure(text: str | None, unit: str, option: str) -> float | None:
    """A pressure option in the model's ``unit``: a number, or one with a unit (``20psi``).

    A bare number (``inf`` too) is returned as given, for the target's own range check.
    """
    from softbend.units import parse_pressure

    if text is None:
        return None
    try:
        return float(text)
    except ValueError:
        return parse_pressure(text, unit, option)


def verification_db(
    out: Path,
    result: SearchResult,
    backend: str,
    material: ResolvedMaterial | None,
    verify: int,
) -> Path:
    """The campaign database the verification of ``result`` keeps beside ``out``.

    ``.NAME.verify-KEY.duckdb`` for an ``out`` named NAME, where KEY is a digest
    of what decides the verification's sweeps: the search's answer (its
    candidates, spec and ranges), the backend, the material (its parameters and
    what named it, a fit file by its SHA-256) and ``--verify``. The same command
    after an interruption finds the same database and sweeps only the designs
    not yet recorded in it; a command that verifies otherwise starts another.
    """
    record = {key: value for key, value in result.to_dict().items() if key != "search_s"}
    elastomer = None if material is None else [material.material.to_dict(), material.given]
    given = {"search": record, "backend": backend, "material": elastomer, "verify": verify}
    digest = hashlib.sha256(_common.json_text(given).encode("utf-8")).hexdigest()[:12]
    folder = Path(os.path.abspath(out))
    return folder.with_name(f".{folder.name}.verify-{digest}.duckdb")


def _extrapolated(result: SearchResult, model: Path, named: bool) -> str | None:
    """One line naming the listed designs outside the model's training data (only kept with
    --allow-extrapolation), as ``softbend predict`` warns; None when every one is inside."""
    outside = [(rank, c) for rank, c in enumerate(result.candidates, start=1) if not c.supported]
    if not outside:
        return None
    ranks = ", ".join(f"#{rank}" for rank, _ in outside)
    first = outside[0][1].flags[0]
    where = f"{result.spec.name}: " if named else ""
    return (
        f"{where}{ranks} of {len(result.candidates)} listed: {model} was not trained there "
        f"({first}); their angles are extrapolations (kept by --allow-extrapolation)."
    )


def _print_result(result: SearchResult) -> None:
    spec = result.spec
    design = "l,r,t,b,φ,lc" if spec.space.paper_b else "design"
    columns = ["#", design, "θ (°)", "miss (°)"]
    columns += [f"{o.name}" for o in spec.objectives if o.name != "error"]
    verified = any(c.fem_meets is not None for c in result.candidates)
    if verified:
        columns += ["FEM θ (°)", "FEM ok"]
    stops: list[str] = []
    columns.append("trained there")
    rows = []
    for rank, c in enumerate(result.candidates, start=1):
        row = [str(rank), str(c.design), f"{c.angle_deg:.2f}", f"{c.error_deg:.2f}"]
        row += [f"{c.objectives[o.name]:.4g}" for o in spec.objectives if o.name != "error"]
        if verified:
            fem = "" if c.fem_angle_deg is None else f"{c.fem_angle_deg:.2f}"
            if c.fem_stop is not None:
                fem = "stopped"
                stops.append(f"#{rank}: {c.fem_stop}")
            row += [fem, "" if c.fem_meets is None else ("yes" if c.fem_meets else "NO")]
        row.append("yes" if c.supported else "no")
        rows.append(row)
    title = (
        f"{spec.name}: {spec.target.describe()} — {result.n_meeting:,} of "
        f"{result.n_designs:,} designs meet it ({result.seconds:.1f} s)"
    )
    by = result.verified_by
    if verified and by is not None:
        title += f"; verified by the {by['backend']} backend, FEM family {by['family']}"
    _common.print_table(title, columns, rows)
    if stops:
        _common.console.print(
            "FEM sweeps stopped before the pressure checked (no angle): " + "; ".join(stops)
        )
