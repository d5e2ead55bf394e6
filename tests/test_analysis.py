"""Tests of the preliminary analysis (paper B §3.3, Fig. 4) and its figures."""

from __future__ import annotations

import json
import math
import warnings

import numpy as np
import pandas as pd
import pytest
import statsmodels.api as sm

from softbend.analysis import (
    DEFAULT_FEATURES,
    DEFAULT_TARGET,
    CampaignAnalysis,
    ConstantFeatureWarning,
    RegressionReport,
    analyze_samples,
    correlation_matrix,
    significance_stars,
    standardized_regression,
    thresholded_mape,
)
from softbend.errors import DatasetError
from softbend.reports.analysis_figures import (
    campaign_analysis_figures,
    column_label,
    correlation_heatmap,
    loadings_bar,
    parity_plot,
)

PNG_MAGIC = b"\x89PNG\r\n\x1a\n"


def _linear_frame(n: int = 400, noise: float = 0.0, seed: int = 0) -> pd.DataFrame:
    """y = 3 x1 − 2 x2 + 5 with x1, x2 of different scales, plus optional noise."""
    rng = np.random.default_rng(seed)
    x1 = rng.normal(10.0, 2.0, n)
    x2 = rng.uniform(0.0, 0.5, n)
    y = 3.0 * x1 - 2.0 * x2 + 5.0 + noise * rng.standard_normal(n)
    return pd.DataFrame({"x1": x1, "x2": x2, "y": y, "other": rng.normal(size=n)})


def _campaign_like_frame(seed: int = 1) -> pd.DataFrame:
    """Samples with the campaign columns: angle rises with pressure, falls with t."""
    rng = np.random.default_rng(seed)
    rows = []
    for l_mm in (100.0, 140.0):
        for t_mm in (2.0, 3.0, 4.0):
            for phi in (5.0, 15.0):
                for p in np.linspace(0.0, 0.2, 11):
                    angle = 1500.0 * p * (l_mm / 100.0) / t_mm**1.5 + rng.normal(0.0, 0.5)
                    rows.append(
                        {
                            "design_id": f"{l_mm}-{t_mm}-{phi}",
                            "l_mm": l_mm,
                            "r_mm": 6.0 + rng.integers(0, 3) * 2.0,
                            "t_mm": t_mm,
                            "b_mm": 2.0 + rng.integers(0, 3),
                            "phi_deg": phi,
                            "lc_mm": 8.0 + rng.integers(0, 3) * 2.0,
                            "pressure_mpa": p,
                            "angle_deg": angle,
                            "converged": True,
                        }
                    )
    return pd.DataFrame(rows)


# ----------------------------------------------------------------------------- regression


def test_loadings_equal_slope_times_std_ratio_without_noise():
    df = _linear_frame(noise=0.0)
    report = standardized_regression(df, ["x1", "x2"], "y")
    sx = df[["x1", "x2"]].std(ddof=1).to_numpy()
    sy = df["y"].std(ddof=1)
    expected = np.array([3.0, -2.0]) * sx / sy
    np.testing.assert_allclose(report.coefficients["loading"].to_numpy(), expected, atol=1e-8)
    np.testing.assert_allclose(report.coefficients["coef_raw"].to_numpy(), [3.0, -2.0], atol=1e-8)
    assert report.intercept_raw == pytest.approx(5.0, abs=1e-7)
    assert report.r2 == pytest.approx(1.0, abs=1e-12)
    np.testing.assert_allclose(report.fitted, df["y"].to_numpy(), atol=1e-8)
    assert report.mape_pct == pytest.approx(0.0, abs=1e-8)
    assert report.rmse == pytest.approx(0.0, abs=1e-8)


def test_t_p_r2_f_match_statsmodels_on_raw_variables():
    df = _linear_frame(noise=4.0, seed=3)
    report = standardized_regression(df, ["x1", "x2"], "y")
    raw = sm.OLS(df["y"].to_numpy(), sm.add_constant(df[["x1", "x2"]].to_numpy())).fit()
    # t-statistics and p-values are invariant under standardization.
    np.testing.assert_allclose(report.coefficients["t_value"], raw.tvalues[1:], rtol=1e-9)
    np.testing.assert_allclose(report.coefficients["p_value"], raw.pvalues[1:], rtol=1e-6)
    np.testing.assert_allclose(report.coefficients["coef_raw"], raw.params[1:], rtol=1e-9)
    assert report.intercept_raw == pytest.approx(raw.params[0], rel=1e-9)
    assert report.r2 == pytest.approx(raw.rsquared, rel=1e-12)
    assert report.adj_r2 == pytest.approx(raw.rsquared_adj, rel=1e-12)
    assert report.f_value == pytest.approx(raw.fvalue, rel=1e-9)
    assert report.df_model == 2 and report.df_resid == len(df) - 3
    np.testing.assert_allclose(report.fitted, raw.fittedvalues, rtol=1e-10, atol=1e-10)
    # Standard error of a standardized slope = raw standard error · std(x) / std(y).
    scale = df[["x1", "x2"]].std(ddof=1).to_numpy() / df["y"].std(ddof=1)
    np.testing.assert_allclose(report.coefficients["std_error"], raw.bse[1:] * scale, rtol=1e-9)
    # x1 (signal std 6 against noise std 4) is clearly significant; the stars follow p.
    assert report.coefficients.loc["x1", "stars"] == "***"
    assert list(report.coefficients["stars"]) == [significance_stars(p) for p in raw.pvalues[1:]]
    assert 0.5 < report.r2 < 0.95


def test_irrelevant_feature_is_not_significant_and_pure_noise_has_no_fit():
    rng = np.random.default_rng(7)
    n = 300
    df = pd.DataFrame({"a": rng.normal(size=n), "junk": rng.normal(size=n)})
    df["y"] = 2.0 * df["a"] + rng.normal(size=n)
    report = standardized_regression(df, ["a", "junk"], "y")
    assert report.coefficients.loc["a", "stars"] == "***"
    assert report.coefficients.loc["junk", "p_value"] > 0.01
    noise = pd.DataFrame({"a": rng.normal(size=n), "y": rng.normal(size=n)})
    flat = standardized_regression(noise, ["a"], "y")
    assert flat.r2 < 0.05 and flat.f_pvalue > 0.001


def test_loadings_are_unit_free():
    df = _linear_frame(noise=1.0, seed=4)
    scaled = df.assign(x1=df["x1"] * 1000.0, x2=df["x2"] - 7.0, y=df["y"] * 0.01)
    a = standardized_regression(df, ["x1", "x2"], "y")
    b = standardized_regression(scaled, ["x1", "x2"], "y")
    np.testing.assert_allclose(a.coefficients["loading"], b.coefficients["loading"], rtol=1e-9)
    np.testing.assert_allclose(a.coefficients["t_value"], b.coefficients["t_value"], rtol=1e-9)


def test_single_feature_loading_is_pearson_r():
    df = _linear_frame(noise=3.0, seed=5)
    report = standardized_regression(df, ["x1"], "y")
    r = np.corrcoef(df["x1"], df["y"])[0, 1]
    assert report.coefficients.loc["x1", "loading"] == pytest.approx(r, rel=1e-10)
    assert report.r2 == pytest.approx(r**2, rel=1e-10)


def test_campaign_columns_by_default_and_physical_signs():
    df = _campaign_like_frame()
    report = standardized_regression(df)
    assert report.features == DEFAULT_FEATURES
    loadings = report.coefficients["loading"]
    assert loadings.abs().idxmax() == "pressure_mpa"
    assert loadings["pressure_mpa"] > 0 and loadings["t_mm"] < 0 and loadings["l_mm"] > 0
    # The angle is not linear in the inputs: the fit is good but not exact.
    assert 0.6 < report.r2 < 0.99
    # The zero-pressure angles (|θ| < 1°) are left out of the MAPE.
    zero_p = int((df["angle_deg"].abs() < 1.0).sum())
    assert report.n_mape_excluded == zero_p > 0
    assert math.isfinite(report.mape_pct) and report.mape_pct > 0


def test_non_converged_and_nan_rows_are_left_out():
    df = _campaign_like_frame()
    full = standardized_regression(df)
    extra = df.iloc[:5].copy()
    extra["angle_deg"] = 1e6  # would dominate the fit if it were used
    extra["converged"] = False
    nan_row = df.iloc[:3].copy()
    nan_row["angle_deg"] = np.nan
    dirty = pd.concat([df, extra, nan_row], ignore_index=True)
    report = standardized_regression(dirty)
    assert report.n_samples == len(df)
    assert report.n_rows_excluded == 8
    np.testing.assert_allclose(report.coefficients["loading"], full.coefficients["loading"])


def test_constant_feature_is_dropped_with_warning():
    df = _linear_frame(noise=1.0).assign(const=2.5)
    with pytest.warns(ConstantFeatureWarning, match="const"):
        report = standardized_regression(df, ["x1", "const", "x2"], "y")
    assert report.features == ("x1", "x2")
    assert report.dropped_features == ("const",)
    assert report.df_model == 2


def test_bad_inputs_raise_clear_errors():
    df = _linear_frame(noise=1.0)
    with pytest.raises(DatasetError, match=r"^df: the samples lack the column.*'missing_col'"):
        standardized_regression(df, ["x1", "missing_col"], "y")
    with pytest.raises(DatasetError, match=r"^df: .*'angle_deg'"):
        standardized_regression(df, ["x1"])
    with pytest.raises(DatasetError, match=r"^target: must not be constant"):
        standardized_regression(df.assign(y=1.0), ["x1"], "y")
    with (
        pytest.raises(DatasetError, match=r"^features: must not all be constant"),
        warnings.catch_warnings(),
    ):
        warnings.simplefilter("ignore", ConstantFeatureWarning)
        standardized_regression(df.assign(c=1.0), ["c"], "y")
    with pytest.raises(DatasetError, match=r"^features: must not be linearly dependent"):
        standardized_regression(df.assign(x3=2.0 * df["x1"] + df["x2"]), ["x1", "x2", "x3"], "y")
    with pytest.raises(DatasetError, match=r"^df: must hold more samples than parameters"):
        standardized_regression(df.iloc[:3], ["x1", "x2"], "y")
    with pytest.raises(DatasetError, match=r"^df: .*must be numeric"):
        standardized_regression(df.assign(x1="a"), ["x1"], "y")
    with pytest.raises(ValueError, match=r"^mape_threshold: .*got -1"):
        standardized_regression(df, ["x1"], "y", mape_threshold=-1)
    with pytest.raises(ValueError, match=r"^features: must be distinct"):
        standardized_regression(df, ["x1", "x1"], "y")
    with pytest.raises(ValueError, match=r"^target: must not be one of the features"):
        standardized_regression(df, ["x1", "y"], "y")
    with pytest.raises(DatasetError, match=r"^df: the 'converged' column must hold booleans"):
        standardized_regression(df.assign(converged="yes"), ["x1"], "y")
    with pytest.raises(DatasetError, match=r"^df: must be a pandas DataFrame"):
        standardized_regression(df.to_numpy(), ["x1"], "y")


def test_report_is_frozen_read_only_and_json_ready():
    report = standardized_regression(_linear_frame(noise=1.0), ["x1", "x2"], "y")
    assert isinstance(report, RegressionReport)
    with pytest.raises(AttributeError):
        report.r2 = 0.0
    with pytest.raises(ValueError):
        report.fitted[0] = 0.0
    payload = report.to_dict()
    text = json.dumps(payload)
    back = json.loads(text)
    assert [row["feature"] for row in back["coefficients"]] == ["x1", "x2"]
    assert back["r2"] == report.r2 and back["n_samples"] == 400
    assert "fitted" not in back
    assert len(report.to_dict(include_samples=True)["fitted"]) == 400


# ----------------------------------------------------------------------------- MAPE, stars


def test_regression_mape_uses_the_threshold():
    df = _campaign_like_frame()
    report = standardized_regression(df, mape_threshold=5.0)
    mape, excluded = thresholded_mape(report.observed, report.fitted, threshold=5.0)
    assert report.mape_pct == pytest.approx(mape)
    assert report.n_mape_excluded == excluded == int((report.observed.__abs__() < 5.0).sum())
    assert report.mape_threshold == 5.0


@pytest.mark.parametrize(
    ("p", "stars"),
    [(1e-9, "***"), (0.001, "***"), (0.005, "**"), (0.01, "**"), (0.03, "*"), (0.05, "*"),
     (0.051, ""), (0.9, ""), (float("nan"), "")],
)  # fmt: skip
def test_significance_stars_follow_paper_b(p, stars):
    assert significance_stars(p) == stars


# ----------------------------------------------------------------------------- correlation


def test_correlation_matrix_matches_numpy():
    df = _campaign_like_frame()
    corr = correlation_matrix(df)
    cols = [*DEFAULT_FEATURES, "angle_deg"]
    assert list(corr.index) == cols and list(corr.columns) == cols
    np.testing.assert_allclose(corr.to_numpy(), corr.to_numpy().T, atol=1e-15)
    np.testing.assert_allclose(np.diag(corr.to_numpy()), 1.0)
    np.testing.assert_allclose(corr.to_numpy(), np.corrcoef(df[cols].to_numpy().T), atol=1e-12)
    assert np.all(np.abs(corr.to_numpy()) <= 1.0)
    # Angle rises with pressure and falls with wall thickness.
    assert corr.loc["pressure_mpa", "angle_deg"] > 0.5
    assert corr.loc["t_mm", "angle_deg"] < 0


def test_correlation_matrix_subset_exact_linear_and_constant():
    df = _linear_frame().assign(neg=lambda d: -4.0 * d["x1"] + 1.0, flat=3.0)
    corr = correlation_matrix(df, ["x1", "neg", "flat"])
    assert corr.loc["x1", "neg"] == pytest.approx(-1.0, abs=1e-12)
    assert corr.loc["neg", "x1"] == pytest.approx(-1.0, abs=1e-12)
    assert corr["flat"].isna().all() and corr.loc["flat"].isna().all()
    assert corr.loc["x1", "x1"] == 1.0


def test_correlation_matrix_bad_input():
    df = _linear_frame()
    with pytest.raises(DatasetError, match=r"^df: .*'nope'"):
        correlation_matrix(df, ["x1", "nope"])
    with pytest.raises(DatasetError, match=r"^df: must be at least 2"):
        correlation_matrix(df.iloc[:1], ["x1", "x2"])
    with pytest.raises(DatasetError, match="pressure_mpa"):
        correlation_matrix(df)


# ----------------------------------------------------------------------------- both at once


def test_analyze_samples_equals_the_separate_analyses():
    df = _campaign_like_frame()
    result = analyze_samples(df, mape_threshold=2.0)
    assert isinstance(result, CampaignAnalysis)
    report = standardized_regression(df, mape_threshold=2.0)
    assert result.regression.to_dict(include_samples=True) == report.to_dict(include_samples=True)
    pd.testing.assert_frame_equal(
        result.correlation, correlation_matrix(df, [*DEFAULT_FEATURES, DEFAULT_TARGET])
    )


def test_analyze_samples_with_chosen_columns():
    df = _linear_frame(noise=0.1)
    result = analyze_samples(df, ["x1", "x2"], "y")
    assert result.regression.features == ("x1", "x2") and result.regression.target == "y"
    assert list(result.correlation.columns) == ["x1", "x2", "y"]
    np.testing.assert_array_equal(
        result.correlation.to_numpy(), correlation_matrix(df, ["x1", "x2", "y"]).to_numpy()
    )


def test_analysis_to_dict_is_the_report_plus_correlations_and_round_trips_json():
    df = _campaign_like_frame().assign(b_mm=3.0)  # a constant column: NaN correlations
    with pytest.warns(ConstantFeatureWarning, match="b_mm"):
        result = analyze_samples(df)
    out = result.to_dict()
    assert list(out) == [*result.regression.to_dict(), "correlation"]
    assert {k: v for k, v in out.items() if k != "correlation"} == result.regression.to_dict()
    corr = out["correlation"]
    assert list(corr) == [*DEFAULT_FEATURES, DEFAULT_TARGET]
    assert corr["pressure_mpa"]["angle_deg"] == float(
        result.correlation.loc["pressure_mpa", "angle_deg"]
    )
    assert math.isnan(corr["b_mm"]["b_mm"])
    back = json.loads(json.dumps(out))
    assert back["coefficients"] == out["coefficients"]
    np.testing.assert_equal(back["correlation"], corr)  # NaN as NaN
    assert "fitted" in result.to_dict(include_samples=True)


def test_analyze_samples_rejects_empty_and_bad_samples():
    with pytest.raises(DatasetError, match=r"^samples: must hold rows"):
        analyze_samples(_campaign_like_frame().iloc[:0])
    with pytest.raises(DatasetError, match=r"^samples: the samples lack the column"):
        analyze_samples(_linear_frame())
    with pytest.raises(ValueError, match=r"^mape_threshold: "):
        analyze_samples(_campaign_like_frame(), mape_threshold=-1.0)


def test_campaign_analysis_figures_writes_three_named_pngs(tmp_path):
    result = analyze_samples(_campaign_like_frame())
    paths = campaign_analysis_figures(
        result,
        tmp_path / "new",
        correlation_png="a.png",
        loadings_png="b.png",
        parity_png="c.png",
    )
    assert paths == {
        "correlation": tmp_path / "new" / "a.png",
        "loadings": tmp_path / "new" / "b.png",
        "parity": tmp_path / "new" / "c.png",
    }
    assert all(_is_png(path) for path in paths.values())
    assert sorted(p.name for p in (tmp_path / "new").iterdir()) == ["a.png", "b.png", "c.png"]


# ----------------------------------------------------------------------------- figures


def _is_png(path) -> bool:
    data = path.read_bytes()
    return len(data) > 1000 and data.startswith(PNG_MAGIC)


def test_figures_are_written_as_png(tmp_path):
    df = _campaign_like_frame()
    report = standardized_regression(df)
    corr = correlation_matrix(df)
    heat = correlation_heatmap(corr, tmp_path / "sub" / "corr.png")
    bars = loadings_bar(report, tmp_path / "loadings.png")
    bars_sorted = loadings_bar(report, tmp_path / "loadings_sorted.png", sort=True)
    parity = parity_plot(report, tmp_path / "parity.png")
    for path in (heat, bars, bars_sorted, parity):
        assert path.exists() and _is_png(path)
    assert heat == tmp_path / "sub" / "corr.png"


def test_heatmap_handles_nan_cells_and_rejects_non_square(tmp_path):
    corr = correlation_matrix(_linear_frame().assign(flat=1.0), ["x1", "x2", "flat", "y"])
    assert _is_png(correlation_heatmap(corr, tmp_path / "nan.png"))
    with pytest.raises(ValueError, match="square"):
        correlation_heatmap(corr.iloc[:2], tmp_path / "bad.png")


def test_column_labels_carry_units():
    assert column_label("pressure_mpa") == "P_act (MPa)"
    assert column_label("angle_deg") == "θ (°)"
    assert column_label("t_mm") == "t (mm)"
    assert column_label("custom") == "custom"
