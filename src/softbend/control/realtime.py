"""The simulated rig kept in step with the wall clock: a stand-in for hardware.

:class:`WallClockRig` wraps a :class:`~softbend.control.rig.SimulatedRig` and,
before every reading or command, integrates it up to the time elapsed on the
clock since it started. Between two calls the valves do not change, so catching
up lazily is exact (the valve delay and camera frames are handled inside the
simulation). It answers the :class:`~softbend.control.rig.Rig` protocol with
real waiting, and it is the plant behind
:class:`~softbend.control.modbus_server.SimulatedModbusServer`. Calls are
serialised by a lock, so a server thread and a watchdog may share it.
"""

from __future__ import annotations

import threading
import time
from collections.abc import Callable

from softbend.control.rig import SimulatedRig

__all__ = ["WallClockRig", "sleep_until_monotonic"]


def sleep_until_monotonic(deadline_s: float, *, spin_s: float = 0.0002) -> None:
    """Wait until ``time.monotonic() >= deadline_s``: sleep, then spin the last ``spin_s``."""
    while True:
        left = deadline_s - time.monotonic()
        if left <= 0.0:
            return
        if left > spin_s:
            time.sleep(left - spin_s)


class WallClockRig:
    """A :class:`SimulatedRig` advanced to the wall clock on every call.

    Parameters
    ----------
    rig : SimulatedRig
        The plant; it is reset when the clock starts.
    clock : callable, default time.monotonic
        Seconds, monotonic.
    """

    synthetic = True
    where = "simulated"

    def __init__(
        self,
        rig: SimulatedRig,
        *,
        clock: Callable[[], float] = time.monotonic,
    ) -> None:
        self.rig = rig
        self._clock = clock
        self.lock = threading.RLock()
        self.start()

    def start(self, seed: int | None = None) -> None:
        """Reset the plant to rest and start its clock now."""
        with self.lock:
            self.rig.reset(seed)
            self._t0 = self._clock()

    def clock_s(self) -> float:
        """Seconds since :meth:`start`."""
        return self._clock() - self._t0

    def catch_up(self) -> None:
        """Integrate the plant up to the present."""
        with self.lock:
            rig = self.rig
            steps = int((self.clock_s() - rig.t_s) / rig.step_s)
            if steps > 0:  # a minute of gap is about 0.2 s of integration
                rig.advance(steps)

    def sleep_until(self, t_s: float) -> None:
        """Wait until ``t_s`` seconds after :meth:`start`."""
        sleep_until_monotonic(self._t0 + t_s)

    def read_pressure_mpa(self) -> float:
        """A sensor reading now, gauge MPa."""
        with self.lock:
            self.catch_up()
            return self.rig.read_pressure_mpa()

    def read_angle_deg(self) -> float:
        """The camera angle now, degrees."""
        with self.lock:
            self.catch_up()
            return self.rig.camera_angle_deg()

    def command(self, inlet: bool, outlet: bool) -> None:
        """Command the valves now (they switch after the rig's valve delay)."""
        with self.lock:
            self.catch_up()
            self.rig.command(inlet, outlet)

    def close(self) -> None:
        """Nothing to release."""
