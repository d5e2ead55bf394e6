"""find_designs: exhaustive on the mould's grid, exact against closed-form answers."""

from __future__ import annotations

import json
import time

import numpy as np
import pytest

from softbend.actuators import SFRBA
from softbend.design_search import search
from softbend.design_search.grid import Listed, designs_at, grid_axes
from softbend.design_search.search import (
    MAX_DESIGNS,
    TOP,
    elastomer_volume_mm3,
    find_designs,
    grid_size,
    pareto_front,
    searched_ranges,
)
from softbend.design_search.spec import NAMES, Objective, ParameterRange, Specification, Target

AT_90 = Target("angle_at", angle_deg=90.0, pressure_mpa=0.08)
# Everything but l fixed: 121 designs, l = 100, 100.5, ..., 160 mm.
ONLY_L = {
    "r": ParameterRange(8, 8),
    "t": ParameterRange(3, 3),
    "b": ParameterRange(3, 3),
    "phi": ParameterRange(10, 10),
    "lc": ParameterRange(10, 10),
}


def _l(candidate) -> float:
    return candidate.design.l_mm


def test_the_smallest_miss_is_the_exact_answer(linear_model):
    result = find_designs(linear_model, Specification(AT_90, ONLY_L))
    assert result.n_designs == 121 and result.feasible
    assert _l(result.candidates[0]) == 112.5
    assert result.candidates[0].angle_deg == pytest.approx(90.0, abs=1e-4)
    # l in [108.75, 116.25] on the 0.5 mm grid: 109 ... 116, 15 designs meet it.
    assert result.n_meeting == 15
    assert all(c.meets and c.error_deg <= 3.0 for c in result.candidates)


def test_minimising_and_maximising_the_length_go_to_the_ends_of_the_tolerance(linear_model):
    shortest = find_designs(linear_model, Specification(AT_90, ONLY_L, (Objective("l"),)))
    longest = find_designs(linear_model, Specification(AT_90, ONLY_L, (Objective("l", "max"),)))
    # Neighbours on the grid (one step apart) are nearly the same actuator: left out ...
    assert [_l(c) for c in shortest.candidates[:3]] == [109.0, 110.0, 111.0]
    assert [_l(c) for c in longest.candidates[:3]] == [116.0, 115.0, 114.0]
    assert shortest.candidates[0].objectives == {"l": 109.0}
    # ... unless asked for.
    every = find_designs(
        linear_model, Specification(AT_90, ONLY_L, (Objective("l"),)), distinct=False
    )
    assert [_l(c) for c in every.candidates[:3]] == [109.0, 109.5, 110.0]


def test_a_margin_keeps_the_answers_off_the_edge(linear_model):
    spec = Specification(AT_90, ONLY_L, (Objective("l"),), margin_deg=1.0)
    result = find_designs(linear_model, spec)
    assert _l(result.candidates[0]) == 110.0  # 0.8·l >= 88 → l >= 110
    assert result.candidates[0].error_deg <= 2.0


def test_every_parameter_stays_in_its_range_and_on_its_step(linear_model):
    ranges = {"t": ParameterRange(3.0, 4.0, 0.5), "phi": ParameterRange(10, 10)}
    result = find_designs(linear_model, Specification(AT_90, ranges), top=50)
    for c in result.candidates:
        assert c.design.t_mm in (3.0, 3.5, 4.0) and c.design.phi_deg == 10.0
        assert c.design.r_mm * 2 == round(c.design.r_mm * 2)
        assert 100.0 <= c.design.l_mm <= 160.0


def test_the_pressure_that_reaches_the_angle(linear_model):
    target = Target("pressure_for", angle_deg=90.0, pressure_mpa=0.1)
    spec = Specification(target, ONLY_L, (Objective("pressure"),))
    result = find_designs(linear_model, spec)
    best = result.candidates[0]
    assert _l(best) == 160.0  # the longest reaches 90° first: p = 90 / (10·160)
    assert best.pressure_mpa == pytest.approx(90.0 / 1600.0, abs=1e-5)
    assert best.objectives["pressure"] == pytest.approx(best.pressure_mpa)
    # Too short to reach 90° below 0.1 MPa: l < 90 mm does not exist, but 0.05 MPa cuts at 180.
    tight = Specification(Target("pressure_for", angle_deg=90.0, pressure_mpa=0.05), ONLY_L)
    assert not find_designs(linear_model, tight).feasible


def test_the_largest_angle_at_a_pressure(linear_model):
    spec = Specification(Target("max_angle", pressure_mpa=0.08), ONLY_L)
    result = find_designs(linear_model, spec)
    assert _l(result.candidates[0]) == 160.0
    assert result.candidates[0].angle_deg == pytest.approx(128.0, abs=1e-4)


def test_a_curve_to_follow(linear_model):
    target = Target("curve", tolerance_deg=2.0, points=((0.05, 62.5), (0.1, 125.0)))
    result = find_designs(linear_model, Specification(target, ONLY_L))
    assert _l(result.candidates[0]) == 125.0 and result.candidates[0].error_deg < 1e-4


def test_a_continuous_parameter_is_polished_to_the_edge(linear_model):
    spec = Specification(AT_90, {**ONLY_L, "l": ParameterRange(100, 160, 0.0)}, (Objective("l"),))
    result = find_designs(linear_model, spec)
    assert _l(result.candidates[0]) == pytest.approx(108.75, abs=0.02)
    assert result.candidates[0].meets


def test_two_objectives_give_the_pareto_front(linear_model):
    # Shorter costs less elastomer but bends less per MPa: the front is the 15 lengths.
    spec = Specification(
        AT_90, ONLY_L, (Objective("volume"), Objective("sensitivity", "max")), name="trade"
    )
    result = find_designs(linear_model, spec, top=15)
    assert result.front.shape == (15, 2)
    order = np.argsort(result.front[:, 0])
    assert np.all(np.diff(result.front[order, 1]) > 0)  # more volume, more dθ/dp
    sensitivities = [c.objectives["sensitivity"] for c in result.candidates]
    assert sensitivities == pytest.approx([10.0 * _l(c) for c in result.candidates], rel=1e-3)


def test_no_design_meets_it_says_so_with_the_closest(linear_model):
    spec = Specification(Target("angle_at", angle_deg=200.0, pressure_mpa=0.08), ONLY_L)
    result = find_designs(linear_model, spec)
    assert not result.feasible
    assert _l(result.candidates[0]) == 160.0  # 128°, the closest
    assert result.candidates[0].error_deg == pytest.approx(72.0, abs=1e-4)
    message = result.message()
    assert "160,8,3,3,10,10" in message and "72" in message and "69" in message  # 72 − 3


def test_outside_the_training_ranges_is_refused_unless_allowed(linear_model):
    ranges = {**ONLY_L, "l": ParameterRange(150.0, 180.0, 10.0)}
    with pytest.raises(
        ValueError, match=r"^allow_extrapolation: must be set for the range of 'l'.*training range"
    ):
        find_designs(linear_model, Specification(AT_90, ranges))
    far = Specification(Target("angle_at", angle_deg=144.0, pressure_mpa=0.08), ranges)
    result = find_designs(linear_model, far, allow_extrapolation=True)
    assert _l(result.candidates[0]) == 180.0
    assert any("l_mm 180 outside" in f for f in result.candidates[0].flags)


def test_designs_past_their_sweep_are_passed_over(short_sweeps_model):
    # The 160 mm designs were swept to 0.05 MPa only: at 0.08 MPa they are not answers.
    spec = Specification(Target("max_angle", pressure_mpa=0.08), ONLY_L)
    result = find_designs(short_sweeps_model, spec)
    assert result.n_passed_over > 0
    assert all(c.flags == [] for c in result.candidates)
    assert _l(result.candidates[0]) < 160.0
    flagged = find_designs(short_sweeps_model, spec, allow_extrapolation=True)
    assert _l(flagged.candidates[0]) == 160.0 and flagged.candidates[0].flags


def test_the_json_names_every_parameter(linear_model):
    result = find_designs(linear_model, Specification(AT_90, ONLY_L))
    payload = json.loads(json.dumps(result.to_dict()))
    first = payload["candidates"][0]
    assert set(first["design"]) == {"l", "r", "t", "b", "phi", "lc"}
    assert first["design"]["l"] == 112.5 and first["angle_deg"] == pytest.approx(90.0)
    assert payload["feasible"] is True and payload["message"] is None


def test_the_shipped_mlp_answers_90_degrees_at_0_08_mpa():
    from softbend.transfer.base import shipped_base_path

    spec = Specification(AT_90, {"phi": ParameterRange(10, 10), "lc": ParameterRange(10, 10)})
    result = find_designs(shipped_base_path(), spec, top=5)
    assert result.feasible and result.n_designs == 121 * 9 * 5 * 5
    best = result.candidates[0]
    assert best.angle_deg == pytest.approx(90.0, abs=0.05) and not best.flags


def test_pareto_front_of_a_small_set():
    values = np.array([[1.0, 5.0], [2.0, 3.0], [3.0, 4.0], [4.0, 1.0], [2.0, 3.0]])
    assert pareto_front(values).tolist() == [0, 1, 3]


def test_elastomer_volume_grows_with_every_size():
    base = np.array([[100.0, 6.0, 2.0, 2.0, 5.0, 8.0]])
    v0 = elastomer_volume_mm3(SFRBA, base)[0]
    for j in (0, 1, 2, 3, 5):
        bigger = base.copy()
        bigger[0, j] += 1.0
        assert elastomer_volume_mm3(SFRBA, bigger)[0] > v0
    assert elastomer_volume_mm3(SFRBA, np.array([[100.0, 6.0, 2.0, 2.0, 15.0, 8.0]]))[0] == v0


def test_a_calibrated_model_gives_each_candidate_its_interval(tmp_path):
    # A refined model records a conformal half-width: each answer carries angle ± it.
    import json as _json

    from .conftest import save_model

    path = save_model(tmp_path / "calibrated.json")
    document = _json.loads(path.read_text())
    document["metadata"]["interval"] = {
        "method": "conformal", "level": 0.9, "half_width_deg": 5.0, "floor_deg": 0.0,
    }  # fmt: skip
    path.write_text(_json.dumps(document))
    result = find_designs(path, Specification(AT_90, ONLY_L))
    best = result.candidates[0]
    assert best.interval_deg == pytest.approx((best.angle_deg - 5.0, best.angle_deg + 5.0))
    assert result.to_dict()["candidates"][0]["interval_deg"] == pytest.approx([85.0, 95.0])


# --- A search's size is counted before anything is built; listing N candidates is not quadratic ---


AT_90_BIG = Target("angle_at", angle_deg=90.0, pressure_mpa=0.08)
TRAINED = {
    "l_mm": [100.0, 160.0], "r_mm": [6.0, 10.0], "t_mm": [2.0, 4.0], "b_mm": [2.0, 4.0],
    "phi_deg": [5.0, 15.0], "lc_mm": [8.0, 12.0], "pressure_mpa": [0.0, 0.5],
}  # fmt: skip


def test_a_range_counts_its_values_without_building_them():
    assert ParameterRange(100.0, 160.0, 0.5).count() == 121
    assert ParameterRange(3.0, 3.0).count() == 1 and ParameterRange(3.0, 4.0).count() == 0
    fine = ParameterRange(100.0, 160.0, 1e-9)
    assert fine.count() == 60_000_000_001
    with pytest.raises(ValueError, match="60,000,000,001 values"):
        fine.values()
    assert ParameterRange(0.0, 60.0, 5e-324).count() == 10**30  # too fine to count in floats


def test_a_grid_too_large_is_refused_at_once_naming_the_resolution():
    spec = Specification(AT_90_BIG, steps=dict.fromkeys(NAMES, 1e-9))
    started = time.perf_counter()
    with pytest.raises(ValueError) as caught:
        searched_ranges(spec, TRAINED)
    assert time.perf_counter() - started < 1.0
    message = str(caught.value)
    assert message.startswith("steps: ") and f"{MAX_DESIGNS:,}" in message
    assert "coarsen the resolution" in message
    assert "l 60,000,000,001 at 1e-09 mm" in message
    ranges, total = searched_ranges(Specification(AT_90_BIG), TRAINED)
    assert total == grid_size(ranges) == 121 * 9 * 5 * 5 * 11 * 9


def test_ranges_without_any_actuator_are_refused_and_the_others_skip_t_not_below_r(
    linear_model,
):
    none = Specification(AT_90_BIG, {"r": ParameterRange(2.0, 3.0, 0.5), "t": ParameterRange(3, 4)})
    with pytest.raises(ValueError, match=r"t < r"):
        searched_ranges(none, TRAINED, allow_extrapolation=True)
    # r from 2 to 4 mm with t = 3 mm: only r = 3.5 and 4 mm are actuators.
    some = Specification(
        Target("max_angle", pressure_mpa=0.08),
        {"l": ParameterRange(110, 110), "r": ParameterRange(2.0, 4.0, 0.5),
         "t": ParameterRange(3, 3), "b": ParameterRange(3, 3), "phi": ParameterRange(10, 10),
         "lc": ParameterRange(10, 10)},
    )  # fmt: skip
    result = find_designs(linear_model, some, allow_extrapolation=True, distinct=False)
    assert result.n_designs == 2
    assert sorted(c.design.r_mm for c in result.candidates) == [3.5, 4.0]


def test_a_design_out_of_its_limits_is_refused_before_the_search():
    spec = Specification(AT_90_BIG, {"t": ParameterRange(0.0, 1.0, 0.5)})
    with pytest.raises(ValueError, match=r"'t' \(0:1 mm\) leaves the values a design may take"):
        searched_ranges(spec, TRAINED, allow_extrapolation=True)


def test_top_has_a_declared_range(linear_model):
    assert (TOP.low, TOP.high) == (1, 1000) and TOP.why
    for bad in (0, 1001, 10**9, True):
        with pytest.raises(ValueError, match=r"^top: must be an integer in"):
            find_designs(linear_model, Specification(AT_90_BIG), top=bad)
    # Each candidate of a continuous search is polished on its own: a shorter list.
    continuous = Specification(AT_90_BIG, {"l": ParameterRange(100.0, 160.0, 0.0)})
    with pytest.raises(
        ValueError, match=r"^top: must be at most 25 with a continuous parameter \(l: step 0"
    ):
        find_designs(linear_model, continuous, top=26)


def _brute_front(values: np.ndarray) -> list[int]:
    """The rule by definition: no earlier row in sorted order is no worse everywhere."""
    v = np.where(np.isnan(values), np.inf, values)
    order = np.lexsort(v.T[::-1])
    kept: list[int] = []
    for i in order:
        if not any(np.all(v[k] <= v[i]) for k in kept):
            kept.append(int(i))
    return kept


@pytest.mark.parametrize("columns", [1, 2, 3, 4])
def test_the_vectorised_pareto_front_is_the_rule(columns):
    rng = np.random.default_rng(columns)
    values = rng.integers(0, 6, size=(400, columns)).astype(float)  # many ties
    values[::37, 0] = np.nan
    assert pareto_front(values).tolist() == _brute_front(values)
    big = rng.random((300_000, 2))
    started = time.perf_counter()
    front = pareto_front(big)
    assert time.perf_counter() - started < 2.0 and front.size < 100


def test_the_filed_cells_find_exactly_the_designs_one_step_away():
    rng = np.random.default_rng(3)
    ranges = {
        "l": ParameterRange(100.0, 110.0, 0.5), "r": ParameterRange(6.0, 10.0, 0.3),
        "t": ParameterRange(3.0, 3.0), "b": ParameterRange(2.0, 4.0, 1.0),
        "phi": ParameterRange(5.0, 15.0, 1.0), "lc": ParameterRange(8.0, 9.0, 0.5),
    }  # fmt: skip
    axes = grid_axes(ranges)
    designs = designs_at(axes, rng.integers(0, grid_size(ranges), size=800))
    tolerance = np.array([ranges[n].step for n in NAMES]) + 1e-9
    listed = Listed(ranges)
    cells = listed.cells_of(designs)
    kept: list[np.ndarray] = []
    for design, cell in zip(designs, cells, strict=True):
        brute = any(np.all(np.abs(k - design) <= tolerance) for k in kept)
        assert listed.near(design, cell) == brute
        if not brute:
            listed.add(design, cell)
            kept.append(design)
    assert 10 < len(kept) < 800


def test_the_batch_check_of_the_support_flags_what_the_flags_name(short_sweeps_model):
    from softbend.surrogates.features import outside_training_ranges
    from softbend.surrogates.predict import load_predictor
    from softbend.surrogates.support import Support

    predictor, saved = load_predictor(short_sweeps_model)
    training = saved.metadata["training_ranges"]
    support = Support.from_dict(saved.metadata["support"])
    rng = np.random.default_rng(0)
    designs = np.column_stack(
        [rng.uniform(90, 170, 200), rng.uniform(6, 10, 200), np.full(200, 3.0),
         np.full(200, 3.0), rng.uniform(4, 16, 200), np.full(200, 10.0)]
    )  # fmt: skip
    masks = []
    for target in (
        Target("max_angle", pressure_mpa=0.08),
        Target("pressure_for", angle_deg=60.0, pressure_mpa=0.2),
        Target("curve", points=((0.03, 30.0), (0.6, 95.0))),
    ):
        spec = Specification(target)
        scores = search._Scorer(predictor.predict, spec).score(designs)
        mask = search._outside_mask(designs, scores, spec, training, support)
        for row in range(designs.shape[0]):
            one = {k: float(v[row]) for k, v in scores.items()}
            flags = search._flags(
                designs[row], one, spec, training, support, outside_training_ranges
            )
            assert mask[row] == bool(flags), (target.kind, designs[row], flags)
        masks.append(mask)
    assert any(m.any() for m in masks) and any(not m.all() for m in masks)


def test_listing_many_candidates_takes_seconds_not_minutes(linear_model):
    # 37,125 of 150,975 designs meet 90° ± 3° here, nearly all one step from a better one.
    ranges = {"l": ParameterRange(100.0, 130.0, 0.5), "lc": ParameterRange(10, 10)}
    spec = Specification(AT_90_BIG, ranges)
    started = time.perf_counter()
    result = find_designs(linear_model, spec, top=200)
    assert time.perf_counter() - started < 30.0  # over 60 s when it was quadratic
    assert len(result.candidates) == 200
    designs = np.array([c.design.as_array() for c in result.candidates])
    steps = np.array([0.5, 0.5, 0.5, 0.5, 1.0, 0.0]) + 1e-9
    for i in range(len(designs)):  # no listed design is one step from another
        others = np.delete(designs, i, axis=0)
        assert not np.any(np.all(np.abs(others - designs[i]) <= steps, axis=1))
