"""The declared ranges of the identification settings and their one-line messages."""

from __future__ import annotations

import math

import numpy as np
import pytest

from softbend.identification.ranges import (
    C_RANGE,
    EPSILON_RANGE,
    FOLDS_RANGE,
    LAGS_RANGE,
    MAX_ABS_VALUE,
    MAX_MEMORY_MB_RANGE,
    SEED_RANGE,
    check_integer,
    check_lags_fit,
    check_number,
)


def test_an_integer_out_of_range_names_the_option_the_range_and_the_value():
    assert check_integer(50, LAGS_RANGE, "input_lags") == 50
    assert check_integer(np.int64(3), LAGS_RANGE, "input_lags") == 3
    message = r"^input_lags: must be an integer in \[1, 50\]; got 1000000000$"
    with pytest.raises(ValueError, match=message):
        check_integer(1_000_000_000, LAGS_RANGE, "input_lags")
    with pytest.raises(ValueError, match=r"in \[0, 4294967295\]; got -1$"):
        check_integer(-1, SEED_RANGE, "seed")
    with pytest.raises(ValueError, match=r"; got 99999999999999999999$"):
        check_integer(99999999999999999999, LAGS_RANGE, "output_lags")


@pytest.mark.parametrize(
    "value",
    [True, 2.0, "2", None, 10**5000, -(10**5000)],
    ids=["bool", "float", "text", "none", "5001 digits", "minus 5001 digits"],
)
def test_not_an_integer_or_an_endless_one_is_one_short_line(value):
    with pytest.raises(ValueError, match=r"^folds: must be an integer in \[2, 1000\]") as err:
        check_integer(value, FOLDS_RANGE, "folds")
    assert len(str(err.value)) < 200 and "\n" not in str(err.value)


@pytest.mark.parametrize(
    ("value", "bounds", "shown"),
    [
        (0.0, C_RANGE, r"\(0, 10000\]; got 0\.0"),
        (1e300, C_RANGE, r"\(0, 10000\]; got 1e\+300"),
        (math.nan, EPSILON_RANGE, r"\[0, 10\]; got nan"),
        (math.inf, EPSILON_RANGE, r"\[0, 10\]; got inf"),
        (-1.0, MAX_MEMORY_MB_RANGE, r"\(0, 1e\+09\]; got -1\.0"),
        (10**400, C_RANGE, r"\(0, 10000\]; got an integer of about 401 digits"),
        ("1", C_RANGE, r"\(0, 10000\]; got '1'"),
        (False, C_RANGE, r"\(0, 10000\]; got False"),
    ],
    ids=["zero C", "huge C", "nan", "inf", "negative MiB", "401 digits", "text", "bool"],
)
def test_a_number_out_of_range_is_refused(value, bounds, shown):
    with pytest.raises(ValueError, match=rf"^x: must be a number in {shown}$"):
        check_number(value, bounds, "x")


def test_the_bounds_themselves_are_accepted():
    assert check_number(1e4, C_RANGE, "C") == 1e4
    assert check_number(0, EPSILON_RANGE, "epsilon") == 0.0
    assert check_integer(2**32 - 1, SEED_RANGE, "seed") == 2**32 - 1
    assert np.finfo(np.float64).max > MAX_ABS_VALUE**2 * 1e7  # the reason for the bound


def test_lags_must_leave_the_shortest_experiment_samples_to_predict():
    check_lags_fit(29, 30, ("short", 30))
    with pytest.raises(ValueError, match=r"^output_lags: must be an integer in \[1, 29\] "
                       r"for these experiments \(the shortest, 'short', has 30 sample\(s\).*"
                       r"; got 30$"):  # fmt: skip
        check_lags_fit(30, 2, ("short", 30))
    with pytest.raises(
        ValueError, match=r"^input_lags: must be an integer in \[1, 27\].*leave 4 to"
    ):
        check_lags_fit(1, 28, ("short", 30), predicted=4)
