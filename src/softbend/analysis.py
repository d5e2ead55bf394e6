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
  MAPE and RMSE of the fitted angle in degrees (Fig. 4c).

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
"""

from __future__ import annotations

import logging
import math
import warnings
from collections.abc import Sequence
from dataclasses import dataclass
from typing import Any

import numpy as np
import pandas as pd

from softbend._validation import check_range
from softbend.design import FEATURES
from softbend.errors import DatasetError
from softbend.metrics import thresholded_mape

__all__ = [
    "DEFAULT_FEATURES",
    "DEFAULT_TARGET",
    "ConstantFeatureWarning",
    "RegressionReport",
    "correlation_matrix",
    "significance_stars",
    "standardized_regression",
    "thresholded_mape",
]

logger = logging.getLogger(__name__)

#: Inputs of paper B's analysis: the design vector and the actuation pressure.
DEFAULT_FEATURES: tuple[str, ...] = FEATURES
#: Output of paper B's analysis: the bending angle in degrees.
DEFAULT_TARGET = "angle_deg"

_OWNER = "standardized_regression"


class ConstantFeatureWarning(UserWarning):
    """A regression feature is constant in the data and was left out."""


# ----------------------------------------------------------------------------- cleaning


def _clean(df: pd.DataFrame, columns: Sequence[str], owner: str) -> tuple[pd.DataFrame, int]:
    """Keep converged rows and drop rows with NaN in ``columns``.

    Returns the cleaned numeric table (only ``columns``, as float) and the
    number of rows removed.
    """
    if not isinstance(df, pd.DataFrame):
        raise DatasetError(
            f"The 'samples' of {owner} must be a pandas DataFrame. Got {type(df).__name__} instead."
        )
    columns = list(dict.fromkeys(columns))
    missing = [c for c in columns if c not in df.columns]
    if missing:
        raise DatasetError(
            f"The samples passed to {owner} lack the column(s) {', '.join(map(repr, missing))}; "
            f"present: {', '.join(map(repr, map(str, df.columns)))}."
        )
    n_rows = len(df)
    table = df
    if "converged" in df.columns:
        try:
            converged = df["converged"].astype("boolean").fillna(False).to_numpy(dtype=bool)
        except (TypeError, ValueError):
            raise DatasetError(
                f"The 'converged' column passed to {owner} must hold booleans. "
                f"Got dtype {df['converged'].dtype} instead."
            ) from None
        n_failed = int((~converged).sum())
        if n_failed:
            logger.info("%s: dropped %d non-converged rows", owner, n_failed)
        table = df.loc[converged]
    try:
        numeric = table[columns].apply(pd.to_numeric, errors="raise").astype(float)
    except (TypeError, ValueError) as exc:
        raise DatasetError(
            f"The columns {', '.join(map(repr, columns))} passed to {owner} must be numeric: {exc}"
        ) from None
    numeric = numeric.replace([np.inf, -np.inf], np.nan)
    complete = numeric.notna().all(axis=1)
    n_nan = int((~complete).sum())
    if n_nan:
        logger.info("%s: dropped %d rows with missing or infinite values", owner, n_nan)
    numeric = numeric.loc[complete].reset_index(drop=True)
    return numeric, n_rows - len(numeric)


def _is_constant(values: np.ndarray) -> bool:
    """True if the spread of ``values`` is at round-off level of their magnitude."""
    return float(np.ptp(values)) <= 1e-12 * max(float(np.max(np.abs(values))), 1.0)


# ----------------------------------------------------------------------------- correlation


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
        raise DatasetError("The 'columns' of correlation_matrix must name at least one column.")
    data, _ = _clean(df, cols, "correlation_matrix")
    if len(data) < 2:
        raise DatasetError(
            f"correlation_matrix needs at least 2 complete, converged rows. Got {len(data)}."
        )
    values = data[cols].to_numpy()
    centred = values - values.mean(axis=0)
    norms = np.sqrt((centred**2).sum(axis=0))
    with np.errstate(divide="ignore", invalid="ignore"):
        corr = (centred.T @ centred) / np.outer(norms, norms)
    corr = np.clip(corr, -1.0, 1.0)
    constant = np.array([_is_constant(values[:, j]) for j in range(len(cols))])
    corr[constant, :] = np.nan
    corr[:, constant] = np.nan
    diag = np.arange(len(cols))
    corr[diag[~constant], diag[~constant]] = 1.0
    return pd.DataFrame(corr, index=cols, columns=cols)


# ----------------------------------------------------------------------------- helpers


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


# ----------------------------------------------------------------------------- regression


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
    import statsmodels.api as sm

    features = [str(f) for f in features] if not isinstance(features, str) else [features]
    if not features:
        raise ValueError(
            f"The 'features' of {_OWNER} must name at least one column. Got [] instead."
        )
    if len(set(features)) != len(features):
        raise ValueError(
            f"The 'features' of {_OWNER} must be distinct column names. Got {features!r} instead."
        )
    if target in features:
        raise ValueError(
            f"The 'target' of {_OWNER} must not be one of the features. Got {target!r} instead."
        )
    mape_threshold = check_range(
        mape_threshold, "mape_threshold", _OWNER, low=0.0, low_inclusive=True
    )

    data, n_excluded = _clean(df, [*features, target], _OWNER)
    n = len(data)
    y = data[target].to_numpy()
    if n < 3:
        raise DatasetError(
            f"{_OWNER} needs at least 3 complete, converged samples. Got {n} "
            f"({n_excluded} rows left out)."
        )

    if _is_constant(y):
        raise DatasetError(
            f"The target {target!r} of {_OWNER} is constant ({y[0]:g}) over the {n} samples; "
            "there is nothing to explain."
        )
    used: list[str] = []
    dropped: list[str] = []
    for name in features:
        if _is_constant(data[name].to_numpy()):
            dropped.append(name)
            warnings.warn(
                f"Feature {name!r} is constant ({data[name].iloc[0]:g}) in the data and was "
                "left out of the regression.",
                ConstantFeatureWarning,
                stacklevel=2,
            )
        else:
            used.append(name)
    if not used:
        raise DatasetError(
            f"Every feature of {_OWNER} is constant in the data ({', '.join(features)})."
        )
    p = len(used)
    if n <= p + 1:
        raise DatasetError(
            f"{_OWNER} needs more samples than parameters: {n} samples for {p} features "
            "plus an intercept."
        )

    X = data[used].to_numpy()
    x_mean, x_std = X.mean(axis=0), X.std(axis=0, ddof=1)
    y_mean, y_std = float(y.mean()), float(y.std(ddof=1))
    Z = sm.add_constant((X - x_mean) / x_std, has_constant="add")
    zy = (y - y_mean) / y_std
    rank = int(np.linalg.matrix_rank(Z))
    if rank < p + 1:
        raise DatasetError(
            f"The features {', '.join(map(repr, used))} of {_OWNER} are linearly dependent "
            f"in the data (rank {rank} < {p + 1} with the intercept); drop one of the "
            "collinear columns."
        )

    with np.errstate(divide="ignore", invalid="ignore"):
        result = sm.OLS(zy, Z).fit()
        params = np.asarray(result.params)[1:]
        bse = np.asarray(result.bse)[1:]
        tvalues = np.asarray(result.tvalues)[1:]
        pvalues = np.asarray(result.pvalues)[1:]
        f_value = float(result.fvalue)
        f_pvalue = float(result.f_pvalue)

    coef_raw = params * y_std / x_std
    intercept_raw = y_mean - float(coef_raw @ x_mean)
    fitted = np.asarray(result.fittedvalues) * y_std + y_mean
    fitted.setflags(write=False)
    observed = y.copy()
    observed.setflags(write=False)
    mape, n_mape_excluded = thresholded_mape(observed, fitted, threshold=mape_threshold)
    rmse = float(np.sqrt(np.mean((fitted - observed) ** 2)))

    coefficients = pd.DataFrame(
        {
            "loading": params,
            "std_error": bse,
            "t_value": tvalues,
            "p_value": pvalues,
            "stars": [significance_stars(float(v)) for v in pvalues],
            "coef_raw": coef_raw,
        },
        index=pd.Index(used, name="feature"),
    )
    logger.info(
        "%s: n=%d, R2=%.4f, F=%.4g, MAPE=%.3g %% (%d below %g left out)",
        _OWNER,
        n,
        result.rsquared,
        f_value,
        mape,
        n_mape_excluded,
        mape_threshold,
    )
    return RegressionReport(
        coefficients=coefficients,
        target=target,
        n_samples=n,
        n_rows_excluded=n_excluded,
        dropped_features=tuple(dropped),
        r2=float(result.rsquared),
        adj_r2=float(result.rsquared_adj),
        f_value=f_value,
        f_pvalue=f_pvalue,
        df_model=round(result.df_model),
        df_resid=round(result.df_resid),
        intercept_raw=intercept_raw,
        mape_pct=mape,
        mape_threshold=mape_threshold,
        n_mape_excluded=n_mape_excluded,
        rmse=rmse,
        fitted=fitted,
        observed=observed,
    )
