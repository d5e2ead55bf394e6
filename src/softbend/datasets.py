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
from a campaign database (``softbend campaign dataset DB --out DIR``).

Any other FEM family's campaign (``--family NAME``) makes a dataset whose tables
carry the family's parameter columns (:func:`family_column_kinds`) and whose
provenance also records ``family`` and ``actuator`` (its description). Shipped
ones lie in ``softbend/data/<family>/`` (paper B's ``"sfrba"``: ``table1_fem``);
:func:`family_dataset`, :func:`family_dataset_designs` and
:func:`family_dataset_provenance` read one, a design value outside the
actuator's range being one more error, and :func:`dataset_samples` reads one by
folder or name for ``softbend train DATASET``.
"""

from __future__ import annotations

import hashlib
import json
import math
import os
import re
from collections.abc import Sequence
from importlib import resources
from pathlib import Path
from typing import TYPE_CHECKING, Any

import numpy as np

from softbend._validation import must_be, short_repr
from softbend.design import FEATURE_QUANTITIES, PARAMETERS
from softbend.errors import DatasetError, InputError
from softbend.limits import check_file_size
from softbend.plausibility import RANGES, implausible_index

if TYPE_CHECKING:
    import pandas as pd

    from softbend.actuators import Actuator

__all__ = [
    "DESIGN_COLUMN_KINDS",
    "DESIGN_STAT_COLUMNS",
    "SAMPLE_COLUMN_KINDS",
    "TABLE1_FOLDER",
    "dataset_samples",
    "family_column_kinds",
    "family_dataset",
    "family_dataset_actuator",
    "family_dataset_designs",
    "family_dataset_provenance",
    "is_dataset_name",
    "shipped_families",
    "table1_fem",
    "table1_fem_designs",
    "table1_fem_provenance",
    "verify_dataset",
]

SAMPLES_FILE = "samples.parquet"
DESIGNS_FILE = "designs.parquet"
PROVENANCE_FILE = "provenance.json"
#: The folder of paper B's shipped dataset (Table 1), that of its family ``"sfrba"``.
TABLE1_FOLDER = "table1_fem"

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
    return _read(Path(folder) if folder is not None else _shipped(TABLE1_FOLDER), SAMPLES_FILE)


def table1_fem_designs(folder: str | os.PathLike[str] | None = None) -> pd.DataFrame:
    """One row per design of :func:`table1_fem` with its sweep's statistics.

    Columns: ``design_id``, the six parameters, then :data:`DESIGN_STAT_COLUMNS`
    (``stop_kind`` one of "last pressure", "angle limit", "stretch limit",
    "inflation instability", "no convergence" ("walls touch" for a PneuNet's
    dataset, :func:`family_dataset_designs`); ``stop_region`` the part of the
    actuator a stretch or instability stop names, else empty; times in s).
    Checked as :func:`table1_fem` is, the columns against :data:`DESIGN_COLUMN_KINDS`.
    """
    return _read(Path(folder) if folder is not None else _shipped(TABLE1_FOLDER), DESIGNS_FILE)


def table1_fem_provenance(folder: str | os.PathLike[str] | None = None) -> dict[str, Any]:
    """How :func:`table1_fem` was made: command, versions, options, dates, machines, CPU time."""
    return verify_dataset(Path(folder) if folder is not None else _shipped(TABLE1_FOLDER))


# -- the datasets of any family ----------------------------------------------------------

#: The family of paper B's actuator, whose shipped dataset is Table 1's.
_PAPER_B = "sfrba"


def family_column_kinds(actuator: Actuator) -> tuple[dict[str, str], dict[str, str]]:
    """The columns of a family's samples and designs tables and the kind of dtype of each.

    As paper B's :data:`~softbend.datasets.SAMPLE_COLUMN_KINDS` and
    :data:`~softbend.datasets.DESIGN_COLUMN_KINDS` with the actuator's parameter
    names (in its units, each of kind "float") in place of ``l_mm`` … ``lc_mm``.

    Returns
    -------
    (dict, dict)
        Samples: ``design_id``, the parameters, ``pressure_mpa`` (MPa),
        ``angle_deg`` (deg), ``tip_x_mm``, ``tip_z_mm`` (mm), ``converged``.
        Designs: ``design_id``, the parameters, then
        :data:`~softbend.datasets.DESIGN_STAT_COLUMNS`.
    """
    return _column_kinds(actuator.names)


def _requirement(parameter: Any) -> str:
    unit = f" {parameter.unit}" if parameter.unit else ""
    span = f"in [{parameter.low:g}, {parameter.high:g}]{unit}"
    if parameter.kind == "categorical":
        return f"a level code {span}"
    return f"a whole number {span}" if parameter.kind == "integer" else f"a value {span}"


def _check_parameters(table: pd.DataFrame, where: str, actuator: Actuator) -> None:
    """Raise :class:`DatasetError` for the first design value outside ``actuator``'s range.

    The message starts with ``where`` and names the row and the column.
    """
    for parameter in actuator.parameters:
        values = table[parameter.name].to_numpy(dtype="float64", na_value=math.nan)
        eps = 1e-9 * max(1.0, abs(parameter.low), abs(parameter.high))
        with np.errstate(invalid="ignore"):
            bad = ~np.isfinite(values)
            bad |= (values < parameter.low - eps) | (values > parameter.high + eps)
            if parameter.kind != "continuous":
                bad |= np.abs(values - np.round(values)) > 1e-9
        hits = np.flatnonzero(bad)
        if hits.size:
            row = int(hits[0])
            raise DatasetError(
                f"{where}, row {row}, column '{parameter.name}': {values[row]:g} is outside the "
                f"actuator {actuator.name!r}: {parameter.name} must be {_requirement(parameter)}."
            )


def _check_family_table(table: pd.DataFrame, path: Path, actuator: Actuator, name: str) -> None:
    """Check a family's ``name`` table ("samples" or "designs") read from ``path``."""
    samples, designs = family_column_kinds(actuator)
    kinds = samples if name == "samples" else designs
    # the design parameters are checked against the actuator's ranges, not RANGES
    _check_table(table, path, kinds, name, quantities=_MEASURED_QUANTITIES[name])
    _check_parameters(table, f"The dataset file {str(path)!r}", actuator)


def _actuator_from(record: object, where: str) -> Actuator:
    """The actuator of a recorded description, or one :class:`DatasetError` starting ``where``."""
    from softbend.actuators import Actuator, ActuatorError

    try:
        return Actuator.from_dict(json.loads(json.dumps(record)))
    except (ActuatorError, TypeError, ValueError) as exc:
        raise DatasetError(
            f"{where}: the field 'actuator' must be an actuator description "
            f"(Actuator.to_dict): {exc}"
        ) from None


# -- shipped datasets -------------------------------------------------------------------


def _data_root() -> Path:
    """The folder of the datasets shipped in the package."""
    return _shipped(TABLE1_FOLDER).parent


def shipped_families() -> dict[str, str]:
    """The families whose dataset softbend ships, each with its folder in ``softbend/data``.

    Paper B's family ``"sfrba"`` is Table 1's folder (:data:`TABLE1_FOLDER`);
    every other is a folder named after its family that holds a provenance record.
    """
    root = _data_root()
    found: dict[str, str] = {}
    if (root / TABLE1_FOLDER / PROVENANCE_FILE).is_file():
        found[_PAPER_B] = TABLE1_FOLDER
    if root.is_dir():
        for entry in sorted(root.iterdir(), key=lambda p: p.name):
            if entry.name not in (TABLE1_FOLDER, _PAPER_B) and (entry / PROVENANCE_FILE).is_file():
                found[entry.name] = entry.name
    return found


def is_dataset_name(text: str) -> bool:
    """Whether ``text`` names a dataset rather than a file: a family or ``"table1_fem"``.

    True for a registered FEM family (with or without a shipped dataset: reading
    one without is the error that names those with one), a family whose dataset
    is shipped, and Table 1's folder name.
    """
    from softbend.fem.families import FEM_FAMILIES

    return text == TABLE1_FOLDER or text in FEM_FAMILIES or text in shipped_families()


def _locate(family: str, folder: str | os.PathLike[str] | None) -> tuple[str, Path]:
    """The family and the folder of its dataset (the shipped one unless ``folder`` is given)."""
    if not isinstance(family, str):
        raise InputError(must_be("the name of an FEM family", family), key="family")
    if family == TABLE1_FOLDER:
        family = _PAPER_B
    if folder is not None:
        return family, Path(folder)
    shipped = shipped_families()
    if family not in shipped:
        from softbend.fem.families import FEM_FAMILIES

        known = ", ".join(shipped) or "none"
        hint = (
            f" ({family!r} is an FEM family without one: write one with 'softbend campaign "
            "dataset' from its campaign)"
            if family in FEM_FAMILIES
            else ""
        )
        raise InputError(
            must_be(f"a family with a shipped dataset ({known})", family) + hint, key="family"
        )
    return family, _data_root() / shipped[family]


def _open(
    family: str, folder: str | os.PathLike[str] | None
) -> tuple[Path, dict[str, Any], Actuator | None]:
    """The folder, the verified provenance and the recorded actuator (None for paper B's)."""
    family, path = _locate(family, folder)
    provenance = verify_dataset(path)
    record = path / PROVENANCE_FILE
    recorded = provenance.get("family", _PAPER_B)
    if recorded != family:
        raise DatasetError(
            f"The dataset {str(path)!r} holds designs of the {recorded!r} family, not of the "
            f"{family!r} family."
        )
    if family == _PAPER_B:
        return path, provenance, None
    if "actuator" not in provenance:
        raise DatasetError(
            f"The dataset file {str(record)!r}: the field 'actuator' is missing (a family's "
            "dataset records its actuator description)."
        )
    return (
        path,
        provenance,
        _actuator_from(provenance["actuator"], f"The dataset file {str(record)!r}"),
    )


def _load(
    family: str, folder: str | os.PathLike[str] | None, name: str
) -> tuple[pd.DataFrame, Actuator | None]:
    """The checked table ``name`` of a family's dataset and its actuator (None for paper B's)."""
    path, provenance, actuator = _open(family, folder)
    if actuator is None:
        return (table1_fem if name == SAMPLES_FILE else table1_fem_designs)(path), None
    table = _read_file(path, name, provenance)
    kind = "samples" if name == SAMPLES_FILE else "designs"
    _check_family_table(table, path / name, actuator, kind)
    return table, actuator


def family_dataset(family: str, folder: str | os.PathLike[str] | None = None) -> pd.DataFrame:
    """Every sample of a family's dataset, verified.

    Parameters
    ----------
    family : str
        The FEM family (``"pneunet"``; ``"sfrba"`` or ``"table1_fem"`` for paper
        B's Table 1, :func:`softbend.datasets.table1_fem`).
    folder : path, optional
        A dataset folder written by ``softbend campaign dataset``; default the
        one shipped for ``family`` (``softbend/data/<family>/``).

    Returns
    -------
    pandas.DataFrame
        ``design_id``, the family's parameters (in its actuator's units),
        ``pressure_mpa`` (MPa), ``angle_deg`` (deg), ``tip_x_mm``, ``tip_z_mm``
        (mm), ``converged``, sorted by design and pressure: the table
        :func:`softbend.campaign.load_samples` returns for its campaign.

    Raises
    ------
    InputError
        ``family`` has no shipped dataset (key ``family``, naming those that have).
    DatasetError
        A file is missing, truncated or altered, the provenance is of another
        shape or another family, or the table lacks a column of
        :func:`family_column_kinds`, has one of another dtype, a physically
        implausible value or a design value outside the recorded actuator's
        range (naming the file, the row and the column).
    """
    return _load(family, folder, SAMPLES_FILE)[0]


def family_dataset_designs(
    family: str, folder: str | os.PathLike[str] | None = None
) -> pd.DataFrame:
    """One row per design of :func:`family_dataset` with its sweep's statistics.

    Columns: ``design_id``, the family's parameters, then
    :data:`~softbend.datasets.DESIGN_STAT_COLUMNS` (``stop_kind`` as Table 1's,
    plus "walls touch" for a PneuNet swept without contact whose neighbouring
    chamber walls touched;
    ``stop_region`` the part a stretch or instability stop names, such as
    ``"chamber 3"``; times in s). Checked as :func:`family_dataset` is.
    """
    return _load(family, folder, DESIGNS_FILE)[0]


def family_dataset_provenance(
    family: str, folder: str | os.PathLike[str] | None = None
) -> dict[str, Any]:
    """How a family's dataset was made: command, family, actuator, versions, options, CPU time."""
    return _open(family, folder)[1]


def family_dataset_actuator(family: str, folder: str | os.PathLike[str] | None = None) -> Actuator:
    """The actuator description a family's dataset records (paper B's registered one for sfrba)."""
    actuator = _open(family, folder)[2]
    if actuator is None:
        from softbend.actuators import get_actuator

        return get_actuator(_PAPER_B)
    return actuator


def dataset_samples(source: str | os.PathLike[str]) -> tuple[pd.DataFrame, Actuator | None]:
    """The samples of a dataset folder or a shipped dataset's name, and its actuator.

    Parameters
    ----------
    source : str or path
        A dataset folder (``softbend campaign dataset``), or the name of a
        shipped dataset: a family of :func:`shipped_families` or ``"table1_fem"``.

    Returns
    -------
    (pandas.DataFrame, Actuator or None)
        :func:`family_dataset`'s table and the recorded actuator (None for paper
        B's Table 1, whose columns are paper B's features).

    Raises
    ------
    InputError, DatasetError
        As :func:`family_dataset`.
    """
    path = Path(source)
    if path.is_dir():
        family = verify_dataset(path).get("family", _PAPER_B)
        if not isinstance(family, str):
            raise DatasetError(
                f"The dataset file {str(path / PROVENANCE_FILE)!r}: the field 'family' must be "
                f"the name of an FEM family; got {family!r}."
            )
        return _load(family, path, SAMPLES_FILE)
    return _load(str(source), None, SAMPLES_FILE)
