"""Calibrated intervals over actuators: the rule, its coverage, its warnings."""

from __future__ import annotations

import warnings

import numpy as np
import pytest

from softbend.transfer.conformal import (
    Calibrated,
    angle_floor,
    calibrate,
    conformal_half_width,
    min_actuators,
)
from softbend.transfer.loco import held_out_residuals, leave_one_configuration_out


def test_the_rule_on_a_hand_made_case():
    # n = 3, level 0.5: the smallest t with Σ F_i(t) >= 0.5·4 = 2 is 5
    # (F_a(5) = 1, F_b(5) = 1, F_c(5) = 0.5).
    errors = {"a": [1, 2, 3, 4], "b": [5], "c": [0.5, 6]}
    assert conformal_half_width(errors, 0.5) == (5.0, True)
    # One reading per actuator: the ⌈level·(n + 1)⌉-th smallest error.
    nine = {str(i): [float(i)] for i in range(1, 10)}
    assert conformal_half_width(nine, 0.9) == (9.0, True)
    nineteen = {str(i): [float(i)] for i in range(1, 20)}
    assert conformal_half_width(nineteen, 0.9) == (18.0, True)  # ⌈0.9·20⌉ = 18
    # Signs do not matter: errors are absolute.
    assert conformal_half_width({"a": [-3.0], "b": [2.0]}, 0.5)[0] == 3.0  # ⌈1.5⌉ = 2nd


def test_too_few_actuators_take_the_plug_in_quantile_or_the_largest_error_and_warn():
    assert min_actuators(0.9) == 9 and min_actuators(0.95) == 19
    seven = {str(i): [float(i), 0.5] for i in range(1, 8)}
    # Σ F_i(t) = 3.5 + t/2 at t = 1..7: the plug-in quantile reaches 0.9·7 = 6.3 at t = 6.
    assert conformal_half_width(seven, 0.9) == (6.0, False)
    assert conformal_half_width(seven, 0.9, fallback="largest") == (7.0, False)
    quantile = calibrate(seven, 0.9)
    message = quantile.warning()
    assert message is not None and "7 actuators are too few" in message
    assert "without a guarantee" in message and quantile.to_dict()["fallback"] == "quantile"
    largest = calibrate(seven, 0.9, fallback="largest")
    assert "87.5%" in largest.warning() and largest.half_width_deg == 7.0
    enough = calibrate({str(i): [1.0] for i in range(9)}, 0.9)
    assert enough.warning() is None and enough.to_dict()["fallback"] is None
    with pytest.raises(ValueError, match="fallback"):
        conformal_half_width(seven, 0.9, fallback="max")


def test_the_low_end_stops_at_the_smallest_angle_seen():
    cal = calibrate({"a": [10.0]}, 0.5, floor_deg=0.0)
    low, high = cal.interval([2.0, 50.0])
    np.testing.assert_allclose(low, [0.0, 40.0])
    np.testing.assert_allclose(high, [12.0, 60.0])
    # A prediction below the floor keeps the prediction inside its interval.
    low, _ = cal.interval([-1.0])
    assert low[0] == -1.0
    # The floor: 0°, unless a reading went below it.
    assert angle_floor([6.9, 30.0]) == 0.0
    assert angle_floor([-0.4, 30.0, np.nan]) == -0.4


@pytest.mark.parametrize(
    ("errors", "level", "match"),
    [
        ({}, 0.9, "at least 1 actuator"),
        ({"a": [np.nan]}, 0.9, "'a'"),
        ({"a": [1.0]}, 1.0, "level"),
    ],
)
def test_bad_input_names_the_field(errors, level, match):
    with pytest.raises(ValueError, match=match):
        conformal_half_width(errors, level)


def test_leave_one_group_out_coverage_is_near_nominal_on_a_known_noise_model():
    # Readings y = offset of the actuator + noise, offsets N(0, 2²), noise N(0, 1):
    # the "strategy" is the mean of the training readings, refitted without each group.
    rng = np.random.default_rng(0)
    n_groups, per_group = 40, 12
    offsets = rng.normal(0.0, 2.0, n_groups)
    y = {g: offsets[g] + rng.normal(0.0, 1.0, per_group) for g in range(n_groups)}

    def errors_without(excluded: set[int], target: int) -> np.ndarray:
        mean = np.mean(np.concatenate([y[g] for g in y if g not in excluded]))
        return np.abs(y[target] - mean)

    covered = []
    for held in range(n_groups):
        others = [g for g in range(n_groups) if g != held]
        cal = calibrate({str(g): errors_without({held, g}, g) for g in others}, 0.9)
        assert cal.guaranteed
        covered.append(np.mean(errors_without({held}, held) <= cal.half_width_deg))
    assert 0.80 <= float(np.mean(covered)) <= 0.97


def test_refined_strategy_gets_an_interval(small_base, quick_measurements):
    from softbend.transfer.strategies import make_strategy

    options = {"epochs": 20}
    errors = held_out_residuals(quick_measurements, small_base, "refined", seed=0, options=options)
    assert set(errors) == set(quick_measurements.actuator_ids)
    y = quick_measurements.angle_deg
    cal = calibrate(errors, 0.9, floor_deg=angle_floor(y))
    assert not cal.guaranteed  # 4 actuators
    model = make_strategy("refined", small_base, **options).fit(quick_measurements.features, y)
    low, high = Calibrated(model, cal).predict_interval(quick_measurements.features, 0.9)
    assert np.all(low <= model.predict(quick_measurements.features))
    assert np.all(low >= min(0.0, y.min())) and np.all(high > low)
    with pytest.raises(ValueError, match="'level'"):
        Calibrated(model, cal).predict_interval(quick_measurements.features, 0.8)


def test_loco_scores_the_nested_calibrated_interval(small_base, quick_measurements):
    result = leave_one_configuration_out(
        quick_measurements,
        small_base,
        ["fem-only", "refined", "residual-gp"],
        options={"refined": {"epochs": 20}, "residual-gp": {"n_restarts": 0}},
        learning_curve=False,
        calibrated=True,
    )
    summary = result.summary.set_index("strategy")
    for name in ("fem-only", "refined", "residual-gp"):
        assert 0.0 <= summary.loc[name, "calibrated_coverage"] <= 1.0
        assert summary.loc[name, "calibrated_width_deg"] > 0.0
        assert result.calibrations[name]["n_actuators"] == len(quick_measurements.actuator_ids)
    # fem-only does not learn: its nested errors are the base's, so calibrating without
    # the held-out actuator is the plug-in quantile of the base errors of the 3 others.
    held = quick_measurements.actuator_ids[0]
    y, X, groups = (
        quick_measurements.angle_deg,
        quick_measurements.features,
        quick_measurements.groups,
    )
    errors = {
        a: np.abs(small_base.predict(X[groups == a]) - y[groups == a])
        for a in quick_measurements.actuator_ids
        if a != held
    }
    expected, guaranteed = conformal_half_width(errors, 0.9)
    assert not guaranteed
    row = result.per_actuator.query("strategy == 'fem-only' and actuator_id == @held").iloc[0]
    assert row["calibration_half_width_deg"] == pytest.approx(expected)
    assert {"cal_lo_deg", "cal_hi_deg"} <= set(result.predictions.columns)
    payload = result.to_dict()
    assert set(payload["calibration"]) == {"fem-only", "refined", "residual-gp"}


def test_refine_records_the_calibration_and_warns_when_too_few(
    small_base, quick_measurements, tmp_path
):
    from softbend.surrogates.persistence import load_surrogate, save_surrogate
    from softbend.transfer.measurements import save_measurements
    from softbend.transfer.refine import refine_surrogate

    base = save_surrogate(small_base, tmp_path / "base.json")
    csv = save_measurements(quick_measurements, tmp_path / "lab.csv")
    with pytest.warns(UserWarning, match="too few to calibrate"):
        result = refine_surrogate(base, csv, "scale-offset")
    interval = result.metadata["interval"]
    assert interval["n_actuators"] == 4 and interval["guaranteed"] is False
    assert interval["half_width_deg"] > 0 and "warning" in interval
    low, high = result.predict_interval(quick_measurements.features)
    assert np.all(high - low > 0)
    saved = load_surrogate(result.save(tmp_path / "model.json"))
    assert saved.metadata["interval"]["half_width_deg"] == pytest.approx(interval["half_width_deg"])
    one = save_measurements(
        quick_measurements.subset(quick_measurements.actuator_ids[:1]), tmp_path / "one.csv"
    )
    with pytest.warns(UserWarning, match="no calibrated interval"):
        alone = refine_surrogate(base, one, "scale-offset")
    assert alone.metadata["interval"] is None
    with warnings.catch_warnings():
        warnings.simplefilter("error")
        assert refine_surrogate(base, csv, "scale-offset", calibrated=False).calibration is None
