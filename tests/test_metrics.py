import math

import numpy as np
import pytest
from sklearn.metrics import mean_squared_error, r2_score

from softbend.errors import DatasetError
from softbend.metrics import (
    fit_percent,
    nrmse,
    r2,
    regression_metrics,
    rmse,
    thresholded_mape,
)

ALL = (rmse, nrmse, r2, fit_percent, regression_metrics)


def test_perfect_prediction_gives_the_ideal_values():
    y = np.array([0.1, 0.4, 0.3, 0.9, -0.2])
    assert regression_metrics(y, y.copy()) == {
        "rmse": 0.0,
        "nrmse": 0.0,
        "r2": 1.0,
        "fit_percent": 100.0,
    }


def test_predicting_the_mean_gives_zero_r2_and_zero_fit():
    y = np.array([1.0, 3.0, 2.0, 6.0])
    mean = np.full_like(y, y.mean())
    assert r2(y, mean) == pytest.approx(0.0, abs=1e-15)
    assert fit_percent(y, mean) == pytest.approx(0.0, abs=1e-13)
    assert rmse(y, mean) == pytest.approx(y.std())


def test_hand_computed_values():
    # errors (0, 0, 0, 2): SSE 4, mean 1.5 so SST = 2.25 + 0.25 + 0.25 + 2.25 = 5, range 3.
    y, y_hat = [0.0, 1.0, 2.0, 3.0], [0.0, 1.0, 2.0, 5.0]
    assert rmse(y, y_hat) == pytest.approx(1.0)
    assert nrmse(y, y_hat) == pytest.approx(1.0 / 3.0)
    assert r2(y, y_hat) == pytest.approx(0.2)
    assert fit_percent(y, y_hat) == pytest.approx(100.0 * (1.0 - math.sqrt(0.8)))


def test_agrees_with_scikit_learn_and_fit_relates_to_r2():
    rng = np.random.default_rng(3)
    y = rng.normal(size=200)
    y_hat = y + 0.3 * rng.normal(size=200)
    assert rmse(y, y_hat) == pytest.approx(math.sqrt(mean_squared_error(y, y_hat)), rel=1e-12)
    assert r2(y, y_hat) == pytest.approx(r2_score(y, y_hat), rel=1e-12)
    assert fit_percent(y, y_hat) == pytest.approx(100 * (1 - math.sqrt(1 - r2(y, y_hat))))


def test_nrmse_is_unit_free_and_rmse_carries_the_unit():
    rng = np.random.default_rng(4)
    y = rng.normal(size=50)
    y_hat = y + 0.1 * rng.normal(size=50)
    assert nrmse(1000 * y, 1000 * y_hat) == pytest.approx(nrmse(y, y_hat), rel=1e-12)
    assert rmse(1000 * y, 1000 * y_hat) == pytest.approx(1000 * rmse(y, y_hat), rel=1e-12)
    assert nrmse(y, y_hat) == pytest.approx(rmse(y, y_hat) / (y.max() - y.min()))


def test_a_diverged_prediction_is_reported_not_hidden():
    y = np.array([0.0, 1.0, 2.0, 3.0])
    with_nan = np.array([0.0, 1.0, np.nan, np.nan])
    values = regression_metrics(y, with_nan)
    assert all(math.isnan(v) for v in values.values())
    with_inf = np.array([0.0, 1.0, 2.0, np.inf])
    assert rmse(y, with_inf) == math.inf
    assert nrmse(y, with_inf) == math.inf
    assert r2(y, with_inf) == -math.inf
    assert fit_percent(y, with_inf) == -math.inf
    huge = np.array([0.0, 1.0, 2.0, 1e300])
    assert rmse(y, huge) == math.inf


def test_constant_measurement_makes_normalized_metrics_nan():
    y = np.full(5, 0.1)
    for y_hat in (y.copy(), y + 0.5):
        assert math.isnan(nrmse(y, y_hat))
        assert math.isnan(r2(y, y_hat))
        assert math.isnan(fit_percent(y, y_hat))
    assert rmse(y, y + 0.5) == pytest.approx(0.5)
    assert rmse(y, y) == 0.0


def test_column_vectors_are_accepted():
    y = np.array([[0.0], [1.0], [3.0]])
    assert rmse(y, y.ravel()) == 0.0


@pytest.mark.parametrize("metric", ALL)
def test_mismatched_lengths_name_y_hat(metric):
    with pytest.raises(ValueError, match=r"^y_hat: must have the length of 'y' \(3\); got 2"):
        metric([1.0, 2.0, 3.0], [1.0, 2.0])


@pytest.mark.parametrize("metric", ALL)
@pytest.mark.parametrize(
    ("y", "y_hat", "field"),
    [
        (np.zeros((3, 2)), np.zeros(3), "y"),
        (np.zeros(3), np.zeros((3, 2)), "y_hat"),
        ([], [], "y"),
        (1.0, 1.0, "y"),
        (["a", "b"], [1.0, 2.0], "y"),
    ],
)
def test_bad_shapes_raise_value_error_naming_the_field(metric, y, y_hat, field):
    with pytest.raises(ValueError, match=rf"^{field}: must be") as info:
        metric(y, y_hat)
    assert info.value.key == field


@pytest.mark.parametrize("metric", ALL)
def test_non_finite_measurement_is_a_dataset_error(metric):
    with pytest.raises(DatasetError, match=r"^y: must be finite"):
        metric([1.0, np.nan, 3.0], [1.0, 2.0, 3.0])


def test_thresholded_mape_rule():
    observed = np.array([0.0, 0.5, -0.99, 2.0, -4.0, 10.0])
    predicted = np.array([3.0, 1.0, 0.0, 2.2, -3.0, 10.0])
    mape, excluded = thresholded_mape(observed, predicted, threshold=1.0)
    # Kept: 2.0 (10 %), -4.0 (25 %), 10.0 (0 %).
    assert excluded == 3
    assert mape == pytest.approx((10.0 + 25.0 + 0.0) / 3.0)
    # Threshold 0 keeps everything except exact zeros.
    mape0, excluded0 = thresholded_mape(observed, predicted, threshold=0.0)
    assert excluded0 == 1
    assert mape0 == pytest.approx((100.0 + 100.0 + 10.0 + 25.0 + 0.0) / 5.0)
    # A threshold above every value gives NaN, not an error.
    nan_mape, all_out = thresholded_mape(observed, predicted, threshold=100.0)
    assert math.isnan(nan_mape) and all_out == 6
    with pytest.raises(ValueError, match=r"^threshold: must be a number in \[0, inf\)"):
        thresholded_mape(observed, predicted, threshold=-0.1)
    with pytest.raises(ValueError, match=r"^predicted: must have the shape of 'observed'"):
        thresholded_mape(observed, predicted[:3])
    with pytest.raises(DatasetError, match=r"^predicted: must be finite"):
        thresholded_mape(observed, np.full(6, np.nan))
