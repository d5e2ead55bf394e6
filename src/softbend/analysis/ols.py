"""Least squares on z-scored variables and its t- and F-tests (paper B Fig. 4b–c).

* :func:`fit_zscored` — ordinary least squares (statsmodels) of the z-scored
  target on the z-scored features with an intercept, and the fit mapped back to
  the raw variables;
* :func:`coefficient_tests` — standard errors, t-statistics and two-sided
  p-values of the slopes, R², adjusted R² and the overall F-test;
* :func:`significance_stars` — the marks of paper B Fig. 4.

z-scores use the sample standard deviation (``ddof=1``). The intercept is kept
(zero for z-scored data), so the residual degrees of freedom are ``n - p - 1``
and the t-statistics, p-values, R² and F equal those of the same regression on
the raw variables (standardization only rescales each slope).
"""

from __future__ import annotations

import math
from collections.abc import Sequence
from dataclasses import dataclass
from typing import Any

import numpy as np
import pandas as pd

from softbend.errors import DatasetError

__all__ = [
    "CoefficientTests",
    "ZScoredFit",
    "coefficient_tests",
    "fit_zscored",
    "significance_stars",
]


def significance_stars(p_value: float) -> str:
    """Significance marks of paper B Fig. 4.

    ``"***"`` for p ≤ 0.001, ``"**"`` for p ≤ 0.01, ``"*"`` for p ≤ 0.05 and
    ``""`` otherwise (also for NaN).
    """
    if p_value is None or not math.isfinite(p_value):
        return ""
    if p_value <= 0.001:
        return "***"
    if p_value <= 0.01:
        return "**"
    if p_value <= 0.05:
        return "*"
    return ""


@dataclass(frozen=True, eq=False)
class ZScoredFit:
    """An ordinary least-squares fit on z-scored variables (:func:`fit_zscored`).

    Attributes
    ----------
    result : statsmodels RegressionResults
        The fit of the z-scored target on the constant and the z-scored features.
    x_mean, x_std : numpy.ndarray
        Mean and sample standard deviation of each feature, feature units.
    y_mean, y_std : float
        Mean and sample standard deviation of the target, target units.
    coef_raw : numpy.ndarray
        Slopes of the equivalent regression on raw variables, target units per
        feature unit.
    intercept_raw : float
        Intercept of the equivalent regression on raw variables, target units.
    fitted : numpy.ndarray
        Fitted target of every sample, target units (read-only).
    """

    result: Any
    x_mean: np.ndarray
    x_std: np.ndarray
    y_mean: float
    y_std: float
    coef_raw: np.ndarray
    intercept_raw: float
    fitted: np.ndarray


def fit_zscored(data: pd.DataFrame, features: Sequence[str], target: str) -> ZScoredFit:
    """Fit ``z(y) = Σ_j β*_j z(x_j) + β*_0`` by ordinary least squares.

    Parameters
    ----------
    data : pandas.DataFrame
        Clean numeric samples (no NaN) holding ``features`` and ``target``.
    features : sequence of str
        Feature columns, none constant in ``data``.
    target : str
        Target column, not constant in ``data``.

    Returns
    -------
    ZScoredFit

    Raises
    ------
    DatasetError
        Keyed ``features``, if they are linearly dependent in the data.
    """
    import statsmodels.api as sm

    used = list(features)
    p = len(used)
    y = data[target].to_numpy()
    X = data[used].to_numpy()
    x_mean, x_std = X.mean(axis=0), X.std(axis=0, ddof=1)
    y_mean, y_std = float(y.mean()), float(y.std(ddof=1))
    Z = sm.add_constant((X - x_mean) / x_std, has_constant="add")
    zy = (y - y_mean) / y_std
    rank = int(np.linalg.matrix_rank(Z))
    if rank < p + 1:
        raise DatasetError(
            f"must not be linearly dependent in the data; got {', '.join(map(repr, used))} "
            f"(rank {rank} < {p + 1} with the intercept): drop one of the collinear columns",
            key="features",
        )
    with np.errstate(divide="ignore", invalid="ignore"):
        result = sm.OLS(zy, Z).fit()
        params = np.asarray(result.params)[1:]

    coef_raw = params * y_std / x_std
    intercept_raw = y_mean - float(coef_raw @ x_mean)
    fitted = np.asarray(result.fittedvalues) * y_std + y_mean
    fitted.setflags(write=False)
    return ZScoredFit(
        result=result,
        x_mean=x_mean,
        x_std=x_std,
        y_mean=y_mean,
        y_std=y_std,
        coef_raw=coef_raw,
        intercept_raw=intercept_raw,
        fitted=fitted,
    )


@dataclass(frozen=True, eq=False)
class CoefficientTests:
    """The tests of a :class:`ZScoredFit` (:func:`coefficient_tests`).

    Attributes
    ----------
    loading, std_error, t_value, p_value : numpy.ndarray
        Per slope (intercept left out): standardized coefficient, its standard
        error, t-statistic and two-sided p-value of a zero coefficient.
    stars : list of str
        :func:`significance_stars` of each p-value.
    r2, adj_r2 : float
        Coefficient of determination and its adjusted value.
    f_value, f_pvalue : float
        Overall F-statistic (all slopes zero) and its p-value.
    df_model, df_resid : int
        Degrees of freedom of the model and of the residuals.
    """

    loading: np.ndarray
    std_error: np.ndarray
    t_value: np.ndarray
    p_value: np.ndarray
    stars: list[str]
    r2: float
    adj_r2: float
    f_value: float
    f_pvalue: float
    df_model: int
    df_resid: int


def coefficient_tests(fit: ZScoredFit) -> CoefficientTests:
    """t-tests of the slopes, R² and the overall F-test of ``fit``.

    Parameters
    ----------
    fit : ZScoredFit
        From :func:`fit_zscored`.

    Returns
    -------
    CoefficientTests
        NaN where a statistic is undefined (e.g. a perfect fit).
    """
    result = fit.result
    with np.errstate(divide="ignore", invalid="ignore"):
        params = np.asarray(result.params)[1:]
        bse = np.asarray(result.bse)[1:]
        tvalues = np.asarray(result.tvalues)[1:]
        pvalues = np.asarray(result.pvalues)[1:]
        f_value = float(result.fvalue)
        f_pvalue = float(result.f_pvalue)
    return CoefficientTests(
        loading=params,
        std_error=bse,
        t_value=tvalues,
        p_value=pvalues,
        stars=[significance_stars(float(v)) for v in pvalues],
        r2=float(result.rsquared),
        adj_r2=float(result.rsquared_adj),
        f_value=f_value,
        f_pvalue=f_pvalue,
        df_model=round(result.df_model),
        df_resid=round(result.df_resid),
    )
