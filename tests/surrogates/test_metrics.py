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
