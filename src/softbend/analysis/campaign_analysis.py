"""Regression and correlations of one campaign together (what ``softbend analyze`` shows)."""

from __future__ import annotations

from collections.abc import Sequence
from dataclasses import dataclass
from typing import Any

import pandas as pd

from softbend.analysis.correlation import correlation_matrix
from softbend.analysis.regression import RegressionReport, standardized_regression
from softbend.analysis.samples import DEFAULT_FEATURES, DEFAULT_TARGET
from softbend.errors import DatasetError, SoftbendError

__all__ = ["CampaignAnalysis", "analyze_samples"]


@dataclass(frozen=True, eq=False)
class CampaignAnalysis:
    """Result of :func:`analyze_samples`.

    Attributes
    ----------
    regression : RegressionReport
        Standardized regression of the target on the features (Fig. 4b–c).
    correlation : pandas.DataFrame
        Pearson correlations of the features followed by the target (Fig. 4a).
    """

    regression: RegressionReport
    correlation: pd.DataFrame

    def to_dict(self, *, include_samples: bool = False) -> dict[str, Any]:
        """JSON-ready summary: :meth:`RegressionReport.to_dict` plus ``"correlation"``.

        Parameters
        ----------
        include_samples : bool, default False
            Also include the regression's ``fitted`` and ``observed`` arrays.

        Returns
        -------
        dict
            The regression's keys, then ``"correlation"``: row name → column
            name → Pearson r (NaN for a constant column).
        """
        out = self.regression.to_dict(include_samples=include_samples)
        corr = self.correlation
        out["correlation"] = {
            str(row): {str(col): float(v) for col, v in corr.loc[row].items()} for row in corr.index
        }
        return out


def analyze_samples(
    samples: pd.DataFrame,
    features: Sequence[str] = DEFAULT_FEATURES,
    target: str = DEFAULT_TARGET,
    *,
    mape_threshold: float = 1.0,
) -> CampaignAnalysis:
    """Standardized regression and correlation matrix of campaign samples (paper B Fig. 4).

    Parameters
    ----------
    samples : pandas.DataFrame
        Campaign samples, one row per design and pressure; cleaned as
        :func:`~softbend.analysis.standardized_regression` and
        :func:`~softbend.analysis.correlation_matrix` clean them.
    features : sequence of str, default :data:`DEFAULT_FEATURES`
        Input columns (design parameters in mm / degrees, pressure in MPa).
    target : str, default ``"angle_deg"``
        Output column (bending angle, degrees).
    mape_threshold : float, default 1.0
        Samples with ``|observed| < mape_threshold`` (target units, degrees) are
        left out of the regression's MAPE.

    Returns
    -------
    CampaignAnalysis
        ``standardized_regression(samples, features, target, mape_threshold=...)``
        and ``correlation_matrix(samples, [*features, target])``.

    Warns
    -----
    ConstantFeatureWarning
        For each feature constant in the data (left out of the regression; its
        correlations are NaN).

    Raises
    ------
    DatasetError
        If ``samples`` has no rows, or as the two analyses raise it.
    ValueError
        On a bad ``features``, ``target`` or ``mape_threshold``.
    """
    if isinstance(samples, pd.DataFrame) and len(samples) == 0:
        raise DatasetError("must hold rows; got none: there is nothing to analyze", key="samples")
    names = [features] if isinstance(features, str) else [str(f) for f in features]
    try:
        regression = standardized_regression(samples, names, target, mape_threshold=mape_threshold)
        correlation = correlation_matrix(samples, [*names, target])
    except SoftbendError as error:
        if error.key == "df":  # the table the two analyses were given is ``samples`` here
            error.key = "samples"
        raise
    return CampaignAnalysis(regression=regression, correlation=correlation)
