"""Shipped datasets: the same table as a campaign database, verified on every load."""

from __future__ import annotations

import json

import pandas as pd
import pytest

from softbend.campaign import load_samples, run_campaign
from softbend.campaign.backends import default_pressures_mpa
from softbend.datasets import (
    DESIGN_STAT_COLUMNS,
    table1_fem,
    table1_fem_designs,
    table1_fem_provenance,
    write_dataset,
)
from softbend.design import PARAMETERS, DesignSpace
from softbend.errors import DatasetError


@pytest.fixture(scope="module")
def campaign(tmp_path_factory):
    db = tmp_path_factory.mktemp("campaign") / "c.duckdb"
    run_campaign(
        db,
        DesignSpace.sample(5, seed=2),
        backend="analytical",
        pressures_mpa=default_pressures_mpa(0.2),
        workers=0,
    )
    return db


@pytest.fixture
def dataset(campaign, tmp_path):
    folder = tmp_path / "ds"
    write_dataset(campaign, folder, command="softbend campaign run c.duckdb", description="test")
    return folder


def test_dataset_round_trips_the_campaign_table(campaign, dataset):
    pd.testing.assert_frame_equal(table1_fem(dataset), load_samples(campaign))
    designs = table1_fem_designs(dataset)
    assert list(designs.columns) == ["design_id", *PARAMETERS, *DESIGN_STAT_COLUMNS]
    assert len(designs) == 5 and set(designs["status"]) == {"done"}
    provenance = table1_fem_provenance(dataset)
    assert provenance["command"] == "softbend campaign run c.duckdb"
    assert provenance["designs"]["done"] == 5
    assert provenance["samples"]["rows"] == len(load_samples(campaign))
    assert provenance["cpu_time_s"] == pytest.approx(designs["wall_time_s"].sum())
    assert provenance["campaign_runs"][0]["executor"] == "serial"


@pytest.mark.parametrize("name", ["samples.parquet", "designs.parquet"])
def test_a_truncated_altered_or_missing_file_names_the_file(dataset, name):
    path = dataset / name
    data = path.read_bytes()
    path.write_bytes(data[: len(data) // 2])
    with pytest.raises(DatasetError, match=rf"{name}.*truncated"):
        table1_fem(dataset)
    altered = bytearray(data)
    altered[len(data) // 2] ^= 0xFF
    path.write_bytes(bytes(altered))
    with pytest.raises(DatasetError, match=rf"{name}.*SHA-256"):
        table1_fem_designs(dataset)
    path.unlink()
    with pytest.raises(DatasetError, match=rf"{name}' is missing"):
        table1_fem(dataset)


def test_a_missing_or_foreign_provenance_is_a_clear_error(dataset):
    record = dataset / "provenance.json"
    record.write_text(json.dumps({"something": "else"}))
    with pytest.raises(DatasetError, match="not a softbend provenance record"):
        table1_fem(dataset)
    record.unlink()
    with pytest.raises(DatasetError, match=r"provenance\.json' is missing"):
        table1_fem(dataset)


def test_stop_kinds_and_regions_are_read_from_the_reasons():
    from softbend.datasets import _stop_kind, _stop_region

    assert _stop_kind("bending angle above 300 deg") == "angle limit"
    assert _stop_kind("reached the last pressure") == "last pressure"
    reason = "stretch 5.02 above 5 in the distal cap at x = 104 mm (beyond the material model)"
    assert (_stop_kind(reason), _stop_region(reason, "stretch limit")) == (
        "stretch limit",
        "distal cap",
    )
    reason = "inflation instability above 0.49 MPa: the distal cap at x = 104 mm balloons"
    assert _stop_region(reason, _stop_kind(reason)) == "distal cap"
    assert _stop_kind("no convergence above 0.1 MPa") == "no convergence"
