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
from collections.abc import Sequence
from dataclasses import dataclass, field
from pathlib import Path
from typing import TYPE_CHECKING, Any

import typer

from softbend._validation import check_choice, must_be
from softbend.cli import _common
from softbend.cli import design_options as opt
from softbend.errors import InputError, SoftbendError
from softbend.parameters import Range

if TYPE_CHECKING:
    from softbend.campaign.backends import ResolvedMaterial
    from softbend.design_search.search import LoadedModel, SearchResult
    from softbend.design_search.space import SearchSpace
    from softbend.design_search.spec import Specification

#: How many of the best candidates ``--verify`` sweeps.
VERIFY = Range(0, 100, "designs", "each is a sweep of the FEM, minutes long")

#: The processes of the verification (``--workers``).
WORKERS = Range(1, 4096, "processes", "the bound of a campaign's local workers")

#: The refinements of ``--refine-rounds``.
REFINE_ROUNDS = Range(0, 20, "rounds", "each a refit and a search, then FEM sweeps")

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
_VERIFY_OPTIONS: tuple[str, ...] = (
    "backend",
    "workers",
    "material",
    "replace_stopped",
    "refine_rounds",
)


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


@app.command("find", help=opt.FIND_HELP)
def find(
    ctx: typer.Context,
    out: Path = opt.OUT,
    model: Path = opt.MODEL,
    spec: Path = opt.SPEC_FILE,
    angle: float = opt.ANGLE,
    at: str = opt.AT,
    max_pressure: str = opt.MAX_PRESSURE,
    max_angle_at: str = opt.MAX_ANGLE_AT,
    curve: str = opt.CURVE,
    tolerance: float = opt.TOLERANCE,
    margin: float = opt.MARGIN,
    minimize: list[str] = opt.MINIMIZE,
    maximize: list[str] = opt.MAXIMIZE,
    fix: list[str] = opt.FIX,
    ranges: list[str] = opt.RANGE,
    resolution: list[str] = opt.RESOLUTION,
    top: int = opt.TOP,
    neighbours: bool = opt.NEIGHBOURS,
    verify: int = opt.VERIFY,
    backend: str = opt.BACKEND,
    workers: int = opt.WORKERS,
    material: str = opt.MATERIAL,
    replace_stopped: bool = opt.REPLACE_STOPPED,
    refine_rounds: int = opt.REFINE_ROUNDS,
    allow_extrapolation: bool = opt.ALLOW_EXTRAPOLATION,
    as_json: bool = opt.JSON,
) -> None:
    """Find the designs that meet a target bending (help: :data:`.design_options.FIND_HELP`)."""
    from softbend.design_search.search import LoadedModel
    from softbend.design_search.spec_text import specification_from_options
    from softbend.transfer.base import shipped_base_path

    out = Path(out)
    model_path = shipped_base_path() if model is None else Path(model)
    _check_outputs(out, model, spec, top)
    _check_count(refine_rounds, "refine_rounds", REFINE_ROUNDS)
    elastomer = _verification(ctx, verify, backend, workers, material)
    loaded = LoadedModel.load(model_path)  # read once; its actuator names the parameters
    space = _space(loaded, verify)
    if spec is not None:
        chosen = _from_file(ctx, spec, space)
    else:
        chosen = [
            specification_from_options(
                space, angle=angle, at=at, max_pressure=max_pressure, max_angle_at=max_angle_at,
                curve=curve, tolerance=tolerance, margin=margin, minimize=minimize or (),
                maximize=maximize or (), fixes=fix or (), ranges=ranges or (),
                resolution=resolution or (),
            )
        ]  # fmt: skip
    _check_grids(chosen, loaded, spec, allow_extrapolation=allow_extrapolation, top=top)
    results = _search(loaded, chosen, top, allow_extrapolation, not neighbours, as_json)
    verification = _Verification(
        verify, backend, workers, elastomer, replace_stopped, refine_rounds,
        dict(top=top, allow_extrapolation=allow_extrapolation, distinct=not neighbours),
    )  # fmt: skip
    payload = _verify_and_write(out, results, loaded, verification, as_json)
    _warn(results, model_path, verification.skipped)
    if as_json:
        _common.print_json(payload[0] if len(payload) == 1 else {"specs": payload})
        return
    _print_results(results, out)


def _check_outputs(out: Path, model: Path | None, spec: Path | None, top: int) -> None:
    """Refuse an ``--out`` that cannot take the results (nor hold the inputs), and a
    ``--top`` outside :data:`~softbend.design_search.search.TOP`."""
    from softbend.design_search.search import TOP

    inputs = tuple(p for p in (model, spec) if p is not None)
    _common.check_output_dir(out, "--out", inputs=inputs)
    _common.check_replaceable_dir(out, "--out", inputs=inputs)
    _check_count(top, "top", TOP)


def _space(loaded: LoadedModel, verify: int) -> SearchSpace:
    """The search space of the model's actuator; with ``--verify`` its FEM family checked
    first (a family that cannot sweep its designs is refused before any search)."""
    from softbend.design_search.space import space_of
    from softbend.design_search.verify import verify_family

    space = space_of(loaded.actuator)
    if verify and space.verifiable:
        verify_family(space)
    return space


def _from_file(ctx: typer.Context, spec: Path, space: SearchSpace) -> list[Specification]:
    """The specifications of ``--spec``, refused beside an option the file gives itself."""
    from softbend.design_search.spec_toml import load_specifications
    from softbend.reports.design_outputs import FILES

    for name, what in _SPEC_GIVES.items():
        if _typed(ctx, name):
            raise InputError(
                f"cannot be used with --spec: the spec file gives each spec's {what}", key=name
            )
    return load_specifications(
        spec, reserved=sorted({"search.json", *FILES}), actuator=space.actuator
    )


def _check_grids(
    chosen: Sequence[Specification],
    loaded: LoadedModel,
    spec: Path | None,
    *,
    allow_extrapolation: bool,
    top: int,
) -> None:
    """Count every grid before any is built; a spec of a file is named by its number."""
    from softbend.design_search.search import searched_ranges

    training = loaded.metadata.get("training_ranges")
    for number, one in enumerate(chosen, start=1):
        try:
            searched_ranges(one, training, allow_extrapolation=allow_extrapolation, top=top)
        except ValueError as exc:
            if spec is None:
                raise
            said = exc.detail if isinstance(exc, SoftbendError) else str(exc)
            raise InputError(f"[[spec]] {number} ({one.name!r}): {said}", file=str(spec)) from None


def _search(
    loaded: LoadedModel,
    chosen: Sequence[Specification],
    top: int,
    allow_extrapolation: bool,
    distinct: bool,
    as_json: bool,
) -> list[SearchResult]:
    """The answer to each specification, in order."""
    from softbend.design_search.search import find_designs

    with _common.library_progress(enabled=not as_json):
        return [
            find_designs(
                loaded, one, top=top, allow_extrapolation=allow_extrapolation, distinct=distinct
            )
            for one in chosen
        ]


@dataclass
class _Verification:
    """What ``--verify`` asks for, and why it checks nothing (``skipped``), once known."""

    count: int
    backend: str
    workers: int | None
    material: ResolvedMaterial | None
    replace_stopped: bool
    rounds: int = 0
    search: dict[str, Any] = field(default_factory=dict)  # each round's find_designs options
    skipped: str | None = None


def _verify_and_write(
    out: Path,
    results: list[SearchResult],
    loaded: LoadedModel,
    verification: _Verification,
    as_json: bool,
) -> list[dict[str, Any]]:
    """Verify the candidates (``--verify``) and write every result into ``out``, swapped in
    when complete, the verification's campaigns removed after; the results' records."""
    from softbend._outdir import staged_dir
    from softbend.design_search.verify import verify_skipped
    from softbend.reports.design_outputs import write_search

    v = verification
    v.skipped = verify_skipped(results[0], v.backend) if v.count else None
    if v.skipped is not None:  # another actuator: said once, and in each record
        for result in results:
            result.verify_skipped = v.skipped
    kept: list[Path] = []  # the verification's campaigns, removed once the command ends
    models = [loaded] * len(results)  # the surrogate each answer was searched on, drawn with
    with _common.output_errors(out, "--out"), staged_dir(out) as stage:
        if v.count and v.skipped is None:
            with _common.library_progress(enabled=not as_json):
                for i, result in enumerate(results):
                    if not result.candidates:
                        continue
                    folder = stage / result.spec.name if len(results) > 1 else stage
                    results[i], models[i], db = _verify(
                        out, result, loaded, v, stage, folder / "rounds"
                    )
                    kept.append(db)
        payload = [r.to_dict() for r in results]
        for result, model in zip(results, models, strict=True):
            folder = stage / result.spec.name if len(results) > 1 else stage
            write_search(result, model.predictor, folder)
        if len(results) > 1:  # the record of them all, and the folder's marker
            (stage / "search.json").write_text(
                _common.json_text({"specs": payload}) + "\n", encoding="utf-8"
            )
    for db in kept:
        for path in (db, db.with_name(db.name + ".wal")):
            path.unlink(missing_ok=True)
    return payload


def _verify(
    out: Path,
    result: SearchResult,
    loaded: LoadedModel,
    v: _Verification,
    stage: Path,
    rounds_folder: Path,
) -> tuple[SearchResult, LoadedModel, Path]:
    """Sweep the best candidates of ``result`` (in rounds with ``--refine-rounds``): the
    last search (its ``rounds`` recorded), the surrogate it ran on and the campaign
    database, kept beside ``out``."""
    from softbend.design_search.rounds import verify_in_rounds

    db = verification_db(out, result, v.backend, v.material, v.count)
    result, model, _ = verify_in_rounds(
        loaded,
        result.spec,
        result,
        verify=v.count,
        rounds=v.rounds,
        folder=rounds_folder,
        **v.search,
        db_path=db,
        backend=v.backend,
        workers=v.workers,
        material=v.material,
        scratch_dir=stage,
        replace_stopped=v.replace_stopped,
    )
    return result, model, db


def _warn(results: Sequence[SearchResult], model_path: Path, skipped: str | None) -> None:
    """The warnings of the search on stderr: no design meets a target, target pressures
    outside the trained range, answers outside the training data, --verify skipped."""
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


def _print_results(results: Sequence[SearchResult], out: Path) -> None:
    """Each result's table, then the files written."""
    from softbend.reports.design_outputs import FILES

    for result in results:
        _print_result(result)
    _common.console.print(f"{', '.join(FILES)} written to {out}")


def _rounds_line(rounds: list[dict[str, Any]]) -> str:
    """The verification's rounds in one line: the FEM angles of each, and whether one met."""

    def angles(record: dict[str, Any]) -> str:
        return ", ".join(
            "stopped" if d["fem_angle_deg"] is None else f"{d['fem_angle_deg']:.2f}°"
            for d in record["verified"]
        )

    met = any(d["fem_meets"] for d in rounds[-1]["verified"])
    return (
        f"refined on the verification's sweeps {len(rounds) - 1} time(s); their angles by "
        "round: "
        + "; ".join(f"{r['round']}: {angles(r)}" for r in rounds)
        + (" (the last within the tolerance)" if met else " (none within the tolerance)")
    )


def _print_result(result: SearchResult) -> None:
    spec = result.spec
    columns = ["#", "design", "θ (°)", "miss (°)"]
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
    if result.rounds:
        _common.console.print(_rounds_line(result.rounds))
    if stops:
        _common.console.print(
            "FEM sweeps stopped before the pressure checked (no angle): " + "; ".join(stops)
        )
