"""The FEM's solver statistics: the keys of FEMStats, and their round trips through storage."""

from __future__ import annotations

import json
import math
import typing

import pandas as pd
import pytest

from softbend._io import json_text
from softbend.campaign.store import CampaignStore
from softbend.dataset_writing import _design_table
from softbend.fem import FEMStats, FEMTimings, fem_stats, simulate
from softbend.models import default_pressures_mpa

from .conftest import COARSE, REFERENCE

GRID = default_pressures_mpa(0.01)


@pytest.fixture(scope="module")
def result():
    return simulate(REFERENCE, GRID, COARSE)


def _check_type(value, expected, where):
    origin = typing.get_origin(expected)
    if origin is typing.NotRequired:
        (expected,) = typing.get_args(expected)
        origin = typing.get_origin(expected)
    if origin is list:
        (item,) = typing.get_args(expected)
        assert isinstance(value, list), where
        for k, entry in enumerate(value):
            _check_type(entry, item, f"{where}[{k}]")
    elif origin is dict:
        assert isinstance(value, dict), where
    elif typing.is_typeddict(expected):
        _check_typeddict(value, expected, where)
    elif expected is float:
        assert isinstance(value, float), where
    else:
        assert isinstance(value, expected) and not isinstance(value, bool), where


def _check_typeddict(value, kind, where):
    hints = typing.get_type_hints(kind, include_extras=True)
    assert kind.__required_keys__ <= set(value) <= set(hints), where
    for key, entry in value.items():
        _check_type(entry, hints[key], f"{where}[{key!r}]")


def test_an_fem_sweep_records_exactly_the_keys_and_types_of_femstats(result):
    _check_typeddict(result.stats, FEMStats, "stats")
    assert set(result.stats["timings"]) == set(FEMTimings.__required_keys__)
    assert "failure" not in result.stats  # only when the sweep stopped on an error
    assert "step_volume_mm3" not in result.stats  # the PneuNet's sweeps record it
    # ... and, with contact, the contact force and pressure of every step.
    assert "step_contact_force_n" not in result.stats
    assert FEMStats.__optional_keys__ == {
        "failure",
        "step_volume_mm3",
        "step_contact_force_n",
        "step_contact_pressure_kpa",
    }


def test_fem_stats_is_the_same_dictionary_read_by_key(result):
    stats = fem_stats(result)
    assert stats is result.stats
    assert fem_stats(result.stats) is result.stats
    assert stats["stop_reason"] == "reached the last pressure"
    assert stats["steps_mpa"][0] == 0.0 and stats["ndof"] > 0
    assert len(stats["step_angles_deg"]) == len(stats["steps_mpa"])


def _same(a, b):
    """Equal, with NaN equal to NaN (the campaign store keeps NaN as NaN)."""
    if isinstance(a, float) and isinstance(b, float):
        return a == b or (math.isnan(a) and math.isnan(b))
    if isinstance(a, list) and isinstance(b, list):
        return len(a) == len(b) and all(_same(x, y) for x, y in zip(a, b, strict=True))
    if isinstance(a, dict) and isinstance(b, dict):
        return a.keys() == b.keys() and all(_same(a[k], b[k]) for k in a)
    return a == b


def test_the_stats_round_trip_through_the_campaign_store_and_the_dataset_table(result, tmp_path):
    with CampaignStore(tmp_path / "c.duckdb") as store:
        store.bind("fem", GRID)
        store.record_success(result)
    with CampaignStore(tmp_path / "c.duckdb", read_only=True) as store:
        designs = store.load_designs()
    stored = json.loads(designs["stats"].iloc[0])
    assert _same(stored, result.stats)
    _check_typeddict(stored, FEMStats, "stored stats")
    table = _design_table(designs)
    row = table.iloc[0]
    stats = fem_stats(stored)
    assert row["stop_reason"] == stats["stop_reason"]
    assert row["stop_kind"] == "last pressure"
    assert row["load_steps"] == len(stats["steps_mpa"])
    assert row["ndof"] == stats["ndof"] and row["rejected_steps"] == stats["rejected_steps"]
    assert row["options_sha256"] == stats["options_sha256"] == COARSE.digest()


def test_the_stats_round_trip_through_strict_json(result):
    # What `softbend fem run` writes to sweep.json: strict JSON, NaN as null.
    back = json.loads(json_text(result.stats))
    assert back.keys() == result.stats.keys()
    _check_typeddict(back, FEMStats, "sweep.json stats")
    assert back["steps_mpa"] == result.stats["steps_mpa"]
    assert back["timings"] == result.stats["timings"]


def test_a_design_of_another_backend_reads_as_empty_fem_stats():
    designs = pd.DataFrame(
        {
            "design_id": ["x"],
            **{name: [1.0] for name in ("l_mm", "r_mm", "t_mm", "b_mm", "phi_deg", "lc_mm")},
            "status": ["done"],
            "error": [None],
            "n_samples": [3],
            "max_pressure_mpa": [0.01],
            "max_angle_deg": [1.0],
            "wall_time_s": [0.1],
            "newton_iterations_total": [0],
            "mesh_size": [None],
            "softbend_version": ["0"],
            "finished_at": [pd.Timestamp("2024-01-01")],
            "stats": [json.dumps({"warnings": []})],
        }
    )
    row = _design_table(designs).iloc[0]
    assert (row["stop_reason"], row["load_steps"], row["ndof"]) == ("", 0, 0)
