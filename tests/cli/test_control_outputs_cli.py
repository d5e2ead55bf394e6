"""``control simulate`` and ``control run``: honest scores, and all-or-nothing outputs.

A score a run does not define (an angle that never settled within the run, a run
without a rising edge) is null with its reason in the JSON and ``null (why)`` in
the table, never NaN, exit 0. Both commands build their ``--out`` beside it and
swap it in whole: a failure, Ctrl-C, SIGTERM or ``kill -9`` leaves the previous
results (or none), never a mix and never a temporary file.
"""

from __future__ import annotations

import errno
import json
import os
import re
import signal
import subprocess
import sys
import time
from pathlib import Path

import pytest

from softbend._outdir import MANIFEST
from softbend.cli import main

from .conftest import one_error_line

NOT_FINITE = re.compile(r"\b(nan|inf|infinity)\b", re.IGNORECASE)


def _snapshot(folder: Path) -> dict[str, bytes]:
    return {p.name: p.read_bytes() for p in sorted(folder.iterdir())}


def _hidden(parent: Path) -> list[str]:
    """Temporary files or staging folders left beside the outputs (not a folder's manifest)."""
    return sorted(p.name for p in parent.rglob(".*") if p.name != MANIFEST)


def test_a_run_that_never_settles_reports_null_with_the_reason(tmp_path, capsys):
    out = tmp_path / "o"
    args = ["control", "simulate", "--out", str(out), "--duration", "1.5"]
    args += ["--rig-param", "valve_delay_s=1"]  # the valves open after the run is over
    assert main([*args, "--json"]) == 0
    printed = json.loads(capsys.readouterr().out)
    written = json.loads((out / "metrics.json").read_text())
    for payload in (printed, written):
        metrics, why = payload["metrics"], payload["undefined_metrics"]
        assert metrics["settling_s"] is None and metrics["rise_s"] is None
        assert (
            "did not settle within ±5 % of the reference before the run ended"
            in (why["settling_s"])
        )
        assert set(why) == {k for k, v in metrics.items() if v is None}
    assert not NOT_FINITE.search((out / "metrics.json").read_text())
    assert main(args) == 0  # the table: the same, as 'null (why)'
    table = capsys.readouterr().out
    assert "null (the angle did not settle" in " ".join(table.split())
    assert not NOT_FINITE.search(table)


def test_a_loop_run_without_a_rising_edge_reports_null_with_the_reason(tmp_path, capsys):
    out = tmp_path / "o"
    args = ["control", "run", "--out", str(out), "--duration", "0.3", "--reference", "step:90:5"]
    assert main([*args, "--json"]) == 0
    payload = json.loads(capsys.readouterr().out)
    assert payload["metrics"]["rise_s"] is None and payload["metrics"]["rising_edges"] == 0
    assert payload["undefined_metrics"]["rise_s"] == (
        "no rising edge of the reference with 10 samples after it within the run"
    )
    assert (
        json.loads((out / "run.json").read_text())["undefined_metrics"]
        == (payload["undefined_metrics"])
    )
    assert not NOT_FINITE.search((out / "run.json").read_text())


@pytest.mark.parametrize("command", ["simulate", "run"])
@pytest.mark.parametrize(
    ("args", "needles"),
    [
        (["--set", "period=1e-12"], ["--set: period: must be in [0.0001, 1] s; got '1e-12'"]),
        (["--rig-param", "valve_delay_s=1e9"], ["--rig-param: valve_delay_s: must be in [0, 1] s"]),
        (["--set", "period=nan"], ["--set: period: must be a finite number"]),
        (["--rig-param", "step_s="], ["--rig-param: step_s: must be a number"]),
    ],
)
def test_values_out_of_their_range_are_one_line(tmp_path, capsys, command, args, needles):
    assert main(["control", command, "--out", str(tmp_path / "o"), *args]) == 2
    line = one_error_line(capsys)
    for needle in needles:
        assert needle in line
    assert not (tmp_path / "o").exists()


def _fail_figure(*args, **kwargs):
    raise OSError(errno.ENOSPC, "No space left on device", str(args[1]))


@pytest.mark.parametrize(
    ("command", "files"),
    [("simulate", {"run.csv", "metrics.json", "run.png", MANIFEST}),
     ("run", {"ticks.csv", "run.json", "run.png", MANIFEST})],
)  # fmt: skip
def test_a_failed_write_leaves_the_previous_results(tmp_path, capsys, monkeypatch, command, files):
    out = tmp_path / "o"
    args = ["control", command, "--out", str(out), "--duration", "0.3"]
    assert main(args) == 0
    before = _snapshot(out)
    assert set(before) == files
    monkeypatch.setattr("softbend.reports.control_figures.run_figure", _fail_figure)
    capsys.readouterr()
    assert main([*args, "--reference", "step:45:0.1"]) == 2  # another run, whose figure fails
    line = one_error_line(capsys)
    assert "'--out'" in line and "No space left on device" in line
    assert _snapshot(out) == before  # the previous results, whole
    assert _hidden(tmp_path) == []  # no temporary file, no staging folder


@pytest.mark.parametrize("command", ["simulate", "run"])
def test_a_folder_of_other_files_is_not_replaced(tmp_path, capsys, command):
    out = tmp_path / "o"
    out.mkdir()
    (out / "notes.txt").write_text("mine")
    assert main(["control", command, "--out", str(out), "--duration", "0.3"]) == 2
    line = one_error_line(capsys)
    assert "replaced as a whole" in line and "notes.txt" in line
    assert _snapshot(out) == {"notes.txt": b"mine"}


def test_a_new_run_replaces_the_old_one_whole(tmp_path, capsys):
    out = tmp_path / "o"
    base = ["control", "run", "--out", str(out), "--duration", "0.3"]
    assert main(base) == 0
    assert main([*base, "--log-format", "parquet"]) == 0  # the old ticks.csv goes too
    assert {p.name for p in out.iterdir()} == {"ticks.parquet", "run.json", "run.png", MANIFEST}
    assert _hidden(tmp_path) == []


def _softbend() -> str:
    return str(Path(sys.executable).with_name("softbend"))  # the console script


def _wait_for(condition, timeout: float) -> bool:
    end = time.monotonic() + timeout
    while time.monotonic() < end:
        if condition():
            return True
        time.sleep(0.05)
    return False


@pytest.mark.slow
@pytest.mark.skipif(sys.platform == "win32", reason="POSIX signals to a child")
def test_kill_9_mid_run_leaves_the_previous_run_whole(tmp_path, capsys):
    out = tmp_path / "o"
    assert main(["control", "run", "--out", str(out), "--duration", "0.3"]) == 0
    before = _snapshot(out)
    cmd = [_softbend(), "control", "run", "--out", str(out), "--duration", "600"]
    child = subprocess.Popen(cmd, stdout=subprocess.DEVNULL, stderr=subprocess.DEVNULL)
    try:
        staged = lambda: list(tmp_path.glob(".o.*.new/ticks.csv.partial"))  # noqa: E731
        assert _wait_for(staged, timeout=120.0), "the run never started its log"
        assert _wait_for(lambda: staged()[0].stat().st_size > 10_000, timeout=60.0)
        child.send_signal(signal.SIGKILL)
        child.wait(timeout=30)
    finally:
        child.kill()
    assert _snapshot(out) == before  # not a mix of the old and the new run
    left = [p.name for p in tmp_path.glob(".o.*.new")]  # the killed run's ticks, hidden
    assert len(left) == 1 and left[0].startswith(f".o.{child.pid}-")
    assert main(["control", "run", "--out", str(out), "--duration", "0.3"]) == 0
    assert _hidden(tmp_path) == []  # the next run removed the dead run's staging folder


#: A command whose figure is never drawn: the process signals itself instead, once the
#: other outputs are written (the moment a kill leaves a mix or temporary files behind).
_KILLED_WHILE_WRITING = """
import os, signal, sys
from softbend.reports import control_figures

def killed(*args, **kwargs):
    os.kill(os.getpid(), int(os.environ["SIGNAL"]))

control_figures.run_figure = killed
from softbend.cli import main
sys.exit(main(sys.argv[1:]))
"""


@pytest.mark.skipif(sys.platform == "win32", reason="POSIX signals to a child")
@pytest.mark.parametrize("signum", [signal.SIGKILL, signal.SIGTERM])
@pytest.mark.parametrize("command", ["simulate", "run"])
def test_a_kill_while_writing_leaves_the_previous_results(tmp_path, capsys, command, signum):
    out = tmp_path / "o"
    args = ["control", command, "--out", str(out), "--duration", "0.3"]
    assert main(args) == 0
    before = _snapshot(out)
    env = {**os.environ, "SIGNAL": str(int(signum))}
    cmd = [sys.executable, "-c", _KILLED_WHILE_WRITING, *args, "--reference", "step:45:0.1"]
    child = subprocess.run(cmd, capture_output=True, text=True, env=env, timeout=300)
    assert child.returncode == (-signal.SIGKILL if signum == signal.SIGKILL else 130), child.stderr
    assert _snapshot(out) == before  # the previous results, not a mix
    if signum == signal.SIGTERM:  # as Ctrl-C: the staged results are removed at once
        assert _hidden(tmp_path) == []
    assert main(args) == 0  # a kill -9 leaves a staging folder, which the next run removes
    assert _hidden(tmp_path) == []
