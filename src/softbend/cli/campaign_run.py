"""``softbend campaign run``: sweep a design space (or one shard of it) into a database."""

from __future__ import annotations

from contextlib import ExitStack
from pathlib import Path
from typing import TYPE_CHECKING

import typer

from softbend.cli import _common

if TYPE_CHECKING:
    from softbend.campaign.runner import CampaignSummary

#: The design spaces of --space (softbend.campaign.spaces.SPACE_FORMS, not imported at start).
SPACE_FORMS = "table1, corners, lhs:N or sobol:N"


def one_line(text: str) -> str:
    """``text`` with its whitespace runs (newlines too) as single spaces."""
    return " ".join(str(text).split())


def with_surrogates() -> None:
    """Make the ``"surrogate"`` campaign backend available (registered on import)."""
    import softbend.surrogates.model  # noqa: F401  (registers the backend on import)


def run(
    db: Path = typer.Argument(..., help="Campaign database (DuckDB); created or resumed."),
    backend: str = typer.Option(
        "analytical",
        help="Sweep model, a campaign backend: analytical, fem or surrogate (with --model).",
    ),
    model: Path | None = typer.Option(
        None, help="A surrogate saved by 'softbend train' (models/*.json), for --backend surrogate."
    ),
    space: str = typer.Option("table1", help=f"Designs: {SPACE_FORMS}."),
    ranges: list[str] = typer.Option(
        None,
        "--range",
        help="Range of one parameter of an lhs/sobol space, NAME=LOW:HIGH in mm or deg "
        "(repeatable; the others keep paper B's Table 1 ranges).",
    ),
    seed: int = typer.Option(0, help="Seed of the lhs/sobol sampler."),
    shard: str | None = typer.Option(
        None,
        help="Only shard K/N of the space (every N-th design from the K-th, K in 0..N-1); "
        "merge the shards' databases with 'softbend campaign merge'.",
    ),
    pmax: float = typer.Option(0.5, help="Largest pressure of the sweep's grid, MPa."),
    pstep: float = typer.Option(0.005, help="Pressure step of the sweep's grid, MPa."),
    workers: int | None = typer.Option(
        None, help="Local worker processes (default: all cores; 0 or 1: serial)."
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
        None, help="Largest element size of --backend fem, mm (default: the FEM's, 5)."
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

    Example:

    \b
        softbend campaign run table1.duckdb --backend analytical --space table1
        softbend campaign run own.duckdb --space sobol:256 --range l=60:90 --range t=1:2
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
    spec = parse_space(space)
    if ranges:
        spec = spec.with_ranges(parse_ranges(ranges))
    check_int(seed, "seed")
    shard_of = parse_shard(shard) if shard is not None else None
    pressures = default_pressures_mpa(pmax, pstep)
    with_surrogates()
    chosen = resolve_material(material) if material is not None else None  # read once
    backend_obj = backend_for_run(
        backend, model=model, compiled=compile_energy, material=chosen, maxh_mm=maxh
    )
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
        _common.print_json({"space": designs.name, **summary.as_dict()})
        _exit_if_all_failed(summary, db)
        return
    _common.print_table(
        f"campaign {summary.db_path}",
        ["quantity", "value"],
        [
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
        _common.print_table(
            "failed designs",
            ["design (l,r,t,b,phi,lc)", "error"],
            [[by_id.get(i, i), one_line(e)] for i, e in summary.failures[:20]],
        )
    _exit_if_all_failed(summary, db)


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
