import math

import numpy as np
import pytest

from softbend._validation import check_choice, check_finite_array, check_int, check_range
from softbend.errors import ConvergenceError, DatasetError, SoftbendError


def test_check_range_message_format_matches_the_project_convention():
    with pytest.raises(ValueError) as info:
        check_range(-2.0, "wall_thickness_mm", low=0.0)
    assert str(info.value) == "wall_thickness_mm: must be a number in (0, inf); got -2.0"
    assert info.value.key == "wall_thickness_mm"
    assert info.value.detail == "must be a number in (0, inf); got -2.0"


@pytest.mark.parametrize("value", [math.nan, "abc", None, True, 0.0, 1.0])
def test_check_range_rejects_nan_non_numbers_bools_and_open_bounds(value):
    with pytest.raises(ValueError):
        check_range(value, "x", low=0.0, high=1.0)


def test_check_range_accepts_inclusive_bounds_and_converts():
    assert check_range("0.5", "x", low=0.0, high=1.0) == 0.5
    assert check_range(1, "x", low=0.0, high=1.0, high_inclusive=True) == 1.0


def test_check_choice_lists_the_allowed_values():
    with pytest.raises(ValueError, match=r"^mode: must be one of 'a', 'b'; got \"c\"$"):
        check_choice("c", "mode", ("a", "b"))


def test_check_finite_array_points_at_the_first_bad_value():
    with pytest.raises(
        DatasetError, match=r"^pressure_kpa: must be finite; got .*nan.* at position 2 \(2 non"
    ):
        check_finite_array([1.0, 2.0, np.nan, np.inf], "pressure_kpa")


def test_error_hierarchy_lets_standard_handlers_catch_input_errors():
    assert issubclass(DatasetError, ValueError)
    assert issubclass(DatasetError, SoftbendError)
    error = ConvergenceError("Newton stalled", pressure_mpa=0.105, step=21, residual=3e-4)
    assert "pressure_mpa=0.105" in str(error) and "step=21" in str(error)
    assert error.residual == 3e-4


@pytest.mark.parametrize("value", [0, -1, 1.0, 2.5, True, "3", None])
def test_check_int_rejects_non_integers_and_values_below_low(value):
    with pytest.raises(ValueError, match=r"^epochs: must be an integer in \[1, inf\); got "):
        check_int(value, "epochs", low=1)


def test_check_int_accepts_numpy_integers():
    assert check_int(np.int64(3), "epochs", low=1) == 3
    assert type(check_int(np.int64(3), "epochs")) is int


def test_check_object_keys_names_the_place_and_the_keys():
    from softbend._validation import check_object_keys
    from softbend.errors import SchemaError

    ok = {"a": 1, "b": 2}
    assert check_object_keys(ok, "top", ("a", "b", "c"), ("a",), SchemaError) is ok
    with pytest.raises(SchemaError, match=r"^'top' must be a JSON object; got \[1\]$"):
        check_object_keys([1], "top", ("a",), (), SchemaError)
    with pytest.raises(SchemaError, match=r"unknown key\(s\) 'x' in 'top'; allowed keys: a, b"):
        check_object_keys({"a": 1, "x": 2}, "top", ("a", "b"), (), SchemaError)
    with pytest.raises(SchemaError, match=r"'top' lacks the key\(s\) b"):
        check_object_keys({"a": 1}, "top", ("a", "b"), ("a", "b"), SchemaError)
