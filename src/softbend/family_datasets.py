"""Datasets of any FEM actuator family, verified on every load.

A campaign of a family other than paper B's (``softbend campaign run DB
--family NAME``) written by ``softbend campaign dataset DB --out DIR`` is a
folder like Table 1's (:mod:`softbend.datasets`): ``samples.parquet``,
``designs.parquet`` and a ``provenance.json`` recording each file's size and
SHA-256. Its tables carry the family's own parameter columns
(:func:`family_column_kinds`), and its provenance also records ``family`` (the
family's name) and ``actuator`` (its description,
:meth:`~softbend.actuators.Actuator.to_dict`), so the folder describes itself.

The datasets softbend ships lie beside Table 1's, each in the folder named after
its family (``softbend/data/<family>/``); paper B's family ``"sfrba"`` is Table
1's folder ``table1_fem``. :func:`family_dataset`, :func:`family_dataset_designs`
and :func:`family_dataset_provenance` read one (or any such folder): a file of
another size or SHA-256, a column of another name or dtype, a physically
implausible value, or a design value outside the recorded actuator's range is a
:class:`~softbend.errors.DatasetError` naming the file and the column, never a
wrong table. :func:`dataset_samples` reads a dataset by folder or name for
:func:`softbend.surrogates.features.dataset_training_data`, the training data of
``softbend train DATASET`` (a dataset folder or the name of a shipped one)::

    from softbend.family_datasets import family_dataset, shipped_families

    shipped_families()          # {"sfrba": "table1_fem", ...}
    samples = family_dataset("sfrba")
"""

from __future__ import annotations

import json
import math
import os
import re
from pathlib import Path
from typing import TYPE_CHECKING, Any

import numpy as np

from softbend._validation import must_be
from softbend.datasets import (
    _MEASURED_QUANTITIES,
    DESIGNS_FILE,
    PROVENANCE_FILE,
    SAMPLES_FILE,
    _check_table,
    _column_kinds,
    _design_table,
    _read_file,
    _shipped,
    table1_fem,
    table1_fem_designs,
    verify_dataset,
)
from softbend.errors import DatasetError, InputError

if TYPE_CHECKING:
    import pandas as pd

    from softbend.actuators import Actuator
    from softbend.campaign.families import FamilySchema

__all__ = [
    "TABLE1_FOLDER",
    "dataset_samples",
    "family_column_kinds",
    "family_dataset",
    "family_dataset_actuator",
    "family_dataset_designs",
    "family_dataset_provenance",
    "family_stop_region",
    "is_dataset_name",
    "shipped_families",
]

#: The family of paper B's actuator and the folder of its shipped dataset (Table 1).
_PAPER_B = "sfrba"
TABLE1_FOLDER = "table1_fem"

#: Where a stretch or instability stop is: "… in the chamber 3 at x = 24 mm …"
#: or "…: the chamber 3 at x = 24 mm balloons".
_SITE = re.compile(r"(?:in the|: the) (.+?) at x = ")


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


def family_stop_region(reason: str, kind: str) -> str:
    """The part a stretch or instability stop names (such as ``"chamber 3"``), else ``""``."""
    if kind not in ("stretch limit", "inflation instability"):
        return ""
    match = _SITE.search(reason)
    return match[1] if match else ""


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
    plus "walls touch" for a PneuNet whose neighbouring chamber walls touched;
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
