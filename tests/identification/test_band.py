"""The free-run band: closed-form quantiles, coverage, the cross-fitted check, bad input."""

from __future__ import annotations

import numpy as np
import pytest
from scipy import stats

from softbend.errors import InputError
from softbend.identification.band import (
    BAND_LEVEL,
    FreeRunBand,
    coverage,
    estimate_band,
    fold_coverage,
    free_run_residuals,
)

NAMES = ("x_mm", "y_mm")


def _gaussian(n: int, seed: int = 0) -> np.ndarray:
    """Residuals of two outputs: N(0, 1) and N(0.5, 2²), mm."""
    rng = np.random.default_rng(seed)
    return np.column_stack([rng.normal(0.0, 1.0, n), rng.normal(0.5, 2.0, n)])


def test_gaussian_residuals_give_the_gaussian_quantiles():
    band = estimate_band(_gaussian(200_000), NAMES)
    z = stats.norm.ppf(0.95)  # 1.645: the 5-95 % band of N(0, 1) is ±z
    np.testing.assert_allclose(band.low, [-z, 0.5 - 2 * z], atol=0.03)
    np.testing.assert_allclose(band.high, [z, 0.5 + 2 * z], atol=0.03)
    np.testing.assert_allclose(band.width(), [2 * z, 4 * z], rtol=0.01)
    assert band.level == BAND_LEVEL == 0.90 and band.n_residuals == 200_000


def test_the_band_covers_its_level_on_fresh_samples_of_the_same_law():
    band = estimate_band(_gaussian(50_000, seed=1), NAMES, level=0.8)
    np.testing.assert_allclose(coverage(band, _gaussian(50_000, seed=2)), [0.8, 0.8], atol=0.01)
    # a model whose free run is 3 standard deviations off: the band misses it
    shifted = _gaussian(10_000, seed=3) + np.array([3.0, 0.0])
    assert coverage(band, shifted)[0] < 0.2


def test_coverage_counts_the_samples_inside_bounds_included():
    band = FreeRunBand(0.5, ("y",), low=np.array([-1.0]), high=np.array([2.0]), n_residuals=4)
    residuals = np.array([-2.0, -1.0, 0.0, 2.0, 2.5])[:, None]
    assert coverage(band, residuals).tolist() == [3 / 5]


def test_residuals_leave_out_the_initial_conditions_and_bounds_have_no_width_there():
    measured = [np.arange(6.0).reshape(3, 2), np.ones((4, 2))]
    simulated = [np.zeros((3, 2)), np.zeros((4, 2))]
    r = free_run_residuals(measured, simulated, start=2)
    np.testing.assert_array_equal(r, [[4.0, 5.0], [1.0, 1.0], [1.0, 1.0]])
    band = FreeRunBand(
        0.9, NAMES, low=np.array([-1.0, -2.0]), high=np.array([1.0, 3.0]), n_residuals=3
    )
    low, high = band.bounds(np.zeros((4, 2)), start=2)
    np.testing.assert_array_equal(low, [[0, 0], [0, 0], [-1, -2], [-1, -2]])
    np.testing.assert_array_equal(high, [[0, 0], [0, 0], [1, 3], [1, 3]])


def test_fold_coverage_estimates_each_fold_without_it():
    # folds with the same law: the cross-fitted coverage is the level
    folds = [_gaussian(20_000, seed=s) for s in range(3)]
    cov, samples = fold_coverage(folds, NAMES)
    np.testing.assert_allclose(cov, [0.9, 0.9], atol=0.01)
    assert samples == 60_000
    # one fold much wider than the others: the band of the others misses much of it
    wide = [folds[0], folds[1], 10 * folds[2]]
    cov, _ = fold_coverage(wide, NAMES)
    assert (cov < 0.75).all()


def test_summary_and_json_state_the_level_and_the_coverage():
    band = estimate_band(_gaussian(1000), NAMES)
    assert "not checked" in band.summary()
    checked = FreeRunBand(
        0.9, NAMES, band.low, band.high, 1000, coverage=(0.88, 0.86),
        coverage_on="validation experiments", coverage_samples=500,
    )  # fmt: skip
    assert checked.summary().startswith("90 % free-run band covers 87 % of held-out samples")
    record = checked.to_dict()
    assert record["quantiles"] == pytest.approx([0.05, 0.95])
    assert record["coverage_mean"] == pytest.approx(0.87) and record["outputs"] == list(NAMES)


@pytest.mark.parametrize(
    ("call", "key"),
    [
        (lambda: estimate_band(_gaussian(10), NAMES, level=1.0), "level"),
        (lambda: estimate_band(_gaussian(10), NAMES, level=True), "level"),
        (lambda: estimate_band(np.zeros((0, 2)), NAMES), "residuals"),
        (lambda: estimate_band(_gaussian(10), ("x_mm",)), "residuals"),
        (lambda: estimate_band(np.full((3, 2), np.nan), NAMES), "residuals"),
        (lambda: free_run_residuals([np.zeros((3, 2))], []), "simulated"),
        (lambda: free_run_residuals([np.zeros((3, 2))], [np.zeros((2, 2))]), "simulated"),
        (lambda: free_run_residuals([np.zeros((3, 2))], [np.zeros((3, 2))], start=-1), "start"),
        (lambda: free_run_residuals([], []), "measured"),
        (lambda: fold_coverage([_gaussian(10)], NAMES), "residuals_by_fold"),
        (lambda: FreeRunBand(0.9, NAMES, np.ones(2), np.zeros(2), 1), "low"),
        (lambda: FreeRunBand(0.9, NAMES, np.zeros(3), np.ones(2), 1), "low"),
    ],
)
def test_bad_input_names_the_field(call, key):
    with pytest.raises(InputError) as error:
        call()
    assert error.value.key == key


def _arx_system(sigma: float, *, a: float = 0.8, n: int = 2000, k: int = 4, seed: int = 0):
    """``y(t) = a y(t-1) + 0.2 u(t-1) + e(t)``, e ~ N(0, σ²): an ARX system with equation noise."""
    from softbend.identification.timeseries import Series, TimeSeriesSet

    rng = np.random.default_rng(seed)
    experiments = []
    for i in range(k):
        u = np.repeat(rng.uniform(-1.0, 1.0, n // 20), 20)
        e = rng.normal(0.0, sigma, n)
        y = np.zeros(n)
        for t in range(1, n):
            y[t] = a * y[t - 1] + 0.2 * u[t - 1] + e[t]
        experiments.append(Series(f"e{i}", np.arange(n) * 0.01, u[:, None], y[:, None]))
    return TimeSeriesSet(("u",), ("y_mm",), tuple(experiments), "t_s")


@pytest.mark.parametrize("validate_on", [["e3"], None])
def test_the_selection_band_of_a_known_arx_system_is_its_free_run_noise(validate_on):
    """Run free, the true ARX model leaves r(t) = a r(t-1) + e(t): AR(1) noise of standard
    deviation σ/√(1 - a²), so the 90 % band is ±1.645 σ/√(1 - a²) and holds 90 % of
    held-out samples (on the validation experiment, or fold by fold without one)."""
    from softbend.identification.selection import Candidate, select_model

    sigma, a = 0.05, 0.8
    data = _arx_system(sigma, a=a)
    truth = Candidate("arx-1-2", "arx", 1, 2)  # y(t-1), u(t), u(t-1)
    selection = select_model(data, validate_on=validate_on, folds=3, candidates=[truth])
    band = selection.band
    half = stats.norm.ppf(0.95) * sigma / np.sqrt(1 - a**2)
    np.testing.assert_allclose([-band.low[0], band.high[0]], [half, half], rtol=0.1)
    assert band.coverage is not None and abs(band.coverage[0] - 0.9) < 0.03
    expected_on = "validation experiments" if validate_on else "cross-validation folds"
    assert band.coverage_on == expected_on
    trained = 3 if validate_on else 4  # experiments of 2000 samples, the first one given
    assert band.n_residuals == trained * 1999
    assert band.coverage_samples == (1999 if validate_on else band.n_residuals)
    record = selection.to_dict()
    assert record["band"]["coverage"] == list(band.coverage)
    assert record["seconds"] > 0 and (
        record["peak_memory_mib"] is None or record["peak_memory_mib"] > 0
    )
