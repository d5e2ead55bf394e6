"""Datasets shipped with softbend, verified on every load.

:func:`table1_fem` returns paper B's Table 1 design space swept by softbend's FEM
(the campaign of ``softbend campaign run … --space table1 --backend fem``), as
the same table that :func:`softbend.campaign.load_samples` returns for a
campaign database, so analysis and surrogate training take either.
:func:`table1_fem_designs` gives one row per design with the sweep's statistics
(wall time, Newton iterations, load steps, stop reason and the region it names,
unknowns, softbend version, hash of the FEM options) and
:func:`table1_fem_provenance` how the data were made (command, versions,
options, dates, machines, total CPU time).

A dataset is a folder of Parquet files and a ``provenance.json`` that records
each file's size and SHA-256. Every load checks them: a missing, truncated or
altered file is a :class:`~softbend.errors.DatasetError` naming the file, never
a wrong table. :func:`write_dataset` makes such a folder from a campaign
database (``softbend campaign dataset DB DIR``).
"""

from __future__ import annotations

import hashlib
import json
import os
import re
from datetime import UTC, datetime
from importlib import resources
from pathlib import Path
from typing import TYPE_CHECKING, Any

from softbend._io import json_text, write_text_atomic
from softbend.errors import DatasetError

if TYPE_CHECKING:
    import pandas as pd

__all__ = [
    "DESIGN_STAT_COLUMNS",
    "table1_fem",
    "table1_fem_designs",
    "table1_fem_provenance",
    "verify_dataset",
    "write_dataset",
]

SAMPLES_FILE = "samples.parquet"
DESIGNS_FILE = "designs.parquet"
PROVENANCE_FILE = "provenance.json"
_TABLE1_FEM = "table1_fem"

#: Columns of the designs table besides the design parameters.
DESIGN_STAT_COLUMNS: tuple[str, ...] = (
    "status",
    "error",
    "n_samples",
    "max_pressure_mpa",
    "max_angle_deg",
    "stop_kind",
    "stop_region",
    "stop_reason",
    "wall_time_s",
    "newton_iterations_total",
    "load_steps",
    "rejected_steps",
    "ndof",
    "mesh_size",
    "softbend_version",
    "options_sha256",
    "finished_at",
)

#: Stop reasons of the FEM sweep, by the start of their text.
_STOP_KINDS = (
    ("reached the last pressure", "last pressure"),
    ("bending angle above", "angle limit"),
    ("stretch ", "stretch limit"),
    ("inflation instability", "inflation instability"),
    ("no convergence", "no convergence"),
)
_REGION = re.compile(r"(proximal cap|distal cap|chamber wall)")


def _shipped(name: str) -> Path:
    return Path(str(resources.files("softbend").joinpath("data", name)))


def _sha256(path: Path) -> str:
    digest = hashlib.sha256()
    with path.open("rb") as handle:
        for block in iter(lambda: handle.read(1 << 20), b""):
            digest.update(block)
    return digest.hexdigest()


def verify_dataset(folder: str | os.PathLike[str]) -> dict[str, Any]:
    """Check every file of a dataset folder against its provenance; return the provenance.

    Raises
    ------
    DatasetError
        The provenance file is missing or unreadable, or a data file is missing,
        has another size (truncated) or another SHA-256 (altered).
    """
    folder = Path(folder)
    record = folder / PROVENANCE_FILE
    try:
        provenance = json.loads(record.read_text(encoding="utf-8"))
        files = provenance["files"]
    except FileNotFoundError:
        raise DatasetError(f"The dataset file {str(record)!r} is missing.") from None
    except (OSError, ValueError, KeyError, TypeError) as exc:
        raise DatasetError(
            f"The dataset file {str(record)!r} is not a softbend provenance record ({exc})."
        ) from None
    for name, expected in files.items():
        path = folder / name
        if not path.is_file():
            raise DatasetError(f"The dataset file {str(path)!r} is missing.")
        size = path.stat().st_size
        if size != expected["bytes"]:
            raise DatasetError(
                f"The dataset file {str(path)!r} has {size} bytes, not the {expected['bytes']} "
                "its provenance records (truncated or replaced)."
            )
        if _sha256(path) != expected["sha256"]:
            raise DatasetError(
                f"The dataset file {str(path)!r} does not match the SHA-256 its provenance "
                "records (altered or corrupt)."
            )
    return provenance


def _read(folder: Path, name: str) -> pd.DataFrame:
    import pandas as pd

    provenance = verify_dataset(folder)
    if name not in provenance["files"]:
        raise DatasetError(f"The dataset {str(folder)!r} has no {name!r} in its provenance.")
    return pd.read_parquet(folder / name)


def table1_fem(folder: str | os.PathLike[str] | None = None) -> pd.DataFrame:
    """Paper B's Table 1 swept by softbend's FEM: every stored sample.

    Parameters
    ----------
    folder : path, optional
        A dataset folder made by :func:`write_dataset`; default: the one shipped
        in the package.

    Returns
    -------
    pandas.DataFrame
        The columns of :func:`softbend.campaign.load_samples` (``design_id``,
        ``l_mm`` … ``lc_mm``, ``pressure_mpa``, ``angle_deg`` (deg), ``tip_x_mm``,
        ``tip_z_mm``, ``converged``), sorted by design and pressure; the last row
        of a sweep that stopped on a failed step has ``converged`` False and NaN
        values.

    Raises
    ------
    DatasetError
        A file of the dataset is missing, truncated or altered.
    """
    return _read(Path(folder) if folder is not None else _shipped(_TABLE1_FEM), SAMPLES_FILE)


def table1_fem_designs(folder: str | os.PathLike[str] | None = None) -> pd.DataFrame:
    """One row per design of :func:`table1_fem` with its sweep's statistics.

    Columns: ``design_id``, the six parameters, then :data:`DESIGN_STAT_COLUMNS`
    (``stop_kind`` one of "last pressure", "angle limit", "stretch limit",
    "inflation instability", "no convergence"; ``stop_region`` the part of the
    actuator a stretch or instability stop names, else empty; times in s).
    """
    return _read(Path(folder) if folder is not None else _shipped(_TABLE1_FEM), DESIGNS_FILE)


def table1_fem_provenance(folder: str | os.PathLike[str] | None = None) -> dict[str, Any]:
    """How :func:`table1_fem` was made: command, versions, options, dates, machines, CPU time."""
    return verify_dataset(Path(folder) if folder is not None else _shipped(_TABLE1_FEM))


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


def _design_table(designs: pd.DataFrame) -> pd.DataFrame:
    """The campaign's designs table with its JSON stats unpacked into columns."""
    from softbend.design import PARAMETERS

    stats = [json.loads(s) if isinstance(s, str) and s else {} for s in designs["stats"]]
    out = designs[["design_id", *PARAMETERS]].copy()
    out["status"] = designs["status"]
    out["error"] = designs["error"].fillna("")
    out["n_samples"] = designs["n_samples"].astype("int32")
    out["max_pressure_mpa"] = designs["max_pressure_mpa"]
    out["max_angle_deg"] = designs["max_angle_deg"]
    reasons = [s.get("stop_reason", "") for s in stats]
    out["stop_kind"] = [_stop_kind(r) for r in reasons]
    out["stop_region"] = [
        (
            m[1]
            if (m := _REGION.search(r)) and k in ("stretch limit", "inflation instability")
            else ""
        )
        for r, k in zip(reasons, out["stop_kind"], strict=True)
    ]
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
        Folder of the dataset (created); its files are replaced atomically, the
        provenance last, so a reader sees the old dataset or the new one.
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
        The provenance record written.
    """
    from softbend import __version__
    from softbend.campaign.store import CampaignStore

    out = Path(out_dir)
    out.mkdir(parents=True, exist_ok=True)
    with CampaignStore(db_path, read_only=True) as store:
        samples = store.load_samples()
        designs = store.load_designs()
        status = store.status_summary()
        runs = store.runs()
        backend = store.backend
        grid = store.pressures_mpa
    table = _design_table(designs)
    stats = [json.loads(s) for s in designs["stats"] if isinstance(s, str) and s]
    options = {json.dumps(s.get("options"), sort_keys=True) for s in stats if "options" in s}
    files: dict[str, dict[str, Any]] = {}
    for name, frame in ((SAMPLES_FILE, samples), (DESIGNS_FILE, table)):
        tmp = out / f".{name}.tmp"
        frame.to_parquet(tmp, compression="zstd", index=False)
        os.replace(tmp, out / name)
        files[name] = {"bytes": (out / name).stat().st_size, "sha256": _sha256(out / name)}
    done = table[table["status"] == "done"]
    provenance = {
        "name": "table1_fem",
        "description": description,
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
            "by_stop_kind": {str(k): int(v) for k, v in done["stop_kind"].value_counts().items()},
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
    write_text_atomic(out / PROVENANCE_FILE, json_text(provenance) + "\n")
    return provenance
