"""Writing a campaign database as a verified dataset folder (Parquet + provenance).

:func:`write_dataset` reads a campaign (paper B's or another FEM family's),
checks it, and writes the folder that :mod:`softbend.datasets` (Table 1) and
:mod:`softbend.family_datasets` (the other families) read back, with every
file's size and SHA-256 in its ``provenance.json``.
"""

from __future__ import annotations

import json
import os
from datetime import UTC, datetime
from pathlib import Path
from typing import Any

from softbend._io import json_text, write_text_atomic
from softbend.datasets import (
    _TABLE1_FEM,
    DESIGNS_FILE,
    PROVENANCE_FILE,
    SAMPLES_FILE,
    _design_table,
    _sha256,
)
from softbend.errors import DatasetError
from softbend.family_datasets import family_tables

__all__ = ["write_dataset"]


def write_dataset(
    db_path: str | os.PathLike[str],
    out_dir: str | os.PathLike[str],
    *,
    command: str,
    description: str = "",
    planned: int | None = None,
) -> dict[str, Any]:
    """Write a campaign database as a verified dataset folder (Parquet + provenance).

    Parameters
    ----------
    db_path : path
        Campaign database (see :class:`softbend.campaign.CampaignStore`).
    out_dir : path
        Folder of the dataset (created). It is written beside its place and
        swapped in whole when complete (:func:`softbend._outdir.staged_dir`), so a
        reader, or a run that fails half-way, sees the old dataset or the new one;
        an existing folder may hold only an earlier dataset
        (:func:`softbend._outdir.check_replaceable`).
    command : str
        The command that produced the campaign, recorded for reproduction.
    description : str
        One paragraph saying what the data are.
    planned : int, optional
        Designs of the whole campaign; recorded so that a dataset written from
        part of it (some shards) says so.

    Returns
    -------
    dict
        The provenance record written. A campaign of another FEM family than
        paper B's is written with its family's columns
        (:func:`softbend.family_datasets.family_column_kinds`), its values
        checked against the family's actuator, and its provenance also records
        ``family`` (the name) and ``actuator`` (the description,
        :meth:`~softbend.actuators.Actuator.to_dict`).

    Raises
    ------
    DatasetError
        If the campaign has no run or no design yet, ``out_dir`` holds other
        files than a dataset's, or a family's value lies outside its actuator's
        range (naming the column).
    """
    from softbend import __version__
    from softbend._outdir import check_replaceable, staged_dir
    from softbend.campaign.families import DEFAULT_FAMILY
    from softbend.campaign.store import CampaignStore

    out = Path(out_dir)
    check_replaceable(out, "campaign dataset", key="out_dir")
    with CampaignStore(db_path, read_only=True) as store:
        samples = store.load_samples()
        designs = store.load_designs()
        status = store.status_summary()
        runs = store.runs()
        backend = store.backend
        grid = store.pressures_mpa
        schema = store.family_schema
    if backend is None or grid is None or len(grid) == 0 or designs.empty:
        raise DatasetError(
            f"The campaign database {db_path} holds no finished run (backend, pressure grid "
            "and designs): run 'softbend campaign run' on it before writing a dataset."
        )
    if schema.name == DEFAULT_FAMILY:  # paper B's: the table of every dataset before families
        dataset_name, family = _TABLE1_FEM, {}
        table = _design_table(designs)
    else:
        actuator, table = family_tables(schema, samples, designs, db_path)
        dataset_name, family = schema.name, {"family": schema.name, "actuator": actuator.to_dict()}
    stats = [_stats_record(s, db_path) for s in designs["stats"] if isinstance(s, str) and s]
    options = {json.dumps(s.get("options"), sort_keys=True) for s in stats if "options" in s}
    files: dict[str, dict[str, Any]] = {}
    with staged_dir(out, "campaign dataset") as stage:
        for name, frame in ((SAMPLES_FILE, samples), (DESIGNS_FILE, table)):
            frame.to_parquet(stage / name, compression="zstd", index=False)
            files[name] = {"bytes": (stage / name).stat().st_size, "sha256": _sha256(stage / name)}
        done = table[table["status"] == "done"]
        provenance = {
            "name": dataset_name,
            "description": description,
            **family,
            "command": command,
            "backend": backend,
            "pressures_mpa": {
                "first": float(grid[0]),
                "last": float(grid[-1]),
                "count": len(grid),
            },
            "designs": {
                "planned": int(planned) if planned is not None else len(table),
                "recorded": len(table),
                "done": int(status["done"]),
                "failed": int(status["failed"]),
                "by_stop_kind": {
                    str(k): int(v) for k, v in done["stop_kind"].value_counts().items()
                },
            },
            "samples": {"rows": len(samples), "converged": int(samples["converged"].sum())},
            "cpu_time_s": float(done["wall_time_s"].sum()),
            "cpu_time_note": "sum of the sweeps' wall times, each sweep on one thread",
            "softbend_versions": sorted(set(table["softbend_version"])),
            "options_sha256": sorted(set(table["options_sha256"]) - {""}),
            "options": [json.loads(o) for o in sorted(options)],
            "campaign_runs": runs,
            "first_design_at": str(table["finished_at"].min()),
            "last_design_at": str(table["finished_at"].max()),
            "written_at": datetime.now(UTC).isoformat(timespec="seconds"),
            "written_by": f"softbend {__version__}",
            "files": files,
        }
        write_text_atomic(stage / PROVENANCE_FILE, json_text(provenance) + "\n")
    return provenance


def _stats_record(text: str, db_path: str | os.PathLike[str]) -> dict[str, Any]:
    """One design's stored solver statistics (JSON object text), checked."""
    try:
        record = json.loads(text)
    except (ValueError, RecursionError):
        record = None
    if not isinstance(record, dict):
        raise DatasetError(
            f"The campaign database {db_path} holds a design whose solver statistics are "
            "not a JSON object; the database is damaged."
        )
    return record
