"""The campaign database: schema, one transaction per design, reading and export."""

from __future__ import annotations

import os
import signal
import subprocess
import sys
import textwrap

import duckdb
import numpy as np
import pandas as pd
import pytest

from softbend import __version__
from softbend.actuators import Design
from softbend.campaign import store as store_module
from softbend.campaign.backends import AnalyticalBackend, SweepResult, default_pressures_mpa
from softbend.campaign.store import SCHEMA_VERSION, CampaignStore, load_samples
from softbend.design import PARAMETERS, sfrba_design
from softbend.errors import SchemaError, SoftbendError

GRID = default_pressures_mpa(0.5, 0.05)
A = sfrba_design(100, 6, 3, 2, 5, 8)  # converges up to 0.5 MPa
B = sfrba_design(120, 8, 3, 3, 10, 10)

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


def _sweep(design: Design, grid: np.ndarray = GRID) -> SweepResult:
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


def test_a_ctrl_c_during_a_write_is_raised_after_the_design_is_committed(store, monkeypatch):
    # A Ctrl-C inside a DuckDB query would surface as "RuntimeError: Query
    # interrupted" and roll back a finished design; it waits for the commit.
    real_delete = store._delete

    def delete_then_ctrl_c(design_id):
        real_delete(design_id)
        os.kill(os.getpid(), signal.SIGINT)

    monkeypatch.setattr(store, "_delete", delete_then_ctrl_c)
    previous = signal.signal(signal.SIGINT, signal.default_int_handler)  # as in a new process
    try:
        with pytest.raises(KeyboardInterrupt):
            store.record_success(_sweep(A))
        assert signal.getsignal(signal.SIGINT) is signal.default_int_handler
    finally:
        signal.signal(signal.SIGINT, previous)
    assert store.finished_ids() == {A.design_id}
    assert set(store.load_samples()["design_id"]) == {A.design_id}


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
    with pytest.raises(ValueError, match=r"^format: must be one of"):
        store.export(tmp_path / "x.xlsx", format="xlsx")
    with pytest.raises(ValueError, match=r"^table: must be one of"):
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


# -- merging shards all or nothing, failed writes, damaged metadata -----------------


def _shard(path, *designs, grid=GRID, backend="analytical"):
    with CampaignStore(path) as opened:
        opened.bind(backend, grid)
        for design in designs:
            if backend == "analytical":
                opened.record_success(_sweep(design, grid))
            else:
                opened.record_failure(design, "RuntimeError: lost", 1.0)
    return path


def test_merge_campaigns_takes_every_shard_in_one_replacement(tmp_path):
    from softbend.campaign.store import merge_campaigns

    shards = [_shard(tmp_path / "a.duckdb", A), _shard(tmp_path / "b.duckdb", B)]
    empty = tmp_path / "never-ran.duckdb"
    CampaignStore(empty).close()
    target = tmp_path / "m.duckdb"
    counts = merge_campaigns(target, [*shards, empty])
    assert [c["added"] for c in counts] == [1, 1, 0]
    assert len(load_samples(target)) == 2 * len(GRID)
    assert sorted(p.name for p in tmp_path.iterdir()) == [
        "a.duckdb",
        "b.duckdb",
        "m.duckdb",
        "never-ran.duckdb",
    ]
    assert merge_campaigns(target, shards) == [
        {"added": 0, "replaced_failed": 0, "kept": 1},
        {"added": 0, "replaced_failed": 0, "kept": 1},
    ]


@pytest.mark.parametrize(
    ("make_bad", "error", "needle"),
    [
        (
            lambda p: _shard(p, B, grid=default_pressures_mpa(0.5, 0.1)),
            ValueError,
            "The 'pressures_mpa' of the campaign in",
        ),
        (lambda p: _shard(p, B, backend="fem"), ValueError, "The backend of the campaign in"),
        (
            lambda p: p.write_bytes(_shard(p, B).read_bytes()[:600000]),
            SchemaError,
            "is not a readable softbend campaign database",
        ),
        (lambda p: p.write_text("design_id\nx\n"), SchemaError, "not a DuckDB database file"),
    ],
    ids=["another grid", "another backend", "truncated", "not a database"],
)
def test_merge_campaigns_checks_every_shard_before_writing(tmp_path, make_bad, error, needle):
    from softbend.campaign.store import merge_campaigns

    good, bad = _shard(tmp_path / "a.duckdb", A), tmp_path / "bad.duckdb"
    make_bad(bad)
    target = tmp_path / "m.duckdb"
    with pytest.raises(error, match=needle) as info:
        merge_campaigns(target, [good, bad])
    assert str(bad) in str(info.value)
    assert not target.exists()  # not even the first shard was merged
    merge_campaigns(target, [good])
    before = target.read_bytes()
    with pytest.raises(error, match=needle):
        merge_campaigns(target, [bad])
    assert target.read_bytes() == before
    assert sorted(p.name for p in tmp_path.iterdir()) == ["a.duckdb", "bad.duckdb", "m.duckdb"]


def test_merge_campaigns_refuses_its_own_target_and_no_shards(tmp_path):
    from softbend.campaign.store import merge_campaigns

    target = _shard(tmp_path / "m.duckdb", A)
    before = target.read_bytes()
    with pytest.raises(ValueError, match="merged into itself"):
        merge_campaigns(target, [_shard(tmp_path / "b.duckdb", B), tmp_path / "." / "m.duckdb"])
    with pytest.raises(ValueError, match="at least one"):
        merge_campaigns(target, [])
    with pytest.raises(FileNotFoundError, match="No campaign database"):
        merge_campaigns(target, [tmp_path / "missing.duckdb"])
    assert target.read_bytes() == before


@pytest.mark.parametrize(
    ("text", "expected"),
    [
        (
            'TransactionContext Error: Failed to commit: Could not write file "/d/c.duckdb.wal": '
            "No space left on device",
            (28, "No space left on device"),
        ),
        (
            'IO Error: Async write failed: {"exception_type":"IO","exception_message":"Could not '
            'write file \\".x.tmp\\": No space left on device","errno":"28"}',
            (28, "No space left on device"),
        ),
        ('IO Error: Could not write file "/d/c.duckdb": File too large', (27, "File too large")),
        ('IO Error: Could not write file "/d/c.duckdb": Odd failure', (5, "Odd failure")),
        ('IO Error: Could not read file "/d/c.duckdb": Input/output error', None),
        ("Binder Error: Referenced column x not found", None),
    ],
    ids=["commit", "async json", "file size", "unknown reason", "a read", "no write"],
)
def test_a_failed_write_of_duckdb_is_the_os_error_naming_the_output(text, expected):
    from softbend.campaign.schema import write_error

    found = write_error(duckdb.IOException(text), "/out/x.parquet")
    if expected is None:
        assert found is None
    else:
        assert isinstance(found, OSError)
        assert (found.errno, found.strerror, found.filename) == (*expected, "/out/x.parquet")


def test_a_merge_that_cannot_be_checkpointed_leaves_the_target(tmp_path, monkeypatch):
    """A checkpoint that fails on closing is silent in DuckDB: the merge must not be lost."""
    from softbend.campaign.store import merge_campaigns

    target = _shard(tmp_path / "m.duckdb", A)
    before = target.read_bytes()
    shard = _shard(tmp_path / "b.duckdb", B)
    real_execute = duckdb.DuckDBPyConnection.execute

    def execute(con, query, *args, **kwargs):
        if query == "FORCE CHECKPOINT":
            raise duckdb.IOException('IO Error: Could not write file "x": No space left on device')
        return real_execute(con, query, *args, **kwargs)

    try:
        monkeypatch.setattr(duckdb.DuckDBPyConnection, "execute", execute)
    except TypeError:  # pragma: no cover - a DuckDB whose connection class is closed
        pytest.skip("this DuckDB's connection methods cannot be replaced")
    with pytest.raises(OSError, match="No space left on device") as info:
        merge_campaigns(target, [shard])
    assert info.value.filename == str(target)
    monkeypatch.undo()
    assert target.read_bytes() == before
    assert sorted(p.name for p in tmp_path.iterdir()) == ["b.duckdb", "m.duckdb"]


@pytest.mark.parametrize(
    ("key", "value"),
    [
        ("pressures_mpa", "[0.0, 0.1"),
        ("pressures_mpa", '"0.1"'),
        ("pressures_mpa", "[0.0, true]"),
        ("pressures_mpa", "[0.0, -0.1]"),
        ("pressures_mpa", "[[0.0], [0.1]]"),
    ],
)
def test_a_damaged_stored_grid_is_a_schema_error_on_opening(tmp_path, key, value):
    path = _shard(tmp_path / "c.duckdb", A)
    con = duckdb.connect(str(path))
    con.execute("UPDATE meta SET value = ? WHERE key = ?", [value, key])
    con.close()
    for read_only in (True, False):
        with pytest.raises(SchemaError, match=f"has a damaged {key!r} in its 'meta' table"):
            CampaignStore(path, read_only=read_only)


def test_damaged_runs_and_planned_counts_are_schema_errors(tmp_path):
    path = _shard(tmp_path / "c.duckdb", A)
    con = duckdb.connect(str(path))
    con.execute("INSERT INTO meta VALUES ('runs', '{\"a\": 1}'), ('n_designs_planned', 'x')")
    con.close()
    with CampaignStore(path, read_only=True) as opened:
        with pytest.raises(SchemaError, match="damaged 'runs'"):
            opened.runs()
        with pytest.raises(SchemaError, match="damaged 'n_designs_planned'"):
            opened.status_summary()


def _left_with_a_log(path, *designs):
    """A campaign whose last writes are only in its write-ahead log (as after a kill)."""
    opened = CampaignStore(path)
    opened.bind("analytical", GRID)
    for design in designs:
        opened.record_success(_sweep(design))
    opened._con.execute("PRAGMA disable_checkpoint_on_shutdown")
    opened._con.close()
    assert (path.parent / f"{path.name}.wal").stat().st_size > 0
    return path


def test_merge_campaigns_keeps_what_only_the_write_ahead_logs_hold(tmp_path):
    from softbend.campaign.store import merge_campaigns

    target = _left_with_a_log(tmp_path / "m.duckdb", A)
    shard = _left_with_a_log(tmp_path / "s.duckdb", B)
    assert merge_campaigns(target, [shard]) == [{"added": 1, "replaced_failed": 0, "kept": 0}]
    with CampaignStore(target, read_only=True) as merged:
        assert merged.finished_ids() == {A.design_id, B.design_id}
    assert len(load_samples(target)) == 2 * len(GRID)
    assert not (tmp_path / "m.duckdb.wal").exists()
