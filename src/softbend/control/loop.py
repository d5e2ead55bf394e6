"""The fixed-period control loop on any :class:`~softbend.control.rig.Rig`, with its safety.

:func:`run_loop` runs one controller on one rig for a set time. The loop ticks
every ``period_s`` (1 ms: the valve timing of a PLC) and reads the pressure
sensor every ``sensor_period_s`` (paper B: 100 Hz), exactly as
:func:`~softbend.control.experiments.simulate` does in simulated time, so a
controller that times its valve pulses finer than the sensor (PWM, a relay's
early close) behaves the same on a rig. Each tick, at its scheduled time
``k·period_s``:

1. on a sensor tick, read the pressure (and, on a Modbus rig, the angle in the
   same request) and check it: a failed, garbage or stale reading is a *missed
   read*, which closes the inlet at once (the outlet is left as it is) and
   keeps the controller out until a good reading; ``max_missed_reads`` in a
   row, or no good reading for ``stale_after_s``, vents and stops the run; a
   reading above ``max_pressure_mpa`` vents and stops the run;
2. call ``controller.step(reading, θr(k·period_s), k·period_s)`` with the
   latest good reading and send its valve command when it changed.

Every tick is one row of the log: the scheduled and actual times, the reading
(``status`` ``ok`` when read on that tick, ``held`` in between), the
reference, the controller's predicted angle, the valve command and the angle
sensor. With ``log_path`` the rows stream to a CSV file as they come (flushed
every ``flush_every`` ticks, so a killed process keeps its ticks in
``<log>.partial``), which is moved into place at the end; a ``.parquet`` path is
written from the finished table.

However the run ends (its duration reached, a fault, an exception, Ctrl-C)
the loop vents the actuator: inlet closed, outlet open. The stop reason is
written once that vent has been tried, and says what happened to it: "vented
and stopped" when the vent command reached the rig, or, when it did not, that
the rig is not vented and its own watchdog must vent it (never both).

Period jitter is ``|Δt − period_s|`` over consecutive actual tick times;
lateness is the actual minus the scheduled time of each tick. The garbage
collector is run once before the first tick and paused during the run (a full
collection in a process holding PyTorch and pandas takes 100+ ms: a stalled
tick); the loop itself makes no reference cycles.
"""

from __future__ import annotations

import gc
import math
import os
from array import array
from collections.abc import Callable
from dataclasses import dataclass, field
from pathlib import Path
from typing import TYPE_CHECKING, Any

import numpy as np

from softbend._io import atomic_file
from softbend._validation import check_int, check_range, must_be
from softbend.control.budget import LOOP_BYTES_PER_TICK, check_run_size
from softbend.control.experiments import ControlRun, Reference, parse_reference, run_metrics
from softbend.control.rigconfig import SafetyLimits
from softbend.errors import InputError, RigError

if TYPE_CHECKING:
    from softbend.control.controllers import Controller
    from softbend.control.rig import Rig

__all__ = ["COLUMNS", "LoopRun", "run_loop"]

#: The columns of a loop's log, one row per tick.
COLUMNS: tuple[str, ...] = (
    "tick",
    "t_target_s",
    "t_s",
    "lateness_s",
    "measured_mpa",
    "reference_deg",
    "predicted_deg",
    "inlet",
    "outlet",
    "angle_deg",
    "status",
)

_VENT = (False, True)


@dataclass(eq=False)
class LoopRun:
    """The ticks of one loop run and how it ended.

    Attributes
    ----------
    ticks : pandas.DataFrame
        One row per tick, columns :data:`COLUMNS`.
    period_s : float
        The loop's tick, s.
    completed : bool
        True when the run reached its duration.
    stop_reason : str
        ``"completed"``, or the fault, exception or interruption that ended it,
        followed by the outcome of the final vent: ``"; vented and stopped."``,
        or ``"; stopped, but could not vent the rig (...)"`` when the vent
        command failed (a completed run whose vent failed starts ``"Completed,
        but could not vent"``).
    fault_kind : str or None
        The :class:`~softbend.errors.RigError` kind, ``"over-pressure"``,
        ``"interrupted"``, ``"error"``, or None when completed.
    vented : bool
        Whether the final vent command reached the rig.
    switches : int
        Valve state changes commanded.
    reference : Reference
    metadata : dict
        Anything the caller adds (rig, controller, versions...).
    """

    ticks: Any
    period_s: float
    completed: bool
    stop_reason: str
    fault_kind: str | None
    vented: bool
    switches: int
    reference: Reference
    metadata: dict[str, Any] = field(default_factory=dict)

    def jitter(self) -> dict[str, float]:
        """Period jitter and lateness percentiles, ms."""
        t = self.ticks["t_s"].to_numpy(dtype=float)
        late = self.ticks["lateness_s"].to_numpy(dtype=float)
        out: dict[str, float] = {"ticks": int(t.size)}
        if t.size >= 2:
            dev = np.round(np.abs(np.diff(t) - self.period_s) * 1e3, 6)  # ns resolution
            out["period_jitter_p50_ms"] = float(np.percentile(dev, 50))
            out["period_jitter_p99_ms"] = float(np.percentile(dev, 99))
            out["period_jitter_max_ms"] = float(np.max(dev))
        if late.size:
            out["lateness_p50_ms"] = float(np.percentile(late, 50) * 1e3)
            out["lateness_p99_ms"] = float(np.percentile(late, 99) * 1e3)
        return out

    def control_run(self) -> ControlRun:
        """The ticks as a :class:`ControlRun` on the scheduled times (for :func:`run_metrics`)."""
        ticks = self.ticks
        angle = ticks["angle_deg"].to_numpy(dtype=float)
        measured = ticks["measured_mpa"].to_numpy(dtype=float)
        return ControlRun(
            t_s=ticks["t_target_s"].to_numpy(dtype=float),
            reference_deg=ticks["reference_deg"].to_numpy(dtype=float),
            angle_deg=angle,
            camera_deg=angle,
            predicted_deg=ticks["predicted_deg"].to_numpy(dtype=float),
            pressure_mpa=measured,
            measured_mpa=measured,
            inlet=ticks["inlet"].to_numpy(dtype=bool),
            outlet=ticks["outlet"].to_numpy(dtype=bool),
            air_used_kg=math.nan,
            switches=self.switches,
            wall_s=math.nan,
            reference=self.reference,
        )

    def metrics(self, reasons: dict[str, str] | None = None) -> dict[str, float]:
        """:func:`run_metrics` on the angle sensor's readings (NaN without one).

        ``reasons``, when given, receives why a score is NaN, by name.
        """
        why: dict[str, str] = {}
        out = run_metrics(self.control_run(), reasons=why)
        for key in ("air_used_kg", "realtime_factor"):
            out.pop(key, None)
            why.pop(key, None)
        if reasons is not None:
            reasons.update(why)
        return out


#: How each column of the log is kept in memory (array typecodes; "status" as codes).
_STORAGE: tuple[str, ...] = ("q", "d", "d", "d", "d", "d", "d", "b", "b", "d", "H")


class _Log:
    """The tick rows, streamed to ``<path>.partial`` as CSV and kept in memory by column.

    Rows are gathered ``flush_every`` at a time and moved into one array of machine
    numbers per column (8 bytes a number, 1 a valve state, 2 a status code): a long
    run holds about 70 bytes a tick instead of a tuple of Python objects (about 300).
    """

    def __init__(self, path: Path | None, flush_every: int) -> None:
        self.path = path
        self.flush_every = flush_every
        self.count = 0
        self._batch: list[tuple] = []
        self._columns = [array(code) for code in _STORAGE]
        self._statuses: dict[str, int] = {}
        self._file = None
        if path is not None and path.suffix.lower() == ".csv":
            self.partial = path.with_name(path.name + ".partial")
            self._file = open(self.partial, "w", encoding="utf-8", newline="")  # noqa: SIM115
            self._file.write(",".join(COLUMNS) + "\n")

    def add(self, row: tuple) -> None:
        self._batch.append(row)
        self.count += 1
        if self._file is not None:
            self._file.write(",".join(_cell(v) for v in row) + "\n")
        if len(self._batch) >= self.flush_every:
            if self._file is not None:
                self._file.flush()
            self._store()

    def _store(self) -> None:
        """Move the gathered rows into the column arrays."""
        if not self._batch:
            return
        *values, statuses = zip(*self._batch, strict=True)
        for column, part in zip(self._columns, values, strict=False):
            column.extend(part)
        codes = self._statuses
        self._columns[-1].extend(codes.setdefault(s, len(codes)) for s in statuses)
        self._batch = []

    def frame(self):  # -> pandas.DataFrame
        """The ticks so far as a table, columns :data:`COLUMNS`."""
        import pandas as pd

        self._store()
        data = {}
        for name, code, column in zip(COLUMNS, _STORAGE, self._columns, strict=True):
            if name == "status":
                names = np.array(list(self._statuses), dtype=object)
                data[name] = names[np.frombuffer(column, dtype=np.uint16)] if column else []
            elif code == "b":
                data[name] = np.frombuffer(column, dtype=np.int8).view(bool) if column else []
            else:
                data[name] = np.frombuffer(column, dtype=np.dtype(code)) if column else []
        frame = pd.DataFrame(data, columns=list(COLUMNS))
        if not self.count:  # no tick: the types the columns would have
            frame = frame.astype({"tick": "int64", "inlet": bool, "outlet": bool})
        return frame

    def finish(self):  # -> pandas.DataFrame
        frame = self.frame()
        if self._file is not None:
            self._file.flush()
            os.fsync(self._file.fileno())
            self._file.close()
            os.replace(self.partial, self.path)
        elif self.path is not None:
            with atomic_file(self.path, "wb") as fh:
                frame.to_parquet(fh, index=False)
        return frame


def _cell(value: object) -> str:
    if isinstance(value, bool):
        return "1" if value else "0"
    if isinstance(value, float):
        return "" if math.isnan(value) else repr(value)
    text = str(value)
    return '"' + text.replace('"', '""') + '"' if ("," in text or '"' in text) else text


def run_loop(
    rig: Rig,
    controller: Controller,
    reference: Reference | str,
    duration_s: float,
    *,
    period_s: float = 0.001,
    sensor_period_s: float = 0.01,
    limits: SafetyLimits | None = None,
    log_path: str | os.PathLike[str] | None = None,
    flush_every: int = 1000,
    progress: Callable[[int, int], None] | None = None,
) -> LoopRun:
    """Run ``controller`` on ``rig`` at a fixed period for ``duration_s``, safely.

    Parameters
    ----------
    rig : Rig
        Any :class:`~softbend.control.rig.Rig` (simulated, wall-clock, Modbus).
        It should be at rest; the loop does not reset it.
    controller : Controller
        Reset first; called once per tick with the latest good reading and the
        tick's scheduled time.
    reference : Reference or str
        θr(t), degrees (a spec as in :func:`~softbend.control.experiments.parse_reference`).
    duration_s : float
        Run time, s (``round(duration_s/period_s)`` ticks), in (0, 86400]; the
        ticks are held to the ``loop_ticks`` limit and the memory the machine
        has left (:func:`~softbend.control.budget.check_run_size`).
    period_s : float, default 0.001
        Tick of the controller and the valves, s.
    sensor_period_s : float, default 0.01
        Period of the pressure readings, s; rounded to a whole number of ticks.
    limits : SafetyLimits, optional
        Over-pressure, missed-read and staleness limits (default :class:`SafetyLimits`).
    log_path : path, optional
        ``.csv`` (streamed) or ``.parquet`` (written at the end).
    flush_every : int, default 1000
        Ticks between flushes of a CSV log.
    progress : callable, optional
        ``progress(done_ticks, total_ticks)``, called about once a second of run time.

    Returns
    -------
    LoopRun
        Its ``stop_reason`` says why it ended; it is not an exception: a fault
        is a result, with every tick before it logged.

    Raises
    ------
    KeyboardInterrupt
        Never: Ctrl-C ends the run as ``fault_kind="interrupted"``, vented (if the
        rig answers the vent command; the stop reason says which).
    """
    ref = parse_reference(reference) if isinstance(reference, str) else reference
    period = check_range(period_s, "period_s", low=0.0, high=1.0, high_inclusive=True)
    sensor = check_range(
        sensor_period_s, "sensor_period_s", low=period, high=10.0,
        low_inclusive=True, high_inclusive=True,
    )  # fmt: skip
    n = check_run_size(
        duration_s, period, LOOP_BYTES_PER_TICK, what="A run", step_word="period"
    ).ticks
    flush = check_int(flush_every, "flush_every", low=1)
    limits = SafetyLimits() if limits is None else limits
    path = None if log_path is None else Path(log_path)
    if path is not None and path.suffix.lower() not in (".csv", ".parquet"):
        raise InputError(must_be("a file ending in .csv or .parquet", str(path)), key="log_path")
    sensor_every = max(1, round(sensor / period))
    log = _Log(path, flush)
    controller.reset()
    state: tuple[bool, bool] | None = None  # unknown: the first command is always sent
    switches = 0
    missed = 0
    held = math.nan  # the latest good reading; NaN after a missed read
    reason, kind = "completed", None
    report_every = max(1, round(1.0 / period))

    def send(command: tuple[bool, bool]) -> None:
        nonlocal state, switches
        if command != state:
            rig.command(command[0], command[1])
            if state is not None:
                switches += (command[0] != state[0]) + (command[1] != state[1])
            state = command

    def row(k: int, now: float, status: str) -> tuple:
        shown = state if state is not None else (False, False)
        return _row(k, k * period, now - t_start, held, ref, controller, shown, rig, status)

    collecting = gc.isenabled()
    gc.collect()
    gc.disable()
    try:
        t_start = rig.clock_s()
        last_good = t_start
        for k in range(n):
            rig.sleep_until(t_start + k * period)
            now = rig.clock_s()
            status = "held"
            if k % sensor_every == 0:
                status = "ok"
                try:
                    reading = float(rig.read_pressure_mpa())
                    if not math.isfinite(reading):
                        raise RigError(f"The pressure reading is {reading}.", kind="garbage")
                except RigError as exc:
                    missed += 1
                    held = math.nan
                    status = f"missed ({exc.kind})"
                    quiet = rig.clock_s() - last_good
                    if missed >= limits.max_missed_reads or quiet > limits.stale_after_s:
                        why = (
                            f"{missed} missed reads in a row"
                            if missed >= limits.max_missed_reads
                            else f"no good reading for {quiet:.3f} s"
                        )
                        reason, kind = f"{_clause(exc)} ({why})", exc.kind
                        log.add(row(k, now, status))
                        break
                    send((False, True if state is None else state[1]))  # inlet shut at once
                else:
                    missed = 0
                    held = reading
                    last_good = rig.clock_s()
                    if reading > limits.max_pressure_mpa:
                        reason = (
                            f"Over-pressure: {reading:.4f} MPa read, above max_pressure_mpa "
                            f"{limits.max_pressure_mpa:g}"
                        )
                        kind = "over-pressure"
                        log.add(row(k, now, "over-pressure"))
                        break
            if held == held:  # a good reading to act on
                theta_r = float(ref.values(np.array([k * period]))[0])
                command = controller.step(held, theta_r, k * period)
                send((bool(command[0]), bool(command[1])))
            log.add(row(k, now, status))
            if progress is not None and (k + 1) % report_every == 0:
                progress(k + 1, n)
    except KeyboardInterrupt:
        reason, kind = "Interrupted (Ctrl-C or SIGTERM)", "interrupted"
    except RigError as exc:  # a command that did not reach the rig
        reason, kind = _clause(exc), exc.kind
    except Exception as exc:  # a controller or rig bug: still leave the valves safe
        reason, kind = f"Stopped by an error: {type(exc).__name__}: {_clause(exc)}", "error"
    finally:
        if collecting:
            gc.enable()
    # How the run ended is told only once the vent has been tried: its outcome decides
    # between "vented and stopped" and "not vented".
    vent_error: BaseException | None = None
    try:
        rig.command(*_VENT)
        if state is not None and state != _VENT:
            switches += (state[0] != _VENT[0]) + (state[1] != _VENT[1])
    except Exception as exc:
        vent_error = exc
    reason = _ending(reason if kind is not None else None, vent_error)
    frame = log.finish()
    return LoopRun(
        ticks=frame,
        period_s=period,
        completed=kind is None,
        stop_reason=reason,
        fault_kind=kind,
        vented=vent_error is None,
        switches=switches,
        reference=ref,
    )


def _clause(exc: BaseException) -> str:
    """An exception's message as a clause: one line, without its final full stop."""
    return " ".join(str(exc).split()).rstrip(".")


def _ending(cause: str | None, vent_error: BaseException | None) -> str:
    """The one stop reason of a run: its ``cause`` (None: completed) and the vent's outcome."""
    if vent_error is None:
        return "completed" if cause is None else f"{cause}; vented and stopped."
    not_vented = (
        f"could not vent the rig ({_clause(vent_error)}): the vent command did not reach it, "
        "so its own watchdog must vent it; check the valves by hand."
    )
    if cause is None:
        return f"Completed, but {not_vented}"
    return f"{cause}; stopped, but {not_vented}"


def _row(
    k: int,
    target: float,
    actual: float,
    reading: float,
    ref: Reference,
    controller: Controller,
    state: tuple[bool, bool],
    rig: Rig,
    status: str,
) -> tuple:
    theta_r = float(ref.values(np.array([target]))[0])
    try:
        angle = float(rig.read_angle_deg())
    except Exception:
        angle = math.nan
    return (
        k,
        target,
        actual,
        actual - target,
        reading,
        theta_r,
        float(getattr(controller, "predicted_deg", math.nan)),
        state[0],
        state[1],
        angle,
        status,
    )
