"""``softbend campaign``: run, inspect and export design campaigns.

``run`` sweeps a design space (or one shard of it) into a DuckDB file (resuming
if it exists), ``merge`` joins the databases of shards, ``status`` summarises a
database, ``export`` writes its samples (or designs) to Parquet or CSV.
"""

from __future__ import annotations

import re
from contextlib import ExitStack
from pathlib import Path
from typing import TYPE_CHECKING

import typer

from softbend.cli import _common

if TYPE_CHECKING:
    from softbend.campaign.spaces import SpaceSpec
    from softbend.design import DesignSpace

app = typer.Typer(help="Run FEM or analytical sweeps over a design space.", no_args_is_help=True)

_SPACE_FORMS = "table1, corners, lhs:N or sobol:N"


def parse_space(spec: str, seed: int = 0) -> DesignSpace:
    """Design space from a CLI string: ``table1``, ``corners``, ``lhs:N`` or ``sobol:N``.

    ``lhs`` and ``sobol`` sample ``N`` designs over the Table 1 ranges with ``seed``.
    """
    return _space_spec(spec).build(seed)


def _space_spec(spec: str) -> SpaceSpec:
    from softbend.campaign.spaces import parse_space as parse

    return parse(spec, option="--space", owner="softbend campaign run")


def parse_shard(spec: str) -> tuple[int, int]:
    """``K/N`` (0-based shard K of N) from the CLI."""
    match = re.fullmatch(r"\s*(\d+)\s*/\s*(\d+)\s*", spec)
    if match is None or int(match[2]) < 1 or int(match[1]) >= int(match[2]):
        raise ValueError(
            "The '--shard' of softbend campaign run must be K/N with N >= 1 and K in 0..N-1 "
            f"(e.g. 0/8). Got {spec!r} instead."
        )
    return int(match[1]), int(match[2])


def _designs_to_run(db: Path, designs: DesignSpace, retry_failed: bool) -> int:
    """Designs of ``designs`` that a run on ``db`` will sweep (the progress bar total)."""
    from softbend.campaign import CampaignStore

    if not db.exists():
        return len(designs)
    with CampaignStore(db, read_only=True) as store:
        skip = store.finished_ids(include_failed=not retry_failed)
    return sum(d.design_id not in skip for d in designs)


def _one_line(text: str) -> str:
    return " ".join(str(text).split())


@app.command("run")
def run(
    db: Path = typer.Argument(..., help="Campaign database (DuckDB); created or resumed."),
    backend: str = typer.Option(
        "analytical", help="Sweep model: analytical, fem or surrogate (with --model)."
    ),
    model: Path | None = typer.Option(
        None, help="A surrogate saved by 'softbend train' (models/*.json), for --backend surrogate."
    ),
    space: str = typer.Option("table1", help=f"Designs: {_SPACE_FORMS}."),
    seed: int = typer.Option(0, help="Seed of the lhs/sobol sampler."),
    shard: str | None = typer.Option(
        None,
        help="Only shard K/N of the space (every N-th design from the K-th, K in 0..N-1); "
        "merge the shards' databases with 'softbend campaign merge'.",
    ),
    pmax: float = typer.Option(0.5, help="Largest pressure of the sweep, MPa."),
    pstep: float = typer.Option(0.005, help="Pressure step of the sweep, MPa."),
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
    json_output: bool = typer.Option(False, "--json", help="Print the summary as JSON."),
) -> None:
    """Sweep every design of a space not yet in DB; re-run the same command to resume."""
    from softbend.campaign import default_pressures_mpa, get_backend, run_campaign
    from softbend.campaign.runner import parse_scheduler_address
    from softbend.campaign.spaces import campaign_footprint, check_footprint

    _common.check_output_file(db, "DB", inputs=(model,) if model is not None else ())
    spec = _space_spec(space)
    if seed < 0:
        raise ValueError(
            f"The '--seed' of softbend campaign run must be an integer >= 0. Got {seed} instead."
        )
    shard_of = parse_shard(shard) if shard is not None else None
    pressures = default_pressures_mpa(pmax, pstep)
    if (backend == "surrogate") != (model is not None):
        raise ValueError(
            "The '--model' of softbend campaign run must be given with --backend surrogate, "
            f"and only then. Got --backend {backend} and --model {model} instead."
        )
    if backend == "surrogate":
        from softbend.surrogates.model import SurrogateModel

        backend_obj = SurrogateModel.load(model)
    else:
        from softbend._validation import check_choice
        from softbend.campaign.backends import INTERNAL_BACKENDS, available_backends

        public = [name for name in available_backends() if name not in INTERNAL_BACKENDS]
        check_choice(backend, "--backend", "softbend campaign run", (*public, "surrogate"))
        backend_obj = (
            get_backend(backend, compiled=compile_energy)
            if backend == "fem"
            else get_backend(backend)
        )
    if scheduler is not None:
        parse_scheduler_address(scheduler)
    k, count = shard_of or (0, 1)
    n_stored = len(range(k, spec.n_designs, count))  # designs of the shard
    check_footprint(
        campaign_footprint(spec.n_designs, len(pressures), n_stored=n_stored),
        db,
        allow_large=allow_large,
        option="--space",
        owner="softbend campaign run",
        allow_flag="--allow-large",
    )
    designs = spec.build(seed)
    if shard_of is not None:
        designs = designs.shard(*shard_of)
    n_todo = _designs_to_run(db, designs, retry_failed)
    if n_todo < len(designs) and not json_output:
        _common.err_console.print(
            f"resuming {db}: {len(designs) - n_todo} of {len(designs)} designs already recorded",
            highlight=False,
            soft_wrap=True,  # one line whatever the path's length (logs, tests)
        )
    with ExitStack() as stack:
        # The bar opens with the first report, so errors before any work print no bar.
        advance = None
        shown = 0

        def progress(done: int, failed: int, running: int, total: int) -> None:
            nonlocal advance, shown
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
            ["designs per second", summary.designs_per_s],
            ["sweep time, sum (s)", summary.sweep_time_s],
        ],
    )
    if summary.failures:
        _common.print_table(
            "failed designs",
            ["design_id", "error"],
            [[i, _one_line(e)] for i, e in summary.failures[:20]],
        )


@app.command("merge")
def merge(
    db: Path = typer.Argument(..., help="Campaign database to merge into; created if missing."),
    shards: list[Path] = typer.Argument(..., help="Campaign databases to copy designs from."),
    json_output: bool = typer.Option(False, "--json", help="Print the counts as JSON."),
) -> None:
    """Merge the databases of campaign shards (same backend and grid) into DB."""
    from softbend.campaign import CampaignStore
    from softbend.campaign.store import merge_campaigns

    for shard in shards:
        if not shard.is_file():
            raise FileNotFoundError(f"No campaign database at {str(shard)!r}.")
    _common.check_output_file(db, "DB", inputs=tuple(shards))
    # Every shard is checked before anything is written, and DB is replaced only
    # when the whole merge is done: a failed merge leaves DB as it was (or absent).
    with _common.output_errors(db, "DB"):
        counts = merge_campaigns(db, shards)
    rows = [{"shard": str(shard), **c} for shard, c in zip(shards, counts, strict=True)]
    with CampaignStore(db, read_only=True) as store:
        total = store.status_summary()
    if json_output:
        _common.print_json(
            {"db": str(db), "shards": rows, "done": total["done"], "failed": total["failed"]}
        )
        return
    _common.print_table(
        f"merged into {db}",
        ["shard", "added", "replaced failed", "already there"],
        [[r["shard"], r["added"], r["replaced_failed"], r["kept"]] for r in rows],
    )
    _common.err_console.print(
        f"{db}: {total['done']} designs done, {total['failed']} failed", highlight=False
    )


@app.command("status")
def status(
    db: Path = typer.Argument(..., help="Campaign database (DuckDB)."),
    json_output: bool = typer.Option(False, "--json", help="Print the status as JSON."),
) -> None:
    """Summarise a campaign database: designs done and failed, samples, metadata."""
    from softbend.campaign import CampaignStore

    with CampaignStore(db, read_only=True) as store:
        summary = store.status_summary()
    if json_output:
        _common.print_json(summary)
        return
    planned = summary["n_designs_planned"]
    grid = (
        "-"
        if summary["n_pressures"] is None
        else (
            f"{summary['n_pressures']} pressures, "
            f"{summary['pmin_mpa']:g}–{summary['pmax_mpa']:g} MPa"
        )
    )
    _common.print_table(
        f"campaign {summary['path']}",
        ["quantity", "value"],
        [
            ["backend", summary["backend"] or "-"],
            ["space of the latest run", f"{summary['space'] or '-'} ({planned or 0} designs)"],
            ["designs done", summary["done"]],
            ["designs failed", summary["failed"]],
            ["samples (converged)", f"{summary['samples']} ({summary['converged_samples']})"],
            ["pressure grid", grid],
            ["sweep time, sum (s)", summary["sweep_time_s_total"]],
            [
                "largest angle (deg)",
                summary["max_angle_deg"] if summary["max_angle_deg"] is not None else "-",
            ],
            ["schema / softbend", f"{summary['schema_version']} / {summary['softbend_version']}"],
            [
                "created / last design",
                f"{summary['created_at']} / {summary['last_finished_at'] or '-'}",
            ],
        ],
    )
    if summary["failures"]:
        _common.print_table(
            "failed designs",
            ["design_id", "design", "error"],
            [[f["design_id"], f["design"], _one_line(f["error"])] for f in summary["failures"]],
        )


@app.command("export")
def export(
    db: Path = typer.Argument(..., help="Campaign database (DuckDB)."),
    out: Path = typer.Argument(..., help="Output file (.parquet or .csv)."),
    format: str | None = typer.Option(
        None, "--format", help="parquet or csv (default: from the suffix of OUT, else parquet)."
    ),
    table: str = typer.Option("samples", help="samples (joined with the designs) or designs."),
) -> None:
    """Write the samples (or the designs table) of a campaign to Parquet or CSV."""
    from softbend._validation import check_choice
    from softbend.campaign import CampaignStore

    if format is None:
        format = "csv" if out.suffix.lower() == ".csv" else "parquet"
    check_choice(format, "--format", "softbend campaign export", ("parquet", "csv"))
    check_choice(table, "--table", "softbend campaign export", ("samples", "designs"))
    _common.check_output_file(out, "OUT", inputs=(db,), kind=format)
    with CampaignStore(db, read_only=True) as store, _common.output_errors(out, "OUT"):
        path = store.export(out, format=format, table=table)
        n_rows = len(store.load_samples() if table == "samples" else store.load_designs())
    _common.console.print(f"wrote {n_rows} {table} rows to {path} ({format})", highlight=False)


@app.command("dataset")
def dataset(
    db: Path = typer.Argument(..., help="Campaign database (DuckDB)."),
    out: Path = typer.Argument(..., help="Dataset folder (created; its files are replaced)."),
    command: str = typer.Option(
        ..., help="The command that produced the campaign (recorded in the provenance)."
    ),
    description: str = typer.Option("", help="What the data are, one paragraph."),
    space: str | None = typer.Option(
        None, help=f"The campaign's whole design space, {_SPACE_FORMS}: its size is recorded."
    ),
    json_output: bool = typer.Option(False, "--json", help="Print the provenance as JSON."),
) -> None:
    """Write a campaign as a verified dataset: Parquet samples and designs, provenance."""
    from softbend.datasets import DESIGNS_FILE, PROVENANCE_FILE, SAMPLES_FILE, write_dataset

    if not db.is_file():
        raise FileNotFoundError(f"No campaign database at {str(db)!r}.")
    planned = _space_spec(space).n_designs if space is not None else None
    written = (SAMPLES_FILE, DESIGNS_FILE, PROVENANCE_FILE)
    _common.check_output_dir(out, "OUT", inputs=(db,), files=written)
    # write_dataset reads and checks the whole campaign before it writes anything
    with _common.output_errors(out, "OUT"):
        provenance = write_dataset(
            db, out, command=command, description=description, planned=planned
        )
    if json_output:
        _common.print_json(provenance)
        return
    designs = provenance["designs"]
    _common.print_table(
        f"dataset {out}",
        ["quantity", "value"],
        [
            [
                "designs done / failed (of planned)",
                f"{designs['done']} / {designs['failed']} (of {designs['planned']})",
            ],
            [
                "samples (converged)",
                f"{provenance['samples']['rows']} ({provenance['samples']['converged']})",
            ],
            ["stops", ", ".join(f"{k}: {v}" for k, v in designs["by_stop_kind"].items())],
            ["CPU time (h)", provenance["cpu_time_s"] / 3600.0],
            ["files", ", ".join(f"{k} ({v['bytes']} B)" for k, v in provenance["files"].items())],
        ],
    )
