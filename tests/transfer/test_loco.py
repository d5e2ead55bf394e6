"""Leave-one-configuration-out: the right folds, honest scores, files written."""

from __future__ import annotations

import json

import numpy as np
import pytest

from softbend.metrics import rmse
from softbend.transfer.loco import (
    CURVE_SIZES,
    learning_curve_sizes,
    leave_one_configuration_out,
)

FAST = {
    "refined": {"epochs": 30},
    "refined-ensemble": {"epochs": 30, "n_members": 2},
    "residual-gp": {"n_restarts": 0},
}


@pytest.fixture(scope="module")
def result(small_base, quick_measurements):
    return leave_one_configuration_out(
        quick_measurements,
        small_base,
        ["fem-only", "refined", "scale-offset", "residual-gp", "refined-ensemble"],
        options=FAST,
        calibrated=True,
    )


def test_every_strategy_is_scored_on_every_held_out_actuator(result, quick_measurements):
    ids = quick_measurements.actuator_ids
    assert len(result.per_actuator) == 5 * len(ids)
    for _, row in result.per_actuator.iterrows():
        assert row["n_points"] == int(np.sum(quick_measurements.groups == row["actuator_id"]))
    assert set(result.summary["strategy"]) == set(result.per_actuator["strategy"])


def test_fem_only_scores_are_the_base_error(result, small_base, quick_measurements):
    for actuator in quick_measurements.actuator_ids:
        rows = quick_measurements.groups == actuator
        expected = rmse(
            quick_measurements.angle_deg[rows],
            small_base.predict(quick_measurements.features[rows]),
        )
        got = result.per_actuator.query("strategy == 'fem-only' and actuator_id == @actuator")
        assert float(got["rmse_deg"].iloc[0]) == pytest.approx(expected)


def test_a_held_out_actuator_never_trains_its_own_model(small_base, quick_measurements):
    # Refit one fold by hand: training on the others must give the reported score.
    from softbend.transfer.strategies import ScaleOffset

    result = leave_one_configuration_out(quick_measurements, small_base, ["scale-offset"])
    held = quick_measurements.actuator_ids[1]
    test = quick_measurements.groups == held
    X, y = quick_measurements.features, quick_measurements.angle_deg
    model = ScaleOffset(small_base).fit(X[~test], y[~test])
    expected = rmse(y[test], model.predict(X[test]))
    got = result.per_actuator.query("actuator_id == @held")["rmse_deg"].iloc[0]
    assert got == pytest.approx(expected)


def test_intervals_report_a_coverage_and_point_models_do_not(result):
    summary = result.summary.set_index("strategy")
    assert np.isnan(summary.loc["fem-only", "coverage"])
    for name in ("scale-offset", "residual-gp", "refined-ensemble"):
        assert 0.0 <= summary.loc[name, "coverage"] <= 1.0


def test_learning_curve_covers_one_to_n_minus_one_actuators(result, quick_measurements):
    n = len(quick_measurements.actuator_ids)
    curve = result.learning_curve
    assert "refined-ensemble" not in set(curve["strategy"])  # too slow for the curve
    for name, part in curve.groupby("strategy"):
        assert sorted(set(part["n_actuators"])) == list(range(1, n)), name
        assert len(part) == n * (n - 1)


@pytest.mark.parametrize("n", range(2, 40))
def test_learning_curve_sizes_are_every_size_up_to_the_cap_then_geometric(n):
    sizes = learning_curve_sizes(n)
    assert sizes == sorted(set(sizes)) and len(sizes) <= CURVE_SIZES
    if n - 2 <= CURVE_SIZES:
        assert sizes == list(range(1, n - 1))  # paper B's seven actuators: 1..5, unchanged
    else:
        assert sizes[0] == 1 and sizes[-1] == n - 2 and len(sizes) >= CURVE_SIZES - 1
        assert np.all(np.diff(np.log(sizes)) > 0)


def test_same_seed_same_numbers(small_base, quick_measurements, result):
    names = ["refined", "refined-ensemble"]
    again = leave_one_configuration_out(
        quick_measurements, small_base, names, options=FAST, learning_curve=False
    )
    cols = ["rmse_deg", "mape_pct", "max_error_deg", "coverage"]
    before = result.per_actuator[result.per_actuator["strategy"].isin(names)]
    np.testing.assert_array_equal(again.per_actuator[cols], before[cols])


def test_refining_beats_the_base_on_a_systematic_gap(small_base, quick_measurements):
    # The lab's elastomer is not the base's: correcting with measurements must help.
    result = leave_one_configuration_out(
        quick_measurements,
        small_base,
        ["fem-only", "scale-offset", "refined"],
        options={"refined": {"epochs": 300}},
        learning_curve=False,
    )
    summary = result.summary.set_index("strategy")["rmse_deg"]
    assert summary["scale-offset"] < summary["fem-only"]
    assert summary["refined"] < summary["fem-only"]


def test_written_files_are_tables_and_strict_json(result, tmp_path):
    files = result.write(tmp_path / "out")
    for key in ("summary", "per_actuator", "predictions", "learning_curve", "loss_curves"):
        assert (tmp_path / "out").joinpath(files[key].split("/")[-1]).is_file()
    payload = json.loads((tmp_path / "out" / "loco.json").read_text())  # no NaN tokens
    assert {r["strategy"] for r in payload["summary"]} == set(result.summary["strategy"])
    assert payload["summary"][0]["coverage"] is None  # fem-only: no interval


@pytest.mark.parametrize(
    ("kwargs", "match"),
    [
        ({"strategies": []}, "at least one"),
        ({"strategies": ["refined", "refined"]}, "distinct"),
        ({"strategies": ["magic"]}, r"(?i)^strategies: unknown transfer strategy 'magic'"),
        ({"level": 1.0}, "^level: must be a number in"),
        ({"seed": -1}, "^seed: must be an integer"),
        (
            {"options": {"magic": {}}},
            r"(?i)^options: unknown transfer strategy 'magic'; known: fem-only",
        ),
        (
            {"options": {"refined": {"epoch": 5}}},
            "^options: epoch: is not a parameter; known: epochs",
        ),
    ],
)
def test_bad_arguments_name_the_field(small_base, quick_measurements, kwargs, match):
    with pytest.raises(ValueError, match=match):
        leave_one_configuration_out(quick_measurements, small_base, **kwargs)


def test_one_actuator_is_not_enough(small_base, quick_measurements):
    one = quick_measurements.subset([quick_measurements.actuator_ids[0]])
    with pytest.raises(ValueError, match="at least 2 actuators"):
        leave_one_configuration_out(one, small_base, ["fem-only"])


def test_calibrated_intervals_are_scored_nested_and_written(result, tmp_path):
    summary = result.summary.set_index("strategy")
    for name in ("fem-only", "refined", "scale-offset", "residual-gp"):
        assert 0.0 <= summary.loc[name, "calibrated_coverage"] <= 1.0
        assert summary.loc[name, "calibrated_width_deg"] > 0.0
    # The slowest strategy is not calibrated (as it has no learning curve).
    assert np.isnan(summary.loc["refined-ensemble", "calibrated_coverage"])
    assert "refined-ensemble" not in result.calibrations
    result.write(tmp_path / "out")
    payload = json.loads((tmp_path / "out" / "loco.json").read_text())
    assert payload["calibration"]["refined"]["n_actuators"] == 4
    assert payload["calibration"]["refined"]["guaranteed"] is False


def test_calibration_can_be_left_out_and_leaves_the_scores_alone(
    small_base, quick_measurements, result
):
    plain = leave_one_configuration_out(
        quick_measurements, small_base, ["scale-offset"], calibrated=False, learning_curve=False
    )
    assert plain.summary["calibrated_coverage"].isna().all() and plain.calibrations == {}
    mine = result.per_actuator.query("strategy == 'scale-offset'")["rmse_deg"].to_numpy()
    np.testing.assert_array_equal(plain.per_actuator["rmse_deg"].to_numpy(), mine)
