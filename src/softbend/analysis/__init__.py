"""Preliminary statistical analysis of a design campaign (paper B §3.3, Fig. 4).

Two views of the campaign samples (one row per design and pressure):

* :func:`correlation_matrix` — Pearson correlations between the design
  parameters, the actuation pressure and the bending angle (Fig. 4a);
* :func:`standardized_regression` — ordinary least squares of the z-scored
  bending angle on the z-scored inputs. Its coefficients are the standardized
  regression coefficients ("loadings", Fig. 4b): the change of the angle, in
  standard deviations, per standard deviation of one input with the others
  held fixed. Each comes with its standard error, t-statistic and two-sided
  p-value; the fit comes with R², adjusted R², the overall F-test, and the
  MAPE and RMSE of the fitted angle in degrees (Fig. 4c);
* :func:`analyze_samples` — both of the above with the same features and
  target, as one :class:`CampaignAnalysis` (what ``softbend analyze`` prints).

Paper B reports, on its 29577 FEM samples, a pressure loading of 0.832, a top
wall loading of −0.369, a bottom wall loading of −0.005, R² = 0.8893,
F = 33935.8 and MAPE = 42.3 %: a linear model ranks the inputs well but fits
the strongly nonlinear angle poorly.

Data cleaning (the same for both functions):

* if the table has a ``converged`` column, only rows where it is true are used
  (a point past the last converged load step is not a result);
* rows with a missing (NaN) value in any column used are dropped; the count is
  logged and returned in the report.

Modelling choices, stated once:

* z-scores use the sample standard deviation (``ddof=1``); the regression keeps
  an intercept (zero for z-scored data), so the residual degrees of freedom are
  ``n - p - 1`` and the t-statistics, p-values, R² and F equal those of the same
  regression on the raw variables (standardization only rescales each slope);
* a feature that is constant in the data (e.g. every structural parameter in a
  one-design campaign) carries no information and makes the design matrix
  singular: it is dropped with a :class:`ConstantFeatureWarning` and listed in
  :attr:`RegressionReport.dropped_features`. A constant target, linearly
  dependent features or too few samples raise :class:`DatasetError`;
* the MAPE is taken only over samples whose observed angle is at least
  ``mape_threshold`` in magnitude (default 1°): at zero pressure the angle is
  (close to) 0° and the percentage error is undefined or explodes. The number
  of samples left out is reported (:func:`thresholded_mape`).

Modules: :mod:`~softbend.analysis.samples` (default columns, cleaning),
:mod:`~softbend.analysis.correlation`, :mod:`~softbend.analysis.ols` (z-scored
least squares and its tests), :mod:`~softbend.analysis.regression` (the report)
and :mod:`~softbend.analysis.campaign_analysis`; :mod:`~softbend.analysis.effects`
reads a design space's main effects (group means per parameter). Names are imported lazily, so
``import softbend.analysis`` stays light (pandas is loaded by the first name used).
"""

from __future__ import annotations

from typing import TYPE_CHECKING, Any

from softbend._lazy import export as _export

if TYPE_CHECKING:
    from softbend.analysis.campaign_analysis import CampaignAnalysis, analyze_samples
    from softbend.analysis.correlation import correlation_matrix
    from softbend.analysis.effects import MainEffects, angle_at_pressure, main_effects
    from softbend.analysis.ols import significance_stars
    from softbend.analysis.regression import (
        ConstantFeatureWarning,
        RegressionReport,
        standardized_regression,
    )
    from softbend.analysis.samples import DEFAULT_FEATURES, DEFAULT_TARGET
    from softbend.metrics import thresholded_mape

#: Public name → module that defines it.
_EXPORTS = {
    "DEFAULT_FEATURES": "softbend.analysis.samples",
    "DEFAULT_TARGET": "softbend.analysis.samples",
    "CampaignAnalysis": "softbend.analysis.campaign_analysis",
    "MainEffects": "softbend.analysis.effects",
    "angle_at_pressure": "softbend.analysis.effects",
    "main_effects": "softbend.analysis.effects",
    "ConstantFeatureWarning": "softbend.analysis.regression",
    "RegressionReport": "softbend.analysis.regression",
    "analyze_samples": "softbend.analysis.campaign_analysis",
    "correlation_matrix": "softbend.analysis.correlation",
    "significance_stars": "softbend.analysis.ols",
    "standardized_regression": "softbend.analysis.regression",
    "thresholded_mape": "softbend.metrics",
}

__all__ = [
    "DEFAULT_FEATURES",
    "DEFAULT_TARGET",
    "CampaignAnalysis",
    "ConstantFeatureWarning",
    "MainEffects",
    "RegressionReport",
    "analyze_samples",
    "angle_at_pressure",
    "correlation_matrix",
    "main_effects",
    "significance_stars",
    "standardized_regression",
    "thresholded_mape",
]


def __getattr__(name: str) -> Any:
    return _export(__name__, _EXPORTS, name)


def __dir__() -> list[str]:
    return list(__all__)
