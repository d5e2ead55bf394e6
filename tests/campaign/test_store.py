"""The campaign database: schema, one transaction per design, reading and export."""

from __future__ import annotations

import subprocess
import sys
import textwrap

import duckdb
import numpy as np
import pandas as pd
import pytest

from softbend import __version__
from softbend.campaign import store as store_module
from softbend.campaign.backends import AnalyticalBackend, SweepResult, default_pressures_mpa
from softbend.campaign.store import SCHEMA_VERSION, CampaignStore, load_samples
from softbend.design import PARAMETERS, SFRBADesign
from softbend.errors import SchemaError, SoftbendError

GRID = default_pressures_mpa(0.5, 0.05)
A = SFRBADesign(100, 6, 3, 2, 5, 8)  # converges up to 0.5 MPa
B = SFRBADesign(120, 8, 3, 3, 10, 10)

SAMPLE_COLUMNS = [
    "design_id",
    "l_mm",
    "r_mm",
    "t_mm",
    "b_mm",
    "phi_deg",
    "lc_mm",
    "pressure_mpa",
    "angle_deg",
    "tip_x_mm",
    "tip_z_mm",
    "converged",
]


def _sweep(design: SFRBADesign, grid: np.ndarray = GRID) -> SweepResult:
    return AnalyticalBackend().sweep(design, grid)


@pytest.fixture
def store(tmp_path):
    with CampaignStore(tmp_path / "c.duckdb") as opened:
        opened.bind("analytical", GRID)
        yield opened


def _count(path, sql: str) -> int:
    con = duckdb.connect(str(path), read_only=True)
    try:
        return con.execute(sql).fetchone()[0]
    finally:
        con.close()


def test_new_database_has_the_schema_and_metadata(tmp_path):
    path = tmp_path / "new.duckdb"
    with CampaignStore(path) as store:
        meta = store.meta()
        assert store.backend is None and store.pressures_mpa is None
        store.bind("analytical", GRID, space="test", n_designs_planned=7)
        assert store.backend == "analytical"
        np.testing.assert_array_equal(store.pressures_mpa, GRID)
    assert meta["schema_version"] == str(SCHEMA_VERSION) == "1"
    assert meta["softbend_version"] == __version__
    assert meta["created_at"].endswith("Z")
    con = duckdb.connect(str(path), read_only=True)
    query = "SELECT table_name FROM information_schema.tables"
    tables = {r[0] for r in con.execute(query).fetchall()}
    keys = dict(con.execute("SELECT key, value FROM meta").fetchall())
    con.close()
    assert {"meta", "designs", "samples"} <= tables
    assert keys["backend"] == "analytical" and keys["space"] == "test"
    assert keys["n_designs_planned"] == "7"
    # The grid is stored exactly (JSON of the doubles).
    with CampaignStore(path, read_only=True) as again:
        np.testing.assert_array_equal(again.pressures_mpa, GRID)


def test_samples_round_trip_with_design_parameters(store, soft_design):
    full, truncated = _sweep(A), _sweep(soft_design)
    store.record_success(full)
    store.record_success(truncated)
    frame = store.load_samples()
    assert list(frame.columns) == SAMPLE_COLUMNS
    assert len(frame) == len(full.pressure_mpa) + len(truncated.pressure_mpa)
    assert frame["converged"].dtype == bool
    rows = frame[frame["design_id"] == soft_design.design_id].reset_index(drop=True)
    np.testing.assert_array_equal(rows["pressure_mpa"], truncated.pressure_mpa)
    np.testing.assert_array_equal(rows["angle_deg"], truncated.angle_deg)  # NaN == NaN here
    np.testing.assert_array_equal(rows["tip_z_mm"], truncated.tip_z_mm)
    np.testing.assert_array_equal(rows["converged"], truncated.converged)
    for name in PARAMETERS:
        assert (rows[name] == getattr(soft_design, name)).all()
    designs = store.load_designs().set_index("design_id")
    row = designs.loc[soft_design.design_id]
    assert row["status"] == "done" and pd.isna(row["error"])
    assert row["n_samples"] == len(truncated.pressure_mpa)
    assert row["max_pressure_mpa"] == truncated.max_pressure_mpa < GRID[-1]
    assert row["max_angle_deg"] == pytest.approx(truncated.max_angle_deg)
    assert row["backend"] == "analytical" and row["schema_version"] == SCHEMA_VERSION
    assert pd.isna(row["mesh_size"]) and row["newton_iterations_total"] == 0
    assert "does not converge" in row["stats"]


def test_non_converged_values_are_null_in_the_database(tmp_path, soft_design):
    path = tmp_path / "n.duckdb"
    with CampaignStore(path) as store:
        store.bind("analytical", GRID)
        store.record_success(_sweep(soft_design))
    assert _count(path, "SELECT count(*) FROM samples WHERE angle_deg IS NULL") == 1
    assert _count(path, "SELECT count(*) FROM samples WHERE NOT converged") == 1
    assert _count(path, "SELECT count(*) FROM samples WHERE isnan(angle_deg)") == 0


def test_failure_then_success_replaces_the_row_without_duplicates(store):
    store.record_failure(A, "ConvergenceError: no luck", 1.5)
    assert store.failed_ids() == {A.design_id}
    assert store.finished_ids() == set()
    assert store.finished_ids(include_failed=True) == {A.design_id}
    failed = store.load_designs().iloc[0]
    assert failed["status"] == "failed" and failed["error"] == "ConvergenceError: no luck"
    assert failed["n_samples"] == 0 and failed["wall_time_s"] == 1.5
    assert store.load_samples().empty

    store.record_success(_sweep(A))
    store.record_success(_sweep(A))  # recorded twice: still one row and one set of samples
    designs = store.load_designs()
    assert list(designs["design_id"]) == [A.design_id]
    assert designs.iloc[0]["status"] == "done" and pd.isna(designs.iloc[0]["error"])
    assert len(store.load_samples()) == len(GRID)
    assert store.finished_ids() == {A.design_id} and store.failed_ids() == set()


def test_a_design_is_written_completely_or_not_at_all(store, monkeypatch):
    store.record_success(_sweep(B))
    monkeypatch.setattr(store_module, "_INSERT_SAMPLES", "INSERT INTO no_such_table VALUES (1)")
    with pytest.raises(duckdb.Error):
        store.record_success(_sweep(A))
    monkeypatch.undo()
    # The failed write left neither a designs row nor samples; the earlier design is intact.
    assert store.finished_ids() == {B.design_id}
    assert set(store.load_samples()["design_id"]) == {B.design_id}
    store.record_success(_sweep(A))
    assert store.finished_ids() == {A.design_id, B.design_id}


def test_results_off_the_campaign_grid_are_refused(store):
    with pytest.raises(ValueError, match="leading values of the campaign grid"):
        store.record_success(_sweep(A, default_pressures_mpa(0.5, 0.1)))
    store.record_success(_sweep(A, GRID[:4]))  # a prefix is fine
    assert store.load_designs().iloc[0]["n_samples"] == 4


def test_resume_with_another_backend_or_grid_is_refused(tmp_path):
    path = tmp_path / "c.duckdb"
    with CampaignStore(path) as store:
        store.bind("analytical", GRID)
    with CampaignStore(path) as store:
        store.bind("analytical", GRID.copy())  # the same campaign: fine
        with pytest.raises(ValueError, match=r"'backend' of the campaign .* is 'analytical'"):
            store.bind("fem", GRID)
        with pytest.raises(ValueError, match=r"'pressures_mpa' of the campaign .* 11 pressures"):
            store.bind("analytical", default_pressures_mpa())
    with (
        CampaignStore(tmp_path / "unbound.duckdb") as store,
        pytest.raises(ValueError, match="'backend'"),
    ):
        store.record_failure(A, "x", 0.0)


def test_newer_schema_is_refused_with_one_clear_line(tmp_path):
    path = tmp_path / "future.duckdb"
    CampaignStore(path).close()
    con = duckdb.connect(str(path))
    con.execute("UPDATE meta SET value = '2' WHERE key = 'schema_version'")
    con.close()
    for read_only in (False, True):
        with pytest.raises(SchemaError) as info:
            CampaignStore(path, read_only=read_only)
        message = str(info.value)
        assert "\n" not in message
        assert "schema version 2, newer than this softbend supports (1)" in message


def test_files_that_are_not_campaigns_are_refused(tmp_path):
    junk = tmp_path / "junk.duckdb"
    junk.write_text("not a database at all" * 50)
    with pytest.raises(SchemaError, match="not a DuckDB database"):
        CampaignStore(junk)
    other = tmp_path / "other.duckdb"
    con = duckdb.connect(str(other))
    con.execute("CREATE TABLE measurements (x INTEGER)")
    con.close()
    with pytest.raises(SchemaError, match=r"not a softbend campaign database.*measurements"):
        CampaignStore(other)
    with pytest.raises(FileNotFoundError, match="No campaign database"):
        CampaignStore(tmp_path / "missing.duckdb", read_only=True)
    with pytest.raises(FileNotFoundError, match="folder"):
        CampaignStore(tmp_path / "no" / "dir.duckdb")


def test_a_database_in_use_by_another_process_is_a_clear_error(tmp_path):
    path = tmp_path / "busy.duckdb"
    CampaignStore(path).close()
    holder = subprocess.Popen(
        [
            sys.executable,
            "-c",
            textwrap.dedent(
                f"""
                import sys, duckdb
                con = duckdb.connect({str(path)!r})
                print("locked", flush=True)
                sys.stdin.readline()
                """
            ),
        ],
        stdin=subprocess.PIPE,
        stdout=subprocess.PIPE,
        text=True,
    )
    try:
        assert holder.stdout.readline().strip() == "locked"
        with pytest.raises(SoftbendError, match="in use by another process"):
            CampaignStore(path, read_only=True)
    finally:
        holder.stdin.close()
        holder.wait(timeout=30)


def test_status_summary_counts(store, soft_design):
    store.record_success(_sweep(A))
    store.record_success(_sweep(soft_design))
    store.record_failure(B, "RuntimeError: boom", 0.25)
    summary = store.status_summary()
    n_soft = len(_sweep(soft_design).pressure_mpa)
    assert summary["done"] == 2 and summary["failed"] == 1 and summary["designs_recorded"] == 3
    assert summary["samples"] == len(GRID) + n_soft
    assert summary["converged_samples"] == len(GRID) + n_soft - 1
    assert summary["n_pressures"] == 11 and summary["pmax_mpa"] == 0.5
    assert summary["backend"] == "analytical" and summary["schema_version"] == 1
    assert summary["failures"] == [
        {"design_id": B.design_id, "design": str(B), "error": "RuntimeError: boom"}
    ]


@pytest.mark.parametrize("fmt", ["parquet", "csv"])
def test_export_round_trip(store, soft_design, tmp_path, fmt):
    store.record_success(_sweep(A))
    store.record_success(_sweep(soft_design))
    store.record_failure(B, "RuntimeError: boom", 0.25)
    expected = store.load_samples()
    out = tmp_path / f"samples.{fmt}"
    out.write_text("an older export")
    assert store.export(out, format=fmt) == out
    back = pd.read_parquet(out) if fmt == "parquet" else pd.read_csv(out)
    assert list(back.columns) == SAMPLE_COLUMNS
    pd.testing.assert_frame_equal(
        back.astype({"design_id": object}),
        expected.astype({"design_id": object}),
        check_dtype=False,
    )
    designs_out = tmp_path / f"designs.{fmt}"
    store.export(designs_out, format=fmt, table="designs")
    designs = pd.read_parquet(designs_out) if fmt == "parquet" else pd.read_csv(designs_out)
    assert sorted(designs["status"]) == ["done", "done", "failed"]
    assert not [p for p in tmp_path.iterdir() if p.name.endswith(".tmp")]


def test_export_bad_input(store, tmp_path):
    with pytest.raises(ValueError, match=r"'format' of CampaignStore\.export must be one of"):
        store.export(tmp_path / "x.xlsx", format="xlsx")
    with pytest.raises(ValueError, match="'table'"):
        store.export(tmp_path / "x.csv", format="csv", table="meta")
    with pytest.raises(FileNotFoundError, match="folder"):
        store.export(tmp_path / "missing" / "x.csv", format="csv")


def test_module_level_load_samples(tmp_path):
    path = tmp_path / "c.duckdb"
    with CampaignStore(path) as store:
        store.bind("analytical", GRID)
        store.record_success(_sweep(A))
        expected = store.load_samples()
    pd.testing.assert_frame_equal(load_samples(path), expected)
    pd.testing.assert_frame_equal(load_samples(str(path)), expected)


def test_merge_takes_done_designs_over_failed_and_refuses_another_campaign(tmp_path):
    with CampaignStore(tmp_path / "a.duckdb") as a:
        a.bind("analytical", GRID)
        a.record_success(_sweep(A))
        a.record_failure(B, "RuntimeError: lost worker", 1.0)
    with CampaignStore(tmp_path / "b.duckdb") as b:
        b.bind("analytical", GRID)
        b.record_success(_sweep(B))
        b.record_failure(A, "RuntimeError: other failure", 1.0)
    with CampaignStore(tmp_path / "a.duckdb") as a:
        counts = a.merge(tmp_path / "b.duckdb")
        assert counts == {"added": 0, "replaced_failed": 1, "kept": 1}
        designs = a.load_designs().set_index("design_id")
        assert set(designs["status"]) == {"done"}  # B's failure replaced, A's success kept
        assert len(a.load_samples()) == 2 * len(GRID)
        with pytest.raises(ValueError, match="merged into itself"):
            a.merge(tmp_path / "a.duckdb")
    with CampaignStore(tmp_path / "other.duckdb") as other:
        other.bind("analytical", default_pressures_mpa(0.5, 0.1))
        other.record_success(_sweep(A, default_pressures_mpa(0.5, 0.1)))
    with CampaignStore(tmp_path / "a.duckdb") as a, pytest.raises(ValueError, match="pressures"):
        a.merge(tmp_path / "other.duckdb")


def _campaign_file(tmp_path):
    """A closed campaign database with two done designs, and its bytes."""
    path = tmp_path / "good.duckdb"
    with CampaignStore(path) as opened:
        opened.bind("analytical", GRID)
        opened.record_success(_sweep(A))
        opened.record_success(_sweep(B))
    return path, path.read_bytes()


def _overwrite_every_block(data: bytes) -> bytes:
    """Garbage over the first 4 KiB of every 256 KiB block (after its checksum)."""
    corrupt = bytearray(data)
    block, header = 262144, 3 * 4096
    for start in range(header, len(corrupt) - block + 1, block):
        corrupt[start + 8 : start + 4096] = b"\xa5" * (4096 - 8)
    return bytes(corrupt)


_BROKEN_FILES = {
    "truncated to 600000 bytes": lambda data: data[:600000],
    "truncated by 5000 bytes": lambda data: data[:-5000],
    "headers only": lambda data: data[: 3 * 4096],
    "truncated to 100 bytes": lambda data: data[:100],
    "garbage in every block": _overwrite_every_block,
    "a csv renamed": lambda data: b"design_id,angle_deg\nd1,12.5\n",
    "empty": lambda data: b"",
    "random bytes": lambda data: np.random.default_rng(0).bytes(len(data)),
}


@pytest.mark.parametrize("read_only", [True, False], ids=["read-only", "read-write"])
@pytest.mark.parametrize("damage", list(_BROKEN_FILES))
def test_unreadable_files_are_one_schema_error_naming_the_file(tmp_path, damage, read_only):
    _, data = _campaign_file(tmp_path)
    broken = tmp_path / "broken.duckdb"
    broken.write_bytes(_BROKEN_FILES[damage](data))
    before = broken.read_bytes()
    with pytest.raises(SchemaError) as info:
        CampaignStore(broken, read_only=read_only)
    message = str(info.value)
    assert message.startswith(f"{str(broken)!r} is not a readable softbend campaign database (")
    assert message.endswith(").") and "\n" not in message and len(message) < 400
    assert broken.read_bytes() == before  # refused without writing to it
    with pytest.raises(SchemaError, match="not a readable softbend campaign database"):
        load_samples(broken)


def test_a_truncated_file_names_the_sizes(tmp_path):
    path, data = _campaign_file(tmp_path)
    broken = tmp_path / "t.duckdb"
    broken.write_bytes(data[:600000])
    with pytest.raises(
        SchemaError, match=r"\(truncated: 600000 bytes, its blocks in use need \d+\)"
    ):
        CampaignStore(broken, read_only=True)
    with CampaignStore(path, read_only=True) as intact:  # the original still reads
        assert intact.status_summary()["done"] == 2


def test_a_damaged_samples_block_is_found_when_opening_not_on_a_later_query(tmp_path):
    path, data = _campaign_file(tmp_path)
    block_id = _count(
        path, "SELECT max(block_id) FROM pragma_storage_info('samples') WHERE persistent"
    )
    start = 3 * 4096 + block_id * 262144
    corrupt = bytearray(data)
    corrupt[start + 8 : start + 4096] = b"\xa5" * (4096 - 8)
    broken = tmp_path / "broken.duckdb"
    broken.write_bytes(bytes(corrupt))
    with pytest.raises(SchemaError, match=r"not a readable .*\(Corrupt database file: "):
        CampaignStore(broken, read_only=True)
