"""The pressure map: the scaling law it rests on, its fit, and the strategies built on it."""

from __future__ import annotations

import numpy as np
import pytest

from softbend.analytical import AnalyticalModel
from softbend.design import sfrba_design
from softbend.materials.models import Yeoh
from softbend.surrogates.corrected import scaled_pressure_rows as scaled_rows
from softbend.transfer.pressure_map import SCALE_BOUNDS, fit_pressure_scale, scale_mlp_pressure
from softbend.transfer.strategies import (
    AnalyticalBaseline,
    PressureScale,
    RefinedMLP,
    ScaledRefinedMLP,
    make_strategy,
)

DESIGNS = (sfrba_design(100, 6, 2, 2, 5, 8), sfrba_design(120, 8, 3, 2, 10, 10))


def _rows(pressures):
    return np.vstack([d.feature_rows(pressures) for d in DESIGNS])


def test_the_scaling_law_holds_where_only_the_elastomer_is_elastic():
    # The analytical model's fibers are inextensible and it has no gravity: an
    # elastomer k times as stiff at pressure k·p bends exactly as the original at p.
    p = np.linspace(0.0, 0.1, 11)
    soft = AnalyticalModel(material=Yeoh(0.11, 0.003, 0.0))
    stiff = AnalyticalModel(material=Yeoh(0.11 * 1.3, 0.003 * 1.3, 0.0))
    for design in DESIGNS:
        np.testing.assert_allclose(
            stiff.sweep(design, 1.3 * p).angle_deg, soft.sweep(design, p).angle_deg, atol=1e-9
        )


def test_fit_recovers_the_stiffness_of_an_elastomer_known_in_closed_form():
    X = _rows(np.linspace(0.0, 0.08, 9))
    stiff = AnalyticalModel(material=Yeoh(0.11 * 1.25, 0.003 * 1.25, 0.0))
    y = AnalyticalBaseline(stiff).fit(X, np.zeros(len(X))).predict(X)
    base = AnalyticalBaseline(AnalyticalModel(material=Yeoh(0.11, 0.003, 0.0)))
    base.fit(X, y)
    model = PressureScale(base).fit(X, y)
    assert model.scale_ == pytest.approx(1 / 1.25, rel=1e-5)
    assert model.residual_std_ < 1e-3
    np.testing.assert_allclose(model.predict(X), y, atol=1e-3)


def test_fit_recovers_a_known_scale_of_any_surrogate(small_base, quick_measurements):
    X = quick_measurements.features
    y = small_base.predict(scaled_rows(X, 1.15))
    assert fit_pressure_scale(small_base, X, y) == pytest.approx(1.15, rel=1e-5)


def test_scale_needs_pressurized_readings(small_base):
    X = _rows(np.zeros(3))
    with pytest.raises(ValueError, match=r"^X: must include a pressure above 0 MPa"):
        PressureScale(small_base).fit(X, np.zeros(len(X)))


def test_a_scale_on_its_bound_is_one_clear_error(small_base, quick_measurements):
    X = quick_measurements.features
    y = small_base.predict(scaled_rows(X, 1.15)) + 3000.0  # nothing like the base's actuator
    with pytest.raises(ValueError, match=r"^X: .*pressure scale on its bound.*0.25–4") as err:
        PressureScale(small_base).fit(X, y)
    assert "\n" not in str(err.value)
    assert SCALE_BOUNDS == (0.25, 4.0)


class _Trap:
    """A base whose squared error in s has a local minimum at s = 0.7 and the global at 2.5.

    Asked at p = 0.1 MPa only: ``q = 0.1·s``, the error ``(q − 0.25)²·1e4`` with
    a dip at q = 0.072. Brent's method alone on the whole range starts at
    s = 0.72 and stays in the dip (it returns 0.726).
    """

    n_features_in_ = 7

    def predict(self, X):
        q = np.asarray(X)[:, -1]
        return (q - 0.25) ** 2 * 1e4 - 300.0 * np.exp(-(((q - 0.072) / 0.01) ** 2))


def test_the_scan_finds_the_global_minimum_not_the_nearest(quick_measurements):
    X = quick_measurements.features.copy()
    X[:, -1] = 0.1
    scale = fit_pressure_scale(_Trap(), X, np.zeros(len(X)))
    assert scale == pytest.approx(2.5, rel=1e-4)


def test_a_base_that_never_answers_is_one_clear_error(quick_measurements):
    class Silent:
        n_features_in_ = 7

        def predict(self, X):
            return np.full(len(X), np.nan)

    X = quick_measurements.features
    with pytest.raises(ValueError, match=r"^base: predicts no finite angle"):
        fit_pressure_scale(Silent(), X, np.ones(len(X)))


def test_a_scaled_mlp_answers_the_base_at_the_scaled_pressure(small_base, quick_measurements):
    X = quick_measurements.features
    scaled = scale_mlp_pressure(small_base, 0.87)
    np.testing.assert_allclose(
        scaled.predict(X), small_base.predict(scaled_rows(X, 0.87)), rtol=1e-12, atol=1e-9
    )
    np.testing.assert_array_equal(small_base.x_scale_[:-1], scaled.x_scale_[:-1])
    assert small_base.x_scale_[-1] != scaled.x_scale_[-1]  # the base is not modified


def test_scaled_refined_starts_from_the_mapped_base(small_base, quick_measurements):
    X = quick_measurements.features
    y = small_base.predict(scaled_rows(X, 1.1)) + 2.0  # a stiffness gap and an offset
    model = ScaledRefinedMLP(small_base, epochs=200).fit(X, y)
    assert model.pressure_scale_ == pytest.approx(
        PressureScale(small_base).fit(X, y).scale_, rel=1e-9
    )
    start = scale_mlp_pressure(small_base, model.pressure_scale_).predict(X)
    # the first epoch's loss is the mapped start's error, lower than the base's
    assert model.loss_curve_[0] == pytest.approx(np.mean((start - y) ** 2), rel=1e-9)
    assert model.loss_curve_[0] < np.mean((small_base.predict(X) - y) ** 2)
    assert model.loss_curve_[-1] < 0.5 * model.loss_curve_[0]
    plain = RefinedMLP(small_base, epochs=200).fit(X, y)
    assert model.loss_curve_[-1] < plain.loss_curve_[-1]


def test_scaled_refined_batch_equals_one_at_a_time(small_base, quick_measurements):
    X, y = quick_measurements.features, quick_measurements.angle_deg
    sets = [np.arange(40), np.arange(len(y))]
    together = ScaledRefinedMLP.fit_batch(
        [make_strategy("scaled-refined", small_base, epochs=30) for _ in sets], X, y, sets
    )
    for rows, model in zip(sets, together, strict=True):
        alone = ScaledRefinedMLP(small_base, epochs=30).fit(X[rows], y[rows])
        assert model.pressure_scale_ == alone.pressure_scale_
        np.testing.assert_allclose(model.predict(X), alone.predict(X), rtol=1e-9, atol=1e-9)
