"""A design search over another actuator's description: its names, kinds, constraints, units.

The PneuNet of the conftest bends θ = p·(0.4·n − 0.5·w + 0.2·L) (p in kPa), so
every answer is checked against a brute force of the closed form on the same
grid: the whole numbers of n_chambers, the multiples of wall_mm's resolution,
both levels of layer, and the description's constraint.
"""

from __future__ import annotations

import itertools
import json

import numpy as np
import pytest

from softbend.actuators import Actuator, Design, DesignParameter
from softbend.design_search.search import find_designs
from softbend.design_search.space import space_of
from softbend.design_search.spec import Objective, ParameterRange, Specification, Target
from softbend.design_search.spec_text import build_ranges, parse_objectives
from softbend.design_search.spec_toml import load_specifications
from softbend.design_search.verify import verify_candidates
from softbend.errors import DatasetError
from softbend.surrogates.persistence import load_surrogate

from .conftest import pneunet_angle, train_pneunet

#: wall_mm >= 0.15·n_chambers: a wall that grows with the chambers it joins.
CONSTRAINED = Actuator(
    name="pneunet-test",
    title="a PneuNet with a wall for its chambers",
    parameters=(
        DesignParameter("n_chambers", "", 6, 12, kind="integer"),
        DesignParameter("wall_mm", "mm", 0.5, 3.0, resolution=0.1),
        DesignParameter("layer", "", kind="categorical", levels=("fabric", "paper")),
    ),
    pressure_column="p_kpa",
    pressure_unit="kPa",
    constraints=("wall_mm >= 0.15 * n_chambers",),
)

#: Training designs that meet the constraint; the walls trained span 1 to 3 mm.
DESIGNS = [
    (n, w, layer)
    for n, w, layer in itertools.product((6, 9, 12), (1.0, 2.0, 3.0), ("fabric", "paper"))
    if w >= 0.15 * n
]


@pytest.fixture(scope="module")
def constrained(tmp_path_factory):
    path = train_pneunet(tmp_path_factory.mktemp("constrained"), DESIGNS, CONSTRAINED)
    return path, load_surrogate(path).actuator


def _brute_force(angle, tolerance, *, constraint=True, layer=None):
    """The smallest n_chambers of a design on the grid (wall 1–3 mm in 0.1) within
    ``tolerance`` of ``angle`` at 30 kPa, by the closed form."""
    best = None
    for n, k, index in itertools.product(range(6, 13), range(10, 31), (0, 1)):
        wall = k / 10
        if layer is not None and index != layer:
            continue
        if constraint and not wall >= 0.15 * n:
            continue
        if abs(pneunet_angle(n, wall, index, 30.0) - angle) <= tolerance:
            best = n if best is None else min(best, n)
    return best


def test_the_model_records_the_description_with_its_constraint(constrained):
    _, actuator = constrained
    assert actuator.constraints == CONSTRAINED.constraints
    assert actuator.parameter("wall_mm").resolution == 0.1
    space = space_of(actuator)
    assert space.names == ("n_chambers", "wall_mm", "layer") and "volume" not in space.objectives
    assert "volume" not in space.objectives and "layer" not in space.objectives
    assert space.objectives["sensitivity"] == "deg/kPa"


def test_the_smallest_chamber_count_that_bends_88_degrees_at_30_kpa(constrained):
    path, actuator = constrained
    target = Target("angle_at", angle_deg=88.0, pressure_mpa=30.0, unit="kPa")
    objectives = parse_objectives(["n_chambers"], [], space_of(actuator))
    spec = Specification(target, objectives=objectives, actuator=actuator)
    result = find_designs(path, spec, top=20)
    assert result.feasible
    expected = _brute_force(88.0, 3.0)
    # the constraint decides: without it, 8 chambers would do
    assert (expected, _brute_force(88.0, 3.0, constraint=False)) == (9, 8)
    best = result.candidates[0]
    assert isinstance(best.design, Design)
    record = best.design.record()
    assert record["n_chambers"] == expected and isinstance(record["n_chambers"], int)
    for c in result.candidates:
        n, wall, layer = c.design.record().values()
        assert isinstance(n, int) and layer in ("fabric", "paper")
        assert wall == pytest.approx(round(wall * 10) / 10, abs=1e-9)  # on the resolution
        assert 1.0 - 1e-9 <= wall <= 3.0 + 1e-9  # the training range within the description
        assert wall >= 0.15 * n - 1e-9  # the constraint
        truth = pneunet_angle(n, wall, ("fabric", "paper").index(layer), 30.0)
        assert c.angle_deg == pytest.approx(truth, abs=1e-3)
        assert abs(c.angle_deg - 88.0) <= 3.0 and c.meets and not c.flags
    assert [c.objectives["n_chambers"] for c in result.candidates] == sorted(
        c.objectives["n_chambers"] for c in result.candidates
    )


def test_every_design_of_the_grid_meets_the_constraint_or_is_left_out(constrained):
    path, actuator = constrained
    spec = Specification(
        Target("max_angle", pressure_mpa=30.0, unit="kPa"),
        {"layer": ParameterRange(1, 1), "n_chambers": ParameterRange(12, 12)},
        actuator=actuator,
    )
    result = find_designs(path, spec, distinct=False, top=50)
    # n = 12 needs a wall of 1.8 mm at least: 1.8, 1.9, ..., 3.0 mm, 13 designs
    assert result.n_designs == 13
    best = result.candidates[0].design.record()
    assert best == {"n_chambers": 12, "wall_mm": 1.8, "layer": "paper"}
    assert result.candidates[0].angle_deg == pytest.approx(30 * (4.8 - 0.9 + 0.2), abs=1e-3)


def test_the_json_names_the_actuator_s_parameters_and_units(constrained):
    path, actuator = constrained
    spec = Specification(
        Target("pressure_for", angle_deg=90.0, pressure_mpa=40.0, unit="kPa"),
        {"layer": ParameterRange(1, 1)},
        (Objective("pressure", unit="kPa"),),
        actuator=actuator,
    )
    result = find_designs(path, spec, top=3)
    payload = json.loads(json.dumps(result.to_dict()))
    assert payload["actuator"] == "pneunet-test" and payload["pressure_unit"] == "kPa"
    assert payload["spec"]["pressure_kpa"] == 40.0 and "pressure_mpa" not in payload["spec"]
    assert payload["spec"]["target"] == "90° ± 3° at no more than 40 kPa"
    assert payload["spec"]["objectives"] == ["min pressure (kPa)"]
    assert payload["spec"]["ranges"]["layer"] == {"levels": ["paper"]}
    assert payload["spec"]["ranges"]["n_chambers"] == {"low": 6, "high": 12, "step": 1}
    assert payload["spec"]["ranges"]["wall_mm"]["unit"] == "mm"
    first = payload["candidates"][0]
    assert set(first["design"]) == {"n_chambers", "wall_mm", "layer"}
    assert first["design"]["layer"] == "paper" and "pressure_kpa" in first
    # the longest, thinnest-walled finger reaches 90° first: p = 90 / (4.8 − 0.5·w + 0.2)
    assert first["design"]["n_chambers"] == 12 and first["design"]["wall_mm"] == 1.8
    assert first["pressure_kpa"] == pytest.approx(90.0 / (4.8 - 0.9 + 0.2), abs=1e-3)
    assert "verified" not in payload


def test_verify_says_the_fem_does_not_model_it_and_runs_nothing(constrained):
    path, actuator = constrained
    spec = Specification(
        Target("angle_at", angle_deg=88.0, pressure_mpa=30.0, unit="kPa"), actuator=actuator
    )
    result = find_designs(path, spec, top=2)
    assert verify_candidates(result, 2, backend="fem") == []
    assert result.verify_skipped == "the FEM does not model actuator pneunet-test"
    assert all(c.fem_meets is None for c in result.candidates)
    payload = result.to_dict()
    assert payload["verified"] is None and payload["verify_skipped"] == result.verify_skipped


def test_ranges_fixes_and_steps_by_the_description(constrained):
    _, actuator = constrained
    space = space_of(actuator)
    ranges, steps = build_ranges(
        ["layer=paper"], ["wall_mm=1:2", "n_chambers=8:10"], ["wall_mm=0.2"], space=space
    )
    assert ranges == {
        "layer": ParameterRange(1, 1),
        "wall_mm": ParameterRange(1, 2, 0.2),
        "n_chambers": ParameterRange(8, 10, 1.0),
    }
    assert steps == {"n_chambers": 1.0, "wall_mm": 0.2}
    for args, needle in [
        ((["wall=1"],), "fixes: names 'wall', which is not a design parameter"),
        (((), ["wall_mm=2:1"]), "finite LOW <= HIGH"),
        (((), ["wall_mm=0.2:2"]), "0.2 leaves the range [0.5, 3] mm"),
        (((), ["n_chambers=6.5:9"]), "6.5 is not a whole number"),
        (((), ["layer=0:1"]), "cannot span the categorical parameter 'layer'"),
        ((["layer=wood"],), "levels fabric, paper"),
        ((["wall_mm=1.25"],), "not a multiple of the resolution 0.1 mm"),
        (((), (), ["wall_mm=0.25"]), "whole multiple of the resolution 0.1 mm"),
        (((), (), ["n_chambers=0.5"]), "whole number >= 1"),
    ]:
        with pytest.raises(ValueError, match=None) as caught:
            build_ranges(*args, space=space)
        assert needle in str(caught.value), (args, str(caught.value))


def test_a_specification_is_checked_against_its_actuator(constrained):
    path, actuator = constrained
    in_kpa = Target("angle_at", angle_deg=88.0, pressure_mpa=30.0, unit="kPa")
    with pytest.raises(ValueError, match=r"in MPa, but the actuator pneunet-test .* kPa"):
        Specification(Target("angle_at", angle_deg=88.0, pressure_mpa=0.03), actuator=actuator)
    with pytest.raises(ValueError, match="among n_chambers, wall_mm, layer"):
        Specification(in_kpa, {"l": ParameterRange(100, 100)}, actuator=actuator)
    with pytest.raises(ValueError, match="must be one of n_chambers, wall_mm, pressure"):
        Specification(in_kpa, objectives=(Objective("volume"),), actuator=actuator)
    trained = load_surrogate(path).metadata["training_ranges"]
    too_thin = Specification(in_kpa, {"wall_mm": ParameterRange(0.2, 1.0, 0.1)}, actuator=actuator)
    with pytest.raises(ValueError, match=r"'wall_mm' \(0.2:1 mm\) leaves the range"):
        too_thin.resolved(trained)
    untrained = Specification(in_kpa, {"wall_mm": ParameterRange(0.5, 1.0, 0.1)}, actuator=actuator)
    with pytest.raises(ValueError, match="leaves the model's training range"):
        untrained.resolved(trained)
    with pytest.raises(
        ValueError, match=r"the actuator sfrba \(paper B's .* the actuator pneunet-test"
    ):
        find_designs(path, Specification(Target("max_angle", pressure_mpa=0.05)))
    with pytest.raises(ValueError, match="kPa"):
        Target("angle_at", angle_deg=90.0, pressure_mpa=2000.0, unit="kPa")


def test_a_spec_file_names_the_actuator_s_parameters(constrained, tmp_path):
    _, actuator = constrained
    path = tmp_path / "specs.toml"
    path.write_text(
        '[[spec]]\nname = "finger"\nangle = 88.0\nat = 30.0\nminimize = ["n_chambers"]\n'
        'fix = {layer = "paper"}\nrange = {wall_mm = [1.0, 2.0]}\nresolution = {wall_mm = 0.2}\n'
        '[[spec]]\nname = "curve"\ncurve = [[10.0, 30.0], [30.0, 90.0]]\nresolution = 0.5\n'
    )
    finger, curve = load_specifications(path, actuator=actuator)
    assert finger.actuator == actuator and finger.target.unit == "kPa"
    assert finger.ranges == {"layer": ParameterRange(1, 1), "wall_mm": ParameterRange(1, 2, 0.2)}
    assert finger.objectives == (Objective("n_chambers", "min", ""),)
    assert curve.target.points == ((10.0, 30.0), (30.0, 90.0)) and curve.steps["wall_mm"] == 0.5
    for table, needle in [
        ("fix = {wall = 1.0}", "expected parameters among n_chambers, wall_mm, layer"),
        ("range = {layer = [0, 1]}", "a categorical parameter takes no range"),
        ("fix = {n_chambers = 7.5}", "not a whole number"),
        ('fix = {layer = "wood"}', "levels fabric, paper"),
        ('minimize = ["volume"]', "objectives among n_chambers, wall_mm, pressure"),
        ("resolution = {n_chambers = 0.5}", "whole number >= 1"),
    ]:
        path.write_text(f"[[spec]]\nangle = 88.0\nat = 30.0\n{table}\n")
        with pytest.raises(DatasetError) as caught:
            load_specifications(path, actuator=actuator)
        assert needle in str(caught.value), (table, str(caught.value))
    path.write_text("[[spec]]\nangle = 88.0\nat = 3000.0\n")
    with pytest.raises(DatasetError, match=r"\(0, 1000\] kPa"):
        load_specifications(path, actuator=actuator)


def test_a_table_described_actuator_searches_its_continuous_parameter_on_a_round_step(
    pneunet_model,
):
    actuator = load_surrogate(pneunet_model).actuator
    space = space_of(actuator)
    assert space.grid_steps() == {"wall_mm": 0.025}  # 2.5 mm in 100 steps
    spec = Specification(
        Target("angle_at", angle_deg=90.0, pressure_mpa=30.0, unit="kPa"),
        {"layer": ParameterRange(1, 1)},
        parse_objectives(["n_chambers"], [], space),
        actuator=actuator,
    )
    result = find_designs(pneunet_model, spec)
    best = result.candidates[0].design.record()
    # paper, 30 kPa: θ = 12·n − 15·w + 6: n = 8 with w in [0.6, 1.0], n = 7 cannot reach 87°
    assert best["n_chambers"] == 8 and 0.6 - 1e-9 <= best["wall_mm"] <= 1.0 + 1e-9
    assert result.candidates[0].angle_deg == pytest.approx(90.0, abs=3.0)
    walls = np.array([c.design.record()["wall_mm"] for c in result.candidates])
    assert np.allclose(walls / 0.025, np.round(walls / 0.025))
