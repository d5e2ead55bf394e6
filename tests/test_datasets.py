"""Shipped datasets: the same table as a campaign database, verified on every load."""

from __future__ import annotations

import hashlib
import json

import pandas as pd
import pytest

from softbend.campaign import load_samples, run_campaign
from softbend.campaign.backends import default_pressures_mpa
from softbend.dataset_writing import write_dataset
from softbend.datasets import (
    DESIGN_COLUMN_KINDS,
    DESIGN_STAT_COLUMNS,
    SAMPLE_COLUMN_KINDS,
    table1_fem,
    table1_fem_designs,
    table1_fem_provenance,
    verify_dataset,
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
    from softbend.dataset_writing import _stop_kind, _stop_region

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


# --- a provenance or a table of another shape is one DatasetError naming the file and field ---


def _rewrite_provenance(folder, change):
    record = folder / "provenance.json"
    provenance = json.loads(record.read_text())
    change(provenance)
    record.write_text(json.dumps(provenance))
    return record


@pytest.mark.parametrize(
    ("change", "field", "allowed"),
    [
        (lambda p: p.update(files=list(p["files"])), "'files'", "non-empty object"),
        (lambda p: p.update(files={}), "'files'", "non-empty object"),
        (lambda p: p.pop("files"), "'files'", "missing"),
        (lambda p: p["files"]["samples.parquet"].pop("bytes"), "samples.parquet'", "'bytes'"),
        (
            lambda p: p["files"]["samples.parquet"].update(bytes=None),
            "samples.parquet.bytes'",
            "integer >= 0",
        ),
        (
            lambda p: p["files"]["samples.parquet"].update(
                bytes=str(p["files"]["samples.parquet"]["bytes"])
            ),
            "samples.parquet.bytes'",
            "integer >= 0",
        ),
        (
            lambda p: p["files"]["designs.parquet"].update(bytes=-1),
            "designs.parquet.bytes'",
            "integer >= 0",
        ),
        (
            lambda p: p["files"]["designs.parquet"].update(bytes=True),
            "designs.parquet.bytes'",
            "integer >= 0",
        ),
        (
            lambda p: p["files"]["designs.parquet"].update(bytes=1.5e3),
            "designs.parquet.bytes'",
            "integer >= 0",
        ),
        (
            lambda p: p["files"]["samples.parquet"].update(sha256="abc"),
            "samples.parquet.sha256'",
            "64 hexadecimal digits",
        ),
        (
            lambda p: p["files"]["samples.parquet"].update(sha256=None),
            "samples.parquet.sha256'",
            "64 hexadecimal digits",
        ),
        (
            lambda p: p["files"]["samples.parquet"].update(sha256="z" * 64),
            "samples.parquet.sha256'",
            "64 hexadecimal digits",
        ),
        (lambda p: p["files"].update({"samples.parquet": 7}), "samples.parquet'", "an object"),
        (
            lambda p: p["files"].update({"../outside.parquet": p["files"]["samples.parquet"]}),
            "'files'",
            "no folders",
        ),
        (lambda p: p.update(cpu_time_s="long"), "'cpu_time_s'", "finite number"),
        (lambda p: p.update(cpu_time_s=float("nan")), "'cpu_time_s'", "got NaN"),
    ],
    ids=[
        "files-list",
        "files-empty",
        "files-missing",
        "bytes-missing",
        "bytes-null",
        "bytes-string",
        "bytes-negative",
        "bytes-bool",
        "bytes-float",
        "sha256-short",
        "sha256-null",
        "sha256-not-hex",
        "entry-not-object",
        "name-outside-folder",
        "cpu-time-string",
        "cpu-time-nan",
    ],
)
def test_a_provenance_of_another_shape_names_the_file_and_field(dataset, change, field, allowed):
    record = _rewrite_provenance(dataset, change)
    for load in (table1_fem, table1_fem_designs, verify_dataset):
        with pytest.raises(DatasetError, match=r"provenance\.json") as info:
            load(dataset)
        message = str(info.value)
        assert field in message and allowed in message, message
        assert "\n" not in message
    assert record.exists()


def test_a_provenance_that_is_not_an_object_or_nests_too_deeply_is_a_dataset_error(dataset):
    record = dataset / "provenance.json"
    record.write_text("[1, 2]")
    with pytest.raises(DatasetError, match=r"provenance\.json.*expected a JSON object, got list"):
        table1_fem(dataset)
    record.write_text("[" * 100_000 + "]" * 100_000)
    with pytest.raises(DatasetError, match=r"provenance\.json.*nests too deeply"):
        table1_fem(dataset)


def test_an_uppercase_sha256_still_matches(dataset):
    _rewrite_provenance(
        dataset,
        lambda p: p["files"]["samples.parquet"].update(
            sha256=p["files"]["samples.parquet"]["sha256"].upper()
        ),
    )
    assert len(table1_fem(dataset)) > 0


def _replace_table(folder, name, frame):
    """Write ``frame`` as the dataset's ``name`` and record its size and hash, as a forger would."""
    path = folder / name
    frame.to_parquet(path, index=False)
    data = path.read_bytes()
    _rewrite_provenance(
        folder,
        lambda p: p["files"][name].update(bytes=len(data), sha256=hashlib.sha256(data).hexdigest()),
    )
    return path


def test_a_one_column_table_with_a_matching_hash_is_refused_naming_the_columns(dataset):
    _replace_table(dataset, "samples.parquet", pd.DataFrame({"x": [1.0, 2.0]}))
    with pytest.raises(DatasetError, match=r"samples\.parquet' lacks the column\(s\)") as info:
        table1_fem(dataset)
    message = str(info.value)
    assert "design_id, l_mm, r_mm" in message and "angle_deg" in message and "converged" in message


def test_a_designs_table_without_a_column_is_refused(dataset):
    designs = table1_fem_designs(dataset).drop(columns=["stop_kind"])
    _replace_table(dataset, "designs.parquet", designs)
    with pytest.raises(DatasetError, match=r"designs\.parquet' lacks the column\(s\) stop_kind;"):
        table1_fem_designs(dataset)


@pytest.mark.parametrize(
    ("column", "values", "expected"),
    [
        ("angle_deg", "text", r"angle_deg \(.*expected float\)"),
        ("converged", 1.0, r"converged \(float, expected bool\)"),
        ("design_id", 7, r"design_id \(integer, expected string\)"),
    ],
)
def test_a_mistyped_column_is_refused_naming_it(dataset, column, values, expected):
    samples = table1_fem(dataset)
    samples[column] = values
    _replace_table(dataset, "samples.parquet", samples)
    with pytest.raises(DatasetError, match=r"samples\.parquet' has column\(s\) of another type"):
        table1_fem(dataset)
    with pytest.raises(DatasetError, match=expected):
        table1_fem(dataset)


def test_an_implausible_value_is_refused_naming_row_and_column(dataset):
    samples = table1_fem(dataset)
    samples.loc[3, "l_mm"] = 1e300
    _replace_table(dataset, "samples.parquet", samples)
    with pytest.raises(DatasetError, match=r"samples\.parquet', row 3, column 'l_mm': 1e\+300"):
        table1_fem(dataset)


def test_a_table_that_is_not_parquet_is_a_dataset_error(dataset):
    path = dataset / "designs.parquet"
    path.write_bytes(b"not parquet at all")
    data = path.read_bytes()
    _rewrite_provenance(
        dataset,
        lambda p: p["files"]["designs.parquet"].update(
            bytes=len(data), sha256=hashlib.sha256(data).hexdigest()
        ),
    )
    with pytest.raises(DatasetError, match=r"designs\.parquet' is not a Parquet table"):
        table1_fem_designs(dataset)


def test_the_shipped_dataset_passes_every_check():
    samples, designs = table1_fem(), table1_fem_designs()
    assert list(samples.columns) == list(SAMPLE_COLUMN_KINDS)
    assert list(designs.columns) == list(DESIGN_COLUMN_KINDS)
    assert len(samples) == table1_fem_provenance()["samples"]["rows"]


def test_a_write_that_fails_half_way_leaves_the_previous_dataset_whole(
    campaign, dataset, monkeypatch
):
    import softbend.dataset_writing as writing

    before = {p.name: p.read_bytes() for p in dataset.iterdir()}

    def full_disk(path, text):
        raise OSError(28, "No space left on device", str(path))

    monkeypatch.setattr(writing, "write_text_atomic", full_disk)  # the provenance, last
    with pytest.raises(OSError, match="No space left"):
        write_dataset(campaign, dataset, command="again")
    assert {p.name: p.read_bytes() for p in dataset.iterdir()} == before
    assert not [p for p in dataset.parent.iterdir() if p.name.startswith(".")]  # no leftovers
    table1_fem(dataset)  # still verifies


def test_a_folder_with_other_files_is_not_replaced(campaign, tmp_path):
    folder = tmp_path / "mine"
    folder.mkdir()
    (folder / "notes.txt").write_text("keep me")
    with pytest.raises(
        ValueError, match=r"^out_dir: .*mine is replaced as a whole .*\(notes.txt\)"
    ):
        write_dataset(campaign, folder, command="x")
    assert (folder / "notes.txt").read_text() == "keep me"


def test_a_campaign_that_never_ran_is_one_dataset_error(tmp_path):
    from softbend.campaign import CampaignStore

    db = tmp_path / "empty.duckdb"
    with CampaignStore(db):
        pass
    with pytest.raises(DatasetError, match="holds no finished run"):
        write_dataset(db, tmp_path / "ds", command="x")
    assert not (tmp_path / "ds").exists()
