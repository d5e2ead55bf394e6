"""The fixed-period loop on the simulated rig: metrics, safety stops, the tick log."""

import math

import numpy as np
import pandas as pd
import pytest

from softbend.control.controllers import BangBang, ValveCommand
from softbend.control.experiments import run_metrics, simulate
from softbend.control.loop import COLUMNS, run_loop
from softbend.control.rig import RigParams, SimulatedRig
from softbend.control.rigconfig import SafetyLimits
from softbend.errors import RigError


class Always:
    """A stuck controller: always the same command."""

    predicted_deg = math.nan

    def __init__(self, command=None, fail_at_s=None, exc=None):
        self.command = ValveCommand(True, False) if command is None else command
        self.fail_at_s = fail_at_s
        self.exc = exc

    def reset(self):
        pass

    def step(self, measurement_mpa, reference_deg, t_s):
        if self.fail_at_s is not None and t_s >= self.fail_at_s:
            raise self.exc
        return self.command


class Flaky:
    """A simulated rig whose sensor fails from ``t_fail`` on (or whose valves can't be set)."""

    def __init__(self, rig, t_fail=math.inf, kind="timeout", command_fails=False):
        self.rig = rig
        self.t_fail = t_fail
        self.kind = kind
        self.command_fails = command_fails
        self.commands = []

    def clock_s(self):
        return self.rig.clock_s()

    def sleep_until(self, t):
        self.rig.sleep_until(t)

    def read_pressure_mpa(self):
        if self.rig.t_s >= self.t_fail:
            raise RigError("The rig at test:// did not answer.", kind=self.kind)
        return self.rig.read_pressure_mpa()

    def read_angle_deg(self):
        return self.rig.read_angle_deg()

    def command(self, inlet, outlet):
        if self.command_fails and self.rig.t_s >= self.t_fail:
            raise RigError("Lost the rig at test:// while setting the valves.")
        self.commands.append((round(self.rig.t_s, 6), inlet, outlet))
        self.rig.command(inlet, outlet)

    def close(self):
        pass


def settle(rig, seconds=0.02):
    rig.advance(round(seconds / rig.step_s))


def test_completed_run_logs_every_tick_and_leaves_the_rig_vented(table):
    rig = SimulatedRig(table, RigParams())
    run = run_loop(rig, BangBang(table), "step:90:0.5", 2.0)
    assert run.completed and run.fault_kind is None and run.vented
    assert list(run.ticks.columns) == list(COLUMNS) and len(run.ticks) == 2000
    np.testing.assert_allclose(run.ticks["t_target_s"], np.arange(2000) * 0.001, atol=1e-12)
    assert (run.ticks["status"] == "ok").sum() == 200  # read at 100 Hz
    assert set(run.ticks["status"]) == {"ok", "held"}
    settle(rig)
    assert (rig.inlet_open, rig.outlet_open) == (False, True)
    jitter = run.jitter()
    assert jitter["period_jitter_p99_ms"] == 0.0  # simulated time is exact


def test_loop_on_the_simulated_rig_matches_the_direct_simulation(table):
    """Same controller, same plant: only the 100 Hz angle sampling differs (noise)."""
    loop = [
        run_loop(SimulatedRig(table, seed=s), BangBang(table), "step:90:0.5", 3.0) for s in (0, 1)
    ]
    direct = [
        run_metrics(simulate(SimulatedRig(table), BangBang(table), "step:90:0.5", 3.0, seed=s))
        for s in (0, 1)
    ]
    for run, ref in zip(loop, direct, strict=True):
        m = run.metrics()
        assert m["mape_pct"] == pytest.approx(ref["mape_pct"], abs=0.6)
        assert m["switches"] == pytest.approx(ref["switches"], rel=0.1)
        assert m["rise_s"] == pytest.approx(ref["rise_s"], abs=0.02)


def test_over_pressure_vents_and_stops(table):
    rig = SimulatedRig(table, RigParams(supply_gauge_mpa=0.2))
    limits = SafetyLimits(max_pressure_mpa=0.1)
    run = run_loop(rig, Always(), "step:90", 5.0, limits=limits)
    assert not run.completed and run.fault_kind == "over-pressure"
    assert "Over-pressure" in run.stop_reason and "max_pressure_mpa 0.1" in run.stop_reason
    last = run.ticks.iloc[-1]
    assert last["status"] == "over-pressure" and last["measured_mpa"] > 0.1
    assert last["t_s"] < 1.0  # stopped at the first reading above the limit, not at 5 s
    peak = rig.pressure_mpa
    settle(rig, 0.5)
    assert (rig.inlet_open, rig.outlet_open) == (False, True)
    assert rig.pressure_mpa < 0.5 * peak  # it really vents


def test_missed_reads_close_the_inlet_then_vent_and_stop(table):
    rig = Flaky(SimulatedRig(table), t_fail=0.5)
    limits = SafetyLimits(max_missed_reads=3, stale_after_s=1.0)
    run = run_loop(rig, Always(), "step:90", 5.0, limits=limits)
    assert run.fault_kind == "timeout" and run.vented
    assert "3 missed reads in a row" in run.stop_reason and "test://" in run.stop_reason
    missed = run.ticks[run.ticks["status"].str.startswith("missed")]
    assert len(missed) == 3 and np.isnan(missed["measured_mpa"]).all()
    # the first missed read already closed the inlet
    first_miss = missed["t_target_s"].iloc[0]
    assert any(t <= first_miss + 1e-9 and not inlet for t, inlet, _ in rig.commands[1:])
    assert rig.commands[-1][1:] == (False, True)


def test_a_stale_sensor_stops_before_the_missed_read_count(table):
    rig = Flaky(SimulatedRig(table), t_fail=0.5, kind="stale")
    limits = SafetyLimits(max_missed_reads=50, stale_after_s=0.035)
    run = run_loop(rig, Always(), "step:90", 5.0, limits=limits)
    assert run.fault_kind == "stale" and "no good reading for" in run.stop_reason
    assert run.ticks["status"].str.startswith("missed").sum() <= 5


def test_a_rig_that_cannot_be_vented_says_so(table):
    rig = Flaky(SimulatedRig(table), t_fail=0.5, command_fails=True)
    run = run_loop(rig, Always(ValveCommand(True, False)), "step:90", 2.0)
    assert not run.vented
    assert "watchdog must vent it" in run.stop_reason


@pytest.mark.parametrize(
    ("exc", "kind"), [(KeyboardInterrupt(), "interrupted"), (ZeroDivisionError("x"), "error")]
)
def test_ctrl_c_or_a_controller_error_ends_vented(table, exc, kind):
    rig = SimulatedRig(table)
    run = run_loop(rig, Always(fail_at_s=0.3, exc=exc), "step:90", 2.0)
    assert run.fault_kind == kind and run.vented
    assert 299 <= len(run.ticks) <= 301
    settle(rig)
    assert (rig.inlet_open, rig.outlet_open) == (False, True)


@pytest.mark.parametrize("suffix", [".csv", ".parquet"])
def test_tick_log_round_trips(tmp_path, table, suffix):
    path = tmp_path / f"ticks{suffix}"
    run = run_loop(
        SimulatedRig(table), BangBang(table), "square:90:1", 1.0, log_path=path, flush_every=7
    )
    back = pd.read_csv(path) if suffix == ".csv" else pd.read_parquet(path)
    assert list(back.columns) == list(COLUMNS) and len(back) == len(run.ticks)
    np.testing.assert_allclose(back["measured_mpa"], run.ticks["measured_mpa"])
    assert back["inlet"].astype(bool).tolist() == run.ticks["inlet"].tolist()
    assert not (tmp_path / f"ticks{suffix}.partial").exists()


def test_a_csv_log_is_streamed_while_the_run_goes(tmp_path, table):
    path = tmp_path / "ticks.csv"
    partial = tmp_path / "ticks.csv.partial"
    seen = []

    def progress(done, total):
        seen.append(len(partial.read_text().splitlines()) - 1)

    run_loop(SimulatedRig(table), BangBang(table), "step:90", 2.0, log_path=path, progress=progress)
    assert seen[0] >= 50  # a killed run keeps its ticks up to the last flush
    assert path.exists() and not partial.exists()


def test_bad_arguments_are_one_line(table):
    rig = SimulatedRig(table)
    with pytest.raises(ValueError, match=r"^period_s: must be a number in \(0, 1\]"):
        run_loop(rig, BangBang(table), "step:90", 1.0, period_s=0)
    with pytest.raises(ValueError, match=r"^log_path: must be a file ending in \.csv"):
        run_loop(rig, BangBang(table), "step:90", 1.0, log_path="x.txt")


def test_the_garbage_collector_is_paused_only_during_the_run(table):
    import gc

    assert gc.isenabled()
    run_loop(SimulatedRig(table), Always(fail_at_s=0.1, exc=ZeroDivisionError("x")), "step:90", 1.0)
    assert gc.isenabled()
