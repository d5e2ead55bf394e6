"""Refinement strategies: each does what it claims on cases with a known answer."""

from __future__ import annotations

import warnings

import numpy as np
import pytest

from softbend.errors import ConvergenceError, DatasetError
from softbend.transfer.finetune import fine_tune_many, fine_tune_mlp, row_weights
from softbend.transfer.strategies import (
    NETWORK_STRATEGIES,
    STRATEGIES,
    AnalyticalBaseline,
    ExperimentalMLP,
    PressureScale,
    RefinedEnsemble,
    RefinedMLP,
    ResidualGP,
    ScaleOffset,
    has_interval,
    make_strategy,
)


def test_the_network_strategies_are_the_ones_with_epochs(small_base):
    with_epochs = {n for n in STRATEGIES if "epochs" in make_strategy(n, small_base).get_params()}
    assert with_epochs == set(NETWORK_STRATEGIES)


def test_every_named_strategy_fits_and_predicts(small_base, quick_measurements):
    X, y = quick_measurements.features, quick_measurements.angle_deg
    for name in STRATEGIES:
        options = {"epochs": 20} if name in NETWORK_STRATEGIES else {}
        model = make_strategy(name, small_base, **options).fit(X, y)
        pred = model.predict(X)
        assert pred.shape == y.shape and np.isfinite(pred).all(), name
        if has_interval(model):
            lo, hi = model.predict_interval(X, 0.9)
            assert np.all(lo <= pred) and np.all(pred <= hi)


def test_unknown_strategy_lists_the_allowed_ones():
    with pytest.raises(
        ValueError, match=r"(?i)^name: unknown transfer strategy 'transfer-magic'.*refined"
    ):
        make_strategy("transfer-magic")
    with pytest.raises(
        ValueError, match=r"^options: epoch: is not a parameter; known: epochs, learning_rate"
    ):
        make_strategy("refined", epoch=5)


def test_refining_needs_an_mlp_base(quick_measurements):
    with pytest.raises(
        ValueError,
        match=r"^base: must be a fitted mlp surrogate: .*; got a model of no saved family$",
    ):
        RefinedMLP(ScaleOffset()).fit(quick_measurements.features, quick_measurements.angle_deg)


def test_refined_mlp_keeps_the_base_scaling_and_lowers_the_training_loss(
    small_base, quick_measurements
):
    X, y = quick_measurements.features, quick_measurements.angle_deg
    model = RefinedMLP(small_base, epochs=300).fit(X, y)
    np.testing.assert_array_equal(model.model_.x_mean_, small_base.x_mean_)
    np.testing.assert_array_equal(model.model_.x_scale_, small_base.x_scale_)
    assert model.model_.y_scale_ == small_base.y_scale_
    before = np.mean((small_base.predict(X) - y) ** 2)
    # the first epoch's loss is the base's own error on the rows, in deg²
    assert model.loss_curve_[0] == pytest.approx(before, rel=1e-9)
    assert model.loss_curve_[-1] < 0.5 * before
    assert np.mean((model.predict(X) - y) ** 2) == pytest.approx(model.loss_curve_[-1], rel=0.2)


def test_refining_on_the_base_own_predictions_barely_moves_it(small_base, quick_measurements):
    # No gap to learn: the gradient starts at rounding level, and Adam's normalized
    # steps (learning rate 6e-4 per weight) can only wander a little.
    X = quick_measurements.features
    model = fine_tune_mlp(small_base, X, small_base.predict(X), epochs=50)
    assert model.loss_curve_[0] < 1e-20
    np.testing.assert_allclose(model.predict(X), small_base.predict(X), atol=0.5)


def test_batched_refinement_equals_one_at_a_time(small_base, quick_measurements):
    X, y = quick_measurements.features, quick_measurements.angle_deg
    rng = np.random.default_rng(0)
    sets = [np.arange(40), rng.choice(len(y), size=60, replace=True), np.arange(len(y))]
    together = fine_tune_many(small_base, X, y, row_weights(sets, len(y)), epochs=40)
    for rows, model in zip(sets, together, strict=True):
        alone = fine_tune_mlp(small_base, X[rows], y[rows], epochs=40)
        np.testing.assert_allclose(model.predict(X), alone.predict(X), rtol=1e-9, atol=1e-9)


def test_experimental_batch_equals_single_fit(quick_measurements):
    X, y = quick_measurements.features, quick_measurements.angle_deg
    single = ExperimentalMLP(epochs=30, hidden_sizes=(8, 8)).fit(X, y)
    batch = ExperimentalMLP.fit_batch(
        [ExperimentalMLP(epochs=30, hidden_sizes=(8, 8)) for _ in range(2)],
        X,
        y,
        [np.arange(len(y)), np.arange(30)],
    )
    np.testing.assert_allclose(batch[0].predict(X), single.predict(X), rtol=1e-12)
    assert not np.allclose(batch[1].predict(X), single.predict(X))


def test_scale_offset_recovers_a_known_linear_gap(small_base, quick_measurements):
    X = quick_measurements.features
    y = 0.8 * small_base.predict(X) + 3.0
    model = ScaleOffset(small_base).fit(X, y)
    assert model.scale_ == pytest.approx(0.8) and model.offset_ == pytest.approx(3.0)
    assert model.residual_std_ == pytest.approx(0.0, abs=1e-9)


def test_residual_gp_on_pure_noise_stays_on_the_base_and_covers(small_base, quick_measurements):
    X = quick_measurements.features
    noise = np.random.default_rng(1).normal(0.0, 1.0, size=len(X))
    model = ResidualGP(small_base).fit(X, small_base.predict(X) + noise)
    pred = model.predict(X)
    assert np.sqrt(np.mean((pred - small_base.predict(X)) ** 2)) < 0.5
    fresh = small_base.predict(X) + np.random.default_rng(2).normal(0.0, 1.0, size=len(X))
    lo, hi = model.predict_interval(X, 0.9)
    assert 0.8 <= np.mean((fresh >= lo) & (fresh <= hi)) <= 0.99
    wide = model.predict_interval(X, 0.99)
    assert np.all(wide[1] - wide[0] > hi - lo)


def test_ensemble_members_differ_and_their_spread_widens_the_interval(
    small_base, quick_measurements
):
    X, y = quick_measurements.features, quick_measurements.angle_deg
    model = RefinedEnsemble(small_base, n_members=3, epochs=50).fit(X, y)
    preds = np.array([m.predict(X) for m in model.members_])
    assert preds.std(axis=0).max() > 0.0
    lo, hi = model.predict_interval(X, 0.9)
    assert np.all(hi - lo >= 2 * 1.6448 * model.residual_std_ - 1e-9)


def test_analytical_baseline_is_the_analytical_sweep(quick_measurements):
    from softbend.analytical import AnalyticalModel

    X = quick_measurements.features
    model = AnalyticalBaseline().fit(X, quick_measurements.angle_deg)
    design = quick_measurements.designs[0]
    rows = quick_measurements.groups == quick_measurements.actuator_ids[0]
    sweep = AnalyticalModel().sweep(design, X[rows, -1])
    np.testing.assert_allclose(model.predict(X[rows]), sweep.angle_deg)


@pytest.mark.parametrize("level", [0.0, 1.0, 1.5, float("nan")])
def test_interval_level_must_be_a_probability(small_base, quick_measurements, level):
    model = ScaleOffset(small_base).fit(quick_measurements.features, quick_measurements.angle_deg)
    with pytest.raises(ValueError, match=r"^level: must be a number in"):
        model.predict_interval(quick_measurements.features, level)


def test_fit_rejects_wrong_columns_and_nan(small_base):
    with pytest.raises(ValueError, match=r"^X: must have the 7 columns"):
        ScaleOffset(small_base).fit(np.ones((5, 3)), np.ones(5))
    X = np.ones((5, 7))
    y = np.array([1.0, np.nan, 2.0, 3.0, 4.0])
    with pytest.raises(ValueError):
        ScaleOffset(small_base).fit(X, y)


def test_fit_strategy_is_make_then_fit_on_all_readings(small_base, quick_measurements):
    from softbend.transfer.strategies import fit_strategy

    X, y = quick_measurements.features, quick_measurements.angle_deg
    fitted = fit_strategy("refined", small_base, quick_measurements, seed=3, epochs=40)
    by_hand = make_strategy("refined", small_base, seed=3, epochs=40).fit(X, y)
    assert len(fitted.loss_curve_) == 40
    np.testing.assert_array_equal(fitted.predict(X), by_hand.predict(X))


# --- A fit never ends with non-finite parameters, overflow warnings or a misleading success ---


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
    assert "row 5, column 'angle_deg': 1e+300 is not a plausible bending angle" in message
    assert f"the '{name}' strategy's training readings" in message and ".fit" not in message
    assert "-3600 to 3600" in message


def test_an_absurd_pressure_is_refused_before_fitting(small_base, rows):
    X, y = rows
    X = X.copy()
    X[3, -1] = 250.0  # kPa
    with pytest.raises(
        DatasetError,
        match=r"^the 'scale-offset' strategy's training readings, row 3, column 'pressure_mpa': "
        r"250 is not a plausible.*kPa",
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
