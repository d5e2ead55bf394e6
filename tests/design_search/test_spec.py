"""Specifications: targets, ranges and objectives from code, command-line text and TOML."""

from __future__ import annotations

import pytest

from softbend.design_search.spec import Objective, ParameterRange, Specification, Target
from softbend.design_search.spec_text import build_ranges, parse_objectives, target_from_options
from softbend.design_search.spec_toml import load_specifications
from softbend.errors import DatasetError

TRAINED = {
    "l_mm": [100.0, 160.0], "r_mm": [6.0, 10.0], "t_mm": [2.0, 4.0], "b_mm": [2.0, 4.0],
    "phi_deg": [5.0, 15.0], "lc_mm": [8.0, 12.0], "pressure_mpa": [0.0, 0.5],
}  # fmt: skip
AT = Target("angle_at", angle_deg=90, pressure_mpa=0.08)


def test_a_range_s_values_lie_on_its_step():
    assert ParameterRange(3.0, 4.0, 0.5).values() == [3.0, 3.5, 4.0]
    assert ParameterRange(100.0, 101.2, 0.5).values() == [100.0, 100.5, 101.0]
    assert ParameterRange(10.0, 10.0).values() == [10.0] and ParameterRange(10, 10).fixed


def test_unnamed_parameters_take_the_training_range_at_the_mould_s_step():
    spec = Specification(Target("angle_at", angle_deg=90, pressure_mpa=0.08))
    ranges = spec.resolved(TRAINED)
    assert ranges["l"] == ParameterRange(100.0, 160.0, 0.5)
    assert ranges["phi"] == ParameterRange(5.0, 15.0, 1.0)
    assert spec.objectives == (Objective("error"),)
    coarse = Specification(spec.target, steps={"l": 10.0}).resolved(TRAINED)
    assert len(coarse["l"].values()) == 7


@pytest.mark.parametrize(
    ("make", "match"),
    [
        (lambda: Target("angle_at", angle_deg=90, pressure_mpa=80), r"kPa\?"),
        (lambda: Target("angle_at", angle_deg=-5, pressure_mpa=0.08), r"\(0, 360\]"),
        (lambda: Target("spin", angle_deg=90, pressure_mpa=0.08), "angle_at, pressure_for"),
        (lambda: Target("curve", points=((0.05, 40.0),)), "at least 2"),
        (lambda: ParameterRange(4.0, 3.0), "low <= high"),
        (lambda: Objective("colour"), "l, r, t, b, phi, lc, pressure"),
        (
            lambda: Specification(
                Target("angle_at", angle_deg=90, pressure_mpa=0.08),
                objectives=(Objective("pressure"),),
            ),
            "pressure_for",
        ),
        (
            lambda: Specification(
                Target("angle_at", angle_deg=90, pressure_mpa=0.08), margin_deg=3
            ),
            "margin",
        ),
        (
            lambda: Specification(
                Target("max_angle", pressure_mpa=0.1), {"w": ParameterRange(1, 2)}
            ),
            "w",
        ),
    ],
)
def test_bad_specifications_are_one_clear_error(make, match):
    with pytest.raises(ValueError, match=match):
        make()


def test_infeasible_ranges_are_refused_before_searching():
    target = Target("angle_at", angle_deg=90, pressure_mpa=0.08)
    with pytest.raises(ValueError, match="leaves the model's training range"):
        Specification(target, {"t": ParameterRange(1.0, 3.0, 0.5)}).resolved(TRAINED)
    with pytest.raises(ValueError, match="is wider than"):
        Specification(target, {"t": ParameterRange(3.0, 3.2, 0.5)}).resolved(TRAINED)
    with pytest.raises(ValueError, match=r"^ranges: must give the parameter 'l' a range"):
        Specification(target).resolved(None)
    assert Specification(target, {"t": ParameterRange(1.0, 3.0, 0.5)}).resolved(
        TRAINED, allow_extrapolation=True
    )["t"].values() == [1.0, 1.5, 2.0, 2.5, 3.0]


def test_command_line_text():
    ranges, steps = build_ranges(["phi=10"], ["t=3:4"], ["l=1"], step=0.25)
    assert ranges == {"phi": ParameterRange(10, 10), "t": ParameterRange(3, 4, 0.25)}
    assert steps["l"] == 1.0 and steps["r"] == 0.25
    with pytest.raises(ValueError, match=r"^ranges: 't' is given twice"):
        build_ranges(["t=3"], ["t=3:4"])
    with pytest.raises(ValueError, match=r"^fixes: 't' is given twice"):  # named by its option
        build_ranges(["t=3", "t=4"], ())
    with pytest.raises(ValueError, match="NAME=LOW:HIGH"):
        build_ranges((), ["t=3-4"])
    with pytest.raises(ValueError, match=r"^fixes: .*among l, r"):
        build_ranges(["wall=3"])
    assert parse_objectives(["l,volume"], ["sensitivity"]) == (
        Objective("l"), Objective("volume"), Objective("sensitivity", "max")
    )  # fmt: skip
    with pytest.raises(ValueError, match=r"^maximize: must be objectives among"):
        parse_objectives([], ["speed"])
    assert target_from_options(angle=90, at=0.08).kind == "angle_at"
    assert target_from_options(angle=90, max_pressure=0.1).kind == "pressure_for"
    assert target_from_options(max_angle_at=0.1).kind == "max_angle"
    curve = target_from_options(curve="0.1:95, 0.05:40")
    assert curve.points == ((0.05, 40.0), (0.1, 95.0))
    with pytest.raises(ValueError, match=r"^max_angle_at: .*; got at, max_angle_at"):
        target_from_options(angle=90, at=0.08, max_angle_at=0.1)
    with pytest.raises(ValueError, match=r"^angle: is needed with at"):
        target_from_options(at=0.08)


def test_a_toml_file_of_specifications(tmp_path):
    path = tmp_path / "specs.toml"
    path.write_text(
        """
[[spec]]
name = "finger"
angle = 90.0
at = 0.08
minimize = ["l"]
fix = {phi = 10.0}
range = {t = [3.0, 4.0]}
resolution = 0.5
margin = 1.0

[[spec]]
name = "reach"
max_angle_at = 0.1
resolution = {l = 2.0}

[[spec]]
curve = [[0.05, 40.0], [0.1, 95.0]]
tolerance = 5.0
"""
    )
    finger, reach, third = load_specifications(path)
    assert finger.name == "finger" and finger.target.kind == "angle_at"
    assert finger.ranges == {"phi": ParameterRange(10, 10), "t": ParameterRange(3, 4, 0.5)}
    assert finger.objectives == (Objective("l"),) and finger.margin_deg == 1.0
    assert reach.target.kind == "max_angle" and reach.steps["l"] == 2.0
    assert third.name == "spec3" and third.target.tolerance_deg == 5.0
    path.write_text("[[spec]]\nangle = 90\nat = 0.08\ncolour = 'red'\n")
    with pytest.raises(DatasetError, match=r"\[\[spec\]\] 1: unknown key\(s\) 'colour'"):
        load_specifications(path)
    path.write_text("[[spec]\n")
    with pytest.raises(DatasetError, match="line 1, column 7: not valid TOML"):
        load_specifications(path)


def test_paper_b_s_column_names_name_its_parameters_too(tmp_path):
    ranges, _ = build_ranges(["phi_deg=10"], ["t_mm=3:4"])
    assert ranges == {"phi": ParameterRange(10, 10), "t": ParameterRange(3, 4, 0.5)}
    assert parse_objectives(["l_mm"], []) == (Objective("l"),)
    path = tmp_path / "specs.toml"
    path.write_text("[[spec]]\nangle = 90.0\nat = 0.08\nfix = {phi_deg = 10.0}\n")
    (spec,) = load_specifications(path)
    assert spec.ranges == {"phi": ParameterRange(10, 10)}
    path.write_text("[[spec]]\nangle = 90.0\nat = 0.08\nfix = {phi = 10.0, phi_deg = 5.0}\n")
    with pytest.raises(DatasetError, match="gives 'phi' twice"):
        load_specifications(path)
