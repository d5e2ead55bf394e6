import hashlib

import numpy as np
import pytest

from softbend.design import (
    PARAMETERS,
    TABLE1_LEVELS,
    DesignSpace,
    parse_sfrba,
    sfrba_design,
    sfrba_from_sequence,
)


def test_table1_has_972_unique_designs_over_the_paper_levels():
    space = DesignSpace.table1()
    assert len(space) == 972
    assert len({d.design_id for d in space}) == 972
    frame = space.to_frame()
    for name, levels in TABLE1_LEVELS.items():
        assert sorted(frame[name].unique()) == sorted(levels)


def test_corners_are_the_64_extremes():
    corners = DesignSpace.corners()
    assert len(corners) == 64
    frame = corners.to_frame()
    for name, levels in TABLE1_LEVELS.items():
        assert set(frame[name]) == {min(levels), max(levels)}


def test_design_id_is_stable_and_distinguishes_designs():
    a = sfrba_design(100, 6, 2, 2, 5, 10)
    assert a.design_id == sfrba_design(100.0, 6.0, 2.0, 2.0, 5.0, 10.0).design_id
    assert a.design_id == parse_sfrba("100,6,2,2,5,10").design_id
    assert a.design_id != sfrba_design(100, 6, 2, 2, 5, 12).design_id
    # The id is a content hash of the rounded parameters, so stored campaigns stay addressable
    # across versions and machines.
    canonical = "100.000000,6.000000,2.000000,2.000000,5.000000,10.000000"
    assert a.design_id == hashlib.sha1(canonical.encode()).hexdigest()[:16]


def test_parse_round_trip_and_array_order():
    design = parse_sfrba("120,8,3,2,10,12")
    assert parse_sfrba(str(design)) == design
    np.testing.assert_array_equal(design.as_array(), [120, 8, 3, 2, 10, 12])
    assert list(design.as_dict()) == list(PARAMETERS)


@pytest.mark.parametrize("method", ["lhs", "sobol"])
def test_space_filling_samples_are_seeded_and_inside_the_ranges(method):
    a = DesignSpace.sample(16, method=method, seed=3)
    b = DesignSpace.sample(16, method=method, seed=3)
    c = DesignSpace.sample(16, method=method, seed=4)
    assert [d.design_id for d in a] == [d.design_id for d in b]
    assert [d.design_id for d in a] != [d.design_id for d in c]
    frame = a.to_frame()
    for name, levels in TABLE1_LEVELS.items():
        assert frame[name].between(min(levels), max(levels)).all()


def test_latin_hypercube_stratifies_every_parameter():
    n = 20
    frame = DesignSpace.sample(n, method="lhs", seed=0).to_frame()
    for name, levels in TABLE1_LEVELS.items():
        unit = (frame[name] - min(levels)) / (max(levels) - min(levels))
        strata = np.minimum((unit * n).astype(int), n - 1)
        assert sorted(strata) == list(range(n))


@pytest.mark.parametrize(
    ("field", "value"),
    [("t_mm", -2.0), ("r_mm", 0.0), ("l_mm", float("nan")), ("phi_deg", 75.0), ("lc_mm", "x")],
)
def test_bad_design_values_name_the_field_and_the_range(field, value):
    values = dict(zip(PARAMETERS, (100, 6, 2, 2, 5, 10), strict=True))
    values[field] = value
    with pytest.raises(ValueError, match=rf"^{field}: must be a number in") as info:
        sfrba_design(**values)
    assert info.value.key == field


def test_parse_rejects_wrong_count_and_text():
    with pytest.raises(ValueError, match=r"^design: must be six comma-separated"):
        parse_sfrba("100,6,a,2,5,10")
    with pytest.raises(ValueError, match=r"^design: A design needs 6 values"):
        parse_sfrba("100,6,2")


def test_design_space_rejects_duplicates_and_bad_levels():
    d = sfrba_design(100, 6, 2, 2, 5, 10)
    with pytest.raises(ValueError, match=r"^designs: must be unique"):
        DesignSpace((d, d))
    with pytest.raises(ValueError, match=r"^levels: must name exactly .*; missing"):
        DesignSpace.grid({"l_mm": [100]})
    with pytest.raises(ValueError, match=r"^method: must be one of"):
        DesignSpace.sample(4, method="grid")


def test_shards_are_disjoint_and_cover_the_space():
    space = DesignSpace.table1()
    shards = [space.shard(k, 7) for k in range(7)]
    ids = [d.design_id for shard in shards for d in shard]
    assert len(ids) == len(set(ids)) == len(space)
    assert max(len(s) for s in shards) - min(len(s) for s in shards) <= 1
    assert shards[2].name == "table1[2/7]"
    assert list(space.shard(0, 1)) == list(space)
    for index, count in ((7, 7), (-1, 3), (0, 0), (1.0, 3)):
        with pytest.raises(ValueError, match=r"^(index|count): must be an integer in"):
            space.shard(index, count)


@pytest.mark.parametrize("text", ["100,6,7,2,5,10", "100,1,50,2,5,10", "100,6,6,2,5,10"])
def test_a_wall_not_thinner_than_the_radius_is_refused_naming_the_rule(text):
    with pytest.raises(ValueError, match=r"^design: t_mm: must be less than r_mm"):
        parse_sfrba(text)
    with pytest.raises(ValueError, match=r"^t_mm: must be less than r_mm"):
        sfrba_from_sequence([float(v) for v in text.split(",")])


def test_every_design_over_the_table1_ranges_stays_valid():
    # The thickest wall in the narrowest chamber of Table 1: t/r = 4/6.
    low = {p: min(v) for p, v in TABLE1_LEVELS.items()}
    high = {p: max(v) for p, v in TABLE1_LEVELS.items()}
    sfrba_design(**{**low, "t_mm": high["t_mm"]})
    assert len(DesignSpace.table1()) == 972 and len(DesignSpace.corners()) == 64
    assert len(DesignSpace.sample(64, method="sobol", seed=1)) == 64
