"""Uniaxial tensile tests: the data file format and the tests shipped with softbend.

The shipped tests (``softbend/data/materials/``) are five pull-to-failure tests of
soft-robotics silicones from the Soft Robotics Materials Database of Marechal et
al. (Soft Robotics 8(3), 2021, doi:10.1089/soro.2019.0115), under the Open
Database License 1.0; the attribution and the licence text ship beside them
(``README.md``, ``LICENSE-ODbL.md``). They were measured on ASTM D412 die C
dumbbells (3 mm × 6 mm section, 33 mm gauge length) at 450 mm/min, with the strain
taken from the crosshead displacement.

File format (semicolon-separated): ``PARAMETER;INFO;URL`` metadata lines, a blank
line, a header row and one row per sample. The header is recognised by its column
names, not by its line number; the columns used are ``Engineering Strain``
(dimensionless) and ``Engineering Stress (MPa)`` (nominal stress: force per
undeformed cross-section). Other columns (time, true strain and stress) are
ignored. A file over the ``file_mib`` or ``csv_rows`` limit of
:mod:`softbend.limits` is refused before its rows are parsed, and a strain or
stress outside its plausible range (:mod:`softbend.plausibility`) is an error
naming the file, line and column.

A stress column written in kPa under the ``(MPa)`` header is caught by the test's
stiffness: the median secant modulus (stress over strain) up to 50 % strain above
:data:`KPA_SECANT_MODULUS_MPA` (20 MPa) is refused as "looks like kPa". Silicones
lie far below it (the shipped tests: 0.03 to 0.44 MPa; Sylgard 184 about 2 MPa),
while the same tests written in kPa read 34 to 438. An elastomer that truly is this
stiff is read with ``force=True`` (``--force``), with a warning.
"""

from __future__ import annotations

import logging
import math
import os
import warnings
from collections.abc import Mapping
from dataclasses import dataclass, field
from importlib import resources
from pathlib import Path
from types import MappingProxyType
from typing import Any

import numpy as np

from softbend._io import read_input_text
from softbend._validation import check_choice, check_finite_array
from softbend.errors import DatasetError
from softbend.limits import check_limit
from softbend.plausibility import check_plausible_columns

__all__ = [
    "ENGINEERING_STRAIN",
    "ENGINEERING_STRESS_MPA",
    "MIN_TENSILE_POINTS",
    "SHIPPED_ATTRIBUTION",
    "TensileTest",
    "load_shipped",
    "load_tensile",
    "load_tensile_csv",
    "shipped_tensile_tests",
]

logger = logging.getLogger(__name__)

#: Header of the engineering (nominal) strain column, dimensionless.
ENGINEERING_STRAIN = "Engineering Strain"
#: Header of the engineering (nominal) stress column, MPa.
ENGINEERING_STRESS_MPA = "Engineering Stress (MPa)"
#: Columns a tensile data file must have.
REQUIRED_COLUMNS: tuple[str, ...] = (ENGINEERING_STRAIN, ENGINEERING_STRESS_MPA)
#: Column names that identify the header row (any one of them is enough).
_KNOWN_COLUMNS: frozenset[str] = frozenset(
    {"Time (s)", "True Strain", "True Stress (MPa)", *REQUIRED_COLUMNS}
)
#: Fewest data rows a tensile test may have.
MIN_TENSILE_POINTS = 5

#: Attribution of the shipped tensile data (ODbL 1.0 requires it to travel with them).
SHIPPED_ATTRIBUTION = "Marechal et al., Soft Robotics 8(3) 2021, ODbL 1.0"

#: Readable material names of the shipped tests (the files' own ``Material`` entries
#: are spelled inconsistently: ``DragonSkin30``, ``Dragon Skin 20``, ``EcoFlex30``).
_SHIPPED_MATERIALS: dict[str, str] = {
    "dragon-skin-10-medium": "Dragon Skin 10 Medium",
    "dragon-skin-20": "Dragon Skin 20",
    "dragon-skin-30": "Dragon Skin 30",
    "ecoflex-0030": "Ecoflex 00-30",
    "ecoflex-0050": "Ecoflex 00-50",
}


@dataclass(frozen=True, eq=False)
class TensileTest:
    """One uniaxial tensile test in engineering (nominal) measures.

    Parameters
    ----------
    name : str
        Short identifier, e.g. ``"dragon-skin-30"``.
    material : str
        Readable material name, e.g. ``"Dragon Skin 30"``.
    engineering_strain : array_like
        Engineering strain ``ΔL/L0``, dimensionless, finite and ≥ 0, at least
        :data:`MIN_TENSILE_POINTS` values.
    engineering_stress_mpa : array_like
        Engineering (nominal, first Piola–Kirchhoff) stress, force per undeformed
        area, in MPa; finite, same length as the strain.
    metadata : mapping of str to str, optional
        The ``PARAMETER;INFO`` entries of the file (specimen, machine, lab ...).
    source : pathlib.Path, optional
        File the test was read from.
    attribution : str, optional
        Who measured the data and under which licence; empty for user files.

    Notes
    -----
    The arrays are stored as read-only float copies; ``metadata`` as a read-only
    mapping. Equality is identity (arrays have no single truth value).
    """

    name: str
    material: str
    engineering_strain: np.ndarray
    engineering_stress_mpa: np.ndarray
    metadata: Mapping[str, str] = field(default_factory=dict)
    source: Path | None = None
    attribution: str = ""

    def __post_init__(self) -> None:
        for text_field in ("name", "material"):
            value = getattr(self, text_field)
            if not isinstance(value, str) or not value.strip():
                raise ValueError(
                    f"The '{text_field}' of TensileTest must be a non-empty string. "
                    f"Got {value!r} instead."
                )
        strain = check_finite_array(self.engineering_strain, "engineering_strain")
        stress = check_finite_array(self.engineering_stress_mpa, "engineering_stress_mpa")
        if strain.ndim != 1 or stress.shape != strain.shape:
            raise DatasetError(
                "The 'engineering_strain' and 'engineering_stress_mpa' of TensileTest must be "
                f"1-D arrays of one length. Got shapes {strain.shape} and {stress.shape} instead."
            )
        if strain.size < MIN_TENSILE_POINTS:
            raise DatasetError(
                f"The 'engineering_strain' of TensileTest must have at least "
                f"{MIN_TENSILE_POINTS} points. Got {strain.size} instead."
            )
        negative = np.flatnonzero(strain < 0.0)
        if negative.size:
            first = int(negative[0])
            raise DatasetError(
                "The 'engineering_strain' of TensileTest must be in [0, inf). "
                f"Got {strain[first]!r} at position {first} instead."
            )
        strain = strain.copy()
        stress = stress.copy()
        strain.setflags(write=False)
        stress.setflags(write=False)
        object.__setattr__(self, "engineering_strain", strain)
        object.__setattr__(self, "engineering_stress_mpa", stress)
        object.__setattr__(self, "metadata", MappingProxyType(dict(self.metadata)))
        if self.source is not None:
            object.__setattr__(self, "source", Path(self.source))

    @property
    def stretch(self) -> np.ndarray:
        """Axial stretch ``λ = 1 + engineering strain``, dimensionless."""
        return 1.0 + self.engineering_strain

    @property
    def n_points(self) -> int:
        """Number of samples."""
        return int(self.engineering_strain.size)

    @property
    def max_strain(self) -> float:
        """Largest engineering strain reached (the strain at failure for a pull-to-failure test)."""
        return float(self.engineering_strain.max())

    def summary(self) -> dict[str, Any]:
        """What the test is, JSON-friendly: name, material, source, size and range."""
        return {
            "name": self.name,
            "material": self.material,
            "source": str(self.source) if self.source is not None else None,
            "attribution": self.attribution,
            "n_points": self.n_points,
            "max_engineering_strain": self.max_strain,
            "max_engineering_stress_mpa": float(self.engineering_stress_mpa.max()),
        }


def _cells(line: str) -> list[str]:
    return [cell.strip() for cell in line.split(";")]


def _find_header(lines: list[str]) -> int | None:
    """Index of the header row: the first line naming a known tensile-test column.

    A file whose header names none of them (misspelled columns) gets the first
    non-blank line after the blank line that ends the metadata block, else its
    first non-blank line, so that the missing-column message can list what the
    file has. ``None`` for a file without any non-blank line.
    """
    for i, line in enumerate(lines):
        if _KNOWN_COLUMNS.intersection(_cells(line)):
            return i
    filled = [i for i, line in enumerate(lines) if any(_cells(line))]
    if not filled:
        return None
    after_gap = [i for i in filled if i > 0 and not any(_cells(lines[i - 1]))]
    return after_gap[0] if after_gap else filled[0]


def _parse_number(text: str, column: str, label: str, row: int, line: int) -> float:
    try:
        value = float(text)
    except ValueError:
        value = math.nan
    if not math.isfinite(value):
        raise DatasetError(
            f"The '{column}' of {label} must be a finite number in every row. "
            f"Got {text!r} at data row {row} (line {line}) instead."
        )
    return value


#: The plausible range (:mod:`softbend.plausibility`) and header of each column read.


#: The median secant modulus up to 50 % strain, MPa, above which a stress column is taken for kPa.
KPA_SECANT_MODULUS_MPA = 20.0


def _check_not_kpa(strain: list[float], stress: list[float], label: str, force: bool) -> None:
    """Refuse a stress column whose small-strain stiffness says it was written in kPa."""
    eps, sig = np.asarray(strain), np.asarray(stress)
    small = (eps > 0.0) & (eps <= 0.5)
    if not small.any():
        small = eps > 0.0
    if not small.any():
        return
    secant = float(np.median(sig[small] / eps[small]))
    if secant <= KPA_SECANT_MODULUS_MPA:
        return
    what = (
        f"The '{ENGINEERING_STRESS_MPA}' of {label} looks like kPa: its median secant modulus "
        f"up to 50 % strain is {secant:.4g} MPa, where silicones lie far below "
        f"{KPA_SECANT_MODULUS_MPA:g} MPa (Dragon Skin 30: 0.44 MPa)"
    )
    if not force:
        raise DatasetError(
            f"{what}. Divide the column by 1000, or read it as given with force=True "
            "(--force) for an elastomer this stiff."
        )
    warnings.warn(f"{what}; read as given (force).", UserWarning, stacklevel=4)


def _parse_tensile_text(
    text: str,
    *,
    label: str,
    stem: str,
    source: Path | None,
    name: str | None,
    material: str | None,
    attribution: str,
    force: bool = False,
) -> TensileTest:
    """Parse the text of a tensile data file; ``label`` names the file in messages."""
    lines = text.splitlines()
    header_index = _find_header(lines)
    if header_index is None:
        raise DatasetError(
            f"The header row of {label} must name the columns {REQUIRED_COLUMNS[0]!r} and "
            f"{REQUIRED_COLUMNS[1]!r}. Got an empty file instead."
        )
    header = _cells(lines[header_index])
    found = [c for c in header if c]
    for column in REQUIRED_COLUMNS:
        if column not in header:
            raise DatasetError(
                f"The columns of {label} must include {column!r}. "
                f"Got {', '.join(repr(c) for c in found)} instead."
            )
    strain_col = header.index(ENGINEERING_STRAIN)
    stress_col = header.index(ENGINEERING_STRESS_MPA)
    rows = sum(1 for line in lines[header_index + 1 :] if line.replace(";", "").strip())
    check_limit("csv_rows", rows, label)

    metadata: dict[str, str] = {}
    for line in lines[:header_index]:
        cells = _cells(line)
        key = cells[0]
        if not key or key.upper() == "PARAMETER" or len(cells) < 2:
            continue
        metadata[key] = cells[1]
        if len(cells) > 2 and cells[2]:
            metadata[f"{key} URL"] = cells[2]

    strain: list[float] = []
    stress: list[float] = []
    line_numbers: list[int] = []
    for offset, line in enumerate(lines[header_index + 1 :], start=1):
        cells = _cells(line)
        if not any(cells):
            continue  # blank line (trailing newline, separator-only line)
        row = len(strain) + 1
        line_no = header_index + 1 + offset
        if len(cells) <= max(strain_col, stress_col):
            raise DatasetError(
                f"The data rows of {label} must have {len(header)} columns. "
                f"Got {len(cells)} at data row {row} (line {line_no}) instead."
            )
        eps = _parse_number(cells[strain_col], ENGINEERING_STRAIN, label, row, line_no)
        sig = _parse_number(cells[stress_col], ENGINEERING_STRESS_MPA, label, row, line_no)
        if eps < 0.0:
            raise DatasetError(
                f"The '{ENGINEERING_STRAIN}' of {label} must be in [0, inf) in every row. "
                f"Got {cells[strain_col]!r} at data row {row} (line {line_no}) instead."
            )
        strain.append(eps)
        stress.append(sig)
        line_numbers.append(line_no)
    check_plausible_columns(
        {ENGINEERING_STRAIN: (strain, "strain"), ENGINEERING_STRESS_MPA: (stress, "stress_mpa")},
        source=label,
        lines=line_numbers,
    )
    if len(strain) < MIN_TENSILE_POINTS:
        raise DatasetError(
            f"The data rows of {label} must number at least {MIN_TENSILE_POINTS}. "
            f"Got {len(strain)} instead."
        )
    _check_not_kpa(strain, stress, label, force)
    test = TensileTest(
        name=name or stem.lower().replace("_", "-").replace(" ", "-"),
        material=material or metadata.get("Material") or stem.replace("_", " "),
        engineering_strain=np.asarray(strain),
        engineering_stress_mpa=np.asarray(stress),
        metadata=metadata,
        source=source,
        attribution=attribution,
    )
    logger.info(
        "read tensile test %s (%s): %d points, strain up to %.4g",
        test.name,
        test.material,
        test.n_points,
        test.max_strain,
    )
    return test


def load_tensile_csv(
    path: str | os.PathLike[str],
    *,
    name: str | None = None,
    material: str | None = None,
    attribution: str = "",
    force: bool = False,
) -> TensileTest:
    """Read a uniaxial tensile test from a semicolon-separated data file.

    Parameters
    ----------
    path : str or os.PathLike
        The file: optional ``PARAMETER;INFO`` metadata lines, a header row with
        the columns ``Engineering Strain`` and ``Engineering Stress (MPa)`` (found
        by name, in any position, among other columns), then one row per sample.
    name : str, optional
        Identifier of the test; default: the file stem in lower case with ``-``
        for ``_`` (``Dragon_Skin_30.csv`` → ``"dragon-skin-30"``).
    material : str, optional
        Readable material name; default: the file's ``Material`` entry, else the stem.
    attribution : str, optional
        Provenance and licence of the data, kept with the test.
    force : bool, default False
        Read a stress column that looks like kPa (:data:`KPA_SECANT_MODULUS_MPA`) as
        given, with a warning, instead of refusing it.

    Returns
    -------
    TensileTest
        Engineering strain (dimensionless) and engineering stress (MPa).

    Raises
    ------
    FileNotFoundError
        If ``path`` does not exist.
    DatasetError
        If no header row is found, a required column is missing (the message
        names it and lists the columns found), a value is empty, non-numeric,
        NaN or infinite, a strain is negative (the message gives the data row and
        the line), a value is outside the plausible range of its column
        (:mod:`softbend.plausibility`: ``strain``, ``stress_mpa``; the message
        names the line and the column), there are fewer than
        :data:`MIN_TENSILE_POINTS` rows, or the stress looks like kPa (without ``force``).
    LimitError
        If the file is larger than the ``file_mib`` limit or has more data rows
        than the ``csv_rows`` limit of :mod:`softbend.limits` (checked before the
        rows are parsed).
    """
    file = Path(path)
    if not file.exists():
        raise FileNotFoundError(f"Tensile data file {str(file)!r} does not exist.")
    if file.is_dir():
        raise DatasetError(f"Tensile data file {str(file)!r} is a folder, not a file.")
    text = read_input_text(file, f"Tensile data file {str(file)!r}", encoding="utf-8-sig")
    return _parse_tensile_text(
        text,
        label=repr(str(file)),
        stem=file.stem,
        source=file,
        name=name,
        material=material,
        attribution=attribution,
        force=force,
    )


def _shipped_dir():
    return resources.files("softbend").joinpath("data", "materials")


def _shipped_files() -> dict[str, str]:
    """Shipped test name → file name, sorted by name."""
    files = {
        entry.name[: -len(".csv")].lower().replace("_", "-"): entry.name
        for entry in _shipped_dir().iterdir()
        if entry.name.endswith(".csv")
    }
    return dict(sorted(files.items()))


def shipped_tensile_tests() -> tuple[str, ...]:
    """Names of the tensile tests shipped with softbend.

    Returns
    -------
    tuple of str
        E.g. ``("dragon-skin-10-medium", "dragon-skin-20", "dragon-skin-30",
        "ecoflex-0030", "ecoflex-0050")``.
    """
    return tuple(_shipped_files())


def load_shipped(name: str) -> TensileTest:
    """Load one of the shipped tensile tests (Marechal et al. 2021, ODbL 1.0).

    Parameters
    ----------
    name : str
        One of :func:`shipped_tensile_tests`, e.g. ``"dragon-skin-30"``.

    Returns
    -------
    TensileTest
        With ``attribution`` set to :data:`SHIPPED_ATTRIBUTION`.

    Raises
    ------
    ValueError
        If ``name`` is not a shipped test; the message lists the allowed names.
    """
    files = _shipped_files()
    check_choice(name, "name", files)
    entry = _shipped_dir().joinpath(files[name])
    return _parse_tensile_text(
        entry.read_text(encoding="utf-8-sig"),
        label=repr(files[name]),
        stem=Path(files[name]).stem,
        # A plain folder in an ordinary install; None inside a zip archive.
        source=entry if isinstance(entry, Path) else None,
        name=name,
        material=_SHIPPED_MATERIALS.get(name),
        attribution=SHIPPED_ATTRIBUTION,
    )


def load_tensile(
    source: str | os.PathLike[str] | None = None, *, force: bool = False
) -> TensileTest:
    """A tensile test by file or by shipped name; the shipped ``"dragon-skin-30"`` by default.

    Parameters
    ----------
    source : str or path-like, optional
        A tensile data file (:func:`load_tensile_csv`) if one exists there, else
        the name of a shipped test (:func:`shipped_tensile_tests`).
    force : bool, default False
        As :func:`load_tensile_csv`: read a stress column that looks like kPa as given.

    Raises
    ------
    FileNotFoundError
        Neither a file nor a shipped test; the message lists the shipped ones.
    """
    if source is None:
        return load_shipped("dragon-skin-30")
    if Path(source).exists():
        return load_tensile_csv(source, force=force)
    shipped = shipped_tensile_tests()
    if source in shipped:
        return load_shipped(str(source))
    raise FileNotFoundError(
        f"Tensile data file {str(source)!r} does not exist and is not a shipped test "
        f"({', '.join(shipped)})."
    )
