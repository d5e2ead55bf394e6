"""Campaigns over an FEM family other than paper B's, with a stand-in family.

The stand-in's sweep is a closed form, ``angle = K * p * (sum of the design's
values)``, so every stored angle can be checked exactly; its description has
an integer parameter, two lengths with a resolution, a constraint between them
and a design the family itself refuses.
"""

from __future__ import annotations

import json
import pickle

import duckdb
import numpy as np
import pandas as pd
import pytest

from softbend.actuators import Design
from softbend.campaign import CampaignStore, load_samples, run_campaign
from softbend.campaign.family_schema import FamilyBackend, family_backend
from softbend.campaign.spaces import parse_family_ranges, parse_family_space
from softbend.campaign.store import campaign_actuator
from softbend.cli import main
from softbend.design import sfrba_design
from softbend.errors import InputError

from ..cli.conftest import one_error_line
from ..stand_ins import (
    CELL_CONSTRAINTS,
    CELL_PARAMETERS,
    CELL_REFERENCE,
    check_closed_form_samples,
    registered_family,
    stand_in_family,
)

K_DEG_PER_MPA = 10.0
NAMES = ("n_cells", "width_mm", "height_mm")
#: Design ids whose stand-in sweep raises (a solver that does not converge).
FAILING: set[str] = set()

STANDIN = stand_in_family(
    "standin",
    CELL_PARAMETERS,
    K_DEG_PER_MPA,
    constraints=CELL_CONSTRAINTS,
    reference=CELL_REFERENCE,
    pmax_mpa=0.04,
    pstep_mpa=0.01,
    cap=("height_mm", 5.5),  # refused: more than 5.5 mm high with 5 cells
    failing=FAILING,
)


@pytest.fixture(autouse=True)
def standin():
    """The stand-in family, registered for the test and removed after it."""
    FAILING.clear()
    with registered_family(STANDIN) as family:
        yield family
    FAILING.clear()


def _values(design: Design) -> np.ndarray:
    return np.array([design.values[n] for n in NAMES])


# -- the design space ----------------------------------------------------------------


@pytest.mark.parametrize("kind", ["lhs", "sobol"])
def test_sampled_space_is_buildable_constrained_distinct_and_seeded(kind):
    space = parse_family_space(f"{kind}:40", STANDIN).build(seed=3)
    assert len(space) == 40 and space.name == f"standin {kind}-40-seed3"
    rows = np.array([_values(d) for d in space])
    assert np.array_equal(rows[:, 0], np.round(rows[:, 0])) and set(rows[:, 0]) <= {2, 3, 4, 5}
    assert np.allclose(rows[:, 1] * 10, np.round(rows[:, 1] * 10))  # 0.1 mm resolution
    assert np.allclose(rows[:, 2] * 2, np.round(rows[:, 2] * 2))  # 0.5 mm resolution
    assert (rows[:, 1] >= 1.0).all() and (rows[:, 1] <= 3.0).all()
    assert (rows[:, 1] < rows[:, 2] - 0.5).all()  # the constraint
    assert not ((rows[:, 0] == 5) & (rows[:, 2] > 5.5)).any()  # refused by the family
    assert len({d.design_id for d in space}) == 40
    assert space.rejected["constraints"] > 0 and space.n_rejected == sum(space.rejected.values())
    again = parse_family_space(f"{kind}:40", STANDIN).build(seed=3)
    other = parse_family_space(f"{kind}:40", STANDIN).build(seed=4)
    assert [d.design_id for d in again] == [d.design_id for d in space]
    assert [d.design_id for d in other] != [d.design_id for d in space]


def test_grid_is_the_full_factorial_less_the_rejected():
    spec = parse_family_space("grid", STANDIN)
    assert (spec.kind, spec.levels, spec.n_designs) == ("grid", 3, 3 * 3 * 3)
    space = spec.build()
    levels = {n: sorted({d.values[n] for d in space}) for n in NAMES}
    assert set(levels["n_cells"]) <= {2.0, 4.0, 5.0}  # linspace(2, 5, 3) rounded
    assert set(levels["width_mm"]) <= {1.0, 2.0, 3.0}
    rows = np.array([_values(d) for d in space])
    assert (rows[:, 1] < rows[:, 2] - 0.5).all()
    assert len(space) + space.n_rejected == 27
    four = parse_family_space("grid:4", STANDIN)
    assert four.n_designs == 4 * 4 * 4  # n_cells 2..5 has four whole values


def test_ranges_narrow_a_sampled_space_and_are_checked():
    ranges = parse_family_ranges(["width_mm=1:1.5", "n_cells=3:4"], STANDIN)
    space = parse_family_space("sobol:8", STANDIN).with_ranges(ranges).build(seed=0)
    rows = np.array([_values(d) for d in space])
    assert (rows[:, 1] <= 1.5).all() and set(rows[:, 0]) <= {3.0, 4.0}
    assert space.name.endswith("n_cells=3:4 width_mm=1:1.5")
    with pytest.raises(InputError, match=r"^ranges: must be NAME=LOW:HIGH with NAME one of n_"):
        parse_family_ranges(["l=60:90"], STANDIN)
    with pytest.raises(InputError, match=r"^ranges: must be a range of width_mm .*\[1, 3\] mm"):
        parse_family_ranges(["width_mm=0.5:2"], STANDIN)
    with pytest.raises(InputError, match=r"^ranges: applies to the sampled spaces"):
        parse_family_space("grid", STANDIN).with_ranges(ranges)


@pytest.mark.parametrize("text", ["table1", "corners", "lhs:0", "grid:1", "grid:51", "LHS:4"])
def test_bad_space_for_a_family_is_one_error_naming_the_forms(text):
    with pytest.raises(InputError, match=r"^space: must be one of lhs:N, sobol:N, grid or grid:K"):
        parse_family_space(text, STANDIN)


def test_too_tight_constraints_are_refused_with_the_counts():
    ranges = parse_family_ranges(["width_mm=2.9:3", "height_mm=2:3"], STANDIN)
    with pytest.raises(InputError, match=r"^space: must leave 5 distinct designs .* got 0 in"):
        parse_family_space("lhs:5", STANDIN).with_ranges(ranges).build()


# -- designs and backend cross process boundaries -----------------------------------------


def test_family_design_and_backend_pickle():
    design = STANDIN.design({"n_cells": 4})
    assert pickle.loads(pickle.dumps(design)) == design
    assert hash(pickle.loads(pickle.dumps(design))) == hash(design)
    backend = family_backend(STANDIN, maxh_mm=1.5)
    back = pickle.loads(pickle.dumps(backend))
    assert isinstance(back, FamilyBackend) and back.options.maxh_mm == 1.5
    result = back.sweep(design, np.array([0.0, 0.02]))
    assert result.angle_deg[1] == pytest.approx(K_DEG_PER_MPA * 0.02 * (4 + 2 + 4))


def test_contact_is_the_family_s_default_and_on_or_off_where_its_walls_touch():
    from dataclasses import replace

    from softbend.fem.families import get_family
    from softbend.fem.options import CONTACT_MAX_ANGLE_DEG, FEMOptions

    assert family_backend(STANDIN).options.contact == "off"
    with pytest.raises(InputError) as error:
        family_backend(STANDIN, contact="on")
    assert error.value.key == "contact"
    touching = replace(STANDIN, contact=True)
    assert family_backend(touching).options.contact == "off"  # its own defaults
    on = family_backend(touching, contact="on").options
    assert (on.contact, on.max_angle_deg) == ("on", CONTACT_MAX_ANGLE_DEG)
    with pytest.raises(InputError) as error:
        family_backend(touching, contact="sometimes")
    assert error.value.key == "contact" and "'off', 'on'" in str(error.value)
    pneunet = get_family("pneunet")
    assert pneunet.contact and not get_family("sfrba").contact
    # the PneuNet's default is its shipped dataset's: contact, to 180°
    assert family_backend(pneunet).options == family_backend(pneunet, contact="on").options
    assert family_backend(pneunet).options.max_angle_deg == CONTACT_MAX_ANGLE_DEG
    # off restores the contact-free options, digest included (their largest angle too)
    off = family_backend(pneunet, contact="off").options
    assert (off.contact, off.max_angle_deg) == ("off", FEMOptions.max_angle_deg)
    assert "contact" not in off.to_dict()
    assert off.digest() == off.replace(contact="on").replace(contact="off").digest()


def test_paper_b_s_campaign_refuses_contact_in_one_line(tmp_path, capsys):
    db = tmp_path / "c.duckdb"
    assert main(["campaign", "run", str(db), "--space", "lhs:2", "--contact", "on"]) == 2
    assert "contact" in one_error_line(capsys)
    assert not db.exists()


# -- run, resume, export, train ------------------------------------------------------


def test_run_resume_export_and_train_reader_over_the_cli(tmp_path, capsys):
    db = tmp_path / "standin.duckdb"
    run = ["campaign", "run", str(db), "--family", "standin", "--space", "lhs:12", "--seed", "1"]
    assert main([*run, "--workers", "0", "--json"]) == 0
    summary = json.loads(capsys.readouterr().out)
    assert summary["family"] == "standin" and summary["backend"] == "fem"
    assert summary["space"] == "standin lhs-12-seed1" and summary["rejected"]["constraints"] > 0
    assert (summary["n_designs"], summary["n_done"], summary["n_failed"]) == (12, 12, 0)

    assert main([*run, "--workers", "0"]) == 0  # the same command resumes: nothing left
    captured = capsys.readouterr()
    assert "12 of 12 designs already recorded" in captured.err
    assert "family" in captured.out and "standin" in captured.out

    with CampaignStore(db, read_only=True) as store:
        assert store.family == "standin" and store.parameters == NAMES
        assert store.meta()["family"] == "standin"
        assert json.loads(store.meta()["actuator"])["name"] == "standin"
        grid = store.pressures_mpa
        settings = store.settings
    assert np.allclose(grid, [0.0, 0.01, 0.02, 0.03, 0.04])  # the family's pmax and pstep
    assert settings["backend"] == "fem" and settings["options"]["maxh_mm"] == 2.0

    designs_csv = tmp_path / "designs.csv"
    assert (
        main(["campaign", "export", str(db), "--out", str(designs_csv), "--table", "designs"]) == 0
    )
    designs = pd.read_csv(designs_csv)
    assert list(designs.columns[:5]) == ["design_id", *NAMES, "status"]
    samples_file = tmp_path / "samples.parquet"
    assert main(["campaign", "export", str(db), "--out", str(samples_file)]) == 0
    samples = pd.read_parquet(samples_file)
    check_closed_form_samples(samples, NAMES, K_DEG_PER_MPA, 12 * 5)
    capsys.readouterr()
    assert main(["campaign", "status", str(db), "--json"]) == 0
    status = json.loads(capsys.readouterr().out)
    assert status["family"] == "standin" and status["parameters"] == list(NAMES)

    actuator = campaign_actuator(db)
    assert actuator is not None and actuator.names == NAMES
    from softbend.surrogates.workflow import _load_data

    data = _load_data(db)
    assert data.actuator == actuator and data.X.shape == (60, 4)
    assert np.allclose(data.y, K_DEG_PER_MPA * data.X[:, 3] * data.X[:, :3].sum(axis=1))


def test_failures_are_recorded_and_retried_on_resume(tmp_path):
    db = tmp_path / "standin.duckdb"
    space = parse_family_space("sobol:6", STANDIN).build(seed=2)
    FAILING.update(d.design_id for d in list(space)[:2])
    first = run_campaign(db, space, backend="fem", workers=0)
    assert (first.n_done, first.n_failed) == (4, 2)
    assert "ConvergenceError: stand-in does not converge" in first.failures[0][1]
    with CampaignStore(db, read_only=True) as store:
        status = store.status_summary()
    assert status["failed"] == 2 and status["failures"][0]["design"].count(",") == 2
    FAILING.clear()
    second = run_campaign(db, space, backend="fem", workers=0)
    assert (second.n_skipped_done, second.n_done, second.n_failed) == (4, 2, 0)
    assert len(load_samples(db)) == 6 * 5


def test_local_worker_processes_sweep_family_designs(tmp_path):
    db = tmp_path / "standin.duckdb"
    space = parse_family_space("lhs:6", STANDIN).build(seed=5)
    summary = run_campaign(db, space, backend="fem", workers=2)
    assert summary.executor == "processes:2" and summary.n_done == 6
    samples = load_samples(db)
    expected = K_DEG_PER_MPA * samples["pressure_mpa"] * samples[list(NAMES)].sum(axis=1)
    assert np.allclose(samples["angle_deg"], expected)


# -- families do not mix ---------------------------------------------------------------


def test_a_database_refuses_designs_of_another_family(tmp_path, capsys):
    paper_b = tmp_path / "paper_b.duckdb"
    run_campaign(paper_b, [sfrba_design(100, 6, 2, 2, 5, 8)], workers=0)
    argv = ["campaign", "run", str(paper_b), "--family", "standin", "--space", "lhs:2"]
    assert main([*argv, "--workers", "0"]) == 2
    line = one_error_line(capsys)
    assert "'sfrba' family" in line and "'standin'" in line and "new database" in line

    family_db = tmp_path / "standin.duckdb"
    run_campaign(family_db, parse_family_space("lhs:2", STANDIN).build(), workers=0, backend="fem")
    assert main(["campaign", "run", str(family_db), "--space", "lhs:2", "--workers", "0"]) == 2
    line = one_error_line(capsys)
    assert "'standin' family" in line and "'sfrba'" in line
    with pytest.raises(ValueError, match="only campaigns of one family merge"):
        from softbend.campaign import merge_campaigns

        merge_campaigns(tmp_path / "all.duckdb", [family_db, paper_b])
    assert not (tmp_path / "all.duckdb").exists()
    with CampaignStore(family_db) as store, pytest.raises(ValueError, match="are of the 'standin'"):
        store.record_failure(sfrba_design(100, 6, 2, 2, 5, 8), "x", 0.0, backend="fem")


def test_shards_of_a_family_merge_into_a_new_database(tmp_path):
    space = parse_family_space("lhs:6", STANDIN).build(seed=7)
    shards = [tmp_path / f"s{k}.duckdb" for k in range(2)]
    for k, shard in enumerate(shards):
        run_campaign(shard, space.shard(k, 2), backend="fem", workers=0)
    from softbend.campaign import merge_campaigns

    merge_campaigns(tmp_path / "all.duckdb", shards)
    with CampaignStore(tmp_path / "all.duckdb", read_only=True) as store:
        assert store.family == "standin" and len(store.finished_ids()) == 6
    con = duckdb.connect(str(tmp_path / "all.duckdb"), read_only=True)
    columns = [r[0] for r in con.execute("DESCRIBE designs").fetchall()]
    con.close()
    assert columns[:4] == ["design_id", *NAMES]


# -- bad input on the command line ---------------------------------------------------


def test_unknown_family_is_one_line_listing_the_known(tmp_path, capsys):
    assert main(["campaign", "run", str(tmp_path / "c.duckdb"), "--family", "nope"]) == 2
    line = one_error_line(capsys)
    assert "family" in line and "'nope'" in line and "sfrba" in line and "standin" in line
    assert not (tmp_path / "c.duckdb").exists()


@pytest.mark.parametrize(
    ("extra", "expected"),
    [
        (["--space", "table1"], "must be one of lhs:N, sobol:N, grid or grid:K"),
        ([], "must be given for the standin family"),
        (["--space", "lhs:2", "--backend", "analytical"], "must be fem for the standin family"),
        (["--space", "lhs:2", "--range", "l=60:90"], "NAME one of n_cells, width_mm, height_mm"),
        (["--space", "lhs:2", "--maxh", "0"], "must be a size > 0 mm"),
        (["--space", "lhs:2", "--contact", "on"], "must be off for the standin family"),
    ],
)
def test_bad_family_options_are_one_line(tmp_path, capsys, extra, expected):
    argv = ["campaign", "run", str(tmp_path / "c.duckdb"), "--family", "standin", *extra]
    assert main([*argv, "--workers", "0"]) == 2
    assert expected in one_error_line(capsys)
    assert not (tmp_path / "c.duckdb").exists()


def test_explicit_sfrba_family_is_the_campaign_of_before(tmp_path, capsys):
    plain, named = tmp_path / "plain.duckdb", tmp_path / "named.duckdb"
    common = ["--space", "lhs:3", "--pmax", "0.1", "--pstep", "0.05", "--workers", "0"]
    assert main(["campaign", "run", str(plain), *common, "--json"]) == 0
    before = json.loads(capsys.readouterr().out)
    assert main(["campaign", "run", str(named), "--family", "sfrba", *common, "--json"]) == 0
    after = json.loads(capsys.readouterr().out)
    assert "family" not in after and after["space"] == before["space"] == "lhs-3-seed0"
    with CampaignStore(named, read_only=True) as store:
        assert "family" not in store.meta() and store.family == "sfrba"
    pd.testing.assert_frame_equal(load_samples(plain), load_samples(named))


def test_family_designs_run_on_a_dask_scheduler(tmp_path):
    distributed = pytest.importorskip("distributed")
    cluster = distributed.LocalCluster(
        n_workers=1,
        threads_per_worker=2,
        processes=False,
        protocol="tcp",
        host="127.0.0.1",
        dashboard_address="127.0.0.1:0",
    )
    try:
        space = parse_family_space("sobol:4", STANDIN).build(seed=1)
        db = tmp_path / "standin.duckdb"
        summary = run_campaign(db, space, backend="fem", scheduler=cluster.scheduler_address)
    finally:
        cluster.close()
    assert summary.n_done == 4 and summary.executor == cluster.scheduler_address
    samples = load_samples(db)
    expected = K_DEG_PER_MPA * samples["pressure_mpa"] * samples[list(NAMES)].sum(axis=1)
    assert np.allclose(samples["angle_deg"], expected)


def test_train_fits_a_family_campaign_on_its_columns_and_actuator(tmp_path, capsys):
    db, out = tmp_path / "standin.duckdb", tmp_path / "surrogates"
    space = parse_family_space("sobol:16", STANDIN).build(seed=0)
    run_campaign(db, space, backend="fem", workers=0)
    argv = ["train", str(db), "--out", str(out), "--models", "plr", "--folds", "3", "--json"]
    assert main([*argv, "--no-onnx"]) == 0
    summary = json.loads(capsys.readouterr().out)
    assert summary["actuator"]["name"] == "standin"
    saved = json.loads((out / "models" / "plr.json").read_text())
    described = saved["metadata"]["actuator"]
    assert [p["name"] for p in described["parameters"]] == list(NAMES)
    assert described["pressure_column"] == "pressure_mpa"
    # the closed form is linear in p times a linear form: a polynomial fits it exactly
    assert summary["models"]["plr"]["rmse_deg"] < 1e-6
