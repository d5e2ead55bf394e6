"""A fit never ends with non-finite parameters, overflow warnings or a misleading success."""

from __future__ import annotations

import warnings

import numpy as np
import pytest

from softbend.errors import ConvergenceError, DatasetError
from softbend.transfer.strategies import PressureScale, ResidualGP, ScaleOffset, make_strategy


class _Stub:
    """A 'base' whose prediction is a fixed function of the rows."""

    n_features_in_ = 7

    def __init__(self, answer):
        self.answer = answer

    def predict(self, X):
        return self.answer(np.asarray(X, dtype=float))


@pytest.fixture
def rows(quick_measurements):
    return quick_measurements.features, quick_measurements.angle_deg


@pytest.mark.parametrize("name", ["scale-offset", "pressure-scale", "residual-gp", "refined"])
def test_an_absurd_angle_is_refused_before_fitting(small_base, rows, name):
    X, y = rows
    y = y.copy()
    y[5] = 1e300
    model = make_strategy(name, small_base, **({"epochs": 5} if name == "refined" else {}))
    with warnings.catch_warnings():
        warnings.simplefilter("error")  # no overflow warning on the way
        with pytest.raises(DatasetError) as error:
            model.fit(X, y)
    message = str(error.value)
    assert "row 5, column 'y': 1e+300 is not a plausible bending angle" in message
    assert "-3600 to 3600" in message


def test_an_absurd_pressure_is_refused_before_fitting(small_base, rows):
    X, y = rows
    X = X.copy()
    X[3, -1] = 250.0  # kPa
    with pytest.raises(
        DatasetError,
        match=r"ScaleOffset.fit, row 3, column 'pressure_mpa': 250 is not a plausible.*kPa",
    ):
        ScaleOffset(small_base).fit(X, y)


def test_scale_offset_never_keeps_non_finite_parameters(small_base, rows, monkeypatch):
    X, y = rows

    def overflowed(A, b, rcond=None):
        return np.array([-np.inf, np.nan]), np.array([]), 2, np.array([1.0, 1.0])

    monkeypatch.setattr(np.linalg, "lstsq", overflowed)
    model = ScaleOffset(small_base)
    with warnings.catch_warnings():
        warnings.simplefilter("error")
        with pytest.raises(ConvergenceError) as error:
            model.fit(X, y)
    message = str(error.value)
    assert "'scale-offset'" in message and "scale=-inf" in message and "offset=nan" in message
    assert not hasattr(model, "model_")


def test_residual_gp_never_keeps_non_finite_parameters(rows):
    X, y = rows
    huge = _Stub(lambda X: 1.7e308 * np.where(np.arange(len(X)) % 2, 1.0, -1.0))
    model = ResidualGP(huge, n_restarts=0)
    with warnings.catch_warnings():
        warnings.simplefilter("error")
        with pytest.raises(ConvergenceError) as error:
            model.fit(X, y)
    assert "'residual-gp'" in str(error.value) and "not all finite" in str(error.value)
    assert not hasattr(model, "model_")


@pytest.mark.parametrize("strategy", [ScaleOffset, ResidualGP])
def test_a_base_without_an_answer_is_named_not_a_library_error(rows, strategy):
    X, y = rows
    blank = _Stub(lambda X: np.where(X[:, -1] > 0.1, np.nan, 10.0))
    with pytest.raises(
        ValueError, match=r"^base: predicts a non-finite angle at .*the '[a-z-]+' strategy cannot"
    ):
        strategy(blank).fit(X, y)


def test_pressure_scale_on_a_huge_base_fails_without_overflow_warnings(rows):
    X, y = rows
    huge = _Stub(lambda X: np.full(len(X), 1e300))
    with warnings.catch_warnings():
        warnings.simplefilter("error")
        with pytest.raises(ValueError, match="no finite angle"):
            PressureScale(huge).fit(X, y)


def test_a_fit_too_small_for_its_spread_is_refused(small_base, rows):
    X, y = rows
    pressurized = np.flatnonzero(X[:, -1] > 0)
    with pytest.raises(ValueError, match=r"^X: .*at least 3 readings: the 'scale-offset' .*got 2$"):
        ScaleOffset(small_base).fit(X[pressurized[:2]], y[pressurized[:2]])
    with pytest.raises(
        ValueError, match=r"^X: .*at least 2 readings: the 'pressure-scale' .*got 1$"
    ):
        PressureScale(small_base).fit(X[pressurized[:1]], y[pressurized[:1]])


def test_scale_offset_refuses_a_base_that_answers_one_angle(rows):
    X, y = rows
    with pytest.raises(ValueError, match=r"^X: .*cannot tell its scale from its offset.*\(12°\)"):
        ScaleOffset(_Stub(lambda X: np.full(len(X), 12.0))).fit(X, y)
