"""Standardized multiple linear regression of a campaign (paper B Fig. 4b–c).

:func:`standardized_regression` cleans the samples (:mod:`softbend.analysis.samples`),
leaves out constant features, fits the z-scored least squares and tests it
(:mod:`softbend.analysis.ols`), and gathers everything in a :class:`RegressionReport`
with the MAPE and RMSE of the fitted target in its own units.

Modelling choices, stated once:

* a feature that is constant in the data (e.g. every structural parameter in a
  one-design campaign) carries no information and makes the design matrix
  singular: it is dropped with a :class:`ConstantFeatureWarning` and listed in
  :attr:`RegressionReport.dropped_features`. A constant target, linearly
  dependent features or too few samples raise :class:`DatasetError`;
* the MAPE is taken only over samples whose observed angle is at least
  ``mape_threshold`` in magnitude (default 1°): at zero pressure the angle is
  (close to) 0° and the percentage error is undefined or explodes. The number
  of samples left out is reported (:func:`thresholded_mape`).
"""

from __future__ import annotations

import logging
import warnings
from collections.abc import Sequence
from dataclasses import dataclass
from typing import Any

import numpy as np
import pandas as pd

from softbend._validation import check_range, must_be
from softbend.analysis.ols import CoefficientTests, ZScoredFit, coefficient_tests, fit_zscored
from softbend.analysis.samples import DEFAULT_FEATURES, DEFAULT_TARGET, clean_samples, is_constant
from softbend.errors import DatasetError, InputError
from softbend.metrics import thresholded_mape

__all__ = ["ConstantFeatureWarning", "RegressionReport", "standardized_regression"]

logger = logging.getLogger(__name__)


class ConstantFeatureWarning(UserWarning):
    """A regression feature is constant in the data and was left out."""


@dataclass(frozen=True, eq=False)
class RegressionReport:
    """Result of :func:`standardized_regression`.

    Attributes
    ----------
    coefficients : pandas.DataFrame
        One row per feature used (index ``feature``, in the order given) with
        columns ``loading`` (standardized coefficient), ``std_error``,
        ``t_value``, ``p_value`` (two-sided t-test of a zero coefficient),
        ``stars`` (:func:`significance_stars`) and ``coef_raw`` (slope in
        target units per feature unit, e.g. degrees per MPa).
    target : str
        Name of the target column.
    n_samples : int
        Samples used in the fit.
    n_rows_excluded : int
        Rows of the input table left out (non-converged or incomplete).
    dropped_features : tuple of str
        Features left out because they are constant in the data.
    r2, adj_r2 : float
        Coefficient of determination and its adjusted value.
    f_value, f_pvalue : float
        Overall F-statistic (all slopes zero) and its p-value.
    df_model, df_resid : int
        Degrees of freedom of the model (number of features) and residuals.
    intercept_raw : float
        Intercept of the equivalent regression on raw variables (target units).
    mape_pct : float
        MAPE of the fitted target in original units, percent, over samples
        with ``|observed| >= mape_threshold`` (NaN if none).
    mape_threshold : float
        The threshold used, in target units (degrees for ``angle_deg``).
    n_mape_excluded : int
        Samples left out of the MAPE by the threshold.
    rmse : float
        Root-mean-square error of the fitted target, target units.
    fitted, observed : numpy.ndarray
        Fitted and observed target of every sample used, original units
        (read-only).
    """

    coefficients: pd.DataFrame
    target: str
    n_samples: int
    n_rows_excluded: int
    dropped_features: tuple[str, ...]
    r2: float
    adj_r2: float
    f_value: float
    f_pvalue: float
    df_model: int
    df_resid: int
    intercept_raw: float
    mape_pct: float
    mape_threshold: float
    n_mape_excluded: int
    rmse: float
    fitted: np.ndarray
    observed: np.ndarray

    @property
    def features(self) -> tuple[str, ...]:
        """Features used in the fit, in order."""
        return tuple(self.coefficients.index)

    def to_dict(self, *, include_samples: bool = False) -> dict[str, Any]:
        """JSON-ready summary: plain floats, ints, strings and lists.

        Parameters
        ----------
        include_samples : bool, default False
            Also include the ``fitted`` and ``observed`` arrays as lists.
        """
        rows = []
        for feature, row in self.coefficients.iterrows():
            rows.append(
                {
                    "feature": str(feature),
                    "loading": float(row["loading"]),
                    "std_error": float(row["std_error"]),
                    "t_value": float(row["t_value"]),
                    "p_value": float(row["p_value"]),
                    "stars": str(row["stars"]),
                    "coef_raw": float(row["coef_raw"]),
                }
            )
        out: dict[str, Any] = {
            "target": self.target,
            "features": list(self.features),
            "dropped_features": list(self.dropped_features),
            "n_samples": int(self.n_samples),
            "n_rows_excluded": int(self.n_rows_excluded),
            "coefficients": rows,
            "intercept_raw": float(self.intercept_raw),
            "r2": float(self.r2),
            "adj_r2": float(self.adj_r2),
            "f_value": float(self.f_value),
            "f_pvalue": float(self.f_pvalue),
            "df_model": int(self.df_model),
            "df_resid": int(self.df_resid),
            "mape_pct": float(self.mape_pct),
            "mape_threshold": float(self.mape_threshold),
            "n_mape_excluded": int(self.n_mape_excluded),
            "rmse": float(self.rmse),
        }
        if include_samples:
            out["fitted"] = self.fitted.tolist()
            out["observed"] = self.observed.tolist()
        return out


def standardized_regression(
    df: pd.DataFrame,
    features: Sequence[str] = DEFAULT_FEATURES,
    target: str = DEFAULT_TARGET,
    *,
    mape_threshold: float = 1.0,
) -> RegressionReport:
    """Multiple linear regression on z-scored variables (paper B Fig. 4b–c).

    Fits ``z(y) = Σ_j β*_j z(x_j) + β*_0`` by ordinary least squares
    (statsmodels), where ``z(v) = (v − mean v) / std v`` with the sample
    standard deviation. The standardized coefficients ("loadings")
    ``β*_j = β_j · std(x_j) / std(y)`` rank the inputs by influence on the
    angle independently of their units; the t-test of each is the t-test of
    the raw slope ``β_j``.

    Parameters
    ----------
    df : pandas.DataFrame
        Campaign samples with the feature and target columns (others are
        ignored). Rows with ``converged`` false (if present) or with NaN in a
        column used are left out.
    features : sequence of str, default :data:`DEFAULT_FEATURES`
        Input columns (design parameters in mm / degrees, pressure in MPa).
    target : str, default ``"angle_deg"``
        Output column (bending angle, degrees).
    mape_threshold : float, default 1.0
        Samples with ``|observed| < mape_threshold`` (target units, degrees)
        are left out of the MAPE; see :func:`thresholded_mape`.

    Returns
    -------
    RegressionReport

    Warns
    -----
    ConstantFeatureWarning
        For each feature constant in the data; it is left out of the fit.

    Raises
    ------
    DatasetError
        If a column is missing or not numeric, the target is constant, every
        feature is constant, the features are linearly dependent, or there are
        not more samples than parameters.
    ValueError
        If ``features`` is empty or repeats a name, or ``mape_threshold`` < 0.
    """
    features, mape_threshold = _check_arguments(features, target, mape_threshold)
    data, n_excluded = clean_samples(df, [*features, target])
    n = len(data)
    if n < 3:
        raise DatasetError(
            f"must hold at least 3 complete, converged samples; got {n} "
            f"({n_excluded} rows left out)",
            key="df",
        )
    used, dropped = _select_features(data, features, target)
    fit = fit_zscored(data, used, target)
    tests = coefficient_tests(fit)
    report = _build_report(
        used,
        target,
        data[target].to_numpy(),
        fit,
        tests,
        n_rows_excluded=n_excluded,
        dropped_features=tuple(dropped),
        mape_threshold=mape_threshold,
    )
    logger.info(
        "standardized regression: n=%d, R2=%.4f, F=%.4g, MAPE=%.3g %% (%d below %g left out)",
        n,
        tests.r2,
        tests.f_value,
        report.mape_pct,
        report.n_mape_excluded,
        mape_threshold,
    )
    return report


def _check_arguments(
    features: Sequence[str], target: str, mape_threshold: float
) -> tuple[list[str], float]:
    """The feature names as a list of str and the checked ``mape_threshold``."""
    features = [str(f) for f in features] if not isinstance(features, str) else [features]
    if not features:
        raise InputError(must_be("at least one column name", features), key="features")
    if len(set(features)) != len(features):
        raise InputError(must_be("distinct column names", features), key="features")
    if target in features:
        raise InputError(f"must not be one of the features; got {target!r}", key="target")
    mape_threshold = check_range(mape_threshold, "mape_threshold", low=0.0, low_inclusive=True)
    return features, mape_threshold


def _select_features(
    data: pd.DataFrame, features: list[str], target: str
) -> tuple[list[str], list[str]]:
    """Split ``features`` into those used and those constant in ``data`` (warned about).

    Raises :class:`DatasetError` if the target or every feature is constant, or if
    there are not more samples than parameters.
    """
    n = len(data)
    y = data[target].to_numpy()
    if is_constant(y):
        raise DatasetError(
            f"must not be constant over the samples; got {target!r}, constant ({y[0]:g}) over "
            f"the {n} samples: there is nothing to explain",
            key="target",
        )
    used: list[str] = []
    dropped: list[str] = []
    for name in features:
        if is_constant(data[name].to_numpy()):
            dropped.append(name)
            warnings.warn(
                f"Feature {name!r} is constant ({data[name].iloc[0]:g}) in the data and was "
                "left out of the regression.",
                ConstantFeatureWarning,
                stacklevel=3,  # the caller of standardized_regression
            )
        else:
            used.append(name)
    if not used:
        raise DatasetError(
            f"must not all be constant in the data; got every feature constant "
            f"({', '.join(features)})",
            key="features",
        )
    p = len(used)
    if n <= p + 1:
        raise DatasetError(
            f"must hold more samples than parameters; got {n} samples for {p} features "
            "plus an intercept",
            key="df",
        )
    return used, dropped


def _build_report(
    features: list[str],
    target: str,
    y: np.ndarray,
    fit: ZScoredFit,
    tests: CoefficientTests,
    *,
    n_rows_excluded: int,
    dropped_features: tuple[str, ...],
    mape_threshold: float,
) -> RegressionReport:
    """Gather the fit, its tests and its errors in target units into a report."""
    observed = y.copy()
    observed.setflags(write=False)
    mape, n_mape_excluded = thresholded_mape(observed, fit.fitted, threshold=mape_threshold)
    rmse = float(np.sqrt(np.mean((fit.fitted - observed) ** 2)))
    coefficients = pd.DataFrame(
        {
            "loading": tests.loading,
            "std_error": tests.std_error,
            "t_value": tests.t_value,
            "p_value": tests.p_value,
            "stars": tests.stars,
            "coef_raw": fit.coef_raw,
        },
        index=pd.Index(features, name="feature"),
    )
    return RegressionReport(
        coefficients=coefficients,
        target=target,
        n_samples=len(observed),
        n_rows_excluded=n_rows_excluded,
        dropped_features=dropped_features,
        r2=tests.r2,
        adj_r2=tests.adj_r2,
        f_value=tests.f_value,
        f_pvalue=tests.f_pvalue,
        df_model=tests.df_model,
        df_resid=tests.df_resid,
        intercept_raw=fit.intercept_raw,
        mape_pct=mape,
        mape_threshold=mape_threshold,
        n_mape_excluded=n_mape_excluded,
        rmse=rmse,
        fitted=fit.fitted,
        observed=observed,
    )
