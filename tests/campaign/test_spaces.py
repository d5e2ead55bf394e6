"""Design spaces named by text, and the size guard of a campaign over one."""

from __future__ import annotations

import numpy as np
import pytest

from softbend.campaign import footprint, spaces
from softbend.campaign.footprint import (
    DISK_LIMIT_BYTES,
    MEMORY_LIMIT_BYTES,
    campaign_footprint,
    check_footprint,
)
from softbend.campaign.spaces import parse_space
from softbend.errors import LimitError


@pytest.mark.parametrize(
    ("text", "kind", "n"),
    [("table1", "table1", 972), ("corners", "corners", 64), ("lhs:3", "lhs", 3)],
)
def test_the_size_is_known_before_any_design_is_built(text, kind, n):
    spec = parse_space(text)
    assert (spec.kind, spec.n_designs) == (kind, n)
    assert len(spec.build(seed=1)) == n


def test_a_huge_space_is_read_without_being_built(monkeypatch):
    monkeypatch.setenv("SOFTBEND_MAX_DESIGNS", str(10**13))
    assert parse_space("sobol:1000000000000").n_designs == 10**12


@pytest.mark.parametrize("text", ["lhs:99999999999999999999", "sobol:1000001"])
def test_a_space_over_the_designs_limit_is_one_limit_error(text):
    with pytest.raises(LimitError) as err:
        parse_space(text)
    message = str(err.value)
    assert err.value.key == "space" and message.startswith(f"space: {text} is ")
    assert "more than the limit of 1,000,000 designs" in message
    assert "SOFTBEND_MAX_DESIGNS" in message and "\n" not in message


def test_a_number_of_thousands_of_digits_is_the_same_limit_error():
    text = "lhs:" + "9" * 5000  # more digits than Python reads as an integer
    with pytest.raises(LimitError, match="a number of 5,000 digits, more than the limit") as err:
        parse_space(text)
    assert "SOFTBEND_MAX_DESIGNS" in str(err.value) and len(str(err.value)) < 300


def test_the_designs_limit_is_raised_by_its_variable(monkeypatch):
    monkeypatch.setenv("SOFTBEND_MAX_DESIGNS", "2000000")
    assert parse_space("lhs:1500000").n_designs == 1_500_000
    monkeypatch.setenv("SOFTBEND_MAX_DESIGNS", "10")
    assert parse_space("lhs:0010").n_designs == 10
    with pytest.raises(LimitError, match="more than the limit of 10 designs"):
        parse_space("table1")
    with pytest.raises(LimitError, match="more than the limit of 10 designs"):
        parse_space("corners")


@pytest.mark.parametrize("text", ["LHS:3", "Table1", " lhs:3", "lhs:0", "lhs:", "grid:5", "lhs:-3"])
def test_names_are_lower_case_like_every_other_choice(text):
    with pytest.raises(ValueError, match=r"^space: must be one of table1, corners") as err:
        parse_space(text)
    assert "(lower case, N >= 1)" in str(err.value) and f'got "{text}"' in str(err.value)


def test_the_footprint_grows_with_designs_and_pressures():
    one = campaign_footprint(1000, 101)
    assert campaign_footprint(2000, 101).memory_bytes == 2 * one.memory_bytes
    assert campaign_footprint(1000, 201).disk_bytes > 1.9 * one.disk_bytes
    # Measured: about 8.8 kB per analytical design of 101 pressures in DuckDB.
    assert 8_000 < one.disk_bytes / 1000 < 12_000
    shard = campaign_footprint(1000, 101, n_stored=100)
    assert shard.memory_bytes == one.memory_bytes and shard.disk_bytes == one.disk_bytes // 10
    assert "1000 designs (100 in this shard) x 101 pressures" in shard.describe()


@pytest.fixture
def roomy(monkeypatch):
    """A machine with 1 TiB of memory and 1 PiB of free disk."""
    monkeypatch.setattr(footprint, "_available_memory_bytes", lambda: 1024**4)
    monkeypatch.setattr(footprint, "_free_disk_bytes", lambda db: 1024**5)


def test_a_large_campaign_needs_allow_large(tmp_path, roomy):
    big = campaign_footprint(10_000_000, 101)
    assert big.memory_bytes > MEMORY_LIMIT_BYTES and big.disk_bytes > DISK_LIMIT_BYTES
    large = r"^allow_large: must be set to run a large campaign, about 23.3 GiB of memory"
    with pytest.raises(ValueError, match=large) as e:
        check_footprint(big, tmp_path / "c.duckdb")
    assert "86.5 GiB of disk for 10000000 designs x 101 pressures" in str(e.value)
    assert str(e.value).endswith("(more than 2 GiB of memory or 20 GiB of disk)")
    check_footprint(big, tmp_path / "c.duckdb", allow_large=True)
    check_footprint(campaign_footprint(100_000, 101), tmp_path / "c.duckdb")


def test_a_campaign_that_does_not_fit_is_refused_even_when_allowed(tmp_path, monkeypatch):
    monkeypatch.setattr(footprint, "_available_memory_bytes", lambda: 8 * 1024**3)
    monkeypatch.setattr(footprint, "_free_disk_bytes", lambda db: 50 * 1024**3)
    big = campaign_footprint(10_000_000, 101)
    with pytest.raises(
        ValueError, match=r"^space: must give a campaign that fits this machine"
    ) as e:
        check_footprint(big, tmp_path / "c.duckdb", allow_large=True)
    assert "(8 GiB available)" in str(e.value) and "(50 GiB free for" in str(e.value)
    # Disk alone: a small space at the finest pressure grid.
    with pytest.raises(ValueError, match="fits this machine"):
        check_footprint(
            campaign_footprint(10_000, 100_001), tmp_path / "c.duckdb", allow_large=True
        )


def test_a_shard_is_k_of_n():
    from softbend.campaign.footprint import parse_shard

    assert parse_shard("0/8") == (0, 8) and parse_shard(" 2 / 3 ") == (2, 3)
    for text in ("3/3", "1of2", "0/0", "-1/2"):
        with pytest.raises(ValueError, match=r"^shard: must be K/N"):
            parse_shard(text)


def test_ranges_of_one_s_own_are_read_by_short_name():
    assert spaces.parse_ranges(["l=60:90", " phi = 0:20"]) == {
        "l": (60.0, 90.0),
        "phi": (0.0, 20.0),
    }


@pytest.mark.parametrize(
    ("texts", "needle"),
    [
        (["l60:90"], "must be NAME=LOW:HIGH"),
        (["l=a:b"], "must be NAME=LOW:HIGH"),
        (["l=nan:9"], "must be NAME=LOW:HIGH"),
        (["l=90:60"], 'a range of l LOW < HIGH within (0, 1000] mm; got "l=90:60"'),
        (["l=0:60"], "(0, 1000] mm"),
        (["phi=-1:20"], "[0, 60] deg"),
        (["l=60:90", "l=70:80"], "gives l twice"),
        (["r=2:4"], "t's high must be below r's low; got t up to 4 mm and r from 2 mm"),
        (["t=1e-9:1e-8"], "at least 1e-06 mm wide from at least 1e-06 mm"),
        (["phi=0:1e-9"], "at least 1e-06 deg wide (designs are sampled to 1e-06 deg)"),
    ],
)
def test_a_bad_range_is_one_error_naming_the_option(texts, needle):
    with pytest.raises(ValueError, match=r"^ranges: ") as caught:
        spaces.parse_ranges(texts)
    assert needle in str(caught.value)


def test_a_sampled_space_over_own_ranges_stays_inside_them_and_is_seeded():
    spec = parse_space("lhs:50").with_ranges({"l": (60.0, 90.0), "t": (1.0, 1.5)})
    space = spec.build(seed=3)
    frame = space.to_frame()
    assert frame["l_mm"].between(60, 90).all() and frame["t_mm"].between(1, 1.5).all()
    assert frame["r_mm"].between(6, 10).all() and frame["phi_deg"].between(5, 15).all()
    # Latin hypercube: every tenth of the own range of l holds five designs.
    assert (np.histogram(frame["l_mm"], bins=10, range=(60, 90))[0] == 5).all()
    assert space.name == "lhs-50-seed3 l=60:90 t=1:1.5"
    assert spec.build(seed=3).to_frame().equals(frame)


def test_the_levels_of_table_1_take_no_range():
    with pytest.raises(
        ValueError, match=r"^ranges: applies to the sampled spaces lhs:N and sobol:N"
    ):
        parse_space("corners").with_ranges({"l": (60.0, 90.0)})
