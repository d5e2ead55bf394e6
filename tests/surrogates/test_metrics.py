import math

import numpy as np
import pytest

from softbend.surrogates.metrics import accuracy, inference_time


def test_perfect_prediction():
    y = np.array([0.0, 0.5, 10.0, 100.0])
    m = accuracy(y, y)
    assert m["r2"] == 1.0 and m["rmse_deg"] == 0.0 and m["mape_pct"] == 0.0
    assert m["max_abs_error_deg"] == 0.0
    assert m["n"] == 4 and m["n_mape_excluded"] == 2  # 0 and 0.5 deg are below 1 deg


def test_known_values():
    y = np.array([10.0, 20.0, 0.2])
    p = np.array([11.0, 18.0, 5.0])
    m = accuracy(y, p)
    assert m["mape_pct"] == pytest.approx(100 * (0.1 + 0.1) / 2)
    assert m["rmse_deg"] == pytest.approx(math.sqrt((1 + 4 + 4.8**2) / 3))
    assert m["max_abs_error_deg"] == pytest.approx(4.8)
    assert accuracy(y, p, mape_threshold_deg=0.1)["n_mape_excluded"] == 0


class _Linear:
    def predict(self, X):
        return np.asarray(X) @ np.arange(7.0)

    def predictor(self):
        w = np.arange(7.0)
        return lambda x: float(x @ w)


class _NoFastPath:
    def predict(self, X):
        return np.asarray(X).sum(axis=1)


def test_inference_time_reports_both_paths():
    X = np.random.default_rng(0).random((50, 7))
    t = inference_time(_Linear(), X, batch=1000, repeats=2)
    assert t["fast_path"] is True and t["batch"] == 1000
    assert t["single_us"] > 0 and t["single_predict_us"] > 0 and t["batch_ms"] > 0
    t2 = inference_time(_NoFastPath(), X, batch=100, repeats=2)
    assert t2["fast_path"] is False and t2["single_us"] == t2["single_predict_us"]


def test_the_default_mape_floor_is_5_deg_or_5_pct_of_the_largest_angle():
    from softbend.metrics import mape_floor

    assert mape_floor([0.0, 3.0, 60.0]) == 5.0  # 5 % of 60 is 3: the 5° part
    assert mape_floor([0.0, -300.0, 20.0]) == pytest.approx(15.0)  # 5 % of |−300|
    assert mape_floor([10.0], minimum=0.0, share=0.0) == 0.0
    with pytest.raises(ValueError, match=r"^share: "):
        mape_floor([10.0], share=1.5)


def test_mape_leaves_out_the_readings_below_the_floor_and_counts_them():
    # Readings of a few degrees at low pressure would dominate a plain mean.
    y = np.array([0.0, 2.0, 4.0, 50.0, 100.0])
    p = np.array([1.0, 6.0, 8.0, 55.0, 90.0])
    m = accuracy(y, p)
    assert m["mape_floor_deg"] == 5.0 and m["n_mape_used"] == 2 and m["n_mape_excluded"] == 3
    assert m["mape_pct"] == pytest.approx(100 * (5 / 50 + 10 / 100) / 2)
    assert m["rmse_deg"] == pytest.approx(np.sqrt(np.mean((p - y) ** 2)))  # every reading
    everything = accuracy(y, p, mape_threshold_deg=1.0)
    assert everything["n_mape_used"] == 4 and everything["mape_pct"] > 50


def test_mape_is_undefined_when_no_reading_reaches_the_floor():
    m = accuracy([0.0, 1.0, 4.0], [0.5, 1.5, 3.0])
    assert math.isnan(m["mape_pct"]) and m["n_mape_used"] == 0 and m["rmse_deg"] > 0


def test_paper_b_keeps_its_mape_and_other_actuators_get_the_floor():
    from softbend.actuators import SFRBA
    from softbend.surrogates.metrics import PAPER_B_MAPE_FLOOR_DEG, mape_floor_deg

    angles = np.array([0.0, 30.0, 300.0])
    assert mape_floor_deg(angles, SFRBA) == mape_floor_deg(angles) == PAPER_B_MAPE_FLOOR_DEG
    other = SFRBA.__class__.from_dict({**SFRBA.to_dict(), "name": "other"})
    assert mape_floor_deg(angles, other) == pytest.approx(15.0)
