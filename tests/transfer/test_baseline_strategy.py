"""The baseline every strategy is judged against: the base plus a mean residual of pressure.

``base-mean-residual`` adds to the base the training actuators' mean residual as a
function of pressure alone, so it recovers a gap that depends on pressure only, leaves
an exact base alone, and cannot tell two designs apart at one pressure. The leave-one-out
summary states every strategy's mean RMSE (and relative to this baseline) and the
coverage of its calibrated interval, or why there is none.
"""

from __future__ import annotations

import json

import numpy as np
import pytest

from softbend.cli.transfer_loco import print_loco_summary
from softbend.transfer.loco import BASELINE_STRATEGY, leave_one_configuration_out
from softbend.transfer.strategies import (
    BUILTIN_STRATEGIES,
    STRATEGIES,
    BaseMeanResidual,
    learns,
    make_strategy,
)

DESIGNS = ([100, 6, 2, 2, 5, 8], [120, 6, 2, 2, 5, 8], [100, 8, 3, 2, 10, 9])


class _DesignBase:
    """A stand-in surrogate whose angle depends on the design and the pressure."""

    n_features_in_ = 7

    def predict(self, X):
        X = np.asarray(X, dtype=np.float64)
        return (900.0 + 2.0 * X[:, 0] - 30.0 * X[:, 2]) * X[:, -1]


def _rows(designs=DESIGNS, pmax=0.15, step=0.01):
    pressures = np.round(np.arange(0.0, pmax + step / 2, step), 4)
    return np.array([[*d, p] for d in designs for p in pressures], dtype=np.float64)


def test_it_is_registered_right_after_the_base_alone_and_saves_nothing():
    assert BUILTIN_STRATEGIES[:2] == ("fem-only", BASELINE_STRATEGY)
    assert STRATEGIES.get(BASELINE_STRATEGY) is BaseMeanResidual
    assert not learns(BASELINE_STRATEGY)  # a baseline: refine does not save it


def test_a_gap_linear_in_pressure_is_recovered_exactly():
    base = _DesignBase()
    X = _rows()
    y = base.predict(X) + 40.0 * X[:, -1] - 1.5  # the gap: g(p) = 40·p − 1.5
    model = make_strategy(BASELINE_STRATEGY, base).fit(X, y)
    np.testing.assert_allclose(model.predict(X), y, atol=1e-9)
    inside = np.linspace(0.0, 0.15, 31)
    np.testing.assert_allclose(model._residual(inside), 40.0 * inside - 1.5, atol=1e-9)
    assert model.residual_std_ == pytest.approx(0.0, abs=1e-9)


def test_any_gap_of_pressure_is_recovered_at_the_measured_pressures_with_a_band_each():
    base = _DesignBase()
    X = _rows(pmax=0.07)  # 8 distinct pressures: each its own band with n_bins=8
    gap = 3000.0 * X[:, -1] ** 2 + np.sin(60.0 * X[:, -1])
    model = BaseMeanResidual(base, n_bins=8).fit(X, base.predict(X) + gap)
    np.testing.assert_allclose(model.predict(X) - base.predict(X), gap, atol=1e-9)
    np.testing.assert_allclose(model.pressure_nodes_mpa_, np.unique(X[:, -1]))


def test_an_exact_base_is_left_as_it_is():
    base = _DesignBase()
    X = _rows()
    model = make_strategy(BASELINE_STRATEGY, base).fit(X, base.predict(X))
    np.testing.assert_allclose(model.residual_nodes_deg_, 0.0, atol=1e-12)
    np.testing.assert_allclose(model.predict(X), base.predict(X), atol=1e-12)
    lo, hi = model.predict_interval(X, 0.9)
    np.testing.assert_allclose(hi - lo, 0.0, atol=1e-9)


def test_the_correction_ignores_the_design():
    base = _DesignBase()
    X = _rows()
    # Each actuator has its own gap: the baseline learns only their mean against pressure.
    own = {tuple(d): k for k, d in enumerate(DESIGNS)}
    factor = np.array([own[tuple(row[:-1])] for row in X]) + 1.0
    y = base.predict(X) + 30.0 * factor * X[:, -1]
    model = make_strategy(BASELINE_STRATEGY, base).fit(X, y)
    asked = np.array([[130, 7, 2.5, 3, 10, 9, 0.083], [100, 6, 2, 2, 5, 8, 0.083]])
    correction = model.predict(asked) - base.predict(asked)
    assert correction[0] == pytest.approx(correction[1], abs=1e-12)
    assert correction[0] == pytest.approx(30.0 * 2.0 * 0.083, abs=1e-9)  # the mean factor, 2


def test_each_actuator_weighs_alike_whatever_its_readings():
    base = _DesignBase()
    few, many = _rows(DESIGNS[:1], step=0.05), _rows(DESIGNS[1:2], step=0.01)
    X = np.vstack([few, many])
    gap = np.r_[np.full(len(few), 10.0), np.full(len(many), 0.0)]
    model = BaseMeanResidual(base, n_bins=1).fit(X, base.predict(X) + gap)
    np.testing.assert_allclose(model.residual_nodes_deg_, [5.0])  # not weighted 4:16


def test_one_measured_actuator_is_enough():
    base = _DesignBase()
    X = _rows(DESIGNS[:1])
    y = base.predict(X) + 20.0 * X[:, -1]
    model = make_strategy(BASELINE_STRATEGY, base).fit(X, y)
    np.testing.assert_allclose(model.predict(X), y, atol=1e-9)


@pytest.mark.parametrize("n_bins", [0, 101, 2.5, "many"])
def test_a_band_count_out_of_range_is_refused(n_bins):
    with pytest.raises(ValueError, match="n_bins"):
        make_strategy(BASELINE_STRATEGY, _DesignBase(), n_bins=n_bins)


def test_bad_input_is_refused():
    base = _DesignBase()
    X = _rows()
    y = base.predict(X)
    bad = X.copy()
    bad[3, -1] = np.nan
    with pytest.raises(ValueError, match="NaN"):
        BaseMeanResidual(base).fit(bad, y)
    model = BaseMeanResidual(base).fit(X, y)
    with pytest.raises(ValueError, match="NaN"):
        model.predict(bad)
    with pytest.raises(ValueError, match=r"^X: must hold at least 2 readings"):
        BaseMeanResidual(base).fit(X[:1], y[:1])
    with pytest.raises(ValueError, match=r"^base: must be a fitted surrogate"):
        BaseMeanResidual(None).fit(X, y)
    with pytest.raises(ValueError, match=r"^X: must have the 7 columns"):
        BaseMeanResidual(base).fit(X[:, :-1], y)


def test_leave_one_out_needs_two_actuators(small_base, quick_measurements):
    one = quick_measurements.subset([quick_measurements.actuator_ids[0]])
    with pytest.raises(ValueError, match="at least 2 actuators"):
        leave_one_configuration_out(one, small_base, [BASELINE_STRATEGY])


# ------------------------------------------------------------------ the loco summary
NAMES = ["fem-only", BASELINE_STRATEGY, "scale-offset", "experimental"]


@pytest.fixture(scope="module")
def calibrated(small_base, quick_measurements):
    return leave_one_configuration_out(
        quick_measurements,
        small_base,
        NAMES,
        options={"experimental": {"epochs": 20}},
        calibrated=True,
        learning_curve=False,
    )


def test_loco_json_states_the_mean_rmse_and_the_coverage_of_every_strategy(calibrated, tmp_path):
    calibrated.write(tmp_path / "out")
    payload = json.loads((tmp_path / "out" / "loco.json").read_text())
    summary = {r["strategy"]: r for r in payload["summary"]}
    assert list(summary) == NAMES
    per_actuator = calibrated.per_actuator
    for name, row in summary.items():
        assert {"rmse_deg_mean", "coverage", "calibrated_coverage"} <= set(row)
        assert {"calibrated_coverage_reason", "rmse_vs_baseline_pct"} <= set(row)
        mine = per_actuator.loc[per_actuator["strategy"] == name, "rmse_deg"]
        assert len(mine) == len(calibrated.settings["actuators"])
        assert row["rmse_deg_mean"] == pytest.approx(float(np.mean(mine)), rel=1e-12)
        assert row["rmse_deg_mean"] == row["rmse_deg"]  # the old name kept
        base_row = summary[BASELINE_STRATEGY]
        expected = 100.0 * (row["rmse_deg_mean"] / base_row["rmse_deg_mean"] - 1.0)
        assert row["rmse_vs_baseline_pct"] == pytest.approx(expected)
    for name in ("fem-only", BASELINE_STRATEGY, "scale-offset"):
        assert 0.0 <= summary[name]["calibrated_coverage"] <= 1.0
        assert summary[name]["calibrated_coverage_reason"] is None
    assert summary["experimental"]["calibrated_coverage"] is None
    assert "never are" in summary["experimental"]["calibrated_coverage_reason"]
    assert 0.0 <= summary[BASELINE_STRATEGY]["coverage"] <= 1.0  # its own Gaussian interval
    assert summary[BASELINE_STRATEGY]["rmse_vs_baseline_pct"] == 0.0
    assert payload["settings"]["baseline"] == BASELINE_STRATEGY


def test_calibrated_coverage_is_the_share_of_held_out_readings_inside(calibrated):
    predictions = calibrated.predictions
    for name in ("fem-only", BASELINE_STRATEGY):
        part = predictions[predictions["strategy"] == name]
        inside = (part["angle_deg"] >= part["cal_lo_deg"]) & (
            part["angle_deg"] <= part["cal_hi_deg"]
        )
        got = calibrated.summary.set_index("strategy").loc[name, "calibrated_coverage"]
        assert got == pytest.approx(float(inside.mean()))


def test_without_calibration_the_coverage_is_null_with_a_reason(small_base, quick_measurements):
    result = leave_one_configuration_out(
        quick_measurements, small_base, ["scale-offset"], learning_curve=False
    )
    row = result.to_dict()["summary"][0]
    assert np.isnan(row["calibrated_coverage"])
    assert "--calibrate" in row["calibrated_coverage_reason"]
    assert np.isnan(row["rmse_vs_baseline_pct"])  # no baseline in the run
    assert result.settings["baseline"] is None


def test_the_table_compares_every_strategy_with_the_baseline(calibrated, capsys, monkeypatch):
    from rich.console import Console

    from softbend.cli import _common, _console

    wide = Console(width=200)
    monkeypatch.setattr(_console, "console", wide)
    monkeypatch.setattr(_common, "console", wide)
    print_loco_summary(calibrated)
    out = capsys.readouterr().out
    assert "vs baseline" in out and "(baseline)" in out
    pct = calibrated.summary.set_index("strategy")["rmse_vs_baseline_pct"]
    shown = f"{pct['fem-only']:+.0f} %".replace("-", "\u2212")
    assert shown in out
