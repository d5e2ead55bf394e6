"""Datasets of an FEM family other than paper B's: campaign → dataset → load → train.

A stand-in family with a closed-form sweep, ``angle = K * p * (sum of the
design's values)``, whose stop reason follows its number of cells (one of them
a PneuNet's touching walls), so every stored value and every stop kind is known.
Its actuator states pressure in kPa, so training reads the pressure in its unit.
"""

from __future__ import annotations

import hashlib
import json
from pathlib import Path

import duckdb
import numpy as np
import pandas as pd
import pytest

from softbend.campaign import CampaignStore, load_samples, run_campaign
from softbend.campaign.spaces import parse_family_space
from softbend.cli import main
from softbend.dataset_writing import _stop_kind, family_stop_region, write_dataset
from softbend.datasets import (
    DESIGN_STAT_COLUMNS,
    family_dataset,
    family_dataset_actuator,
    family_dataset_designs,
    family_dataset_provenance,
    shipped_families,
    table1_fem,
)
from softbend.errors import DatasetError, InputError
from softbend.surrogates.features import dataset_training_data

from .cli.conftest import one_error_line
from .stand_ins import (
    CELL_CONSTRAINTS,
    CELL_PARAMETERS,
    CELL_REFERENCE,
    check_closed_form_samples,
    registered_family,
    stand_in_family,
)

K_DEG_PER_MPA = 10.0
NAMES = ("n_cells", "width_mm", "height_mm")
#: The stop reason of a design with each number of cells.
REASONS = {
    2: "reached the last pressure",
    3: "neighbouring chamber walls touch at 30.00 kPa",
    4: "stretch 3.10 above 3 in the chamber 2 at x = 14 mm (beyond the material model)",
    5: "inflation instability above 0.03 MPa: the chamber 4 at x = 30 mm balloons (stretch 2.00)",
}
KINDS = {2: "last pressure", 3: "walls touch", 4: "stretch limit", 5: "inflation instability"}
REGIONS = {2: "", 3: "", 4: "chamber 2", 5: "chamber 4"}


STANDIN = stand_in_family(
    "standin",
    CELL_PARAMETERS,
    K_DEG_PER_MPA,
    pressure_column="p_kpa",
    pressure_unit="kPa",
    constraints=CELL_CONSTRAINTS,
    reference=CELL_REFERENCE,
    pmax_mpa=0.04,
    pstep_mpa=0.01,
    stop_reasons=REASONS,
    solver_record=True,  # 300 dofs, 5 load steps, 1 rejected, a mesh of 7, 0.5 s a sweep
)


@pytest.fixture(autouse=True)
def standin():
    """The stand-in family, registered for the test and removed after it."""
    with registered_family(STANDIN) as family:
        yield family


@pytest.fixture
def campaign(tmp_path):
    db = tmp_path / "standin.duckdb"
    run_campaign(db, parse_family_space("lhs:16", STANDIN).build(seed=1), backend="fem", workers=0)
    return db


@pytest.fixture
def dataset(campaign, tmp_path):
    folder = tmp_path / "standin"
    write_dataset(campaign, folder, command="softbend campaign run standin.duckdb", planned=16)
    return folder


def _rewrite_provenance(folder, change):
    record = folder / "provenance.json"
    provenance = json.loads(record.read_text())
    change(provenance)
    record.write_text(json.dumps(provenance))


def _replace_table(folder, name, frame):
    """Write ``frame`` as the dataset's ``name`` and record its size and hash, as a forger would."""
    path = folder / name
    frame.to_parquet(path, index=False)
    data = path.read_bytes()
    _rewrite_provenance(
        folder,
        lambda p: p["files"][name].update(bytes=len(data), sha256=hashlib.sha256(data).hexdigest()),
    )


# -- campaign → dataset → load ------------------------------------------------------------


def test_the_cli_writes_a_family_dataset_that_loads_back_the_campaign(tmp_path, capsys):
    db, out = tmp_path / "standin.duckdb", tmp_path / "standin"
    run = ["campaign", "run", str(db), "--family", "standin", "--space", "lhs:12", "--seed", "1"]
    assert main([*run, "--workers", "0", "--json"]) == 0
    capsys.readouterr()
    argv = ["campaign", "dataset", str(db), "--out", str(out), "--command", " ".join(run)]
    assert main([*argv, "--space", "grid", "--json"]) == 0
    provenance = json.loads(capsys.readouterr().out)
    assert provenance["name"] == provenance["family"] == "standin"
    assert provenance["actuator"] == STANDIN.actuator.to_dict()
    assert provenance["designs"]["planned"] == 3 * 3 * 3  # the family's grid, not paper B's
    assert provenance["designs"]["done"] == 12 and provenance["command"].endswith("lhs:12 --seed 1")
    assert family_dataset_provenance("standin", out) == provenance

    samples = family_dataset("standin", out)
    pd.testing.assert_frame_equal(samples, load_samples(db))
    check_closed_form_samples(samples, NAMES, K_DEG_PER_MPA, 12 * 5)

    designs = family_dataset_designs("standin", out)
    assert list(designs.columns) == ["design_id", *NAMES, *DESIGN_STAT_COLUMNS]
    with CampaignStore(db, read_only=True) as store:
        stored = store.load_designs().set_index("design_id")
    stored = stored.loc[designs["design_id"]]
    np.testing.assert_array_equal(designs[list(NAMES)].to_numpy(), stored[list(NAMES)].to_numpy())
    cells = designs["n_cells"].round().astype(int)
    assert list(designs["stop_reason"]) == [REASONS[n] for n in cells]
    assert list(designs["stop_kind"]) == [KINDS[n] for n in cells]
    assert list(designs["stop_region"]) == [REGIONS[n] for n in cells]
    assert set(designs["ndof"]) == {300} and set(designs["load_steps"]) == {5}
    assert set(designs["rejected_steps"]) == {1} and set(designs["mesh_size"]) == {7}
    counts = designs["stop_kind"].value_counts().to_dict()
    assert provenance["designs"]["by_stop_kind"] == counts
    assert provenance["cpu_time_s"] == pytest.approx(0.5 * 12)
    assert family_dataset_actuator("standin", out) == STANDIN.actuator
    capsys.readouterr()
    assert main(argv) == 0  # the table names the family
    assert "family" in capsys.readouterr().out


def test_a_space_of_paper_b_is_refused_for_a_family_campaign(campaign, tmp_path, capsys):
    out = tmp_path / "ds"
    argv = ["campaign", "dataset", str(campaign), "--out", str(out), "--command", "x"]
    assert main([*argv, "--space", "table1"]) == 2
    assert "lhs:N, sobol:N, grid or grid:K for the standin family" in one_error_line(capsys)
    assert not out.exists()
    assert main([*argv, "--space", "grid:4", "--json"]) == 0
    assert json.loads(capsys.readouterr().out)["designs"]["planned"] == 4 * 4 * 4


def test_stop_kinds_and_regions_of_a_pneunet():
    reason = "neighbouring chamber walls touch at 12.34 kPa"
    assert _stop_kind(reason) == "walls touch"
    assert family_stop_region(reason, "walls touch") == ""
    for n in (4, 5):
        assert family_stop_region(REASONS[n], _stop_kind(REASONS[n])) == REGIONS[n]
    distal = "stretch 5.02 above 5 in the distal cap at x = 104 mm (beyond the material model)"
    assert family_stop_region(distal, "stretch limit") == "distal cap"
    assert family_stop_region("bending angle above 300 deg", "angle limit") == ""


# -- verified on every load -----------------------------------------------------------------


@pytest.mark.parametrize("name", ["samples.parquet", "designs.parquet"])
def test_a_truncated_or_altered_file_is_refused_naming_it(dataset, name):
    path = dataset / name
    data = path.read_bytes()
    altered = bytearray(data)
    altered[len(data) // 2] ^= 0xFF
    path.write_bytes(bytes(altered))
    for load in (family_dataset, family_dataset_designs, family_dataset_provenance):
        with pytest.raises(DatasetError, match=rf"{name}.*SHA-256"):
            load("standin", dataset)
    path.write_bytes(data[:-10])
    with pytest.raises(DatasetError, match=rf"{name}.*truncated"):
        family_dataset("standin", dataset)


@pytest.mark.parametrize(
    ("name", "column", "value", "expected"),
    [
        (
            "samples.parquet",
            "n_cells",
            7.0,
            r"7 is outside .* n_cells must be a whole number in \[",
        ),
        ("samples.parquet", "n_cells", 3.5, r"3\.5 is outside .*whole number in \[2, 5\]\."),
        ("designs.parquet", "width_mm", 0.5, r"0\.5 is outside .*a value in \[1, 3\] mm\."),
        ("designs.parquet", "height_mm", float("nan"), r"nan is outside .*in \[2, 6\] mm\."),
    ],
)
def test_a_value_outside_the_actuator_is_refused_naming_row_and_column(
    dataset, name, column, value, expected
):
    load = family_dataset if name == "samples.parquet" else family_dataset_designs
    table = load("standin", dataset)
    table.loc[2, column] = value
    _replace_table(dataset, name, table)
    with pytest.raises(DatasetError, match=rf"{name}', row 2, column '{column}': {expected}"):
        load("standin", dataset)


def test_an_implausible_angle_is_refused(dataset):
    samples = family_dataset("standin", dataset)
    samples.loc[4, "angle_deg"] = 1e6
    _replace_table(dataset, "samples.parquet", samples)
    with pytest.raises(DatasetError, match=r"row 4, column 'angle_deg': 1e\+06 is not a plausible"):
        family_dataset("standin", dataset)


def test_the_columns_are_checked_against_the_recorded_actuator(dataset):
    def rename(provenance):
        provenance["actuator"]["parameters"][1]["name"] = "depth_mm"
        provenance["actuator"]["constraints"] = []

    _rewrite_provenance(dataset, rename)
    with pytest.raises(DatasetError, match=r"samples\.parquet' lacks the column\(s\) depth_mm;"):
        family_dataset("standin", dataset)


def test_a_provenance_without_its_actuator_or_of_another_family_is_refused(dataset):
    _rewrite_provenance(dataset, lambda p: p["actuator"].update(pressure_unit="atm"))
    with pytest.raises(DatasetError, match=r"provenance\.json': the field 'actuator' must be an"):
        family_dataset("standin", dataset)
    _rewrite_provenance(dataset, lambda p: p.pop("actuator"))
    with pytest.raises(DatasetError, match=r"the field 'actuator' is missing"):
        family_dataset_designs("standin", dataset)
    with pytest.raises(
        DatasetError, match=r"holds designs of the 'standin' family, not of the 'sf"
    ):
        family_dataset("sfrba", dataset)


def test_a_campaign_value_outside_the_actuator_is_refused_before_writing(campaign, tmp_path):
    con = duckdb.connect(str(campaign))
    first = con.execute("SELECT design_id FROM designs ORDER BY design_id LIMIT 1").fetchone()[0]
    con.execute("UPDATE designs SET width_mm = 9.5 WHERE design_id = ?", [first])
    con.close()
    with pytest.raises(
        DatasetError, match=r"standin\.duckdb', samples, row \d+, column 'width_mm'"
    ):
        write_dataset(campaign, tmp_path / "ds", command="x")
    assert not (tmp_path / "ds").exists()


# -- shipped datasets ----------------------------------------------------------------------


def test_a_family_without_a_shipped_dataset_is_one_error_naming_those_with_one():
    with pytest.raises(InputError, match=r"^family: must be a family with a shipped dataset") as e:
        family_dataset("standin")
    assert "(sfrba" in str(e.value) and "FEM family without one" in str(e.value)
    with pytest.raises(InputError, match=r'dataset \(sfrba.*; got "nope"$'):
        family_dataset_designs("nope")


def test_paper_b_is_table1_under_its_family_name():
    assert shipped_families()["sfrba"] == "table1_fem"
    pd.testing.assert_frame_equal(family_dataset("sfrba"), table1_fem())
    assert family_dataset_provenance("table1_fem")["name"] == "table1_fem"
    assert family_dataset_actuator("sfrba").names[0] == "l_mm"


def test_a_folder_named_after_its_family_is_shipped(dataset, tmp_path, monkeypatch):
    import softbend.datasets as module

    monkeypatch.setattr(module, "_data_root", lambda: tmp_path)
    assert shipped_families() == {"standin": "standin"}
    pd.testing.assert_frame_equal(family_dataset("standin"), family_dataset("standin", dataset))


def test_the_package_data_takes_a_folder_named_after_a_family(tmp_path):
    import glob
    import tomllib

    pyproject = Path(__file__).parents[1] / "pyproject.toml"
    globs = tomllib.loads(pyproject.read_text())["tool"]["setuptools"]["package-data"]["softbend"]
    (tmp_path / "data" / "pneunet").mkdir(parents=True)
    for name in ("samples.parquet", "designs.parquet", "provenance.json"):
        (tmp_path / "data" / "pneunet" / name).write_bytes(b"")
    found = {f for g in globs for f in glob.glob(g, root_dir=tmp_path, recursive=True)}
    assert {f"data/pneunet/{n}" for n in ("samples.parquet", "provenance.json")} <= found


def test_paper_b_writes_the_dataset_of_before(tmp_path):
    from softbend.design import DesignSpace

    db = tmp_path / "b.duckdb"
    run_campaign(db, DesignSpace.sample(3, seed=2), backend="analytical", workers=0)
    provenance = write_dataset(db, tmp_path / "ds", command="x")
    assert provenance["name"] == "table1_fem"
    assert "family" not in provenance and "actuator" not in provenance
    assert list(provenance)[:3] == ["name", "description", "command"]


# -- training ---------------------------------------------------------------------------------


def test_training_data_reads_the_pressure_in_the_actuators_unit(dataset):
    data = dataset_training_data(dataset)
    assert data.actuator == STANDIN.actuator and data.X.shape == (16 * 5, 4)
    p_mpa = data.X[:, 3] / 1000.0  # kPa
    assert np.allclose(data.y, K_DEG_PER_MPA * p_mpa * data.X[:, :3].sum(axis=1))
    assert data.X[:, 3].max() == pytest.approx(40.0)


def test_train_takes_a_dataset_folder_or_a_shipped_name(dataset, tmp_path, monkeypatch, capsys):
    import softbend.datasets as module

    common = ["--models", "plr", "--folds", "3", "--no-onnx", "--json"]
    assert main(["train", str(dataset), "--out", str(tmp_path / "a"), *common]) == 0
    summary = json.loads(capsys.readouterr().out)
    assert (
        summary["actuator"]["name"] == "standin" and summary["actuator"]["pressure_unit"] == "kPa"
    )
    assert summary["models"]["plr"]["rmse_deg"] < 1e-6  # the closed form is a polynomial

    monkeypatch.chdir(tmp_path / "a")  # no file named standin here
    assert main(["train", "standin", "--out", str(tmp_path / "b"), *common]) == 2
    assert "must be a family with a shipped dataset" in one_error_line(capsys)
    monkeypatch.setattr(module, "_data_root", lambda: tmp_path)
    assert main(["train", "standin", "--out", str(tmp_path / "b"), *common]) == 0
    assert json.loads(capsys.readouterr().out)["models"]["plr"]["rmse_deg"] < 1e-6
    argv = ["train", str(dataset), "--out", str(tmp_path / "c"), "--design-columns", "n_cells"]
    assert main(argv) == 2
    assert "is a dataset" in one_error_line(capsys)


def test_the_shipped_pneunet_dataset_verifies_and_spans_its_described_space():
    """data/pneunet: at least 200 swept designs, each inside the PneuNet's ranges and
    constraints, every sweep from 0 kPa, angles growing with pressure on average."""
    from softbend.actuators import PNEUNET
    from softbend.datasets import family_dataset_designs, family_dataset_provenance

    provenance = family_dataset_provenance("pneunet")
    designs = family_dataset_designs("pneunet")
    samples = family_dataset("pneunet")
    assert provenance["family"] == "pneunet" and provenance["designs"]["done"] >= 200
    assert (designs["status"] == "done").sum() >= 200
    for p in PNEUNET.parameters:
        assert designs[p.name].between(p.low, p.high).all(), p.name
    PNEUNET.check_designs(designs[list(PNEUNET.names)].to_numpy())  # the constraints
    first = samples.groupby("design_id")["pressure_mpa"].min()
    assert (first == 0.0).all()
    slopes = samples[samples["converged"]].groupby("design_id")[["pressure_mpa", "angle_deg"]]
    rising = slopes.apply(
        lambda g: g["angle_deg"].corr(g["pressure_mpa"]) > 0 if len(g) > 2 else True
    )
    assert rising.mean() > 0.95
    # swept with contact: past the touch, to 50 kPa, 180° or where Newton stops
    assert set(designs["stop_kind"]) <= {"angle limit", "last pressure", "no convergence"}
    assert [options["contact"] for options in provenance["options"]] == ["on"]
    # a campaign on the family's defaults sweeps the dataset's model (the same digest)
    from softbend.campaign.family_schema import family_backend
    from softbend.fem.families import get_family

    defaults = family_backend(get_family("pneunet")).options.digest()
    assert provenance["options_sha256"] == [defaults]
    assert (designs["max_angle_deg"] <= 180.0 + 1e-9).all()
    assert (designs["stop_kind"] == "last pressure").sum() >= 200
