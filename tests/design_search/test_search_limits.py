"""A search's size is counted before anything is built; listing N candidates is not quadratic."""

from __future__ import annotations

import time

import numpy as np
import pytest

from softbend.design_search import search
from softbend.design_search.search import (
    MAX_DESIGNS,
    TOP,
    find_designs,
    grid_size,
    pareto_front,
    searched_ranges,
)
from softbend.design_search.spec import NAMES, ParameterRange, Specification, Target

AT_90 = Target("angle_at", angle_deg=90.0, pressure_mpa=0.08)
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
    spec = Specification(AT_90, steps=dict.fromkeys(NAMES, 1e-9))
    started = time.perf_counter()
    with pytest.raises(ValueError) as caught:
        searched_ranges(spec, TRAINED)
    assert time.perf_counter() - started < 1.0
    message = str(caught.value)
    assert message.startswith("steps: ") and f"{MAX_DESIGNS:,}" in message
    assert "coarsen the resolution" in message
    assert "l 60,000,000,001 at 1e-09 mm" in message
    ranges, total = searched_ranges(Specification(AT_90), TRAINED)
    assert total == grid_size(ranges) == 121 * 9 * 5 * 5 * 11 * 9


def test_ranges_without_any_actuator_are_refused_and_the_others_skip_t_not_below_r(
    linear_model,
):
    none = Specification(AT_90, {"r": ParameterRange(2.0, 3.0, 0.5), "t": ParameterRange(3, 4)})
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
    spec = Specification(AT_90, {"t": ParameterRange(0.0, 1.0, 0.5)})
    with pytest.raises(ValueError, match=r"'t' \(0:1 mm\) leaves the values a design may take"):
        searched_ranges(spec, TRAINED, allow_extrapolation=True)


def test_top_has_a_declared_range(linear_model):
    assert (TOP.low, TOP.high) == (1, 1000) and TOP.why
    for bad in (0, 1001, 10**9, True):
        with pytest.raises(ValueError, match=r"^top: must be an integer in"):
            find_designs(linear_model, Specification(AT_90), top=bad)
    # Each candidate of a continuous search is polished on its own: a shorter list.
    continuous = Specification(AT_90, {"l": ParameterRange(100.0, 160.0, 0.0)})
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
    axes = search._grid(ranges)
    designs = search._designs_at(axes, rng.integers(0, grid_size(ranges), size=800))
    tolerance = np.array([ranges[n].step for n in NAMES]) + 1e-9
    listed = search._Listed(ranges)
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
    spec = Specification(AT_90, ranges)
    started = time.perf_counter()
    result = find_designs(linear_model, spec, top=200)
    assert time.perf_counter() - started < 30.0  # over 60 s when it was quadratic
    assert len(result.candidates) == 200
    designs = np.array([c.design.as_array() for c in result.candidates])
    steps = np.array([0.5, 0.5, 0.5, 0.5, 1.0, 0.0]) + 1e-9
    for i in range(len(designs)):  # no listed design is one step from another
        others = np.delete(designs, i, axis=0)
        assert not np.any(np.all(np.abs(others - designs[i]) <= steps, axis=1))
