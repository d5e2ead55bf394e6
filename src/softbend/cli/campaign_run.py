"""``softbend campaign run``: sweep a design space (or one shard of it) into a database."""

from __future__ import annotations

from contextlib import ExitStack
from pathlib import Path
from typing import TYPE_CHECKING, Annotated, Any

import typer

from softbend.cli import _common

if TYPE_CHECKING:
    from softbend.campaign.plan import CampaignPlan
    from softbend.campaign.runner import CampaignSummary

#: The design spaces of --space (softbend.campaign.spaces.SPACE_FORMS, not imported at start).
SPACE_FORMS = "table1, corners, lhs:N or sobol:N"

#: Those of another family than paper B's (softbend.campaign.spaces.FAMILY_SPACE_FORMS).
FAMILY_SPACE_FORMS = "lhs:N, sobol:N, grid or grid:K"

DbArgument = Annotated[Path, typer.Argument(help="Campaign database (DuckDB); created or resumed.")]
FamilyOption = Annotated[
    str,
    typer.Option(
        help="FEM actuator family of the designs: sfrba (paper B's actuator) or another "
        "registered family (pneunet), swept with its own FEM over the ranges of its "
        "description."
    ),
]
BackendOption = Annotated[
    str | None,
    typer.Option(
        help="Sweep model, a campaign backend: analytical, fem or surrogate (with --model); "
        "default analytical, and fem (the only one) for another --family than sfrba."
    ),
]
ModelOption = Annotated[
    Path | None,
    typer.Option(
        help="A surrogate saved by 'softbend train' (models/*.json), for --backend surrogate."
    ),
]
SpaceOption = Annotated[
    str | None,
    typer.Option(
        help=f"Designs: {SPACE_FORMS} (default table1); for another --family "
        f"{FAMILY_SPACE_FORMS} over its ranges (grid: 3 levels a parameter, grid:K: K), "
        "required."
    ),
]
RangesOption = Annotated[
    list[str] | None,
    typer.Option(
        "--range",
        help="Range of one parameter of an lhs/sobol space, NAME=LOW:HIGH in mm or deg "
        "(repeatable; the others keep paper B's Table 1 ranges, or the family's).",
    ),
]
SeedOption = Annotated[int, typer.Option(help="Seed of the lhs/sobol sampler.")]
ShardOption = Annotated[
    str | None,
    typer.Option(
        help="Only shard K/N of the space (every N-th design from the K-th, K in 0..N-1); "
        "merge the shards' databases with 'softbend campaign merge'."
    ),
]
PmaxOption = Annotated[
    float | None,
    typer.Option(help="Largest pressure of the sweep's grid, MPa (default 0.5; the family's)."),
]
PstepOption = Annotated[
    float | None,
    typer.Option(help="Pressure step of the sweep's grid, MPa (default 0.005; the family's)."),
]
WorkersOption = Annotated[
    int | None,
    typer.Option(
        help="Local worker processes (default: all cores; 0 or 1: serial, the compiled FEM in "
        "one worker process)."
    ),
]
SchedulerOption = Annotated[
    str | None,
    typer.Option(help="Dask scheduler tcp://HOST:PORT (or scheduler file) to run on a cluster."),
]
RetryFailedOption = Annotated[
    bool,
    typer.Option("--retry-failed/--no-retry-failed", help="Re-run designs recorded as failed."),
]
ChunkSizeOption = Annotated[
    int | None, typer.Option(help="Designs per worker task (default: auto).")
]
ConnectTimeoutOption = Annotated[
    float, typer.Option(help="Seconds allowed to reach the Dask scheduler and find a worker.")
]
AllowLargeOption = Annotated[
    bool,
    typer.Option(
        "--allow-large",
        help="Run a campaign estimated above 2 GiB of memory or 20 GiB of disk "
        "(one that does not fit the machine is refused anyway).",
    ),
]
CompileEnergyOption = Annotated[
    bool,
    typer.Option(
        "--compile/--no-compile",
        help="--backend fem: compile the energy to machine code once per worker "
        "(about 30 CPU s in the background; then faster assembly, the same results; "
        "see benchmarks/bench_fem.py).",
    ),
]
MaxhOption = Annotated[
    float | None,
    typer.Option(
        help="Largest element size of --backend fem, mm (default: the FEM's, 5; the family's)."
    ),
]
MaterialOption = Annotated[
    str | None,
    typer.Option(
        help="Elastomer of --backend fem or analytical: a preset (dragon-skin-30, the default) "
        "or the fit.json of 'softbend materials fit', optionally with its model after # "
        "(fit.json#yeoh; default the best fit)."
    ),
]
ContactOption = Annotated[
    str | None,
    typer.Option(
        "--contact",
        help="Contact between the facing walls of neighbouring chambers, for a family whose "
        "walls touch (pneunet): on (the default, the shipped dataset's settings: they press "
        "on each other, a sweep goes on to --pmax or 180°) or off (a sweep stops where the "
        "walls first touch). sfrba: off only.",
    ),
]
AcceptNewSettingsOption = Annotated[
    bool,
    typer.Option(
        "--accept-new-settings",
        help="Resume DB even if its recorded settings (mesh, FEM options, material) differ "
        "from this run's; its designs then mix both.",
    ),
]
JsonOutputOption = Annotated[bool, typer.Option("--json", help="Print the summary as JSON.")]


def one_line(text: str) -> str:
    """``text`` with its whitespace runs (newlines too) as single spaces."""
    return " ".join(str(text).split())


def with_surrogates() -> None:
    """Make the ``"surrogate"`` campaign backend available (registered on import)."""
    import softbend.surrogates.model  # noqa: F401  (registers the backend on import)


#: ``campaign run``'s options that plan the campaign, by the name
#: :func:`softbend.campaign.plan.plan_campaign` gives them.
PLAN_OPTIONS = {
    "family": "family",
    "backend": "backend",
    "model": "model",
    "space": "space",
    "ranges": "ranges",
    "seed": "seed",
    "shard": "shard",
    "pmax": "pmax_mpa",
    "pstep": "pstep_mpa",
    "scheduler": "scheduler",
    "allow_large": "allow_large",
    "compile_energy": "compiled",
    "maxh": "maxh_mm",
    "material": "material",
    "contact": "contact",
}


def run(
    db: DbArgument,
    family: FamilyOption = "sfrba",
    backend: BackendOption = None,
    model: ModelOption = None,
    space: SpaceOption = None,
    ranges: RangesOption = None,
    seed: SeedOption = 0,
    shard: ShardOption = None,
    pmax: PmaxOption = None,
    pstep: PstepOption = None,
    workers: WorkersOption = None,
    scheduler: SchedulerOption = None,
    retry_failed: RetryFailedOption = True,
    chunk_size: ChunkSizeOption = None,
    connect_timeout: ConnectTimeoutOption = 5.0,
    allow_large: AllowLargeOption = False,
    compile_energy: CompileEnergyOption = True,
    maxh: MaxhOption = None,
    material: MaterialOption = None,
    contact: ContactOption = None,
    accept_new_settings: AcceptNewSettingsOption = False,
    json_output: JsonOutputOption = False,
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
        softbend campaign run to-touch.duckdb --family pneunet --space sobol:256 --contact off
    """
    from softbend.campaign.plan import plan_campaign

    args = dict(locals())
    _common.check_output_file(db, "DB", inputs=(model,) if model is not None else ())
    with_surrogates()
    plan = plan_campaign(db, **{name: args[option] for option, name in PLAN_OPTIONS.items()})
    if plan.rejected and not json_output:
        _common.err_console.print(plan.rejected, highlight=False, soft_wrap=True)
    summary = _sweep(plan, args)
    _print_summary(plan, summary, db, json_output=json_output)
    _exit_if_all_failed(summary, db)


def _sweep(plan: CampaignPlan, args: dict[str, Any]) -> CampaignSummary:
    """Run the planned campaign into ``args["db"]`` with a progress bar (not with --json)."""
    from softbend.campaign.runner import count_designs_to_run, run_campaign

    db, designs, quiet = args["db"], plan.designs, args["json_output"]
    n_todo = count_designs_to_run(db, designs, args["retry_failed"])
    with ExitStack() as stack:
        # The bar opens with the first report, so errors before any work print no bar.
        advance = None
        shown = 0

        def progress(done: int, failed: int, running: int, total: int) -> None:
            nonlocal advance, shown
            if advance is None and n_todo < len(designs) and not quiet:
                # Said once the settings are checked: a refused resume is one error line.
                _common.err_console.print(
                    f"resuming {db}: {len(designs) - n_todo} of {len(designs)} designs "
                    "already recorded",
                    highlight=False,
                    soft_wrap=True,  # one line whatever the path's length (logs, tests)
                )
            if advance is None:
                advance = stack.enter_context(
                    _common.progress_bar(f"campaign {db.name}", total=total, enabled=not quiet)
                )
            advance(done + failed - shown, done=done, failed=failed, running=running)
            shown = done + failed

        try:
            return run_campaign(
                db,
                designs,
                backend=plan.backend,
                pressures_mpa=plan.pressures_mpa,
                workers=args["workers"],
                scheduler=args["scheduler"],
                retry_failed=args["retry_failed"],
                progress=progress,
                chunk_size=args["chunk_size"],
                connect_timeout_s=args["connect_timeout"],
                material=plan.material,
                accept_new_settings=args["accept_new_settings"],
            )
        except OSError as exc:
            # A failed write of the database (a full disk) names it: one line naming DB.
            # The designs recorded before stay in it; re-running the command resumes.
            if exc.filename is None:
                raise
            with _common.output_errors(db, "DB"):
                raise


def _print_summary(
    plan: CampaignPlan, summary: CampaignSummary, db: Path, *, json_output: bool
) -> None:
    """The run's summary as JSON or as tables (with the first failed designs)."""
    designs, fem_family = plan.designs, plan.family
    recorded = fem_family.recorded  # a family recorded with its campaigns is named in the output
    if json_output:
        extra: dict[str, Any] = {}
        if recorded:
            extra = {"family": fem_family.name, "rejected": dict(designs.rejected)}
        _common.print_json({"space": designs.name, **extra, **summary.as_dict()})
        return
    _common.print_table(
        f"campaign {summary.db_path}",
        ["quantity", "value"],
        [
            *([["family", fem_family.name]] if recorded else []),
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
        header = "design" if recorded else "design (l,r,t,b,phi,lc)"
        _common.print_table(
            "failed designs",
            [header, "error"],
            [[by_id.get(i, i), one_line(e)] for i, e in summary.failures[:20]],
        )


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
