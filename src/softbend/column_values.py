"""What a table column's values are: the kind its cells read as, and whether they increase.

The helpers :mod:`softbend.tables` reads a column with where its format does not
declare the kind (:func:`infer_cells`, :func:`column_kind`, :func:`kind_conflict`),
and the one check and wording of a column that must increase strictly, a time
column (:func:`not_increasing`, :func:`not_increasing_text`), which the arrays of a
time series are held to as well as a file's columns.
"""

from __future__ import annotations

import math
from collections.abc import Sequence
from typing import Literal

import numpy as np

__all__ = [
    "MAX_INTEGER",
    "column_kind",
    "infer_cells",
    "infer_written",
    "kind_conflict",
    "not_increasing",
    "not_increasing_text",
    "reads_as_number",
]

#: The largest integer a float64 holds exactly.
MAX_INTEGER = 2**53


def reads_as_number(cell: object) -> bool:
    """Whether a filled cell is a number or text that reads as one (``"2"``, ``" 1.5e-3"``)."""
    if isinstance(cell, bool):
        return False
    if isinstance(cell, int | float | np.integer | np.floating):
        return True
    try:
        float(str(cell))
    except ValueError:
        return False
    return True


def _filled(cell: object) -> bool:
    if cell is None or (isinstance(cell, str) and not cell.strip()):
        return False
    return not (isinstance(cell, float | np.floating) and math.isnan(cell))


def column_kind(cells: Sequence[object]) -> Literal["empty", "number", "text", "mixed"]:
    """Whether a column's filled cells are all numbers (or text that reads as one), all text,
    a mix of the two, or none at all (empty cells: ``""``, None, NaN)."""
    seen = set()
    for cell in dict.fromkeys(cells):  # each distinct value once: a level repeats
        if _filled(cell):
            seen.add(reads_as_number(cell))
            if len(seen) == 2:
                return "mixed"
    if not seen:
        return "empty"
    return "number" if True in seen else "text"


def kind_conflict(cells: Sequence[object]) -> tuple[int, int] | None:
    """Where a column's filled cells mix numbers and text, or None where they do not.

    Parameters
    ----------
    cells : sequence
        The column's cells; empty ones (``""``, None, NaN) are left out.

    Returns
    -------
    (int, int) or None
        The position of the first cell of the rarer kind (a text cell where
        numbers are at least as many), and how many filled cells are of the
        other kind.
    """
    if column_kind(cells) != "mixed":
        return None
    number = {c: reads_as_number(c) for c in dict.fromkeys(cells) if _filled(c)}
    filled = [i for i, cell in enumerate(cells) if cell in number]
    numbers = [i for i in filled if number[cells[i]]]
    texts = [i for i in filled if not number[cells[i]]]
    if len(numbers) >= len(texts):
        return texts[0], len(numbers)
    return numbers[0], len(texts)


def infer_cells(cells: Sequence[object]) -> np.ndarray:
    """Cells as :func:`~softbend.tables.read_table` reads a column it infers: numbers
    where every filled cell reads as one (empty cells NaN), else text as written (empty
    cells NaN)."""
    return infer_written(["" if not _filled(c) else str(c).strip() for c in cells])


def infer_written(cells: list[str]) -> np.ndarray:
    """Cells as numbers where every filled one is a number (empty ones NaN), else as text.

    Whole numbers written without a point or an exponent are read as integers
    (as :func:`pandas.read_csv` reads them).
    """
    try:
        array = np.array([c or "nan" for c in cells], dtype=np.float64)
    except ValueError:
        return np.asarray([c if c else math.nan for c in cells], dtype=object)
    text = "".join(cells).lower()
    written_whole = all(cells) and not any(ch in text for ch in ".eni")
    if written_whole and np.isfinite(array).all() and (np.abs(array) <= MAX_INTEGER).all():
        return array.astype(np.int64)
    return array


def not_increasing(values: np.ndarray | Sequence[float]) -> int | None:
    """The position of the first value that does not exceed the one before it, else None."""
    array = np.asarray(values, dtype=np.float64).ravel()
    steps = np.flatnonzero(~(np.diff(array) > 0))
    return int(steps[0]) + 1 if steps.size else None


def not_increasing_text(
    values: np.ndarray | Sequence[float],
    k: int,
    where: str,
    experiment: object = None,
) -> str:
    """The one wording of a value ``values[k]`` that does not increase after ``values[k - 1]``.

    Parameters
    ----------
    values : array_like
        The column (a time column, in its unit).
    k : int
        The position of the value (:func:`not_increasing`).
    where : str
        Where the value before it is: ``"line 4"`` in a file, ``"sample 1"`` in an array.
    experiment : optional
        The experiment the values are of, named in the text.
    """
    array = np.asarray(values, dtype=np.float64).ravel()
    of = "" if experiment is None else f" in experiment {experiment!r}"
    return (
        f"{float(array[k])!r} does not increase after {float(array[k - 1])!r} ({where}){of}; "
        "it must increase strictly"
    )
