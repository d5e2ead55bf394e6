"""``softbend campaign run|status|export|dataset``: in-process CLI runs and one-line errors."""

from __future__ import annotations

import dataclasses
import errno
import json
import socket
from types import SimpleNamespace

import duckdb
import pandas as pd
import pytest

from softbend.actuators import Design
from softbend.analytical import AnalyticalModel
from softbend.campaign import CampaignStore, default_pressures_mpa, load_samples
from softbend.cli import main
from softbend.design import DesignSpace, sfrba_design
from softbend.errors import ConvergenceError
from softbend.fem.geometry import check_mesh_size
from softbend.fem.options import FEMOptions

from ..stand_ins import web_server
from .conftest import one_error_line

RUN = ["--space", "lhs:6", "--seed", "3", "--pmax", "0.1", "--pstep", "0.05"]


def test_run_status_export_and_resume(tmp_path, capsys):
    db = tmp_path / "c.duckdb"
    assert main(["campaign", "run", str(db), *RUN, "--workers", "0", "--json"]) == 0
    summary = json.loads(capsys.readouterr().out)
    assert summary["space"] == "lhs-6-seed3" and summary["backend"] == "analytical"
    assert (summary["n_designs"], summary["n_done"], summary["n_failed"]) == (6, 6, 0)
    assert summary["executor"] == "serial"

    assert main(["campaign", "run", str(db), *RUN, "--workers", "2"]) == 0
    captured = capsys.readouterr()
    assert "already done (skipped)" in captured.out and "done in this run" in captured.out
    assert "resuming" in captured.err and "6 of 6 designs already recorded" in captured.err

    assert main(["campaign", "status", str(db), "--json"]) == 0
    status = json.loads(capsys.readouterr().out)
    assert (status["done"], status["failed"], status["samples"]) == (6, 0, 18)
    assert status["n_pressures"] == 3 and status["pmax_mpa"] == 0.1
    assert main(["campaign", "status", str(db)]) == 0
    assert "designs done" in capsys.readouterr().out

    samples = load_samples(db)
    for suffix, reader in ((".parquet", pd.read_parquet), (".csv", pd.read_csv)):
        out = tmp_path / f"samples{suffix}"
        assert main(["campaign", "export", str(db), "--out", str(out)]) == 0
        assert f"wrote 18 samples rows to {out}" in " ".join(capsys.readouterr().out.split())
        back = reader(out)
        pd.testing.assert_frame_equal(
            back.astype({"design_id": object}),
            samples.astype({"design_id": object}),
            check_dtype=False,
        )
    forced = tmp_path / "designs.out"
    assert (
        main(
            [
                "campaign",
                "export",
                str(db),
                "--out",
                str(forced),
                "--format",
                "csv",
                "--table",
                "designs",
            ]
        )
        == 0
    )
    assert len(pd.read_csv(forced)) == 6


def test_a_sampled_space_over_ranges_of_one_s_own(tmp_path, capsys):
    db = tmp_path / "own.duckdb"
    args = ["campaign", "run", str(db), "--space", "sobol:8", "--range", "l=60:90"]
    args += ["--range", "t=1:1.5", "--pmax", "0.02", "--pstep", "0.01", "--workers", "1"]
    assert main(args) == 0
    assert "sobol-8-seed0 l=60:90 t=1:1.5 (8 designs)" in capsys.readouterr().out
    designs = load_samples(db).drop_duplicates("design_id")
    assert len(designs) == 8
    assert designs["l_mm"].between(60, 90).all() and designs["t_mm"].between(1, 1.5).all()
    assert designs["r_mm"].between(6, 10).all()  # the others keep Table 1's ranges
    assert main(args) == 0  # nothing left: no rate is made up
    out = capsys.readouterr().out
    assert "- (none run)" in out and "nan" not in out


def test_a_space_of_the_table_and_the_summary_table(tmp_path, capsys):
    db = tmp_path / "c.duckdb"
    assert (
        main(
            [
                "campaign",
                "run",
                str(db),
                "--space",
                "sobol:4",
                "--pmax",
                "0.02",
                "--pstep",
                "0.01",
                "--workers",
                "1",
                "--no-retry-failed",
            ]
        )
        == 0
    )
    out = capsys.readouterr().out
    assert "sobol-4-seed0 (4 designs)" in out and "done in this run" in out
    with CampaignStore(db, read_only=True) as store:
        assert len(store.finished_ids()) == 4


def test_shards_run_apart_and_merge_into_the_whole_campaign(tmp_path, capsys):
    whole = tmp_path / "whole.duckdb"
    assert main(["campaign", "run", str(whole), *RUN, "--workers", "0", "--json"]) == 0
    capsys.readouterr()
    shards = [tmp_path / f"s{k}.duckdb" for k in range(4)]
    for k, shard in enumerate(shards):
        assert main(["campaign", "run", str(shard), *RUN, "--shard", f"{k}/4", "--json"]) == 0
        summary = json.loads(capsys.readouterr().out)
        assert summary["space"] == f"lhs-6-seed3[{k}/4]"
    capsys.readouterr()
    merged = tmp_path / "merged.duckdb"
    assert main(["campaign", "merge", str(merged), *map(str, shards), "--json"]) == 0
    counts = json.loads(capsys.readouterr().out)
    assert [r["added"] for r in counts["shards"]] == [2, 2, 1, 1]
    assert (counts["done"], counts["failed"]) == (6, 0)
    pd.testing.assert_frame_equal(load_samples(merged), load_samples(whole))
    # Merging a shard again changes nothing.
    assert main(["campaign", "merge", str(merged), str(shards[0]), "--json"]) == 0
    assert json.loads(capsys.readouterr().out)["shards"][0]["kept"] == 2
    assert len(load_samples(merged)) == len(load_samples(whole))
    # A missing shard is one line.
    assert main(["campaign", "merge", str(merged), str(tmp_path / "nope.duckdb")]) == 2
    assert "No campaign database" in one_error_line(capsys)


def test_a_dataset_from_some_shards_says_how_many_designs_it_lacks(tmp_path, capsys):
    from softbend.datasets import table1_fem, table1_fem_provenance

    shards = [tmp_path / f"s{k}.duckdb" for k in range(2)]
    for k, shard in enumerate(shards):
        assert main(["campaign", "run", str(shard), *RUN, "--shard", f"{k}/3", "--json"]) == 0
    part = tmp_path / "part.duckdb"
    assert main(["campaign", "merge", str(part), *map(str, shards), "--json"]) == 0
    capsys.readouterr()
    out = tmp_path / "ds"
    args = [
        "campaign",
        "dataset",
        str(part),
        "--out",
        str(out),
        "--command",
        "run it",
        "--space",
        "lhs:6",
    ]
    assert main(args) == 0
    assert "4 / 0 (of 6)" in capsys.readouterr().out
    provenance = table1_fem_provenance(out)
    assert (provenance["designs"]["planned"], provenance["designs"]["done"]) == (6, 4)
    pd.testing.assert_frame_equal(table1_fem(out), load_samples(part))
    assert (
        main(
            [
                "campaign",
                "dataset",
                str(part),
                "--out",
                str(out),
                "--command",
                "x",
                "--space",
                "grid",
            ]
        )
        == 2
    )
    assert "--space: " in one_error_line(capsys)


def _closed_port() -> int:
    with socket.socket() as sock:
        sock.bind(("127.0.0.1", 0))
        return sock.getsockname()[1]


@pytest.mark.parametrize(
    ("args", "needle"),
    [
        (
            ["--backend", "abaqus"],
            "--backend: Unknown campaign backend 'abaqus'; known: analytical, fem, surrogate.",
        ),
        (["--backend", "fault-injection"], "--backend: Unknown campaign backend 'fault-injection'"),
        (["--space", "grid:5"], "--space: must be one of table1"),
        (["--space", "lhs:0"], "--space: "),
        (["--pmax", "0.1", "--pstep", "0.03"], "number of steps of 0.03 MPa"),
        (["--pmax", "-1"], "--pmax: must be a number in"),
        (["--workers", "-2"], "--workers: must be a number in"),
        (["--shard", "3/3"], "--shard: must be K/N"),
        (["--shard", "1of2"], "--shard: "),
        (["--space", "table1", "--range", "l=60:90"], "applies to the sampled spaces"),
        (["--space", "lhs:4", "--range", "x=1:2"], "NAME one of l, r, t, b, phi, lc"),
        (["--space", "lhs:4", "--range", "phi=50:70"], "within [0, 60] deg"),
        (["--space", "lhs:4", "--range", "t=3:7"], "t's high must be below r's low"),
        (
            ["--scheduler", "127.0.0.1:8786"],
            "--scheduler: must be an address of the form tcp://HOST:PORT",
        ),
    ],
)
def test_bad_run_input_is_one_line_and_exit_2(tmp_path, capsys, args, needle):
    db = tmp_path / "c.duckdb"
    assert main(["campaign", "run", str(db), *RUN, *args]) == 2
    assert needle in one_error_line(capsys)
    assert not db.exists()


def test_unreachable_scheduler_is_exit_2(tmp_path, capsys):
    address = f"tcp://127.0.0.1:{_closed_port()}"
    code = main(
        [
            "campaign",
            "run",
            str(tmp_path / "c.duckdb"),
            *RUN,
            "--scheduler",
            address,
            "--connect-timeout",
            "3",
        ]
    )
    assert code == 2
    assert f"--scheduler: cannot reach the Dask scheduler at {address}" in one_error_line(capsys)


def test_newer_schema_is_exit_2_for_every_subcommand(tmp_path, capsys):
    db = tmp_path / "future.duckdb"
    CampaignStore(db).close()
    con = duckdb.connect(str(db))
    con.execute("UPDATE meta SET value = '2' WHERE key = 'schema_version'")
    con.close()
    for argv in (
        ["campaign", "run", str(db), *RUN],
        ["campaign", "status", str(db)],
        ["campaign", "export", str(db), "--out", str(tmp_path / "x.parquet")],
    ):
        assert main(argv) == 2
        assert "schema version 2, newer than this softbend supports (1)" in one_error_line(capsys)
    assert not (tmp_path / "x.parquet").exists()


def test_status_and_export_bad_input(tmp_path, capsys):
    assert main(["campaign", "status", str(tmp_path / "missing.duckdb")]) == 2
    assert "No campaign database" in one_error_line(capsys)
    db = tmp_path / "c.duckdb"
    assert main(["campaign", "run", str(db), *RUN, "--workers", "0", "--json"]) == 0
    capsys.readouterr()
    assert (
        main(["campaign", "export", str(db), "--out", str(tmp_path / "x.xlsx"), "--format", "xlsx"])
        == 2
    )
    assert "--format: must be one of 'parquet', 'csv'" in (one_error_line(capsys))
    assert main(["campaign", "export", str(db), "--out", str(tmp_path / "no" / "x.csv")]) == 2
    assert "does not exist" in one_error_line(capsys)


def test_help_lists_the_subcommands_and_options(capsys):
    assert main(["campaign", "--help"]) == 0
    out = capsys.readouterr().out
    for word in ("run", "status", "export"):
        assert word in out
    assert main(["campaign", "run", "--help"]) == 0
    out = capsys.readouterr().out
    for option in ("--backend", "--space", "--scheduler", "--retry-failed", "--json", "--pmax"):
        assert option in out


def test_a_truncated_database_is_one_line_and_exit_2_for_every_subcommand(tmp_path, capsys):
    """``head -c 600000 good.duckdb > t.duckdb`` used to end in a traceback."""
    good = tmp_path / "good.duckdb"
    assert main(["campaign", "run", str(good), *RUN, "--workers", "0", "--json"]) == 0
    capsys.readouterr()
    data = good.read_bytes()
    db = tmp_path / "t.duckdb"
    db.write_bytes(data[: min(600000, len(data) // 2)])
    before = db.read_bytes()
    for argv in (
        ["campaign", "status", str(db)],
        ["campaign", "status", str(db), "--json"],
        ["campaign", "export", str(db), "--out", str(tmp_path / "x.parquet")],
        ["campaign", "export", str(db), "--out", str(tmp_path / "x.csv"), "--table", "designs"],
        ["campaign", "run", str(db), *RUN, "--workers", "0"],
    ):
        assert main(argv) == 2, argv
        line = one_error_line(capsys)
        assert f"{str(db)!r} is not a readable softbend campaign database (truncated" in line
    assert db.read_bytes() == before
    assert not (tmp_path / "x.parquet").exists() and not (tmp_path / "x.csv").exists()


@pytest.mark.parametrize(
    ("content", "reason"),
    [
        (b"design_id,angle_deg\nd1,12.5\n", "not a DuckDB database file; "),
        (b"", "an empty file; "),
    ],
    ids=["a csv renamed", "empty"],
)
def test_a_file_that_is_no_database_is_one_line_for_status_and_export(
    tmp_path, capsys, content, reason
):
    db = tmp_path / "c.duckdb"
    db.write_bytes(content)
    for argv in (
        ["campaign", "status", str(db)],
        ["campaign", "export", str(db), "--out", str(tmp_path / "x.csv")],
    ):
        assert main(argv) == 2
        line = one_error_line(capsys)
        assert f"{str(db)!r} is not a readable softbend campaign database ({reason}" in line
        assert line.endswith(
            "the DuckDB file that 'softbend campaign run' or 'softbend campaign merge' writes)."
        )


@pytest.fixture
def campaign_db(tmp_path, capsys):
    db = tmp_path / "c.duckdb"
    assert main(["campaign", "run", str(db), *RUN, "--workers", "0", "--json"]) == 0
    capsys.readouterr()
    return db


@pytest.mark.parametrize("extra", [[], ["--format", "csv"], ["--format", "parquet"]])
def test_export_onto_its_own_database_is_refused_and_keeps_it(campaign_db, capsys, extra):
    before = campaign_db.read_bytes()
    assert main(["campaign", "export", str(campaign_db), "--out", str(campaign_db), *extra]) == 2
    assert f"The '--out' {campaign_db} is also an input" in one_error_line(capsys)
    assert campaign_db.read_bytes() == before
    assert main(["campaign", "status", str(campaign_db), "--json"]) == 0
    assert json.loads(capsys.readouterr().out)["done"] == 6


def test_export_never_replaces_a_file_of_another_kind(campaign_db, tmp_path, capsys):
    other = tmp_path / "other.duckdb"
    other.write_bytes(campaign_db.read_bytes())
    parquet = tmp_path / "s.parquet"
    assert main(["campaign", "export", str(campaign_db), "--out", str(parquet)]) == 0
    capsys.readouterr()
    for out, kind, found in ((other, "parquet", "DuckDB database"), (parquet, "csv", "Parquet")):
        before = out.read_bytes()
        assert (
            main(["campaign", "export", str(campaign_db), "--out", str(out), "--format", kind]) == 2
        )
        assert (
            f"The '--out' must be a new file or a {kind} file to replace. "
            f"Got {out}, an existing {found} file, instead."
        ) in one_error_line(capsys)
        assert out.read_bytes() == before
    # The same kind is replaced, as before.
    assert main(["campaign", "export", str(campaign_db), "--out", str(parquet)]) == 0


def test_export_onto_a_folder_or_into_a_read_only_one_is_one_line(
    campaign_db, tmp_path, monkeypatch, capsys
):
    assert main(["campaign", "export", str(campaign_db), "--out", str(tmp_path)]) == 2
    assert f"The '--out' must name a file; {tmp_path} is a folder." in one_error_line(capsys)
    import os

    # As root every folder is writable: make the check see a read-only one.
    monkeypatch.setattr(os, "access", lambda path, mode: not mode & os.W_OK)
    out = tmp_path / "x.csv"
    assert main(["campaign", "export", str(campaign_db), "--out", str(out)]) == 2
    assert f"The '--out' {out} cannot be written: {tmp_path} is read-only." in one_error_line(
        capsys
    )


def test_a_full_disk_during_the_export_is_one_line_naming_out(campaign_db, tmp_path, capsys):
    from unittest import mock

    out = tmp_path / "x.parquet"
    full = OSError(errno.ENOSPC, "No space left on device")
    with mock.patch.object(CampaignStore, "export", side_effect=full):
        assert main(["campaign", "export", str(campaign_db), "--out", str(out)]) == 2
    assert one_error_line(capsys) == (
        f"softbend: error: The '--out' {out} could not be written: No space left on device."
    )


def test_merge_and_run_refuse_an_output_that_is_an_input_or_a_folder(campaign_db, tmp_path, capsys):
    other = tmp_path / "other.duckdb"
    other.write_bytes(campaign_db.read_bytes())
    argv = ["campaign", "merge", str(campaign_db), str(other), str(campaign_db)]
    assert main(argv) == 2
    assert f"The 'DB' {campaign_db} is also an input" in one_error_line(capsys)
    assert main(["campaign", "run", str(tmp_path), *RUN]) == 2
    assert f"The 'DB' must name a file; {tmp_path} is a folder." in one_error_line(capsys)


@pytest.mark.parametrize("space", ["LHS:3", "Sobol:4", "TABLE1"])
def test_space_names_are_lower_case_like_every_other_choice(tmp_path, capsys, space):
    db = tmp_path / "c.duckdb"
    assert main(["campaign", "run", str(db), "--space", space]) == 2
    assert f'(lower case, N >= 1); got "{space}"' in one_error_line(capsys)
    assert not db.exists()
    assert (
        main(["campaign", "export", str(db), "--out", str(tmp_path / "x.csv"), "--format", "CSV"])
        == 2
    )
    assert "--format: must be one of" in one_error_line(capsys)


@pytest.fixture
def roomy_machine(monkeypatch):
    from softbend.campaign import footprint

    monkeypatch.setattr(footprint, "_available_memory_bytes", lambda: 1024**4)
    monkeypatch.setattr(footprint, "_free_disk_bytes", lambda db: 1024**5)


def test_a_large_space_needs_allow_large_and_is_refused_before_any_design(
    tmp_path, capsys, roomy_machine, monkeypatch
):
    import time

    monkeypatch.setenv("SOFTBEND_MAX_DESIGNS", str(10**13))
    db = tmp_path / "c.duckdb"
    start = time.monotonic()
    assert main(["campaign", "run", str(db), "--space", "lhs:10000000"]) == 2
    line = one_error_line(capsys)
    assert time.monotonic() - start < 10  # no design was drawn
    assert "--allow-large: must be set to run a large campaign, about 23.3 GiB" in line
    assert "86.5 GiB of disk for 10000000 designs x 101 pressures" in line
    assert line.endswith("(more than 2 GiB of memory or 20 GiB of disk)")
    assert not db.exists()


def test_a_space_that_does_not_fit_is_refused_even_with_allow_large(tmp_path, capsys, monkeypatch):
    monkeypatch.setenv("SOFTBEND_MAX_DESIGNS", str(10**13))
    db = tmp_path / "c.duckdb"
    argv = ["campaign", "run", str(db), "--space", "sobol:1000000000000", "--allow-large"]
    assert main(argv) == 2
    line = one_error_line(capsys)
    assert "--space: must give a campaign that fits this machine; got 1000000000000 designs" in line
    assert "about 2.22 PiB of memory" in line
    assert not db.exists()


def test_dataset_records_a_huge_planned_space_without_building_it(
    campaign_db, tmp_path, capsys, monkeypatch
):
    out = tmp_path / "ds"
    argv = ["campaign", "dataset", str(campaign_db), "--out", str(out), "--command", "x"]
    assert main([*argv, "--space", "sobol:1000000000000", "--json"]) == 2
    assert "SOFTBEND_MAX_DESIGNS" in one_error_line(capsys)
    assert not out.exists()
    monkeypatch.setenv("SOFTBEND_MAX_DESIGNS", str(10**13))
    assert main([*argv, "--space", "sobol:1000000000000", "--json"]) == 0
    assert json.loads(capsys.readouterr().out)["designs"]["planned"] == 10**12


# -- bad input and faults: one line, nothing half-written ---------------------------


@pytest.mark.parametrize(
    "space",
    ["lhs:99999999999999999999", "sobol:99999999999999999999", "lhs:" + "7" * 5000],
    ids=["lhs", "sobol", "5000 digits"],
)
def test_a_space_over_the_designs_limit_is_one_line_before_anything(tmp_path, capsys, space):
    db = tmp_path / "c.duckdb"
    for extra in ([], ["--allow-large"], ["--shard", "1/4"]):
        assert main(["campaign", "run", str(db), "--space", space, *extra]) == 2
        line = one_error_line(capsys)
        assert line.startswith(f"softbend: error: --space: {space[:30]}")
        assert "more than the limit of 1,000,000 designs" in line
        assert "set SOFTBEND_MAX_DESIGNS higher" in line
    assert not db.exists()
    out = tmp_path / "ds"
    argv = ["campaign", "dataset", str(db), "--out", str(out), "--command", "x", "--space", space]
    db.write_bytes(b"")  # the space is refused before the database is read
    assert main(argv) == 2
    assert "SOFTBEND_MAX_DESIGNS" in one_error_line(capsys)
    assert not out.exists()


def test_a_negative_seed_names_the_option(tmp_path, capsys):
    db = tmp_path / "c.duckdb"
    assert main(["campaign", "run", str(db), "--space", "lhs:3", "--seed", "-1"]) == 2
    assert "--seed: must be an integer in [0, inf); got -1" in (one_error_line(capsys))
    assert not db.exists()


def _run_shard(db, *extra):
    assert main(["campaign", "run", str(db), *RUN, "--workers", "0", "--json", *extra]) == 0


@pytest.mark.parametrize(
    ("second", "needle"),
    [
        (["--pmax", "0.2"], "The 'pressures_mpa' of the campaign in"),
        (["--backend", "fem"], "The backend of the campaign in"),
        (None, "is not a readable softbend campaign database (truncated"),
    ],
    ids=["another grid", "another backend", "truncated"],
)
def test_a_merge_with_one_bad_shard_writes_nothing(tmp_path, capsys, monkeypatch, second, needle):
    first, bad = tmp_path / "s0.duckdb", tmp_path / "s1.duckdb"
    _run_shard(first, "--shard", "0/2")
    if second is None:
        _run_shard(bad, "--shard", "1/2")
        data = bad.read_bytes()
        bad.write_bytes(data[: len(data) // 2])
    elif "fem" in second:
        from softbend.campaign import CampaignStore

        with CampaignStore(bad) as store:  # a shard of the FEM, without running one
            store.bind("fem", default_pressures_mpa(0.1, 0.05))
            store.record_failure(sfrba_design(100, 6, 2, 2, 5, 8), "RuntimeError: x", 1.0)
    else:
        _run_shard(bad, "--shard", "1/2", *second)
    capsys.readouterr()
    merged = tmp_path / "merged.duckdb"
    assert main(["campaign", "merge", str(merged), str(first), str(bad)]) == 2
    line = one_error_line(capsys)
    assert needle in line and str(bad) in line
    assert not merged.exists()
    assert sorted(p.name for p in tmp_path.iterdir()) == ["s0.duckdb", "s1.duckdb"]
    # A database merged into before is left exactly as it was.
    assert main(["campaign", "merge", str(merged), str(first), "--json"]) == 0
    capsys.readouterr()
    before = merged.read_bytes()
    assert main(["campaign", "merge", str(merged), str(first), str(bad)]) == 2
    assert needle in one_error_line(capsys)
    assert merged.read_bytes() == before
    assert sorted(p.name for p in tmp_path.iterdir()) == [
        "merged.duckdb",
        "s0.duckdb",
        "s1.duckdb",
    ]


def test_a_merge_into_a_campaign_of_another_grid_writes_nothing(tmp_path, capsys):
    target, shard = tmp_path / "t.duckdb", tmp_path / "s.duckdb"
    _run_shard(target, "--pmax", "0.2")
    _run_shard(shard)
    capsys.readouterr()
    before = target.read_bytes()
    assert main(["campaign", "merge", str(target), str(shard)]) == 2
    line = one_error_line(capsys)
    assert f"The 'pressures_mpa' of the campaign in {str(shard)!r}" in line
    assert f"those of {str(target)!r} 5 pressures from 0 to 0.2 MPa" in line
    assert target.read_bytes() == before


#: Runs softbend's CLI in a process whose files may not grow beyond a size: a real
#: write failure of DuckDB's (EFBIG, as a full disk gives ENOSPC), not a mock.
_SMALL_FILES = """
import resource, signal, sys
signal.signal(signal.SIGXFSZ, signal.SIG_IGN)
from softbend.cli import main
resource.setrlimit(resource.RLIMIT_FSIZE, (int(sys.argv[1]), resource.RLIM_INFINITY))
sys.exit(main(sys.argv[2:]))
"""


def _with_small_files(max_bytes, *argv, cwd):
    import subprocess
    import sys

    return subprocess.run(
        [sys.executable, "-c", _SMALL_FILES, str(max_bytes), *argv],
        capture_output=True,
        text=True,
        cwd=cwd,
        timeout=120,
    )


@pytest.fixture(scope="module")
def larger_campaign_db(tmp_path_factory):
    db = tmp_path_factory.mktemp("larger") / "c.duckdb"
    assert main(["campaign", "run", str(db), "--space", "lhs:60", "--workers", "0", "--json"]) == 0
    return db


def test_a_failed_write_of_an_export_is_one_line_and_leaves_no_file(
    larger_campaign_db, tmp_path, capsys
):
    capsys.readouterr()
    out_dir = tmp_path / "exports"
    out_dir.mkdir()
    (out_dir / "old.csv").write_text("design_id\nkept\n")
    argv = ["campaign", "export", str(larger_campaign_db), "--out"]
    done = _with_small_files(10_000, *argv, "new.parquet", cwd=out_dir)
    assert done.returncode == 2, done.stderr
    assert done.stderr.strip() == (
        "softbend: error: The '--out' new.parquet could not be written: File too large."
    )
    done = _with_small_files(10_000, *argv, "old.csv", cwd=out_dir)
    assert done.returncode == 2, done.stderr
    assert done.stderr.strip() == (
        "softbend: error: The '--out' old.csv could not be written: File too large."
    )
    assert sorted(p.name for p in out_dir.iterdir()) == ["old.csv"]  # no temporary file left
    assert (out_dir / "old.csv").read_text() == "design_id\nkept\n"


def test_a_failed_write_of_a_merge_leaves_the_previous_database(
    larger_campaign_db, tmp_path, capsys
):
    capsys.readouterr()
    folder = tmp_path / "m"
    folder.mkdir()
    assert main(["campaign", "merge", str(folder / "m.duckdb"), str(larger_campaign_db)]) == 0
    capsys.readouterr()
    before = (folder / "m.duckdb").read_bytes()
    other = tmp_path / "other.duckdb"  # more designs on the same grid: the merged file grows
    argv = ["campaign", "run", str(other), "--space", "lhs:20", "--seed", "9", "--workers", "0"]
    assert main([*argv, "--json"]) == 0
    done = _with_small_files(len(before), "campaign", "merge", "m.duckdb", str(other), cwd=folder)
    assert done.returncode == 2, done.stderr
    assert done.stderr.strip() == (
        "softbend: error: The 'DB' m.duckdb could not be written: File too large."
    )
    assert (folder / "m.duckdb").read_bytes() == before
    assert sorted(p.name for p in folder.iterdir()) == ["m.duckdb"]
    # Into a new database: nothing at all is left.
    done = _with_small_files(20_000, "campaign", "merge", "new.duckdb", str(other), cwd=folder)
    assert done.returncode == 2, done.stderr
    assert "The 'DB' new.duckdb could not be written: File too large." in done.stderr
    assert sorted(p.name for p in folder.iterdir()) == ["m.duckdb"]


def test_a_failed_write_of_a_run_is_one_line_and_the_run_resumes(tmp_path, capsys):
    argv = ["campaign", "run", "c.duckdb", "--space", "lhs:60", "--workers", "0", "--json"]
    done = _with_small_files(5_000, *argv, cwd=tmp_path)  # not even the empty database fits
    assert done.returncode == 2, done.stderr
    assert done.stderr.strip() == (
        "softbend: error: The 'DB' c.duckdb could not be written: File too large."
    )
    assert list(tmp_path.iterdir()) == []  # no half-made database
    done = _with_small_files(150_000, *argv, cwd=tmp_path)  # full after some designs
    assert done.returncode == 2, done.stderr
    lines = [line for line in done.stderr.splitlines() if line.startswith("softbend:")]
    assert lines == ["softbend: error: The 'DB' c.duckdb could not be written: File too large."]
    assert "Traceback" not in done.stderr
    # What was recorded is kept: the same command, with room, resumes and finishes.
    assert main(["campaign", "run", str(tmp_path / "c.duckdb"), *argv[3:]]) == 0
    summary = json.loads(capsys.readouterr().out)
    assert summary["n_skipped_done"] > 0
    assert summary["n_skipped_done"] + summary["n_done"] == 60


def test_an_http_server_as_scheduler_is_one_line_and_no_destructor_traceback(tmp_path):
    import subprocess
    import sys

    # In a process of its own: a half-made Dask client failed in its destructor only
    # when the interpreter exited, after the error line.
    port, close = web_server()
    address = f"tcp://127.0.0.1:{port}"
    argv = ["campaign", "run", "c.duckdb", *RUN, "--scheduler", address, "--connect-timeout", "1"]
    try:
        done = subprocess.run(
            [
                sys.executable,
                "-c",
                "import sys; from softbend.cli import main; sys.exit(main(sys.argv[1:]))",
                *argv,
            ],
            capture_output=True,
            text=True,
            cwd=tmp_path,
            timeout=120,
        )
    finally:
        close()
    assert done.returncode == 2
    lines = done.stderr.strip().splitlines()
    assert len(lines) == 1, done.stderr
    assert lines[0].startswith(
        f"softbend: error: --scheduler: {address} did not answer as a Dask scheduler"
    )
    assert "EiB" not in lines[0]
    assert list(tmp_path.iterdir()) == []


@pytest.mark.parametrize(
    ("content", "needle"),
    [
        ("[" * 100_000, "not JSON (nested too deeply)"),
        ('["tcp://127.0.0.1:8786"]', "got a JSON array"),
        ('{"address": 8786}', "got 'address' 8786"),
        ('{"adress": "tcp://127.0.0.1:8786"}', "got no 'address'"),
        ("\xff\xfe garbage", "not JSON"),
    ],
    ids=["deep", "array", "number", "misspelt", "binary"],
)
def test_a_bad_scheduler_file_is_one_line_naming_it(tmp_path, capsys, content, needle):
    scheduler = tmp_path / "scheduler.json"
    scheduler.write_bytes(content.encode("latin-1"))
    db = tmp_path / "c.duckdb"
    assert main(["campaign", "run", str(db), *RUN, "--scheduler", str(scheduler)]) == 2
    line = one_error_line(capsys)
    assert f"{scheduler}: must be a Dask scheduler file" in line
    assert needle in line
    assert not db.exists()


def test_a_dataset_of_a_campaign_that_never_ran_is_one_line_and_writes_nothing(tmp_path, capsys):
    from softbend.campaign import CampaignStore

    db = tmp_path / "empty.duckdb"
    CampaignStore(db).close()
    out = tmp_path / "ds"
    assert main(["campaign", "dataset", str(db), "--out", str(out), "--command", "x"]) == 2
    assert f"The campaign database {db} holds no finished run" in one_error_line(capsys)
    assert not out.exists()


_EVERY_READER = ("status", "run", "merge", "export", "dataset")


@pytest.mark.parametrize(
    ("key", "value", "readers"),
    [
        ("pressures_mpa", "not json", _EVERY_READER),
        ("pressures_mpa", '{"a": 1}', _EVERY_READER),
        ("pressures_mpa", "[0.1, 0.0]", _EVERY_READER),
        ("pressures_mpa", "[" * 100_000, _EVERY_READER),
        ("runs", '{"a": 1}', ("merge", "dataset")),
        ("runs", "[1, 2]", ("merge", "dataset")),
        ("n_designs_planned", "many", ("status", "dataset")),
    ],
)
def test_damaged_campaign_metadata_is_one_line_for_every_reader(
    campaign_db, tmp_path, capsys, key, value, readers
):
    con = duckdb.connect(str(campaign_db))
    con.execute("UPDATE meta SET value = ? WHERE key = ?", [value, key])
    con.close()
    other = tmp_path / "other.duckdb"
    _run_shard(other)
    capsys.readouterr()
    before = other.read_bytes()
    commands = {
        "status": ["status", str(campaign_db), "--json"],
        "run": ["run", str(campaign_db), *RUN, "--workers", "0"],
        "merge": ["merge", str(other), str(campaign_db)],
        "export": ["export", str(campaign_db), "--out", str(tmp_path / "x.csv")],
        "dataset": ["dataset", str(campaign_db), "--out", str(tmp_path / "ds"), "--command", "x"],
    }
    for name in readers:
        assert main(["campaign", *commands[name]]) == 2, name
        line = one_error_line(capsys)
        assert f"The campaign database {str(campaign_db)!r} has a damaged {key!r}" in line, name
    assert other.read_bytes() == before
    assert not (tmp_path / "ds").exists() and not (tmp_path / "x.csv").exists()


# --- ``softbend campaign run|merge`` faults: refused before any work, or a runtime fault ---
#
# The FEM's mesh-size rule is checked on every design of the space before any
# sweep (with a stand-in FEM, so no NGSolve is needed); a run whose every design
# fails exits 1 with the first reason; ``campaign merge`` names each input that is
# not a campaign database (a CSV, an empty file, a folder, another DuckDB file).


RUN_FAULT = [
    "--space",
    "lhs:6",
    "--seed",
    "3",
    "--pmax",
    "0.1",
    "--pstep",
    "0.05",
    "--workers",
    "0",
]
FEM_RUN = ["--backend", "fem", "--space", "corners", "--pmax", "0.01", "--workers", "0"]
#: The largest design of the corners: the one a too-fine mesh size is refused for.
LARGEST_CORNER = sfrba_design(160, 10, 4, 4, 5, 12)


@dataclasses.dataclass(frozen=True)
class _StandInFEM:
    """The FEM as the campaign sees it (a name, FEM options, a sweep), without NGSolve."""

    options: FEMOptions
    compiled: bool = False
    name: str = dataclasses.field(default="fem", init=False)

    def sweep(self, design, pressures_mpa):
        raise AssertionError(f"swept {design}: the mesh size should have been refused first")


@pytest.fixture
def stand_in_fem(monkeypatch):
    """``--backend fem`` builds :class:`_StandInFEM` with the real FEMOptions."""
    import softbend.campaign.backends as backends

    fem = SimpleNamespace(FEMOptions=FEMOptions, FEMModel=_StandInFEM)
    monkeypatch.setattr(backends, "_import_fem", lambda: fem)


def _mesh_message(design: Design, maxh_mm: float) -> str:
    with pytest.raises(ValueError) as info:
        check_mesh_size(design, maxh_mm)
    return str(info.value)


# -- --maxh: the FEM's rule, before any work ---------------------------------------------


@pytest.mark.parametrize(
    ("maxh", "message"),
    [
        ("0.3", _mesh_message(LARGEST_CORNER, 0.3)),
        ("25", "--maxh: must be a number in (0, 20]; got 25.0"),
    ],
    ids=["too many elements", "above the range"],
)
def test_a_maxh_the_fem_refuses_is_refused_before_any_design(
    tmp_path, capsys, stand_in_fem, maxh, message
):
    db = tmp_path / "c.duckdb"
    assert main(["campaign", "run", str(db), *FEM_RUN, "--maxh", maxh]) == 2
    assert one_error_line(capsys) == f"softbend: error: {message.replace('maxh_mm: ', '--maxh: ')}"
    assert not db.exists() and list(tmp_path.iterdir()) == []


def test_the_mesh_rule_names_the_design_with_the_most_elements():
    corners = DesignSpace.corners().designs
    # At 1.445 mm only the two largest corners (phi 5 and 15, one volume) need more than
    # 400000 elements; the first of them is named, as the FEM would name it.
    largest = [
        d for d in corners if (d.l_mm, d.r_mm, d.t_mm, d.b_mm, d.lc_mm) == (160, 10, 4, 4, 12)
    ]
    assert len(largest) == 2
    check_mesh_size([d for d in corners if d not in largest], 1.445)
    with pytest.raises(ValueError) as info:
        check_mesh_size(corners, 1.445)
    assert str(info.value) == _mesh_message(LARGEST_CORNER, 1.445)
    assert "got 1.445 mm (about 407888 elements)" in str(info.value)
    FEMOptions(maxh_mm=5.0).check_mesh(corners)  # the default mesh size meshes them all
    check_mesh_size([], 0.1)  # nothing to mesh


def test_run_campaign_checks_the_mesh_of_every_design_first(tmp_path):
    from softbend.campaign import run_campaign

    db = tmp_path / "c.duckdb"
    with pytest.raises(ValueError, match="must give at most 400000 elements for design"):
        run_campaign(
            db,
            DesignSpace.corners(),
            backend=_StandInFEM(FEMOptions(maxh_mm=0.5)),
            pressures_mpa=[0.0, 0.01],
            workers=0,
        )
    assert not db.exists()


def test_the_mesh_rule_is_the_one_the_fem_applies_when_meshing():
    import softbend._torch  # noqa: F401  (PyTorch before NGSolve, as softbend.fem loads them)
    from softbend.fem.geometry import mesh_actuator

    pytest.importorskip("ngsolve")

    design = sfrba_design(100, 6, 2, 2, 5, 10)
    with pytest.raises(ValueError) as info:
        mesh_actuator(design, maxh_mm=0.3)
    assert str(info.value) == _mesh_message(design, 0.3)


# -- a run whose every design failed is a runtime fault ----------------------------------


def _failing_sweeps(monkeypatch, fail) -> None:
    """The analytical model's sweep raises for the designs ``fail(design)`` picks."""
    sweep = AnalyticalModel.sweep

    def flaky(self, design, pressures_mpa):
        if fail(design):
            raise ConvergenceError(f"no equilibrium for design {design}", pressure_mpa=0.05)
        return sweep(self, design, pressures_mpa)

    monkeypatch.setattr(AnalyticalModel, "sweep", flaky)


@pytest.mark.parametrize("as_json", [False, True], ids=["table", "json"])
def test_a_run_whose_every_design_failed_exits_1_with_the_reason(
    tmp_path, capsys, monkeypatch, as_json
):
    _failing_sweeps(monkeypatch, lambda design: True)
    db = tmp_path / "c.duckdb"
    assert main(["campaign", "run", str(db), *RUN_FAULT, *(["--json"] if as_json else [])]) == 1
    captured = capsys.readouterr()
    errors = [line for line in captured.err.splitlines() if line.startswith("softbend: error:")]
    assert len(errors) == 1 and "Traceback" not in captured.err
    assert errors[0].startswith("softbend: error: every design of this run failed (6 of 6); ")
    assert "; the first: no equilibrium for design " in errors[0]
    assert "ConvergenceError" not in errors[0]  # the reason, not the exception's type
    assert f"recorded in {db} as failed" in errors[0]
    if as_json:  # the summary still comes first, whole
        assert json.loads(captured.out)["n_failed"] == 6
    else:
        assert "failed in this run" in captured.out
    # The failures stay recorded; a re-run that sweeps them retries them.
    monkeypatch.undo()
    assert main(["campaign", "run", str(db), *RUN_FAULT, "--json"]) == 0
    assert json.loads(capsys.readouterr().out)["n_done"] == 6


def test_a_run_with_some_failed_designs_or_none_left_exits_0(tmp_path, capsys, monkeypatch):
    failed: list[Design] = []

    def first_only(design):
        if not failed:
            failed.append(design)
        return design == failed[0]

    _failing_sweeps(monkeypatch, first_only)
    db = tmp_path / "c.duckdb"
    assert main(["campaign", "run", str(db), *RUN_FAULT, "--json"]) == 0
    summary = json.loads(capsys.readouterr().out)
    assert (summary["n_done"], summary["n_failed"]) == (5, 1)
    # Nothing left to sweep (the failed one kept): no design run, no fault.
    assert main(["campaign", "run", str(db), *RUN_FAULT, "--no-retry-failed", "--json"]) == 0
    assert json.loads(capsys.readouterr().out)["n_run"] == 0


# -- campaign merge: every input that is not a campaign, named ---------------------------


@pytest.fixture
def shard(tmp_path, capsys):
    path = tmp_path / "s0.duckdb"
    assert main(["campaign", "run", str(path), *RUN_FAULT, "--json"]) == 0
    capsys.readouterr()
    return path


def _csv(path):
    path.write_text("design_id,angle_deg\nd1,12.5\n")


def _empty(path):
    path.write_bytes(b"")


def _folder(path):
    path.mkdir()


def _other_duckdb(path):
    con = duckdb.connect(str(path))
    con.execute("CREATE TABLE measurements (x INTEGER)")
    con.close()


NOT_READABLE = "is not a readable softbend campaign database"
WHAT_IT_MUST_BE = (
    "a campaign database is the DuckDB file that 'softbend campaign run' or "
    "'softbend campaign merge' writes)."
)


@pytest.mark.parametrize(
    ("name", "make", "said"),
    [
        ("all.csv", _csv, f"{NOT_READABLE} (not a DuckDB database file; "),
        ("x.duckdb", _csv, f"{NOT_READABLE} (not a DuckDB database file; "),
        ("e.duckdb", _empty, f"{NOT_READABLE} (an empty file; "),
        ("d.duckdb", _folder, "is a folder, not a softbend campaign database ("),
        ("o.duckdb", _other_duckdb, "is not a softbend campaign database (no 'meta' table; found"),
    ],
    ids=["a csv", "a csv named .duckdb", "empty", "a folder", "another duckdb"],
)
@pytest.mark.parametrize("role", ["shard", "target"])
def test_merge_names_an_input_that_is_not_a_campaign(
    tmp_path, capsys, shard, name, make, said, role
):
    bad = tmp_path / name
    make(bad)
    before = None if bad.is_dir() else bad.read_bytes()
    target, shards = (tmp_path / "m.duckdb", [shard, bad]) if role == "shard" else (bad, [shard])
    assert main(["campaign", "merge", str(target), *map(str, shards)]) == 2
    line = one_error_line(capsys)
    if role == "target" and bad.is_dir():  # the output's own check
        assert line == f"softbend: error: The 'DB' must name a file; {bad} is a folder."
    else:
        assert line.startswith(f"softbend: error: {str(bad)!r} {said}")
        assert line.endswith(WHAT_IT_MUST_BE)
    for words in ("Catalog Error", "IO Error", "in-memory", "Traceback"):
        assert words not in line
    assert (bad.is_dir() and before is None) or bad.read_bytes() == before
    assert sorted(p.name for p in tmp_path.iterdir()) == sorted({shard.name, name})


def test_merge_names_a_missing_shard(tmp_path, capsys, shard):
    missing = tmp_path / "missing.duckdb"
    assert main(["campaign", "merge", str(tmp_path / "m.duckdb"), str(shard), str(missing)]) == 2
    assert one_error_line(capsys) == f"softbend: error: No campaign database at {str(missing)!r}."
    assert sorted(p.name for p in tmp_path.iterdir()) == ["s0.duckdb"]


def test_status_and_run_read_a_csv_as_no_campaign(tmp_path, capsys):
    bad = tmp_path / "all.csv"
    _csv(bad)
    for argv in (["campaign", "status", str(bad)], ["campaign", "run", str(bad), *RUN_FAULT]):
        assert main(argv) == 2
        line = one_error_line(capsys)
        assert line.startswith(f"softbend: error: {str(bad)!r} is not a readable softbend campaign")
        assert line.endswith(WHAT_IT_MUST_BE)
    assert bad.read_text() == "design_id,angle_deg\nd1,12.5\n"
