"""A calibrated leave-one-out interval needs three actuators: refused up front, never missing.

The interval of a held-out actuator is calibrated on the errors of the others, each
predicted by a model fitted without it and without the held-out one; with two actuators
that model has no data. ``leave_one_configuration_out(calibrated=True)`` and
``softbend transfer loco --calibrate`` refuse it before any fit, saying how many
actuators it needs and how many were given, instead of ending with no interval.
"""

from __future__ import annotations

import numpy as np
import pytest

from softbend.cli import main
from softbend.transfer.loco import (
    MIN_CALIBRATION_ACTUATORS,
    check_calibration,
    leave_one_configuration_out,
)


@pytest.fixture(scope="module")
def two_actuators(quick_measurements):
    return quick_measurements.subset(quick_measurements.actuator_ids[:2])


def test_calibration_with_two_actuators_is_refused_before_any_fit(two_actuators):
    class NeverFitted:
        def __getattr__(self, name):
            raise AssertionError(f"the base was used ({name}) before the refusal")

    ids = two_actuators.actuator_ids
    with pytest.raises(ValueError) as info:
        leave_one_configuration_out(
            two_actuators, NeverFitted(), ["scale-offset"], calibrated=True, learning_curve=False
        )
    message = str(info.value)
    assert message.startswith("calibrated: needs measurements of at least 3 actuators")
    assert message.endswith(f"; got 2 ({ids[0]}; {ids[1]})")


def test_calibration_of_only_the_slowest_strategies_is_refused(quick_measurements):
    with pytest.raises(ValueError, match=r"^calibrated: calibrates strategies other than experim"):
        check_calibration(quick_measurements.actuator_ids, ["refined-ensemble"])
    check_calibration(quick_measurements.actuator_ids, ["refined-ensemble", "scale-offset"])
    assert MIN_CALIBRATION_ACTUATORS == 3


class _LinearBase:
    """A stand-in surrogate: the angle grows with the pressure (the last feature)."""

    n_features_in_ = 7

    def predict(self, X):
        X = np.asarray(X, dtype=np.float64)
        return 800.0 * X[:, -1] + 0.01 * X[:, 0]


def test_three_actuators_get_a_calibrated_interval_on_each(quick_measurements):
    three = quick_measurements.subset(quick_measurements.actuator_ids[:3])
    small_base = _LinearBase()
    result = leave_one_configuration_out(
        three, small_base, ["scale-offset"], calibrated=True, learning_curve=False
    )
    rows = result.per_actuator
    assert len(rows) == 3 and np.isfinite(rows["calibrated_width_deg"]).all()
    assert result.calibrations["scale-offset"]["n_actuators"] == 3
    # Without calibration two actuators are scored as before.
    two = quick_measurements.subset(quick_measurements.actuator_ids[:2])
    plain = leave_one_configuration_out(
        two, small_base, ["scale-offset"], calibrated=False, learning_curve=False
    )
    assert len(plain.per_actuator) == 2 and plain.calibrations == {}


def test_the_cli_refuses_calibrate_with_two_actuators_in_one_line(tmp_path, capsys):
    lab = tmp_path / "two.csv"
    argv = ["lab", "measure", "--plant", "analytical", "--pmax", "0.12", "--out", str(lab)]
    argv += ["--design", "100,6,2,2,5,8", "--design", "130,7,2.5,3,10,9", "--json"]
    assert main(argv) == 0
    capsys.readouterr()
    out = tmp_path / "loco"
    # The refusal comes before any strategy is fitted (the base is read first: its
    # actuator description says how to read the measurements).
    argv = ["transfer", "loco", str(lab), "--out", str(out), "--calibrate"]
    argv += ["--strategies", "scale-offset"]
    assert main(argv) == 2
    err = capsys.readouterr().err.strip().splitlines()
    assert len(err) == 1, err
    assert err[0] == (
        "softbend: error: --calibrate: needs measurements of at least 3 actuators (the "
        "held-out one and two others, each predicted by a model fitted without it, to "
        "calibrate its interval on); got 2 (100,6,2,2,5,8; 130,7,2.5,3,10,9)"
    )
    assert not out.exists()
