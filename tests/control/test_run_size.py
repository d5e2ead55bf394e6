"""The size of a control run, checked before it starts, in one place for both commands.

``control simulate`` logs every rig step and ``control run`` every tick, in memory:
both are held to the ``loop_ticks`` limit (``SOFTBEND_MAX_LOOP_TICKS``) and to
the memory the machine has left, by ``softbend.control.budget.check_run_size``,
before any model is loaded or any valve moves.
"""

from __future__ import annotations

import math
import tracemalloc

import pytest

from softbend.cli import main
from softbend.control.budget import (
    LOOP_BYTES_PER_TICK,
    SIMULATE_BYTES_PER_STEP,
    check_run_size,
)
from softbend.control.controllers import BangBang
from softbend.control.experiments import run_metrics, simulate
from softbend.control.loop import run_loop
from softbend.control.rig import RigParams, SimulatedRig
from softbend.errors import LimitError


def one_error_line(capsys) -> str:
    """The single ``softbend: error: …`` line a failed command wrote to stderr."""
    err = capsys.readouterr().err.strip().splitlines()
    assert len(err) == 1, err
    assert err[0].startswith("softbend: error: ")
    return err[0]


def test_the_size_is_ticks_and_memory():
    size = check_run_size(10.0, 1e-3, 300, available_bytes=None)
    assert size.ticks == 10_000 and size.memory_bytes > 10_000 * 300
    assert check_run_size(1e-9, 1e-3, 300, available_bytes=None).ticks == 1


@pytest.mark.parametrize("duration", [0.0, -1.0, 1e5, math.nan, math.inf])
def test_a_duration_out_of_range_is_refused(duration):
    with pytest.raises(ValueError, match=r"^duration_s: must be a number in \(0, 86400\]"):
        check_run_size(duration, 1e-3, 300)


def test_the_loop_ticks_limit_names_the_options(monkeypatch):
    monkeypatch.setenv("SOFTBEND_MAX_LOOP_TICKS", "500")
    with pytest.raises(LimitError) as info:
        check_run_size(
            1.0, 1e-3, 300, what="A simulated run", unit="rig steps", available_bytes=None
        )
    message = str(info.value)
    assert message.startswith(
        "duration_s: A simulated run of 1 s at a rig step of 0.001 s "
        "is 1,000 ticks, more than the limit of 500 ticks"
    )
    assert "SOFTBEND_MAX_LOOP_TICKS" in message


def test_a_run_that_would_not_fit_in_memory_is_refused():
    with pytest.raises(ValueError) as info:
        check_run_size(8000.0, 1e-3, 300, what="A loop run", available_bytes=2**30)
    message = str(info.value)
    assert message.startswith("duration_s: A loop run of 8000 s at a tick of 0.001 s logs")
    assert "logs 8,000,000 ticks: about 2.6 GiB of memory, more than the 1.0 GiB" in message
    assert message.endswith("shorten the run or lengthen its tick")


def test_the_library_functions_apply_the_same_limit(table, monkeypatch):
    monkeypatch.setenv("SOFTBEND_MAX_LOOP_TICKS", "100")
    rig = SimulatedRig(table, RigParams())
    with pytest.raises(
        LimitError, match=r"^duration_s: A simulated run of 0\.2 s at a rig step of 0\.001 s is 200"
    ):
        simulate(rig, BangBang(table), "step:90", 0.2)
    with pytest.raises(
        LimitError, match=r"^duration_s: A run of 0\.2 s at a period of 0\.001 s is"
    ):
        run_loop(rig, BangBang(table), "step:90", 0.2)
    assert simulate(rig, BangBang(table), "step:90", 0.1).t_s.size == 100


@pytest.mark.parametrize("command", ["simulate", "run"])
def test_both_commands_apply_loop_ticks_before_any_work(tmp_path, capsys, monkeypatch, command):
    monkeypatch.setenv("SOFTBEND_MAX_LOOP_TICKS", "1000")
    # a model that does not exist: the size is refused before it would be loaded
    args = ["control", command, "--out", str(tmp_path / "o"), "--duration", "2"]
    assert main([*args, "--model", str(tmp_path / "none.json")]) == 2
    line = one_error_line(capsys)
    assert "--duration: A " in line and "SOFTBEND_MAX_LOOP_TICKS" in line
    assert ("at a rig step of 0.001 s" if command == "simulate" else "at a tick of 0.001") in line
    assert not (tmp_path / "o").exists()


@pytest.mark.parametrize(
    ("args", "needles"),
    [
        (["--duration", "80000"], ["--duration: ", "80,000,000 ticks", "rig step of 0.001 s"]),
        (["--rig-param", "step_s=1e-9"], ["--rig-param: step_s: must be in [1e-05, 0.01] s"]),
        (["--duration", "100000"], ["--duration: must be a number in (0, 86400]"]),
    ],
)
def test_simulate_refuses_a_run_too_large_in_one_line(tmp_path, capsys, args, needles):
    assert main(["control", "simulate", "--out", str(tmp_path / "o"), *args]) == 2
    line = one_error_line(capsys)
    for needle in needles:
        assert needle in line
    assert not (tmp_path / "o").exists()


def test_simulate_refuses_a_run_the_machine_has_no_memory_for(tmp_path, capsys, monkeypatch):
    monkeypatch.setattr(
        "softbend.identification.resources.available_memory_bytes", lambda: 500 * 2**20
    )
    args = ["control", "simulate", "--out", str(tmp_path / "o"), "--duration", "1000"]
    assert main(args) == 2
    line = one_error_line(capsys)
    assert "logs 1,000,000 rig steps" in line and "more than the 0.5 GiB" in line
    assert line.startswith("softbend: error: --duration: ")
    assert "shorten the run or lengthen its rig step" in line


def _peak_bytes(work) -> int:
    tracemalloc.start()
    try:
        work()
        return tracemalloc.get_traced_memory()[1]
    finally:
        tracemalloc.stop()


@pytest.mark.slow
def test_the_bytes_per_step_cover_what_a_run_holds(table):
    """The growth of the peak memory with the steps, below the constants of the estimate."""
    rig = SimulatedRig(table, RigParams())

    def simulated(steps):
        run = simulate(rig, BangBang(table), "step:90", steps * 1e-3)
        run_metrics(run)
        run.frame()
        run.decimated()

    def looped(steps):
        run_loop(rig, BangBang(table), "step:90", steps * 1e-3).metrics()

    for work, bound in ((simulated, SIMULATE_BYTES_PER_STEP), (looped, LOOP_BYTES_PER_TICK)):
        work(1000)  # imports and caches first
        small, large = (_peak_bytes(lambda n=n, w=work: w(n)) for n in (5_000, 20_000))
        assert (large - small) / 15_000 < bound
