"""``softbend campaign``: run, inspect and export design campaigns.

``run`` sweeps a design space (or one shard of it) into a DuckDB file (resuming
if it exists), ``merge`` joins the databases of shards, ``status`` summarises a
database, ``export`` writes its samples (or designs) to Parquet or CSV and
``dataset`` writes it as a verified dataset.
"""

from __future__ import annotations

from pathlib import Path
from typing import TYPE_CHECKING, Any

import typer

from softbend.cli import _common
from softbend.cli.campaign_run import SPACE_FORMS, one_line, run

if TYPE_CHECKING:
    from softbend.design import DesignSpace

app = typer.Typer(
    help="Run FEM or analytical sweeps over a design space.\n\n"
    "A campaign is a DuckDB file of designs and their pressure sweeps; run it, "
    "merge its shards, inspect it and export it.",
    no_args_is_help=True,
)
app.command("run")(run)


def parse_space(spec: str, seed: int = 0) -> DesignSpace:
    """The designs of a ``--space`` text (see :data:`SPACE_FORMS`), sampled with ``seed``."""
    from softbend.campaign.spaces import parse_space as parse

    return parse(spec).build(seed)


@app.command("merge")
def merge(
    db: Path = typer.Argument(..., help="Campaign database to merge into; created if missing."),
    shards: list[Path] = typer.Argument(
        ..., metavar="SHARDS", help="Campaign databases to copy designs from (one or more)."
    ),
    json_output: bool = typer.Option(False, "--json", help="Print the counts as JSON."),
) -> None:
    """Merge the databases of campaign shards into DB.

    The shards must share the backend and the pressure grid. Every shard is
    checked before anything is written; DB is replaced only when the whole
    merge is done.

    Example:

    \b
        softbend campaign merge all.duckdb shard0.duckdb shard1.duckdb
    """
    from softbend.campaign import CampaignStore
    from softbend.campaign.schema import missing_database
    from softbend.campaign.store import merge_campaigns

    for shard in shards:
        if not shard.is_file():  # a folder or nothing: one line naming it, before DB is checked
            raise missing_database(shard)
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
    """Summarise a campaign database.

    Designs done and failed, samples, the pressure grid, the backend's
    material and mesh size and the metadata of the database DB (--json: all
    recorded settings).

    Example:

    \b
        softbend campaign status table1.duckdb --json
    """
    from softbend.campaign import CampaignStore

    with CampaignStore(db, read_only=True) as store:
        summary = store.status_summary()
    if json_output:
        _common.print_json(summary)
        return
    _common.print_table(f"campaign {summary['path']}", ["quantity", "value"], _status_rows(summary))
    if summary["failures"]:
        _common.print_table(
            "failed designs",
            [_design_header(summary), "error"],
            [[f["design"], one_line(f["error"])] for f in summary["failures"]],
        )


def _status_rows(summary: dict[str, Any]) -> list[list[Any]]:
    """The rows of ``campaign status``'s table from :meth:`CampaignStore.status_summary`."""
    planned = summary["n_designs_planned"]
    settings = summary["settings"] or {}  # None in a database of an older softbend
    maxh = (settings.get("options") or {}).get("maxh_mm")
    grid = (
        "-"
        if summary["n_pressures"] is None
        else (
            f"{summary['n_pressures']} pressures, "
            f"{summary['pmin_mpa']:g}–{summary['pmax_mpa']:g} MPa"
        )
    )
    return [
        *([["family", summary["family"]]] if "family" in summary else []),
        ["backend", summary["backend"] or "-"],
        ["material", (settings.get("material") or {}).get("name", "-")],
        ["mesh size maxh (mm)", "-" if maxh is None else maxh],
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
    ]


def _design_header(summary: dict[str, object]) -> str:
    """``design (l,r,t,b,phi,lc)``, or the parameters of another family's campaign."""
    parameters = summary.get("parameters")
    if isinstance(parameters, list):
        return f"design ({','.join(map(str, parameters))})"
    return "design (l,r,t,b,phi,lc)"


@app.command("export")
def export(
    db: Path = typer.Argument(..., help="Campaign database (DuckDB)."),
    out: Path = typer.Option(..., "--out", "-o", help="Output file (.parquet or .csv)."),
    format: str | None = typer.Option(
        None, "--format", help="parquet or csv (default: from the suffix of --out, else parquet)."
    ),
    table: str = typer.Option("samples", help="samples (joined with the designs) or designs."),
) -> None:
    """Write a campaign's samples or designs to Parquet or CSV.

    The samples are joined with their designs' parameters; --table designs
    writes the designs table alone.

    Example:

    \b
        softbend campaign export table1.duckdb --out samples.parquet
    """
    from softbend._validation import check_choice
    from softbend.campaign import CampaignStore

    if format is None:
        format = "csv" if out.suffix.lower() == ".csv" else "parquet"
    check_choice(format, "format", ("parquet", "csv"))
    check_choice(table, "table", ("samples", "designs"))
    _common.check_output_file(out, "--out", inputs=(db,), kind=format)
    with CampaignStore(db, read_only=True) as store, _common.output_errors(out, "--out"):
        path = store.export(out, format=format, table=table)
        n_rows = len(store.load_samples() if table == "samples" else store.load_designs())
    _common.console.print(f"wrote {n_rows} {table} rows to {path} ({format})", highlight=False)


@app.command("dataset")
def dataset(
    db: Path = typer.Argument(..., help="Campaign database (DuckDB)."),
    out: Path = typer.Option(
        ..., "--out", "-o", help="Dataset folder (created; its files are replaced)."
    ),
    command: str = typer.Option(
        ..., help="The command that produced the campaign (recorded in the provenance)."
    ),
    description: str = typer.Option("", help="What the data are, one paragraph."),
    space: str | None = typer.Option(
        None,
        help=f"The campaign's whole design space, {SPACE_FORMS} (for another family than "
        "sfrba lhs:N, sobol:N, grid or grid:K): its size is recorded.",
    ),
    json_output: bool = typer.Option(False, "--json", help="Print the provenance as JSON."),
) -> None:
    """Write a campaign as a verified dataset with its provenance.

    Writes the samples and the designs as Parquet and a provenance file (the
    command, the counts and each file's SHA-256) into the folder --out. The
    campaign of another FEM family than paper B's (campaign run --family) is
    written with its family's design columns, checked against its actuator's
    ranges, and its provenance records the family and the actuator
    description: a folder named after the family beside softbend's table1_fem
    is a shipped dataset of that family.

    Example:

    \b
        softbend campaign dataset table1.duckdb --out data \\
            --command "softbend campaign run table1.duckdb --space table1"
        softbend campaign dataset pneunet.duckdb --out pneunet --space lhs:200 \\
            --command "softbend campaign run pneunet.duckdb --family pneunet --space lhs:200"
    """
    from softbend.campaign.schema import missing_database
    from softbend.dataset_writing import write_dataset
    from softbend.datasets import DESIGNS_FILE, PROVENANCE_FILE, SAMPLES_FILE

    if not db.is_file():
        raise missing_database(db)
    planned = _planned_designs(db, space) if space is not None else None
    written = (SAMPLES_FILE, DESIGNS_FILE, PROVENANCE_FILE)
    _common.check_output_dir(out, "--out", inputs=(db,), files=written)
    _common.check_replaceable_dir(out, "--out", inputs=(db,))
    # write_dataset reads and checks the whole campaign before it writes anything
    with _common.output_errors(out, "--out"):
        provenance = write_dataset(
            db, out, command=command, description=description, planned=planned
        )
    if json_output:
        _common.print_json(provenance)
        return
    _print_provenance(out, provenance)


def _print_provenance(out: Path, provenance: dict[str, Any]) -> None:
    """``campaign dataset``'s table of a written dataset's provenance."""
    designs = provenance["designs"]
    _common.print_table(
        f"dataset {out}",
        ["quantity", "value"],
        [
            *([["family", provenance["family"]]] if "family" in provenance else []),
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


def _planned_designs(db: Path, space: str) -> int:
    """The number of designs of ``--space`` for the family of the campaign ``db``."""
    from softbend.campaign import CampaignStore
    from softbend.campaign.spaces import campaign_space, check_sampled_size
    from softbend.fem.families import get_family

    check_sampled_size(space)  # refused before the database is read
    with CampaignStore(db, read_only=True) as store:
        family = store.family
    return campaign_space(space, get_family(family)).n_designs
