"""Actuator descriptions: parameters, constraints, designs by name, round trips, registry."""

from __future__ import annotations

import re
import warnings

import numpy as np
import pandas as pd
import pytest

from softbend.actuators import (
    ACTUATORS,
    PRESSURE_UNITS,
    SFRBA,
    Actuator,
    ActuatorError,
    DesignParameter,
    get_actuator,
    parse_ranges,
    pressure_to_mpa,
)
from softbend.design import PARAMETERS, sfrba_design


def pneunet() -> Actuator:
    return Actuator(
        name="test-pneunet",
        title="a PneuNet for tests",
        parameters=(
            DesignParameter("n_chambers", "", 6, 14, kind="integer"),
            DesignParameter("wall_mm", "mm", 1.0, 3.0, resolution=0.1),
            DesignParameter("height_mm", "mm", 8.0, 16.0),
            DesignParameter("layer", kind="categorical", levels=("paper", "fabric")),
        ),
        pressure_column="p_kpa",
        pressure_unit="kPa",
        constraints=("4 * wall_mm < height_mm",),
    )


def test_paper_b_is_registered_with_its_six_parameters_in_order():
    assert get_actuator("sfrba") is SFRBA
    assert SFRBA.names == PARAMETERS
    assert SFRBA.features == (*PARAMETERS, "pressure_mpa")
    assert SFRBA.pressure_unit == "MPa" and SFRBA.fem_family == "sfrba"


def test_paper_b_design_by_name_equals_by_position_and_sfrba_design():
    by_name = SFRBA.parse_design("l_mm=100,r_mm=6,t_mm=2,b_mm=2,phi_deg=5,lc_mm=8")
    by_position = SFRBA.parse_design("100,6,2,2,5,8")
    np.testing.assert_array_equal(by_name, by_position)
    np.testing.assert_array_equal(by_name, sfrba_design(100, 6, 2, 2, 5, 8).as_array())


def test_paper_b_constraint_wall_thinner_than_radius():
    with pytest.raises(ActuatorError, match="t_mm < r_mm"):
        SFRBA.parse_design("100,6,7,2,5,8")


@pytest.mark.parametrize(
    ("unit", "factor"), [("kPa", 1e-3), ("MPa", 1.0), ("bar", 0.1), ("psi", 6.894757e-3)]
)
def test_pressure_units_convert_to_mpa(unit, factor):
    assert pressure_to_mpa(unit) == pytest.approx(factor, rel=1e-6)


def test_psi_is_the_pound_per_square_inch():
    # 1 psi = 4.4482216152605 N / (25.4 mm)^2
    assert PRESSURE_UNITS["psi"] == pytest.approx(4.4482216152605 / 25.4**2, rel=1e-12)


@pytest.mark.parametrize("unit", ["kpa", "Pa", "atm", ""])
def test_an_unknown_pressure_unit_is_one_error_naming_the_four(unit):
    with pytest.raises(ActuatorError, match="kPa, MPa, bar, psi"):
        pressure_to_mpa(unit)


def test_design_by_name_encodes_levels_and_checks_kinds():
    a = pneunet()
    codes = a.parse_design("n_chambers=10,wall_mm=2,height_mm=12,layer=fabric")
    np.testing.assert_array_equal(codes, [10, 2, 12, 1])
    assert a.describe(codes) == "n_chambers=10, wall_mm=2 mm, height_mm=12 mm, layer=fabric"
    assert a.design_record(codes) == {
        "n_chambers": 10,
        "wall_mm": 2.0,
        "height_mm": 12.0,
        "layer": "fabric",
    }
    np.testing.assert_array_equal(a.parse_design("10,2,12,fabric"), codes)


@pytest.mark.parametrize(
    ("text", "match"),
    [
        ("n_chambers=10.5,wall_mm=2,height_mm=12,layer=paper", "whole number"),
        ("n_chambers=20,wall_mm=2,height_mm=12,layer=paper", r"in \[6, 14\]"),
        ("n_chambers=10,wall_mm=2,height_mm=12,layer=cloth", "paper, fabric"),
        ("n_chambers=10,wall_mm=2,height_mm=12", "lacks layer"),
        ("n_chambers=10,wall_mm=2,height_mm=12,layer=paper,l_mm=3", "not a design parameter"),
        ("n_chambers=10,wall_mm=nan,height_mm=12,layer=paper", "finite"),
        ("n_chambers=10,wall_mm=2.9,height_mm=5,layer=paper", r"\[8, 16\]"),
        ("n_chambers=10,wall_mm=2.5,height_mm=9,layer=paper", "4 \\* wall_mm < height_mm"),
        ("10,2,12", "4 values"),
        ("", "must be"),
    ],
)
def test_a_bad_design_is_one_error_naming_the_parameter(text, match):
    with pytest.raises(ActuatorError, match=match):
        pneunet().parse_design(text)


def test_snap_keeps_integers_whole_and_continuous_on_the_resolution():
    a = pneunet()
    n, wall = a.parameter("n_chambers"), a.parameter("wall_mm")
    np.testing.assert_array_equal(n.snap(np.array([5.2, 9.6, 30.0])), [6, 10, 14])
    np.testing.assert_allclose(wall.snap(np.array([1.234, 2.96, 0.2])), [1.2, 3.0, 1.0])


def test_constraints_met_is_vectorised():
    a = pneunet()
    rows = np.array([[10, 2.0, 12, 0], [10, 3.0, 6, 0], [10, 2.5, 9.9, 1]])
    np.testing.assert_array_equal(a.constraints_met(rows), [True, False, False])


@pytest.mark.parametrize(
    "text",
    ["wall_mm", "wall_mm < __import__('os')", "wall_mm < mystery", "wall_mm ** 2 < 3", "1 == 1"],
)
def test_a_constraint_is_a_comparison_of_parameters_and_numbers_only(text):
    with pytest.raises(ActuatorError):
        Actuator("x", "x", (DesignParameter("wall_mm", "mm", 1, 3),), constraints=(text,))


@pytest.mark.parametrize(
    ("text", "needle"),
    [
        ("1 / 0 < wall_mm", "'1 / 0 < wall_mm' divides by zero (1 / 0)"),
        ("wall_mm < 2 * (3 / (1 - 1))", "divides by zero (3 / (1 - 1))"),
        ("wall_mm * 1e308 * 10 < 3", None),  # a parameter in it: computed per design
        ("wall_mm < 1e308 * 10", "a number too large to compute (1e308 * 10)"),
        ("wall_mm < -1e999", "a number too large to compute (1e999)"),
    ],
)
def test_a_constraint_s_numbers_are_computed_when_it_is_read(text, needle):
    parameters = (DesignParameter("wall_mm", "mm", 1, 3),)
    if needle is None:
        Actuator("x", "x", parameters, constraints=(text,))
        return
    with pytest.raises(ActuatorError, match=re.escape(needle)):
        Actuator("x", "x", parameters, constraints=(text,))


def test_a_constraint_undefined_for_a_design_is_not_met_and_warns_nothing():
    parameters = (DesignParameter("wall_mm", "mm", 1, 3), DesignParameter("gap_mm", "mm", 1, 3))
    actuator = Actuator("x", "x", parameters, constraints=("wall_mm / (gap_mm - 2) < 5",))
    rows = np.array([[1.0, 1.0], [1.0, 2.0], [2.0, 3.0]])  # -1, 1/0 = inf, 2
    with warnings.catch_warnings():
        warnings.simplefilter("error")
        np.testing.assert_array_equal(actuator.constraints_met(rows), [True, False, True])
        with pytest.raises(ActuatorError, match="breaks the constraint wall_mm / \\(gap_mm - 2\\)"):
            actuator.check_designs(rows)


def test_round_trip_through_json_text():
    import json

    for actuator in (SFRBA, pneunet()):
        back = Actuator.from_dict(json.loads(json.dumps(actuator.to_dict())))
        assert back == actuator
        assert back.constraints == actuator.constraints


def test_description_from_a_table_reads_kinds_and_ranges():
    table = pd.DataFrame(
        {
            "n": [6, 8, 8],
            "w_mm": [1.0, 2.5, 2.0],
            "layer": ["paper", "fabric", "paper"],
            "p_kpa": [0.0, 10.0, 20.0],
            "angle_deg": [0.0, 5.0, 9.0],
        }
    )
    a = Actuator.from_table(
        table, design_columns=["n", "w_mm", "layer"], pressure_column="p_kpa", pressure_unit="kPa"
    )
    n, w, layer = a.parameters
    assert (n.kind, n.low, n.high) == ("integer", 6.0, 8.0)
    assert (w.kind, w.unit, w.low, w.high) == ("continuous", "mm", 1.0, 2.5)
    assert layer.kind == "categorical" and layer.levels == ("fabric", "paper")
    assert a.features == ("n", "w_mm", "layer", "p_kpa")


def test_ranges_are_parsed_by_name_with_one_line_naming_the_allowed_names():
    assert parse_ranges(["w_mm=1:3", " n = 2 : 9 "], ["n", "w_mm"]) == {
        "w_mm": (1.0, 3.0),
        "n": (2.0, 9.0),
    }
    for text in ("x=1:3", "w_mm=3:1", "w_mm=1", "w_mm=a:b", "w_mm=1:inf"):
        with pytest.raises(ActuatorError, match=r"^ranges: must be NAME=LOW:HIGH with NAME one"):
            parse_ranges([text], ["n", "w_mm"])
    with pytest.raises(ActuatorError, match="twice"):
        parse_ranges(["w_mm=1:3", "w_mm=1:2"], ["w_mm"])


def test_a_sampled_range_round_trips_and_is_no_wall():
    p = DesignParameter("w_mm", "mm", 1.0, 2.5, sampled=True)
    assert DesignParameter.from_dict(p.to_dict()) == p
    assert "sampled" not in DesignParameter("w_mm", "mm", 1.0, 2.5).to_dict()
    p.check(np.array([0.5, 3.0]))
    with pytest.raises(ActuatorError, match="must be finite"):
        p.check(np.array([np.nan]))


def test_a_table_s_column_kind_is_numbers_or_wholly_text():
    table = pd.DataFrame(
        {
            "w_mm": ["1.0", "2.5", "2.0"],  # numbers written as text (a Parquet string column)
            "layer": ["paper", "3", "paper"],
            "p_kpa": [0.0, 10.0, 20.0],
            "angle_deg": [0.0, 5.0, 9.0],
        }
    )
    a = Actuator.from_table(
        table, design_columns=["w_mm"], pressure_column="p_kpa", pressure_unit="kPa"
    )
    assert (a.parameters[0].kind, a.parameters[0].low, a.parameters[0].high) == (
        "continuous",
        1.0,
        2.5,
    )
    with pytest.raises(ActuatorError, match=r"^layer: mixes numbers and text \(row 1: .3.\)"):
        Actuator.from_table(
            table, design_columns=["layer"], pressure_column="p_kpa", pressure_unit="kPa"
        )


@pytest.mark.parametrize(
    ("kwargs", "match"),
    [
        ({"parameters": ()}, "at least one"),
        ({"pressure_unit": "Pa"}, "kPa, MPa, bar, psi"),
        ({"pressure_column": "wall_mm"}, "twice"),
        ({"name": "bad name!"}, "name"),
    ],
)
def test_a_bad_description_is_refused(kwargs, match):
    base = {
        "name": "ok",
        "title": "t",
        "parameters": (DesignParameter("wall_mm", "mm", 1, 3),),
    }
    with pytest.raises(ActuatorError, match=match):
        Actuator(**{**base, **kwargs})


@pytest.mark.parametrize(
    ("kwargs", "match"),
    [
        ({"low": 3, "high": 1}, "low <= high"),
        ({"kind": "fuzzy"}, "continuous, integer, categorical"),
        ({"kind": "categorical", "levels": ("a",)}, "two or more"),
        ({"kind": "categorical", "levels": ("a", "a")}, "distinct"),
        ({"levels": ("a", "b")}, "Only a categorical"),
        ({"resolution": 0.0}, "resolution"),
        ({"name": "1abc"}, "name"),
    ],
)
def test_a_bad_parameter_is_refused(kwargs, match):
    with pytest.raises(ActuatorError, match=match):
        DesignParameter(**{"name": "p", "unit": "mm", "low": 0, "high": 1, **kwargs})


def test_registry_refuses_an_unknown_name_listing_the_known():
    with pytest.raises(ValueError, match="sfrba"):
        get_actuator("no-such-actuator")
    assert "sfrba" in ACTUATORS.names()
