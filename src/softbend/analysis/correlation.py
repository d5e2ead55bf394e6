"""Pearson correlations of the campaign samples (paper B Fig. 4a)."""

from __future__ import annotations

from collections.abc import Sequence

import numpy as np
import pandas as pd

from softbend._validation import must_be
from softbend.analysis.samples import DEFAULT_FEATURES, DEFAULT_TARGET, clean_samples, is_constant
from softbend.errors import DatasetError

__all__ = ["correlation_matrix"]


def correlation_matrix(
    df: pd.DataFrame,
    columns: Sequence[str] | None = None,
) -> pd.DataFrame:
    """Pearson correlation matrix of the campaign samples (paper B Fig. 4a).

    Parameters
    ----------
    df : pandas.DataFrame
        Samples, one row per design and pressure. Rows with ``converged``
        false (when that column exists) and rows with NaN in ``columns`` are
        left out.
    columns : sequence of str, optional
        Columns to correlate, in this order. Default: :data:`DEFAULT_FEATURES`
        followed by :data:`DEFAULT_TARGET`.

    Returns
    -------
    pandas.DataFrame
        Square, symmetric matrix indexed by ``columns`` on both axes with ones
        on the diagonal. Correlations involving a column that is constant in
        the data are undefined and returned as NaN (diagonal included).

    Raises
    ------
    DatasetError
        If a column is missing or not numeric, or fewer than two usable rows
        remain.
    """
    cols = list((*DEFAULT_FEATURES, DEFAULT_TARGET) if columns is None else columns)
    if not cols:
        raise DatasetError(must_be("at least one column name", cols), key="columns")
    data, _ = clean_samples(df, cols)
    if len(data) < 2:
        raise DatasetError(must_be("at least 2 complete, converged rows", len(data)), key="df")
    values = data[cols].to_numpy()
    centred = values - values.mean(axis=0)
    norms = np.sqrt((centred**2).sum(axis=0))
    with np.errstate(divide="ignore", invalid="ignore"):
        corr = (centred.T @ centred) / np.outer(norms, norms)
    corr = np.clip(corr, -1.0, 1.0)
    constant = np.array([is_constant(values[:, j]) for j in range(len(cols))])
    corr[constant, :] = np.nan
    corr[:, constant] = np.nan
    diag = np.arange(len(cols))
    corr[diag[~constant], diag[~constant]] = 1.0
    return pd.DataFrame(corr, index=cols, columns=cols)
