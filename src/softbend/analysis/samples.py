"""The campaign samples as the analysis reads them: default columns and cleaning.

Data cleaning, the same for every analysis of :mod:`softbend.analysis`:

* if the table has a ``converged`` column, only rows where it is true are used
  (a point past the last converged load step is not a result);
* rows with a missing (NaN) or infinite value in any column used are dropped;
  the count is logged and returned.
"""

from __future__ import annotations

import logging
from collections.abc import Sequence

import numpy as np
import pandas as pd

from softbend.design import FEATURES
from softbend.errors import DatasetError

__all__ = ["DEFAULT_FEATURES", "DEFAULT_TARGET", "clean_samples", "is_constant"]

logger = logging.getLogger(__name__)

#: Inputs of paper B's analysis: the design vector and the actuation pressure.
DEFAULT_FEATURES: tuple[str, ...] = FEATURES
#: Output of paper B's analysis: the bending angle in degrees.
DEFAULT_TARGET = "angle_deg"


def clean_samples(df: pd.DataFrame, columns: Sequence[str]) -> tuple[pd.DataFrame, int]:
    """Keep converged rows and drop rows with NaN or inf in ``columns``.

    Parameters
    ----------
    df : pandas.DataFrame
        Campaign samples, one row per design and pressure.
    columns : sequence of str
        Columns to keep (repeated names are kept once).

    Returns
    -------
    table : pandas.DataFrame
        The cleaned numeric table (only ``columns``, as float, index reset).
    n_removed : int
        Rows of ``df`` left out.

    Raises
    ------
    DatasetError
        If ``df`` is not a DataFrame, a column is missing or not numeric, or the
        ``converged`` column does not hold booleans; keyed ``df``.
    """
    if not isinstance(df, pd.DataFrame):
        raise DatasetError(f"must be a pandas DataFrame; got {type(df).__name__}", key="df")
    columns = list(dict.fromkeys(columns))
    missing = [c for c in columns if c not in df.columns]
    if missing:
        raise DatasetError(
            f"the samples lack the column(s) {', '.join(map(repr, missing))}; "
            f"present: {', '.join(map(repr, map(str, df.columns)))}",
            key="df",
        )
    n_rows = len(df)
    table = df
    if "converged" in df.columns:
        try:
            converged = df["converged"].astype("boolean").fillna(False).to_numpy(dtype=bool)
        except (TypeError, ValueError):
            raise DatasetError(
                f"the 'converged' column must hold booleans; got dtype {df['converged'].dtype}",
                key="df",
            ) from None
        n_failed = int((~converged).sum())
        if n_failed:
            logger.info("dropped %d non-converged rows", n_failed)
        table = df.loc[converged]
    try:
        numeric = table[columns].apply(pd.to_numeric, errors="raise").astype(float)
    except (TypeError, ValueError) as exc:
        raise DatasetError(
            f"the columns {', '.join(map(repr, columns))} must be numeric: {exc}", key="df"
        ) from None
    numeric = numeric.replace([np.inf, -np.inf], np.nan)
    complete = numeric.notna().all(axis=1)
    n_nan = int((~complete).sum())
    if n_nan:
        logger.info("dropped %d rows with missing or infinite values", n_nan)
    numeric = numeric.loc[complete].reset_index(drop=True)
    return numeric, n_rows - len(numeric)


def is_constant(values: np.ndarray) -> bool:
    """True if the spread of ``values`` is at round-off level of their magnitude."""
    return float(np.ptp(values)) <= 1e-12 * max(float(np.max(np.abs(values))), 1.0)
