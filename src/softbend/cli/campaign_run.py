"""``softbend campaign run``: sweep a design space (or one shard of it) into a database."""

from __future__ import annotations

from contextlib import ExitStack
from pathlib import Path
from typing import TYPE_CHECKING, Any

import typer

from softbend.cli import _common

if TYPE_CHECKING:
    from softbend.campaign.backends import Backend, ResolvedMaterial
    from softbend.campaign.runner import CampaignSummary
    from softbend.fem.families import FEMFamily

#: The design spaces of --space (softbend.campaign.spaces.SPACE_FORMS, not imported at start).
SPACE_FORMS = "table1, corners, lhs:N or sobol:N"

#: Those of another family than paper B's (softbend.campaign.family_spaces.FAMILY_SPACE_FORMS).
FAMILY_SPACE_FORMS = "lhs:N, sobol:N, grid or grid:K"


def one_line(text: str) -> str:
    """``text`` with its whitespace runs (newlines too) as single spaces."""
    return " ".join(str(text).split())


def with_surrogates() -> None:
    """Make the ``"surrogate"`` campaign backend available (registered on import)."""
    import softbend.surrogates.model  # noqa: F401  (registers the backend on import)


def run(
    db: Path = typer.Argument(..., help="Campaign database (DuckDB); created or resumed."),
    family: str = typer.Option(
        "sfrba",
        help="FEM actuator family of the designs: sfrba (paper B's actuator) or another "
        "registered family (pneunet), swept with its own FEM over the ranges of its "
        "description.",
    ),
    backend: str | None = typer.Option(
        None,
        help="Sweep model, a campaign backend: analytical, fem or surrogate (with --model); "
        "default analytical, and fem (the only one) for another --family than sfrba.",
    ),
    model: Path | None = typer.Option(
        None, help="A surrogate saved by 'softbend train' (models/*.json), for --backend surrogate."
    ),
    space: str | None = typer.Option(
        None,
        help=f"Designs: {SPACE_FORMS} (default table1); for another --family "
        f"{FAMILY_SPACE_FORMS} over its ranges (grid: 3 levels a parameter, grid:K: K), "
        "required.",
    ),
    ranges: list[str] = typer.Option(
        None,
        "--range",
        help="Range of one parameter of an lhs/sobol space, NAME=LOW:HIGH in mm or deg "
        "(repeatable; the others keep paper B's Table 1 ranges, or the family's).",
    ),
    seed: int = typer.Option(0, help="Seed of the lhs/sobol sampler."),
    shard: str | None = typer.Option(
        None,
        help="Only shard K/N of the space (every N-th design from the K-th, K in 0..N-1); "
        "merge the shards' databases with 'softbend campaign merge'.",
    ),
    pmax: float | None = typer.Option(
        None, help="Largest pressure of the sweep's grid, MPa (default 0.5; the family's)."
    ),
    pstep: float | None = typer.Option(
        None, help="Pressure step of the sweep's grid, MPa (default 0.005; the family's)."
    ),
    workers: int | None = typer.Option(
        None,
        help="Local worker processes (default: all cores; 0 or 1: serial, the compiled FEM in "
        "one worker process).",
    ),
    scheduler: str | None = typer.Option(
        None, help="Dask scheduler tcp://HOST:PORT (or scheduler file) to run on a cluster."
    ),
    retry_failed: bool = typer.Option(
        True, "--retry-failed/--no-retry-failed", help="Re-run designs recorded as failed."
    ),
    chunk_size: int | None = typer.Option(None, help="Designs per worker task (default: auto)."),
    connect_timeout: float = typer.Option(
        5.0, help="Seconds allowed to reach the Dask scheduler and find a worker."
    ),
    allow_large: bool = typer.Option(
        False,
        "--allow-large",
        help="Run a campaign estimated above 2 GiB of memory or 20 GiB of disk "
        "(one that does not fit the machine is refused anyway).",
    ),
    compile_energy: bool = typer.Option(
        True,
        "--compile/--no-compile",
        help="--backend fem: compile the energy to machine code once per worker "
        "(about 30 CPU s in the background; then faster assembly, the same results; "
        "see benchmarks/bench_fem.py).",
    ),
    maxh: float | None = typer.Option(
        None,
        help="Largest element size of --backend fem, mm (default: the FEM's, 5; the family's).",
    ),
    material: str | None = typer.Option(
        None,
        help="Elastomer of --backend fem or analytical: a preset (dragon-skin-30, the default) "
        "or the fit.json of 'softbend materials fit', optionally with its model after # "
        "(fit.json#yeoh; default the best fit).",
    ),
    accept_new_settings: bool = typer.Option(
        False,
        "--accept-new-settings",
        help="Resume DB even if its recorded settings (mesh, FEM options, material) differ "
        "from this run's; its designs then mix both.",
    ),
    json_output: bool = typer.Option(False, "--json", help="Print the summary as JSON."),
) -> None:
    """Sweep a design space into a campaign database.

    Sweeps every design of --space not yet recorded in DB (a DuckDB file,
    created if missing) from 0 to --pmax MPa in steps of --pstep MPa, one
    transaction per design; re-run the same command to resume. DB records the
    backend's settings (mesh, FEM options, material) and refuses a resume with
    other ones. A design that fails is recorded with the reason and the others
    go on; if every design of the run fails, the command exits with code 1
    and the first reason. A --maxh too fine for a design of --space is
    refused before any work (the FEM's limit on the elements of a mesh).

    With --family other than sfrba the designs are those of that FEM actuator
    family, drawn over the ranges of its description (integers whole, lengths
    to their resolution; designs breaking its constraints are drawn again for
    lhs/sobol and left out of a grid, and counted), swept with its own FEM up
    to its pressure; DB records the family and refuses designs of another.

    Example:

    \b
        softbend campaign run table1.duckdb --backend analytical --space table1
        softbend campaign run own.duckdb --space sobol:256 --range l=60:90 --range t=1:2
        softbend campaign run pneunet.duckdb --family pneunet --space sobol:256
    """
    from softbend._validation import check_int
    from softbend.campaign.backends import (
        backend_for_run,
        default_pressures_mpa,
        resolve_material,
    )
    from softbend.campaign.runner import (
        count_designs_to_run,
        parse_scheduler_address,
        run_campaign,
    )
    from softbend.campaign.spaces import (
        campaign_footprint,
        check_footprint,
        parse_ranges,
        parse_shard,
        parse_space,
    )

    _common.check_output_file(db, "DB", inputs=(model,) if model is not None else ())
    fem_family = _fem_family(family)
    spec: Any
    if fem_family is None:
        spec = parse_space("table1" if space is None else space)
        if ranges:
            spec = spec.with_ranges(parse_ranges(ranges))
    else:
        spec = _family_space(fem_family, space, ranges)
    check_int(seed, "seed")
    shard_of = parse_shard(shard) if shard is not None else None
    if fem_family is None:
        pressures = default_pressures_mpa(
            0.5 if pmax is None else pmax, 0.005 if pstep is None else pstep
        )
    else:
        pressures = default_pressures_mpa(
            fem_family.pmax_mpa if pmax is None else pmax,
            fem_family.pstep_mpa if pstep is None else pstep,
        )
    with_surrogates()
    chosen = resolve_material(material) if material is not None else None  # read once
    if fem_family is None:
        backend_obj = backend_for_run(
            "analytical" if backend is None else backend,
            model=model,
            compiled=compile_energy,
            material=chosen,
            maxh_mm=maxh,
        )
    else:
        backend_obj = _family_backend(fem_family, backend, model, chosen, maxh)
    if scheduler is not None:
        parse_scheduler_address(scheduler)
    k, count = shard_of or (0, 1)
    n_stored = len(range(k, spec.n_designs, count))  # designs of the shard
    check_footprint(
        campaign_footprint(spec.n_designs, len(pressures), n_stored=n_stored),
        db,
        allow_large=allow_large,
    )
    designs = spec.build(seed)
    rejected = getattr(designs, "describe_rejected", lambda: "")()
    if rejected and not json_output:
        _common.err_console.print(
            f"{designs.name}: {len(designs)} designs; {rejected}", highlight=False, soft_wrap=True
        )
    if shard_of is not None:
        designs = designs.shard(*shard_of)
    n_todo = count_designs_to_run(db, designs, retry_failed)
    with ExitStack() as stack:
        # The bar opens with the first report, so errors before any work print no bar.
        advance = None
        shown = 0

        def progress(done: int, failed: int, running: int, total: int) -> None:
            nonlocal advance, shown
            if advance is None and n_todo < len(designs) and not json_output:
                # Said once the settings are checked: a refused resume is one error line.
                _common.err_console.print(
                    f"resuming {db}: {len(designs) - n_todo} of {len(designs)} designs "
                    "already recorded",
                    highlight=False,
                    soft_wrap=True,  # one line whatever the path's length (logs, tests)
                )
            if advance is None:
                advance = stack.enter_context(
                    _common.progress_bar(
                        f"campaign {db.name}", total=total, enabled=not json_output
                    )
                )
            advance(done + failed - shown, done=done, failed=failed, running=running)
            shown = done + failed

        try:
            summary = run_campaign(
                db,
                designs,
                backend=backend_obj,
                pressures_mpa=pressures,
                workers=workers,
                scheduler=scheduler,
                retry_failed=retry_failed,
                progress=progress,
                chunk_size=chunk_size,
                connect_timeout_s=connect_timeout,
                material=chosen,
                accept_new_settings=accept_new_settings,
            )
        except OSError as exc:
            # A failed write of the database (a full disk) names it: one line naming DB.
            # The designs recorded before stay in it; re-running the command resumes.
            if exc.filename is None:
                raise
            with _common.output_errors(db, "DB"):
                raise
    if json_output:
        extra: dict[str, Any] = {}
        if fem_family is not None:
            extra = {"family": fem_family.name, "rejected": dict(designs.rejected)}
        _common.print_json({"space": designs.name, **extra, **summary.as_dict()})
        _exit_if_all_failed(summary, db)
        return
    _common.print_table(
        f"campaign {summary.db_path}",
        ["quantity", "value"],
        [
            *([] if fem_family is None else [["family", fem_family.name]]),
            ["backend", summary.backend],
            ["space", f"{designs.name} ({summary.n_designs} designs)"],
            ["executor", summary.executor],
            ["already done (skipped)", summary.n_skipped_done],
            ["failed before, not retried", summary.n_skipped_failed],
            ["done in this run", summary.n_done],
            ["failed in this run", summary.n_failed],
            ["wall time (s)", summary.wall_time_s],
            ["designs per second", summary.designs_per_s if summary.n_run else "- (none run)"],
            ["sweep time, sum (s)", summary.sweep_time_s],
        ],
    )
    if summary.failures:
        by_id = {design.design_id: str(design) for design in designs}
        header = "design (l,r,t,b,phi,lc)" if fem_family is None else "design"
        _common.print_table(
            "failed designs",
            [header, "error"],
            [[by_id.get(i, i), one_line(e)] for i, e in summary.failures[:20]],
        )
    _exit_if_all_failed(summary, db)


def _fem_family(name: str) -> FEMFamily | None:
    """The FEM family ``name`` of ``--family``; None for paper B's (the campaigns of before).

    An unknown name is one error keyed ``family`` that lists the known families.
    """
    from softbend.errors import keyed
    from softbend.fem.families import get_family

    with keyed("family"):
        fem_family = get_family(name)
    return None if fem_family.name == "sfrba" else fem_family


def _family_space(fem_family: FEMFamily, space: str | None, ranges: list[str] | None) -> Any:
    """The checked ``--space`` (and ``--range``) of another family than paper B's."""
    from softbend.campaign.family_spaces import parse_family_ranges, parse_family_space
    from softbend.errors import InputError

    if space is None:
        raise InputError(
            f"must be given for the {fem_family.name} family: one of {FAMILY_SPACE_FORMS} "
            "over the ranges of its description",
            key="space",
        )
    spec = parse_family_space(space, fem_family)
    if ranges:
        spec = spec.with_ranges(parse_family_ranges(ranges, fem_family))
    return spec


def _family_backend(
    fem_family: FEMFamily,
    backend: str | None,
    model: Path | None,
    chosen: ResolvedMaterial | None,
    maxh: float | None,
) -> Backend:
    """The FEM sweep of ``fem_family`` with ``--maxh`` and ``--material`` (checked)."""
    from softbend.campaign.families import family_backend
    from softbend.errors import InputError

    if backend not in (None, "fem"):
        raise InputError(
            f"must be fem for the {fem_family.name} family (its own FEM sweep); got {backend!r}",
            key="backend",
        )
    if model is not None:
        raise InputError(
            f"applies to --backend surrogate of paper B's actuator; the {fem_family.name} "
            f"family runs its FEM; got {str(model)!r}",
            key="model",
        )
    if maxh is not None and (
        isinstance(maxh, bool) or not (isinstance(maxh, int | float) and maxh > 0)
    ):
        raise InputError(f"must be a size > 0 mm; got {maxh!r}", key="maxh_mm")
    material = None if chosen is None else chosen.material
    return family_backend(fem_family, maxh_mm=maxh, material=material)


def _exit_if_all_failed(summary: CampaignSummary, db: Path) -> None:
    """End with exit code 1 and the first failure if every design this run swept failed.

    A run that swept no design (all done before) or finished any is a success;
    the failed designs stay recorded either way, and a re-run retries them.
    """
    if summary.n_run == 0 or summary.n_done > 0:
        return
    reason = _without_type(summary.failures[0][1]) if summary.failures else "no reason recorded."
    _common.error_line(
        f"every design of this run failed ({summary.n_failed} of {summary.n_failed}); "
        f"the first: {reason} They are recorded in {db} as failed "
        f"('softbend campaign status {db}' lists them); run the command again to retry them."
    )
    raise typer.Exit(1)


def _without_type(error: str, limit: int = 300) -> str:
    """A recorded failure (``"ExceptionType: message"``) as its message: one line, a sentence."""
    text = one_line(error)
    head, sep, rest = text.partition(": ")
    if sep and head.isidentifier() and head[:1].isupper() and rest:
        text = rest
    if len(text) > limit:
        text = text[: limit - 1].rstrip() + "…"
    return text if text.endswith((".", "!", "?", "…")) else text + "."
