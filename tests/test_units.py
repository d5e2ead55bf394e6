"""Units: a column's unit from its name, declared units checked against it, pressures with units."""

import math

import pytest

from softbend.errors import InputError
from softbend.units import check_column_unit, column_unit, convert_pressure, parse_pressure


@pytest.mark.parametrize(
    ("name", "unit"),
    [("pressure_psi", "psi"), ("p_KPA", "kPa"), ("p_mpa", "MPa"), ("p_bar", "bar"),
     ("p_pa", "Pa"), ("angle_deg", "deg"), ("theta_rad", "rad"), ("pressure", ""),
     ("wall_mm", "")],
)  # fmt: skip
def test_column_unit_reads_the_last_suffix(name, unit):
    assert column_unit(name) == unit


def test_a_declared_unit_that_disagrees_with_the_name_is_refused_naming_both():
    with pytest.raises(InputError, match=r"pressure_psi.*psi.*--pressure-unit says kPa"):
        check_column_unit("pressure_psi", "kPa", "--pressure-unit")
    check_column_unit("pressure_psi", "PSI", "--pressure-unit")  # same unit, any case
    check_column_unit("pressure", "kPa", "--pressure-unit")  # the name says nothing


def test_pressures_parse_with_and_without_a_unit():
    assert parse_pressure("20", "psi", "--at") == 20.0
    assert parse_pressure(20, "psi", "--at") == 20.0
    assert math.isclose(parse_pressure("20psi", "kPa", "--at"), 137.895, rel_tol=1e-5)
    assert math.isclose(parse_pressure("138 kPa", "MPa", "--at"), 0.138)
    assert math.isclose(parse_pressure("1.5BAR", "kPa", "--at"), 150.0)
    assert math.isclose(convert_pressure(1.0, "MPa", "Pa"), 1e6)


@pytest.mark.parametrize("text", ["", "psi", "20 furlongs", "1e999", "nan", "20psi30"])
def test_bad_pressures_name_the_option(text):
    with pytest.raises(InputError, match="--supply"):
        parse_pressure(text, "kPa", "--supply")


def test_a_keyed_check_carries_the_key_and_says_the_predicate():
    with pytest.raises(InputError) as caught:
        check_column_unit("pressure_psi", "kPa", "pressure_unit", key="pressure_unit")
    assert caught.value.key == "pressure_unit"
    assert str(caught.value) == (
        "pressure_unit: is kPa, but the column 'pressure_psi' is named in psi; give psi or "
        "rename the column"
    )


def test_one_spelling_of_a_unit_from_a_column_name():
    from softbend.units import pressure_unit_of, seconds_per_unit, unit_from_name

    names = ("p1_kpa", "p_KPA", "x_um", "t_us", "rho", "a_b", "wall_mm", "fill_pct")
    assert [unit_from_name(n) for n in names] == ["kPa", "kPa", "µm", "µs", "", "", "mm", "%"]
    assert unit_from_name("t_ms", ("length",)) == ""
    assert pressure_unit_of("p_bar") == ("bar", 10.0) and pressure_unit_of("x_mm") is None
    assert seconds_per_unit("clock_min") == 60.0 and seconds_per_unit("t") is None
