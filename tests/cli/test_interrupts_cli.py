"""Ctrl-C in a command that sweeps designs in worker processes, as a terminal sends it.

A terminal sends SIGINT to the whole foreground process group: the command and
its workers. Each test starts the command line in a process group of its own,
sends SIGINT to the group once the first design is recorded, and checks one
line, exit code 130, no worker's traceback, and that the same command resumes.
"""

from __future__ import annotations

import json
import os
import re
import signal
import subprocess
import sys
import textwrap
import time
from pathlib import Path

import pytest

from softbend.campaign import CampaignStore

from ..campaign.test_runner import dask_processes  # noqa: F401  (a fixture)
from ..stand_ins import running

#: The command line with the public backends ``slow`` (each sweep runs a child process for
#: $COMPILE_S seconds, as the FEM its compilers, then the analytical model), ``slow-compiled``
#: (the child through ``system()``, as NGSolve's compilers of the compiled FEM) and ``sleepy``
#: (the analytical model after a sleep of $COMPILE_S seconds, as a Dask worker imports it);
#: arguments as softbend's.
_CHILD = textwrap.dedent(
    """
    import os, sys
    from softbend.campaign.backends import get_backend, register_backend
    from tests.stand_ins import CompilingSweep

    register_backend("slow", lambda: CompilingSweep(os.path.abspath("started")))
    register_backend(
        "slow-compiled", lambda: CompilingSweep(os.path.abspath("started"), compiled=True)
    )
    register_backend(
        "sleepy",
        lambda: get_backend("fault-injection", delay_s=float(os.environ["COMPILE_S"])),
    )
    if __name__ == "__main__":
        from softbend.cli import run
        sys.argv[0] = "softbend"
        run()
    """
)


def _as_at_a_terminal() -> None:
    """In the child: SIGINT as at a terminal, even when the test runs as a background job."""
    signal.signal(signal.SIGINT, signal.SIG_DFL)


def _path() -> str:
    """The import path of the child: this checkout's tests and the path softbend came from."""
    root = Path(__file__).resolve().parents[2]
    return os.pathsep.join([str(root), *sys.path])


def _start(args: list[str], cwd: Path, delay_s: float) -> subprocess.Popen[str]:
    return subprocess.Popen(
        [sys.executable, "-c", _CHILD, *args],
        cwd=cwd,
        stdout=subprocess.PIPE,
        stderr=subprocess.PIPE,
        text=True,
        start_new_session=True,  # a process group of its own, as a terminal's job
        preexec_fn=_as_at_a_terminal,
        # faulthandler: a child that hangs prints every thread's stack on SIGABRT
        env={
            **os.environ,
            "COMPILE_S": str(delay_s),
            "PYTHONPATH": _path(),
            "PYTHONFAULTHANDLER": "1",
        },
    )


def _interrupt_after(child: subprocess.Popen[str], started: str, wait_s: float = 0.0) -> str:
    """Send SIGINT to the child's group ``wait_s`` after a stderr line matching ``started``.

    Returns the child's whole stderr (read until every process of the group has
    closed it). A child still running 30 s later fails the test with every
    thread's stack, then is killed (a hang guard: that it stops without
    finishing its designs in flight is what the tests check, by the designs
    recorded).
    """
    assert child.stderr is not None
    lines = []
    try:
        for line in child.stderr:
            lines.append(line)
            if re.search(started, line):
                break
        time.sleep(wait_s)
        os.killpg(child.pid, signal.SIGINT)
        try:
            child.wait(timeout=30)
        except subprocess.TimeoutExpired:
            os.kill(child.pid, signal.SIGABRT)  # faulthandler prints where it hangs
            _, rest = child.communicate(timeout=30)
            pytest.fail("still running 30 s after Ctrl-C:\n" + "".join(lines) + rest)
        _, rest = child.communicate(timeout=30)
    finally:
        if child.poll() is None:
            os.killpg(child.pid, signal.SIGKILL)
            child.communicate()
    return "".join(lines) + rest


def _assert_none_left(folder: Path) -> None:
    """No process a worker started is left running (each given 2 s to go)."""
    pids = [int(line) for line in (folder / "started").read_text().split()]
    deadline = time.monotonic() + 2.0
    while any(running(pid) for pid in pids) and time.monotonic() < deadline:
        time.sleep(0.1)
    assert not any(running(pid) for pid in pids)


def test_ctrl_c_stops_a_campaign_in_one_line_and_the_same_command_resumes(tmp_path):
    args = ["campaign", "run", "c.duckdb", "--backend", "slow", "--space", "lhs:6"]
    args += ["--workers", "2", "--chunk-size", "1", "--pmax", "0.1", "--pstep", "0.05"]
    child = _start(args, tmp_path, delay_s=2.0)
    err = _interrupt_after(child, r"done [1-5] ")
    assert child.returncode == 130, err
    assert "Traceback" not in err and "KeyboardInterrupt" not in err
    last = err.strip().splitlines()[-1]
    assert last == (
        "softbend: interrupted; finished work is kept in c.duckdb; resume with: softbend "
        + " ".join(args)
    )
    assert sum("interrupted" in line for line in err.splitlines()) == 1
    _assert_none_left(tmp_path)
    with CampaignStore(tmp_path / "c.duckdb", read_only=True) as store:
        kept = len(store.finished_ids())
    assert 1 <= kept < 6

    resumed = _start(args, tmp_path, delay_s=0.0)
    _, err = resumed.communicate(timeout=60)
    assert resumed.returncode == 0, err
    assert f"resuming c.duckdb: {kept} of 6 designs already recorded" in err
    with CampaignStore(tmp_path / "c.duckdb", read_only=True) as store:
        assert len(store.finished_ids()) == 6


def test_ctrl_c_as_the_workers_start_is_one_line_too(tmp_path):
    """While the fork server imports the model code and the workers start, before any
    design: neither they nor the fork server print a traceback."""
    args = ["campaign", "run", "c.duckdb", "--backend", "slow", "--space", "lhs:6"]
    args += ["--workers", "2", "--chunk-size", "1", "--pmax", "0.1", "--pstep", "0.05"]
    child = _start(args, tmp_path, delay_s=2.0)
    err = _interrupt_after(child, r"done 0 ", wait_s=0.2)  # the fork server imports
    assert child.returncode == 130, err
    assert "Traceback" not in err and "KeyboardInterrupt" not in err
    assert err.strip().splitlines()[-1].startswith("softbend: interrupted; finished work is kept")


def test_ctrl_c_stops_a_serial_campaign_of_a_backend_that_compiles(tmp_path):
    """Its compilers run through ``system()``, which ignores SIGINT in its caller: the
    designs run in one worker process, and Ctrl-C reaches the command."""
    args = ["campaign", "run", "c.duckdb", "--backend", "slow-compiled", "--space", "lhs:4"]
    args += ["--workers", "1", "--pmax", "0.1", "--pstep", "0.05"]
    child = _start(args, tmp_path, delay_s=2.0)
    err = _interrupt_after(child, r"done [1-3] ")
    assert child.returncode == 130, err
    assert "Traceback" not in err
    assert err.strip().splitlines()[-1].startswith("softbend: interrupted; finished work is kept")
    _assert_none_left(tmp_path)
    with CampaignStore(tmp_path / "c.duckdb", read_only=True) as store:
        assert 1 <= len(store.finished_ids()) < 4


def test_ctrl_c_stops_a_verification_in_one_line_and_the_same_command_resumes(tmp_path):
    from tests.design_search.conftest import save_model

    save_model(tmp_path / "linear.json")
    args = ["design", "find", "--model", "linear.json", "--angle", "90", "--at", "0.08",
            "--minimize", "l", "--fix", "r=8", "--fix", "t=3", "--fix", "b=3", "--fix", "phi=10",
            "--fix", "lc=10", "--out", "found", "--verify", "4", "--backend", "slow",
            "--workers", "2"]  # fmt: skip
    child = _start(args, tmp_path, delay_s=2.0)
    err = _interrupt_after(child, r"\(slow\): [1-3]/4")
    assert child.returncode == 130, err
    assert "Traceback" not in err and "KeyboardInterrupt" not in err
    (db,) = tmp_path.glob(".found.verify-*.duckdb")
    assert err.strip().splitlines()[-1] == (
        f"softbend: interrupted; finished work is kept in {db}; resume with: softbend "
        + " ".join(args)
    )
    assert sum("interrupted" in line for line in err.splitlines()) == 1
    assert not (tmp_path / "found").exists()
    _assert_none_left(tmp_path)
    with CampaignStore(db, read_only=True) as store:
        kept = len(store.finished_ids())
    assert 1 <= kept < 4

    started = len((tmp_path / "started").read_text().split())
    resumed = _start(args, tmp_path, delay_s=0.0)
    _, err = resumed.communicate(timeout=60)
    assert resumed.returncode == 0, err
    assert "verifying 4 designs (slow): 4/4" in err  # those swept before counted
    search = json.loads((tmp_path / "found" / "search.json").read_text())
    assert search["verified"] == {"backend": "slow", "family": "sfrba", "designs": 4}
    assert len((tmp_path / "started").read_text().split()) - started == 4 - kept
    assert not db.exists() and (tmp_path / "found" / "search.json").is_file()


def test_ctrl_c_stops_a_campaign_on_dask_in_one_line_and_the_same_command_resumes(
    tmp_path,
    dask_processes,  # noqa: F811  (the fixture imported above)
):
    _, scheduler_file = dask_processes
    args = ["campaign", "run", "c.duckdb", "--backend", "sleepy", "--space", "lhs:4"]
    args += ["--scheduler", str(scheduler_file), "--chunk-size", "1"]
    args += ["--pmax", "0.1", "--pstep", "0.05"]
    child = _start(args, tmp_path, delay_s=1.5)
    err = _interrupt_after(child, r"done [1-3] ")
    assert child.returncode == 130, err
    assert "Traceback" not in err and "KeyboardInterrupt" not in err
    assert err.strip().splitlines()[-1] == (
        "softbend: interrupted; finished work is kept in c.duckdb; resume with: softbend "
        + " ".join(args)
    )
    with CampaignStore(tmp_path / "c.duckdb", read_only=True) as store:
        kept = len(store.finished_ids())
    assert 1 <= kept < 4

    resumed = _start(args, tmp_path, delay_s=1.5)
    _, err = resumed.communicate(timeout=60)
    assert resumed.returncode == 0, err
    assert f"resuming c.duckdb: {kept} of 4 designs already recorded" in err
    with CampaignStore(tmp_path / "c.duckdb", read_only=True) as store:
        assert len(store.finished_ids()) == 4
