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
each file's size and SHA-256. Every load checks them: a provenance of another
shape (``files`` not an object of ``{"bytes": int >= 0, "sha256": 64 hex
digits}``), a missing, truncated or altered file, or a table without the
columns and dtypes of :data:`SAMPLE_COLUMN_KINDS` or :data:`DESIGN_COLUMN_KINDS`
or with a physically implausible value is a
:class:`~softbend.errors.DatasetError` naming the file and the field, never a
wrong table. :func:`softbend.dataset_writing.write_dataset` makes such a folder
from a campaign database (``softbend campaign dataset DB --out DIR``); a campaign
of another FEM family than paper B's (``softbend campaign run --family NAME``)
makes a dataset of that family, read by :mod:`softbend.family_datasets`.
"""

from __future__ import annotations

import hashlib
import json
import math
import os
import re
from collections.abc import Callable, Sequence
from importlib import resources
from pathlib import Path
from typing import TYPE_CHECKING, Any, cast

from softbend._validation import short_repr
from softbend.design import FEATURE_QUANTITIES, PARAMETERS
from softbend.errors import DatasetError
from softbend.limits import check_file_size
from softbend.plausibility import RANGES, implausible_index

if TYPE_CHECKING:
    import pandas as pd

    from softbend.fem.stats import FEMStats

__all__ = [
    "DESIGN_COLUMN_KINDS",
    "DESIGN_STAT_COLUMNS",
    "SAMPLE_COLUMN_KINDS",
    "table1_fem",
    "table1_fem_designs",
    "table1_fem_provenance",
    "verify_dataset",
]

SAMPLES_FILE = "samples.parquet"
DESIGNS_FILE = "designs.parquet"
PROVENANCE_FILE = "provenance.json"
_TABLE1_FEM = "table1_fem"

#: The kind of dtype of each column of the designs table besides the design parameters.
_DESIGN_STAT_KINDS: dict[str, str] = {
    "status": "string",
    "error": "string",
    "n_samples": "integer",
    "max_pressure_mpa": "float",
    "max_angle_deg": "float",
    "stop_kind": "string",
    "stop_region": "string",
    "stop_reason": "string",
    "wall_time_s": "float",
    "newton_iterations_total": "integer",
    "load_steps": "integer",
    "rejected_steps": "integer",
    "ndof": "integer",
    "mesh_size": "integer",
    "softbend_version": "string",
    "options_sha256": "string",
    "finished_at": "datetime",
}

#: Columns of the designs table besides the design parameters.
DESIGN_STAT_COLUMNS: tuple[str, ...] = tuple(_DESIGN_STAT_KINDS)


def _column_kinds(parameters: Sequence[str]) -> tuple[dict[str, str], dict[str, str]]:
    """The columns of a samples and a designs table of ``parameters`` and their dtype kinds.

    Samples: ``design_id``, the parameters (each "float"), ``pressure_mpa`` (MPa),
    ``angle_deg`` (deg), ``tip_x_mm``, ``tip_z_mm`` (mm), ``converged``. Designs:
    ``design_id``, the parameters, then :data:`DESIGN_STAT_COLUMNS`.
    """
    kinds = dict.fromkeys(parameters, "float")
    samples = {
        "design_id": "string",
        **kinds,
        "pressure_mpa": "float",
        "angle_deg": "float",
        "tip_x_mm": "float",
        "tip_z_mm": "float",
        "converged": "bool",
    }
    return samples, {"design_id": "string", **kinds, **_DESIGN_STAT_KINDS}


#: Columns of the samples table (:func:`table1_fem`) and the kind of dtype of each:
#: "string", "float" (any real dtype: float or integer), "integer", "bool" or "datetime".
SAMPLE_COLUMN_KINDS: dict[str, str] = _column_kinds(PARAMETERS)[0]

#: Columns of the designs table (:func:`table1_fem_designs`) and the kind of dtype of each.
DESIGN_COLUMN_KINDS: dict[str, str] = _column_kinds(PARAMETERS)[1]

#: The quantity of :data:`softbend.plausibility.RANGES` of each physical column
#: besides the design parameters, in any family's samples and designs tables.
_MEASURED_QUANTITIES: dict[str, dict[str, str]] = {
    "samples": {
        "pressure_mpa": "pressure_mpa",
        "angle_deg": "angle_deg",
        "tip_x_mm": "coordinate_mm",
        "tip_z_mm": "coordinate_mm",
    },
    "designs": {
        "max_pressure_mpa": "pressure_mpa",
        "max_angle_deg": "angle_deg",
        "wall_time_s": "time_s",
    },
}

#: The quantity of :data:`softbend.plausibility.RANGES` of each physical column
#: of paper B's tables: its design parameters, then :data:`_MEASURED_QUANTITIES`.
_COLUMN_QUANTITIES: dict[str, dict[str, str]] = {
    table: {**{name: FEATURE_QUANTITIES[name] for name in PARAMETERS}, **measured}
    for table, measured in _MEASURED_QUANTITIES.items()
}

_HEX64 = re.compile(r"[0-9a-fA-F]{64}")

#: Stop reasons of the FEM sweep, by the start of their text.
_STOP_KINDS = (
    ("reached the last pressure", "last pressure"),
    ("bending angle above", "angle limit"),
    ("stretch ", "stretch limit"),
    ("inflation instability", "inflation instability"),
    ("no convergence", "no convergence"),
    ("neighbouring chamber walls touch", "walls touch"),
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


def _provenance_files(provenance: object, record: Path) -> dict[str, dict[str, Any]]:
    """The ``files`` of a provenance record, its shape and types checked.

    Raises
    ------
    DatasetError
        Naming ``record`` and the field: the record is not an object, ``files`` is
        missing or not a non-empty object, a file name is not a plain name in the
        folder, or an entry lacks ``bytes`` (an integer >= 0) or ``sha256`` (64
        hex digits), or has another key.
    """
    where = f"The dataset file {str(record)!r}"
    if not isinstance(provenance, dict):
        raise DatasetError(
            f"{where} is not a softbend provenance record: expected a JSON object, got "
            f"{type(provenance).__name__}."
        )
    if "files" not in provenance:
        raise DatasetError(
            f"{where} is not a softbend provenance record: the field 'files' is missing."
        )
    files = provenance["files"]
    if not isinstance(files, dict) or not files:
        raise DatasetError(
            f"{where}: the field 'files' must be a non-empty object of "
            '{"NAME": {"bytes": ..., "sha256": ...}}; got '
            f"{type(files).__name__ if files else repr(files)}."
        )
    for name, entry in files.items():
        field = f"files.{name}"
        if not name or name in (".", "..") or "/" in name or "\\" in name:
            raise DatasetError(
                f"{where}: the field 'files' must name files of the dataset folder (no "
                f"folders); got {name!r}."
            )
        if not isinstance(entry, dict):
            raise DatasetError(
                f"{where}: the field '{field}' must be an object with 'bytes' and 'sha256'; "
                f"got {type(entry).__name__}."
            )
        unknown = sorted(set(entry) - {"bytes", "sha256"})
        missing = [key for key in ("bytes", "sha256") if key not in entry]
        if missing or unknown:
            found = f"missing {', '.join(missing)}" if missing else f"unknown {unknown[0]!r}"
            raise DatasetError(
                f"{where}: the field '{field}' must have the keys 'bytes' and 'sha256'; "
                f"got {found}."
            )
        size = entry["bytes"]
        if type(size) is not int or size < 0:
            raise DatasetError(
                f"{where}: the field '{field}.bytes' must be an integer >= 0 (the file's "
                f"size); got {short_repr(size)}."
            )
        digest = entry["sha256"]
        if not isinstance(digest, str) or not _HEX64.fullmatch(digest):
            raise DatasetError(
                f"{where}: the field '{field}.sha256' must be 64 hexadecimal digits; "
                f"got {short_repr(digest, 80)}."
            )
    cpu = provenance.get("cpu_time_s", 0.0)
    if type(cpu) not in (int, float) or not 0 <= cpu < math.inf:  # NaN compares False
        raise DatasetError(
            f"{where}: the field 'cpu_time_s' must be a finite number of seconds >= 0; "
            f"got {short_repr(cpu)}."
        )
    return files


def verify_dataset(folder: str | os.PathLike[str]) -> dict[str, Any]:
    """Check every file of a dataset folder against its provenance; return the provenance.

    Raises
    ------
    DatasetError
        The provenance file is missing, unreadable or of another shape (naming
        the field), or a data file is missing, has another size (truncated) or
        another SHA-256 (altered).
    LimitError
        The provenance file is larger than the ``file_mib`` limit of :mod:`softbend.limits`.
    """
    folder = Path(folder)
    record = folder / PROVENANCE_FILE
    check_file_size(record)
    try:
        provenance = json.loads(record.read_text(encoding="utf-8"))
    except FileNotFoundError:
        raise DatasetError(f"The dataset file {str(record)!r} is missing.") from None
    except RecursionError:
        raise DatasetError(
            f"The dataset file {str(record)!r} is not a softbend provenance record (its JSON "
            "nests too deeply to be read)."
        ) from None
    except (OSError, ValueError) as exc:
        raise DatasetError(
            f"The dataset file {str(record)!r} is not a softbend provenance record ({exc})."
        ) from None
    files = _provenance_files(provenance, record)
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
        if _sha256(path) != expected["sha256"].lower():
            raise DatasetError(
                f"The dataset file {str(path)!r} does not match the SHA-256 its provenance "
                "records (altered or corrupt)."
            )
    return provenance


def _dtype_kind(series: pd.Series) -> str:
    """The kind of a column's dtype: "string", "float", "integer", "bool", "datetime" or other."""
    import pandas as pd
    from pandas.api import types

    dtype = series.dtype
    if types.is_bool_dtype(dtype):
        return "bool"
    if types.is_integer_dtype(dtype):
        return "integer"
    if types.is_float_dtype(dtype):
        return "float"
    if types.is_datetime64_any_dtype(dtype):
        return "datetime"
    if isinstance(dtype, pd.StringDtype):
        return "string"
    if types.is_object_dtype(dtype) and all(  # strings as objects (older pandas), None missing
        isinstance(v, str) or v is None or (isinstance(v, float) and math.isnan(v))
        for v in series.array
    ):
        return "string"
    return str(dtype)


def _check_table(
    table: pd.DataFrame,
    path: Path,
    kinds: dict[str, str],
    name: str,
    quantities: dict[str, str] | None = None,
) -> None:
    """Raise :class:`DatasetError` naming ``path`` and the columns of another name or dtype.

    ``quantities`` maps the physical columns to their quantity of
    :data:`softbend.plausibility.RANGES` (default paper B's for the table ``name``).
    """
    missing = [column for column in kinds if column not in table.columns]
    if missing:
        raise DatasetError(
            f"The dataset file {str(path)!r} lacks the column(s) {', '.join(missing)}; "
            f"the {name} table has {', '.join(kinds)}."
        )
    wrong = []
    for column, kind in kinds.items():
        found = _dtype_kind(table[column])
        ok = found == kind or (kind == "float" and found == "integer")
        if not ok:
            wrong.append(f"{column} ({found}, expected {kind})")
    if wrong:
        raise DatasetError(
            f"The dataset file {str(path)!r} has column(s) of another type: {', '.join(wrong)}."
        )
    checked = _COLUMN_QUANTITIES[name] if quantities is None else quantities
    for column, quantity in checked.items():
        values = table[column].to_numpy(dtype="float64", na_value=math.nan)
        row = implausible_index(values, quantity)
        if row is not None:
            bounds = RANGES[quantity]
            unit = f" {bounds.unit}" if bounds.unit else ""
            raise DatasetError(
                f"The dataset file {str(path)!r}, row {row}, column '{column}': "
                f"{values[row]:g} is not a plausible {bounds.label} (allowed {bounds.low:g} "
                f"to {bounds.high:g}{unit})."
            )


def _read(folder: Path, name: str) -> pd.DataFrame:
    table = _read_file(folder, name, verify_dataset(folder))
    if name == SAMPLES_FILE:
        _check_table(table, folder / name, SAMPLE_COLUMN_KINDS, "samples")
    elif name == DESIGNS_FILE:
        _check_table(table, folder / name, DESIGN_COLUMN_KINDS, "designs")
    return table


def _read_file(folder: Path, name: str, provenance: dict[str, Any]) -> pd.DataFrame:
    """The Parquet table ``name`` of a verified dataset folder (its columns not yet checked)."""
    import pandas as pd

    if name not in provenance["files"]:
        raise DatasetError(f"The dataset {str(folder)!r} has no {name!r} in its provenance.")
    path = folder / name
    try:
        table = pd.read_parquet(path)
    except (OSError, ValueError) as exc:  # pyarrow's errors derive from these
        raise DatasetError(
            f"The dataset file {str(path)!r} is not a Parquet table ({exc})."
        ) from None
    return table


def table1_fem(folder: str | os.PathLike[str] | None = None) -> pd.DataFrame:
    """Paper B's Table 1 swept by softbend's FEM: every stored sample.

    Parameters
    ----------
    folder : path, optional
        A dataset folder made by :func:`~softbend.dataset_writing.write_dataset`;
        default: the one shipped in the package.

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
        A file of the dataset is missing, truncated or altered, its provenance
        has another shape, or the table lacks a column of
        :data:`SAMPLE_COLUMN_KINDS`, has one of another dtype or a physically
        implausible value (naming the file and the column).
    """
    return _read(Path(folder) if folder is not None else _shipped(_TABLE1_FEM), SAMPLES_FILE)


def table1_fem_designs(folder: str | os.PathLike[str] | None = None) -> pd.DataFrame:
    """One row per design of :func:`table1_fem` with its sweep's statistics.

    Columns: ``design_id``, the six parameters, then :data:`DESIGN_STAT_COLUMNS`
    (``stop_kind`` one of "last pressure", "angle limit", "stretch limit",
    "inflation instability", "no convergence" ("walls touch" for a PneuNet's
    dataset, :mod:`softbend.family_datasets`); ``stop_region`` the part of the
    actuator a stretch or instability stop names, else empty; times in s).
    Checked as :func:`table1_fem` is, the columns against :data:`DESIGN_COLUMN_KINDS`.
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
