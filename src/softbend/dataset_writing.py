"""Writing a campaign database as a verified dataset folder (Parquet + provenance).

:func:`write_dataset` reads a campaign of any FEM family, checks it, and writes
the folder that :mod:`softbend.datasets` reads back, with every file's size and
SHA-256 in its ``provenance.json``. The designs table unpacks each sweep's
statistics (:func:`_design_table`: the stop's kind and the part it names);
:func:`family_tables` checks a family's campaign against its actuator.
"""

from __future__ import annotations

import json
import os
import re
from collections.abc import Callable, Sequence
from datetime import UTC, datetime
from pathlib import Path
from typing import TYPE_CHECKING, Any, cast

from softbend._io import json_text, write_text_atomic
from softbend.datasets import (
    DESIGNS_FILE,
    PROVENANCE_FILE,
    SAMPLES_FILE,
    TABLE1_FOLDER,
    _actuator_from,
    _check_parameters,
    _sha256,
)
from softbend.design import PARAMETERS
from softbend.errors import DatasetError

if TYPE_CHECKING:
    import pandas as pd

    from softbend.actuators import Actuator
    from softbend.campaign.family_schema import FamilySchema
    from softbend.fem.stats import FEMStats

__all__ = ["family_stop_region", "family_tables", "write_dataset"]

_STOP_KINDS = (
    ("reached the last pressure", "last pressure"),
    ("bending angle above", "angle limit"),
    ("stretch ", "stretch limit"),
    ("inflation instability", "inflation instability"),
    ("no convergence", "no convergence"),
    ("neighbouring chamber walls touch", "walls touch"),
)
_REGION = re.compile(r"(proximal cap|distal cap|chamber wall)")

#: Where a stretch or instability stop is: "… in the chamber 3 at x = 24 mm …"
#: or "…: the chamber 3 at x = 24 mm balloons".
_SITE = re.compile(r"(?:in the|: the) (.+?) at x = ")


def _stop_kind(reason: str | None) -> str:
    text = reason or ""
    for prefix, kind in _STOP_KINDS:
        if text.startswith(prefix):
            return kind
    return "other" if text else ""


def _stop_region(reason: str, kind: str) -> str:
    """The part of the actuator a stretch or instability stop names, else ``""``."""
    match = _REGION.search(reason)
    return match[1] if match and kind in ("stretch limit", "inflation instability") else ""


def _design_table(
    designs: pd.DataFrame,
    parameters: Sequence[str] = tuple(PARAMETERS),
    region: Callable[[str, str], str] = _stop_region,
) -> pd.DataFrame:
    """The campaign's designs table with its JSON stats unpacked into columns.

    The stats are an FEM sweep's (:class:`~softbend.fem.stats.FEMStats`); a key
    that another backend does not record reads as empty or zero. ``parameters``
    are the design columns (paper B's by default) and ``region(reason, kind)``
    the part of the actuator a stop reason names.
    """
    stats = [
        cast("FEMStats", json.loads(s) if isinstance(s, str) and s else {})
        for s in designs["stats"]
    ]
    out = designs[["design_id", *parameters]].copy()
    out["status"] = designs["status"]
    out["error"] = designs["error"].fillna("")
    out["n_samples"] = designs["n_samples"].astype("int32")
    out["max_pressure_mpa"] = designs["max_pressure_mpa"]
    out["max_angle_deg"] = designs["max_angle_deg"]
    reasons = [s.get("stop_reason", "") for s in stats]
    out["stop_kind"] = [_stop_kind(r) for r in reasons]
    out["stop_region"] = [region(r, k) for r, k in zip(reasons, out["stop_kind"], strict=True)]
    out["stop_reason"] = reasons
    out["wall_time_s"] = designs["wall_time_s"]
    out["newton_iterations_total"] = designs["newton_iterations_total"].astype("Int64")
    out["load_steps"] = [len(s.get("steps_mpa", [])) for s in stats]
    out["rejected_steps"] = [int(s.get("rejected_steps", 0)) for s in stats]
    out["ndof"] = [int(s.get("ndof", 0)) for s in stats]
    out["mesh_size"] = designs["mesh_size"].astype("Int64")
    out["softbend_version"] = designs["softbend_version"]
    out["options_sha256"] = [s.get("options_sha256", "") for s in stats]
    out["finished_at"] = designs["finished_at"]
    return out.reset_index(drop=True)


def family_stop_region(reason: str, kind: str) -> str:
    """The part a stretch or instability stop names (such as ``"chamber 3"``), else ``""``."""
    if kind not in ("stretch limit", "inflation instability"):
        return ""
    match = _SITE.search(reason)
    return match[1] if match else ""


def family_tables(
    schema: FamilySchema,
    samples: pd.DataFrame,
    designs: pd.DataFrame,
    db_path: str | os.PathLike[str],
) -> tuple[Actuator, pd.DataFrame]:
    """The actuator and the designs table of a family's campaign, its values checked.

    Parameters
    ----------
    schema : FamilySchema
        What the campaign database records of its family (not paper B's).
    samples, designs : pandas.DataFrame
        The campaign's samples and designs (:meth:`CampaignStore.load_samples`,
        :meth:`CampaignStore.load_designs`).
    db_path : path
        The campaign database, for the messages.

    Returns
    -------
    (Actuator, pandas.DataFrame)
        The recorded actuator (the registered family's when the database
        records none) and the designs table of :func:`family_column_kinds`.

    Raises
    ------
    DatasetError
        The recorded description is unreadable or names other parameters than
        the database's columns, or a design value lies outside its range
        (naming the row and the column).
    """
    where = f"The campaign database {str(db_path)!r}"
    if schema.actuator is not None:
        actuator = _actuator_from(schema.actuator, where)
    else:
        from softbend.fem.families import get_family

        actuator = get_family(schema.name).actuator
    if actuator.names != tuple(schema.parameters):
        raise DatasetError(
            f"{where} records an actuator of the parameters {', '.join(actuator.names)} for "
            f"the design columns {', '.join(schema.parameters)}; the database is damaged."
        )
    table = _design_table(designs, schema.parameters, family_stop_region)
    _check_parameters(samples, f"{where}, samples", actuator)
    _check_parameters(table, f"{where}, designs", actuator)
    return actuator, table


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
        (:func:`softbend.datasets.family_column_kinds`), its values
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
    from softbend.campaign.store import CampaignStore
    from softbend.fem.families import get_family

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
    if get_family(schema.name).recorded:
        actuator, table = family_tables(schema, samples, designs, db_path)
        dataset_name, family = schema.name, {"family": schema.name, "actuator": actuator.to_dict()}
    else:  # a family whose data predate families (paper B's): Table 1's dataset
        dataset_name, family = TABLE1_FOLDER, {}
        table = _design_table(designs)
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
