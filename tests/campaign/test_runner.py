"""The campaign runner: serial, local processes and Dask; resume, failures, bad input."""

from __future__ import annotations

import json
import os
import signal
import socket
import subprocess
import sys
import textwrap
import time
from pathlib import Path

import duckdb
import numpy as np
import pandas as pd
import pytest

from softbend.campaign import CampaignStore, SweepResult, get_backend, load_samples, run_campaign
from softbend.campaign.runner import parse_scheduler_address
from softbend.design import DesignSpace, sfrba_design
from softbend.errors import SchemaError, SoftbendError

from ..stand_ins import web_server


def _rows_per_design(path: Path) -> dict[str, tuple[int, int]]:
    """``{design_id: (rows in designs, rows in samples)}`` straight from the database."""
    con = duckdb.connect(str(path), read_only=True)
    try:
        designs = dict(con.execute("SELECT design_id, count(*) FROM designs GROUP BY 1").fetchall())
        samples = dict(con.execute("SELECT design_id, count(*) FROM samples GROUP BY 1").fetchall())
        n_expected = dict(con.execute("SELECT design_id, n_samples FROM designs").fetchall())
    finally:
        con.close()
    for design_id, n in n_expected.items():
        assert samples.get(design_id, 0) == n
    return {i: (designs[i], samples.get(i, 0)) for i in designs}


def _closed_port() -> int:
    with socket.socket() as sock:
        sock.bind(("127.0.0.1", 0))
        return sock.getsockname()[1]


@pytest.fixture
def reference(tmp_path_factory, designs, grid) -> pd.DataFrame:
    """Samples of the designs from a plain serial analytical run."""
    path = tmp_path_factory.mktemp("ref") / "ref.duckdb"
    run_campaign(path, designs, pressures_mpa=grid, workers=0)
    return load_samples(path)


# ----------------------------------------------------------------------------- local runs


def test_serial_and_two_workers_give_the_same_numbers(tmp_path, designs, grid, reference):
    calls = []
    summary = run_campaign(
        tmp_path / "par.duckdb",
        designs,
        pressures_mpa=grid,
        workers=2,
        chunk_size=2,
        progress=lambda *counts: calls.append(counts),
    )
    assert summary.executor == "processes:2" and summary.chunk_size == 2
    assert (summary.n_done, summary.n_failed, summary.n_skipped_done) == (len(designs), 0, 0)
    assert summary.sweep_time_s > 0 and summary.designs_per_s > 0
    pd.testing.assert_frame_equal(load_samples(tmp_path / "par.duckdb"), reference)
    assert set(reference["design_id"]) == {d.design_id for d in designs}
    # The truncated sweep is there with its final non-converged pressure.
    assert (~reference["converged"]).sum() >= 1
    counts = _rows_per_design(tmp_path / "par.duckdb")
    assert all(n_rows == 1 for n_rows, _ in counts.values())
    # Progress: totals fixed, finished counts never go back, ends with nothing running.
    assert calls[0] == (0, 0, 0, len(designs))
    assert calls[-1] == (len(designs), 0, 0, len(designs))
    finished = [done + failed for done, failed, _, _ in calls]
    assert finished == sorted(finished)
    assert max(running for _, _, running, _ in calls) > 0


def test_resume_runs_only_the_missing_designs(tmp_path, designs, grid, reference):
    path = tmp_path / "c.duckdb"
    first = run_campaign(path, designs.designs[:4], pressures_mpa=grid, workers=0)
    assert first.n_done == 4
    second = run_campaign(path, designs, pressures_mpa=grid, workers=2)
    assert (second.n_skipped_done, second.n_done) == (4, len(designs) - 4)
    third = run_campaign(path, designs, pressures_mpa=grid, workers=2)
    assert (third.n_skipped_done, third.n_done, third.n_failed) == (len(designs), 0, 0)
    pd.testing.assert_frame_equal(load_samples(path), reference)


def test_failing_design_is_recorded_and_the_others_finish(tmp_path, designs, grid, reference):
    path = tmp_path / "c.duckdb"
    bad = designs[3]
    summary = run_campaign(
        path,
        designs,
        backend="fault-injection",
        backend_options={"fail_design_ids": [bad.design_id]},
        pressures_mpa=grid,
        workers=2,
    )
    assert (summary.n_done, summary.n_failed) == (len(designs) - 1, 1)
    ((failed_id, error),) = summary.failures
    assert failed_id == bad.design_id
    assert error.startswith(f"ConvergenceError: injected failure for design {bad}")
    with CampaignStore(path, read_only=True) as store:
        table = store.load_designs().set_index("design_id")
        assert table.loc[bad.design_id, "status"] == "failed"
        assert table.loc[bad.design_id, "error"] == error
        assert store.failed_ids() == {bad.design_id}
    ok = reference[reference["design_id"] != bad.design_id].reset_index(drop=True)
    pd.testing.assert_frame_equal(load_samples(path), ok)

    kept = run_campaign(
        path, designs, backend="fault-injection", pressures_mpa=grid, retry_failed=False, workers=0
    )
    assert (kept.n_skipped_done, kept.n_skipped_failed, kept.n_done) == (len(designs) - 1, 1, 0)
    retried = run_campaign(path, designs, backend="fault-injection", pressures_mpa=grid, workers=0)
    assert (retried.n_done, retried.n_failed) == (1, 0)
    assert all(n == 1 for n, _ in _rows_per_design(path).values())
    pd.testing.assert_frame_equal(load_samples(path), reference)


class _Exploding:
    """A backend object (serial runs need no pickling) failing in two different ways."""

    name = "exploding"

    def sweep(self, design, pressures_mpa):
        if design.r_mm == 6:
            raise ZeroDivisionError("division by zero in the solver")
        return "not a result"


def test_any_exception_and_a_wrong_result_type_are_failures(tmp_path, designs, grid):
    summary = run_campaign(
        tmp_path / "c.duckdb", designs, backend=_Exploding(), pressures_mpa=grid, workers=0
    )
    assert summary.n_done == 0 and summary.n_failed == len(designs)
    errors = dict(summary.failures)
    for design in designs:
        if design.r_mm == 6:
            assert errors[design.design_id] == "ZeroDivisionError: division by zero in the solver"
        else:
            assert errors[design.design_id].startswith(
                "SoftbendError: backend 'exploding' returned str, not a SweepResult"
            )


def test_a_dying_worker_process_fails_only_its_own_design(tmp_path, designs, grid):
    path = tmp_path / "c.duckdb"
    crash = designs[5]
    summary = run_campaign(
        path,
        designs,
        backend="fault-injection",
        backend_options={"crash_design_ids": [crash.design_id]},
        pressures_mpa=grid,
        workers=2,
        chunk_size=1,
    )
    errors = dict(summary.failures)
    # The designs that were queued beside it are rerun alone, not blamed.
    assert list(errors) == [crash.design_id]
    assert errors[crash.design_id].startswith("BrokenProcessPool: the worker process died")
    assert "alone" in errors[crash.design_id]
    assert summary.n_done == len(designs) - 1 and summary.n_failed == 1
    assert set(_rows_per_design(path)) == {d.design_id for d in designs}
    again = run_campaign(path, designs, backend="fault-injection", pressures_mpa=grid, workers=2)
    assert again.n_done == 1 and again.n_failed == 0
    assert all(n == 1 for n, _ in _rows_per_design(path).values())


_CHILD = textwrap.dedent(
    """
    import sys
    from softbend.campaign import default_pressures_mpa, run_campaign
    from softbend.design import parse_sfrba

    designs = [parse_sfrba(text) for text in sys.argv[2].split(";")]

    def progress(done, failed, running, total):
        print("recorded", done + failed, flush=True)

    if __name__ == "__main__":
        run_campaign(
            sys.argv[1], designs, backend="fault-injection",
            backend_options={"delay_s": float(sys.argv[4])},
            pressures_mpa=default_pressures_mpa(0.5, 0.05), workers=int(sys.argv[3]),
            chunk_size=1, progress=progress,
        )
    """
)


@pytest.mark.parametrize("workers", [0, 2])
def test_a_campaign_killed_with_sigkill_resumes_without_losing_or_duplicating(
    tmp_path, designs, grid, reference, workers
):
    path = tmp_path / "killed.duckdb"
    child = subprocess.Popen(
        [sys.executable, "-c", _CHILD, str(path), ";".join(map(str, designs)), str(workers), "0.3"],
        stdout=subprocess.PIPE,
        stderr=subprocess.DEVNULL,
        text=True,
        start_new_session=True,
    )
    try:
        for line in child.stdout:
            if line.startswith("recorded") and int(line.split()[1]) >= 3:
                break
        os.killpg(child.pid, signal.SIGKILL)  # the coordinator and any worker it started
    finally:
        if child.poll() is None:
            os.killpg(child.pid, signal.SIGKILL)
        child.wait(timeout=30)
        child.stdout.close()
    assert child.returncode == -signal.SIGKILL

    with CampaignStore(path, read_only=True) as store:
        n_before = len(store.finished_ids())
    assert 3 <= n_before < len(designs)
    summary = run_campaign(path, designs, backend="fault-injection", pressures_mpa=grid, workers=0)
    assert summary.n_skipped_done == n_before
    assert summary.n_done == len(designs) - n_before and summary.n_failed == 0
    counts = _rows_per_design(path)
    assert set(counts) == {d.design_id for d in designs}
    assert all(n_rows == 1 for n_rows, _ in counts.values())
    pd.testing.assert_frame_equal(load_samples(path), reference)


# ----------------------------------------------------------------------------- bad input


@pytest.mark.parametrize(
    ("kwargs", "error", "match"),
    [
        ({"backend": "abaqus"}, ValueError, "backend 'abaqus'.*known: analytical, fem"),
        ({"backend": "analytical", "backend_options": {"mesh": 2}}, ValueError, "options"),
        ({"workers": -1}, ValueError, r"^workers: must be a number in \[0, "),
        ({"chunk_size": 0}, ValueError, "^chunk_size: "),
        ({"pressures_mpa": [0.0, 0.2, 0.1]}, ValueError, "strictly increasing"),
        ({"pressures_mpa": [-0.1, 0.0, 0.1]}, ValueError, r"\[0, inf\)"),
        ({"scheduler": "localhost:8786"}, ValueError, r"^scheduler: .*tcp://HOST:PORT"),
        ({"scheduler": "tcp://127.0.0.1:99999"}, ValueError, r"^scheduler: "),
        ({"progress": 3}, ValueError, "^progress: must be callable"),
        ({"connect_timeout_s": 0}, ValueError, "^connect_timeout_s: "),
    ],
)
def test_bad_arguments_are_refused_before_anything_is_written(
    tmp_path, designs, kwargs, error, match
):
    path = tmp_path / "c.duckdb"
    with pytest.raises(error, match=match):
        run_campaign(path, designs, **kwargs)
    assert not path.exists()


def test_bad_design_lists(tmp_path):
    with pytest.raises(ValueError, match=r"^designs: must not be empty"):
        run_campaign(tmp_path / "c.duckdb", [])
    with pytest.raises(ValueError, match=r"^designs: must be unique; got 1 duplicates"):
        run_campaign(tmp_path / "c.duckdb", [sfrba_design(100, 6, 2, 2, 5, 8)] * 2)
    with pytest.raises(ValueError, match=r"^designs: must all be Design; got '100,6,2,2,5,8'"):
        run_campaign(tmp_path / "c.duckdb", ["100,6,2,2,5,8"])
    with pytest.raises(ValueError, match=r"^backend_options: apply to a backend name only"):
        run_campaign(
            tmp_path / "c.duckdb",
            [sfrba_design(100, 6, 2, 2, 5, 8)],
            backend=get_backend("analytical"),
            backend_options={"material": None},
        )


def test_resuming_with_another_backend_or_grid_is_refused(tmp_path, designs, grid):
    path = tmp_path / "c.duckdb"
    run_campaign(path, designs.designs[:2], pressures_mpa=grid, workers=0)
    with pytest.raises(ValueError, match="'backend' of the campaign"):
        run_campaign(path, designs, backend="fault-injection", pressures_mpa=grid, workers=0)
    with pytest.raises(ValueError, match="'pressures_mpa' of the campaign"):
        run_campaign(path, designs, workers=0)


def test_newer_schema_is_refused(tmp_path, designs):
    path = tmp_path / "c.duckdb"
    CampaignStore(path).close()
    con = duckdb.connect(str(path))
    con.execute("UPDATE meta SET value = '7' WHERE key = 'schema_version'")
    con.close()
    with pytest.raises(SchemaError, match="schema version 7, newer"):
        run_campaign(path, designs, workers=0)


def test_scheduler_addresses(tmp_path):
    assert parse_scheduler_address("tcp://127.0.0.1:8786") == "tcp://127.0.0.1:8786"
    assert parse_scheduler_address(" tls://node-3.lab:8786 ") == "tls://node-3.lab:8786"
    assert parse_scheduler_address("tcp://[::1]:8786") == "tcp://[::1]:8786"
    scheduler_file = tmp_path / "scheduler.json"
    scheduler_file.write_text(json.dumps({"address": "tcp://10.0.0.5:8786"}))
    assert parse_scheduler_address(str(scheduler_file)) == "tcp://10.0.0.5:8786"
    for bad in ("", "tcp://:8786", "http://host:8786", "tcp://host", "tcp://host:0", "host:8786"):
        with pytest.raises(ValueError, match=r"^scheduler: must be an address"):
            parse_scheduler_address(bad)
    with pytest.raises(FileNotFoundError, match="scheduler file"):
        parse_scheduler_address(str(tmp_path / "missing.json"))


def test_unreachable_scheduler_is_a_clear_error_not_a_hang(tmp_path, designs):
    address = f"tcp://127.0.0.1:{_closed_port()}"
    with pytest.raises(SoftbendError) as info:
        run_campaign(tmp_path / "c.duckdb", designs, scheduler=address, connect_timeout_s=3)
    message = str(info.value)
    assert message.startswith(f"scheduler: cannot reach the Dask scheduler at {address}")
    assert "\n" not in message
    assert not (tmp_path / "c.duckdb").exists()


# ----------------------------------------------------------------------------- Dask


@pytest.fixture
def local_dask_address():
    """An in-process Dask scheduler and worker listening on 127.0.0.1 (fast to start)."""
    distributed = pytest.importorskip("distributed")
    cluster = distributed.LocalCluster(
        n_workers=1,
        threads_per_worker=2,
        processes=False,
        protocol="tcp",
        host="127.0.0.1",
        dashboard_address="127.0.0.1:0",  # its HTTP server too stays on loopback
    )
    try:
        yield cluster.scheduler_address
    finally:
        cluster.close()


def test_campaign_on_a_dask_scheduler(tmp_path, designs, grid, reference, local_dask_address):
    path = tmp_path / "c.duckdb"
    bad = designs[2]
    summary = run_campaign(
        path,
        designs,
        backend="fault-injection",
        backend_options={"fail_design_ids": [bad.design_id]},
        pressures_mpa=grid,
        scheduler=local_dask_address,
        chunk_size=3,
    )
    assert summary.executor == local_dask_address
    assert (summary.n_done, summary.n_failed) == (len(designs) - 1, 1)
    assert summary.failures[0][1].startswith("ConvergenceError: injected failure")
    resumed = run_campaign(
        path, designs, backend="fault-injection", pressures_mpa=grid, scheduler=local_dask_address
    )
    assert (resumed.n_skipped_done, resumed.n_done) == (len(designs) - 1, 1)
    pd.testing.assert_frame_equal(load_samples(path), reference)


@pytest.fixture
def dask_processes(tmp_path):
    """A Dask scheduler and one worker as separate processes on 127.0.0.1."""
    pytest.importorskip("distributed")
    scheduler_file = tmp_path / "scheduler.json"
    # Loopback only, HTTP servers included (their default would listen on all interfaces).
    common = ["--no-dashboard", "--dashboard-address", "127.0.0.1:0", "--host", "127.0.0.1"]
    processes = [
        subprocess.Popen(
            [
                sys.executable,
                "-m",
                "distributed.cli.dask_scheduler",
                "--port",
                "0",
                "--scheduler-file",
                str(scheduler_file),
                *common,
            ],
            stdout=subprocess.DEVNULL,
            stderr=subprocess.DEVNULL,
            start_new_session=True,
        )
    ]
    try:
        processes.append(
            subprocess.Popen(
                [
                    sys.executable,
                    "-m",
                    "distributed.cli.dask_worker",
                    "--scheduler-file",
                    str(scheduler_file),
                    "--nthreads",
                    "2",
                    "--no-nanny",
                    "--death-timeout",
                    "60",
                    *common,
                ],
                stdout=subprocess.DEVNULL,
                stderr=subprocess.DEVNULL,
                start_new_session=True,
            )
        )
        deadline = time.monotonic() + 60
        while not scheduler_file.exists():
            if time.monotonic() > deadline or processes[0].poll() is not None:
                pytest.fail("the Dask scheduler did not start")
            time.sleep(0.05)
        time.sleep(0.1)  # the file is written in one go, but be safe about a partial read
        yield json.loads(scheduler_file.read_text())["address"], scheduler_file
    finally:
        for process in reversed(processes):
            if process.poll() is None:
                os.killpg(process.pid, signal.SIGTERM)
        for process in reversed(processes):
            try:
                process.wait(timeout=10)
            except subprocess.TimeoutExpired:
                os.killpg(process.pid, signal.SIGKILL)
                process.wait()


def test_campaign_on_a_separate_dask_scheduler_and_worker(
    tmp_path, designs, grid, reference, dask_processes
):
    address, scheduler_file = dask_processes
    assert address.startswith("tcp://127.0.0.1:")
    path = tmp_path / "c.duckdb"
    summary = run_campaign(
        path, designs, pressures_mpa=grid, scheduler=str(scheduler_file), connect_timeout_s=60
    )
    assert summary.executor == address
    assert (summary.n_done, summary.n_failed) == (len(designs), 0)
    pd.testing.assert_frame_equal(load_samples(path), reference)


def test_sweep_results_cross_process_boundaries_intact(designs, grid):
    """What a worker sends back is what the coordinator stores (pickle round trip)."""
    import pickle

    result = get_backend("analytical").sweep(designs[0], grid)
    clone = pickle.loads(pickle.dumps(result))
    assert isinstance(clone, SweepResult)
    np.testing.assert_array_equal(clone.tip_z_mm, result.tip_z_mm)


def test_space_name_and_plan_are_stored(tmp_path, grid):
    space = DesignSpace.sample(3, seed=5)
    run_campaign(tmp_path / "c.duckdb", space, pressures_mpa=grid, workers=0)
    with CampaignStore(tmp_path / "c.duckdb", read_only=True) as store:
        status = store.status_summary()
    assert status["space"] == "lhs-3-seed5" and status["n_designs_planned"] == 3
    assert status["done"] == 3


@pytest.mark.parametrize("answer", [None, b"HTTP/1.1 200 OK\r\nContent-Length: 5\r\n\r\nhello"])
def test_a_scheduler_address_that_is_not_dask_ends_in_one_line_within_the_deadline(
    tmp_path, designs, grid, answer
):
    import socket
    import threading

    from softbend.errors import SoftbendError

    server = socket.socket()
    server.bind(("127.0.0.1", 0))
    server.listen()
    port = server.getsockname()[1]
    stop = threading.Event()

    def serve() -> None:  # a silent listener, or a web server answering garbage
        server.settimeout(0.2)
        while not stop.is_set():
            try:
                conn, _ = server.accept()
            except OSError:
                continue
            if answer is not None:
                conn.sendall(answer)
                conn.close()

    thread = threading.Thread(target=serve, daemon=True)
    thread.start()
    try:  # before the fix, the silent listener hung here far past the timeout
        with pytest.raises(SoftbendError, match=f"127.0.0.1:{port}") as info:
            run_campaign(
                tmp_path / "c.duckdb",
                designs[:2],
                backend="analytical",
                pressures_mpa=grid,
                scheduler=f"tcp://127.0.0.1:{port}",
                connect_timeout_s=1.0,
            )
    finally:
        stop.set()
        thread.join()
        server.close()
    assert "\n" not in str(info.value)


def test_a_web_server_at_the_scheduler_address_is_named_and_leaves_no_client(
    tmp_path, designs, grid, monkeypatch
):
    import gc

    distributed = pytest.importorskip("distributed")
    made = []
    real_client = distributed.Client

    class CountingClient(real_client):
        def __init__(self, *args, **kwargs):
            made.append(args)
            super().__init__(*args, **kwargs)

    monkeypatch.setattr(distributed, "Client", CountingClient)
    unraisable = []
    monkeypatch.setattr(sys, "unraisablehook", unraisable.append)
    port, close = web_server()
    address = f"tcp://127.0.0.1:{port}"
    start = time.monotonic()
    try:
        with pytest.raises(SoftbendError) as info:
            run_campaign(
                tmp_path / "c.duckdb",
                designs[:2],
                pressures_mpa=grid,
                scheduler=address,
                connect_timeout_s=1.0,
            )
    finally:
        close()
    message = str(info.value)
    assert message.startswith(f"scheduler: {address} did not answer as a Dask scheduler")
    assert "another protocol, e.g. HTTP" in message and "EiB" not in message
    assert time.monotonic() - start < 5
    assert made == []  # refused before any Dask client was made
    del info
    gc.collect()
    assert unraisable == []
    assert not (tmp_path / "c.duckdb").exists()


_START_A_CLIENT = """
import sys
from distributed import Client
from softbend.campaign.executors import _closing_client
try:
    _closing_client(Client)(sys.argv[1], timeout=1, set_as_default=False)
except Exception as exc:  # Dask's own error: a 3 EiB message length
    print(type(exc).__name__)
"""


def test_a_dask_client_that_fails_to_start_closes_itself():
    pytest.importorskip("distributed")
    # In a process of its own: a half-started client fails in its destructor only when
    # the interpreter exits ("Exception ignored in Client.__del__", a traceback).
    port, close = web_server()
    try:
        done = subprocess.run(
            [sys.executable, "-c", _START_A_CLIENT, f"tcp://127.0.0.1:{port}"],
            capture_output=True,
            text=True,
            timeout=120,
        )
    finally:
        close()
    assert done.returncode == 0 and done.stdout.strip(), done.stderr
    assert "Exception ignored" not in done.stderr and "Traceback" not in done.stderr


def test_a_dask_worker_address_is_not_taken_for_the_scheduler(tmp_path, designs, grid):
    distributed = pytest.importorskip("distributed")
    with distributed.LocalCluster(
        n_workers=1,
        threads_per_worker=1,
        processes=False,
        protocol="tcp",
        host="127.0.0.1",
        dashboard_address=None,
    ) as cluster:
        worker = next(iter(cluster.scheduler_info["workers"]))
        with pytest.raises(SoftbendError, match=r"did not answer as a Dask scheduler \(it is a"):
            run_campaign(tmp_path / "c.duckdb", designs[:2], pressures_mpa=grid, scheduler=worker)
    assert not (tmp_path / "c.duckdb").exists()


@pytest.mark.parametrize(
    ("content", "needle"),
    [
        ("[" * 100_000, "(nested too deeply)"),
        ("null", "got a JSON value"),
        ('{"address": ["tcp://10.0.0.5:8786"]}', "got 'address' ['tcp://10.0.0.5:8786']"),
    ],
)
def test_a_damaged_scheduler_file_is_one_value_error(tmp_path, content, needle):
    scheduler_file = tmp_path / "scheduler.json"
    scheduler_file.write_text(content)
    with pytest.raises(ValueError, match=r"scheduler\.json: must be a Dask scheduler file") as info:
        parse_scheduler_address(str(scheduler_file))
    assert needle in str(info.value)


def test_a_huge_scheduler_file_is_refused_by_the_file_size_limit(tmp_path, monkeypatch):
    from softbend.errors import LimitError

    monkeypatch.setenv("SOFTBEND_MAX_FILE_MIB", "1")
    scheduler_file = tmp_path / "scheduler.json"
    scheduler_file.write_text('{"address": "tcp://10.0.0.5:8786", "x": "' + "a" * 2**21 + '"}')
    with pytest.raises(LimitError, match="SOFTBEND_MAX_FILE_MIB"):
        parse_scheduler_address(str(scheduler_file))
