"""A Modbus TCP server that is a simulated rig: rehearse and test the loop without hardware.

:class:`SimulatedModbusServer` serves the register map of a
:class:`~softbend.control.rigconfig.RigConfig` from a
:class:`~softbend.control.realtime.WallClockRig` (the simulated rig kept in step
with the wall clock), in a background thread:

- the pressure register holds the sensor sample of the current sample period
  (``sample_period_s``, 100 Hz as paper B) and its counter register counts
  samples, so a reader can tell a fresh sample from a frozen one;
- the angle register holds the camera's latest frame;
- writing the valve coils commands the valves;
- a watchdog vents the actuator (inlet closed, outlet open) when no request
  has come for ``watchdog_s``, as a PLC would when its master goes quiet.

Faults for tests (:meth:`SimulatedModbusServer.inject`): ``"garbage"`` (the
pressure register reads 0xFFFF), ``"timeout"`` (reads of the pressure are
answered after ``timeout_delay_s``), ``"frozen"`` (the sample and its counter
stop changing); :meth:`SimulatedModbusServer.disconnect` takes the link away
(the device and its watchdog keep running, as a PLC whose cable was pulled).
"""

from __future__ import annotations

import asyncio
import contextlib
import socket
import threading
import time
from collections.abc import Sequence
from dataclasses import replace
from typing import Any

from softbend._extras import require
from softbend.control.modbus import quiet_pymodbus
from softbend.control.realtime import WallClockRig
from softbend.control.rig import SimulatedRig
from softbend.control.rigconfig import ConnectionConfig, RigConfig
from softbend.errors import RigError

__all__ = ["FAULTS", "SimulatedModbusServer", "free_tcp_port"]

#: The faults :meth:`SimulatedModbusServer.inject` knows.
FAULTS: tuple[str, ...] = ("garbage", "timeout", "frozen")

_REGISTERS = 64  # per table: addresses 0..63
_FC_READ_REGISTERS = (3, 4)
_FC_COILS_WRITE = (5, 15)


def free_tcp_port(host: str = "127.0.0.1") -> int:
    """A TCP port that was free on ``host`` a moment ago."""
    with socket.socket(socket.AF_INET, socket.SOCK_STREAM) as s:
        s.bind((host, 0))
        return int(s.getsockname()[1])


class SimulatedModbusServer:
    """A simulated rig behind a Modbus TCP server on ``host:port``.

    Parameters
    ----------
    rig : SimulatedRig
        The plant (reset when the server starts).
    config : RigConfig, optional
        Register map and scaling (default :class:`RigConfig`); its
        ``[connection]`` is replaced by this server's address (:attr:`config`).
    host : str, default "127.0.0.1"
    port : int, default 0
        0 picks a free port.
    sample_period_s : float, default 0.01
        Period of the pressure sensor's samples (paper B: 100 Hz).
    watchdog_s : float, default 0.25
        Vent when no request has come for this long; 0 disables the watchdog.
    timeout_delay_s : float, default 0.5
        How late the ``"timeout"`` fault answers.
    """

    def __init__(
        self,
        rig: SimulatedRig,
        config: RigConfig | None = None,
        *,
        host: str = "127.0.0.1",
        port: int = 0,
        sample_period_s: float = 0.01,
        watchdog_s: float = 0.25,
        timeout_delay_s: float = 0.5,
    ) -> None:
        require("pymodbus", "The simulated Modbus rig (softbend control serve)")
        quiet_pymodbus()
        base = RigConfig() if config is None else config
        self.port = port or free_tcp_port(host)
        self.config = replace(
            base,
            connection=replace(
                base.connection if base.connection.transport == "tcp" else ConnectionConfig(),
                transport="tcp",
                host=host,
                port=self.port,
            ),
        )
        self.plant = WallClockRig(rig)
        self.sample_period_s = sample_period_s
        self.watchdog_s = watchdog_s
        self.timeout_delay_s = timeout_delay_s
        self.fault: str | None = None
        self.watchdog_vents = 0
        self.requests = 0
        self._last_request = time.monotonic()
        self._sample_index = -1
        self._sample_mpa = 0.0
        self._thread: threading.Thread | None = None
        self._loop: asyncio.AbstractEventLoop | None = None
        self._server: Any = None
        self._ready = threading.Event()
        self._closed = threading.Event()
        self._error: BaseException | None = None

    # -- life cycle ---------------------------------------------------------

    def start(self) -> SimulatedModbusServer:
        """Start serving in a background thread (returns once it listens)."""
        self._thread = threading.Thread(target=self._serve, name="softbend-modbus", daemon=True)
        self._thread.start()
        if not self._ready.wait(10.0) or self._error is not None:
            raise RigError(
                f"The simulated Modbus rig cannot listen on {self.config.connection.where} "
                "(the port is in use, or the host is not an address of this machine); "
                "choose another --port or --host."
            )
        return self

    def disconnect(self) -> None:
        """Stop listening and drop every connection; the plant and its watchdog run on."""
        loop, server = self._loop, self._server
        if loop is not None and server is not None and loop.is_running():
            future = asyncio.run_coroutine_threadsafe(server.shutdown(), loop)
            with contextlib.suppress(Exception):
                future.result(5.0)

    def stop(self) -> None:
        """Vent the rig, stop serving and end the server's thread."""
        self.plant.command(False, True)
        self.disconnect()
        self._closed.set()
        if self._thread is not None:
            self._thread.join(5.0)

    def __enter__(self) -> SimulatedModbusServer:
        return self.start()

    def __exit__(self, *exc: object) -> None:
        self.stop()

    def inject(self, fault: str | None) -> None:
        """Start a fault (one of :data:`FAULTS`), or end it with ``None``."""
        if fault is not None and fault not in FAULTS:
            raise ValueError(
                f"The 'fault' of SimulatedModbusServer.inject must be one of "
                f"{', '.join(map(repr, FAULTS))} or None. Got {fault!r} instead."
            )
        self.fault = fault

    @property
    def valves(self) -> tuple[bool, bool]:
        """The actual (inlet, outlet) states of the simulated valves now."""
        with self.plant.lock:
            self.plant.catch_up()
            return self.plant.rig.inlet_open, self.plant.rig.outlet_open

    # -- the server ---------------------------------------------------------

    def _device(self) -> Any:
        from pymodbus.simulator import DataType, SimData, SimDevice

        def bits() -> list[Any]:
            return [SimData(0, count=_REGISTERS, values=False, datatype=DataType.BITS)]

        def registers() -> list[Any]:
            return [SimData(0, count=_REGISTERS, values=0, datatype=DataType.REGISTERS)]

        return SimDevice(
            self.config.connection.device_id,
            simdata=(bits(), bits(), registers(), registers()),
            action=self._action,
        )

    def _serve(self) -> None:
        from pymodbus.server import ModbusTcpServer

        async def main() -> None:
            self._loop = asyncio.get_running_loop()
            try:
                self._server = ModbusTcpServer(
                    self._device(), address=(self.config.connection.host, self.port)
                )
                await self._server.serve_forever(background=True)
            except BaseException as exc:  # report to start()
                self._error = exc
                self._ready.set()
                return
            self.plant.start()
            self._last_request = time.monotonic()
            self._ready.set()
            watchdog = asyncio.create_task(self._watchdog())
            with contextlib.suppress(asyncio.CancelledError):
                await self._server.serving
            while not self._closed.is_set():  # disconnected: the device lives on
                await asyncio.sleep(0.01)
            watchdog.cancel()

        asyncio.run(main())

    async def _watchdog(self) -> None:
        while True:
            await asyncio.sleep(0.01)
            if self.watchdog_s <= 0:
                continue
            if time.monotonic() - self._last_request > self.watchdog_s:
                with self.plant.lock:
                    self.plant.catch_up()
                    rig = self.plant.rig
                    if rig.inlet_open or not rig.outlet_open:
                        rig.command(False, True)
                        self.watchdog_vents += 1

    def _sample(self) -> tuple[float, int]:
        """The sensor sample of the current period and its index."""
        index = int(self.plant.clock_s() / self.sample_period_s)
        if index != self._sample_index and self.fault != "frozen":
            self._sample_index = index
            self._sample_mpa = self.plant.read_pressure_mpa()
        return self._sample_mpa, self._sample_index

    async def _action(
        self,
        function_code: int,
        start_address: int,
        address: int,
        count: int,
        registers: list[int],
        values: list[int] | list[bool] | None,
    ) -> None:
        self.requests += 1
        self._last_request = time.monotonic()
        config = self.config
        if function_code in _FC_COILS_WRITE and values is not None:
            self._write_coils(address, list(values))
            return None
        if function_code not in _FC_READ_REGISTERS:
            return None
        table = "input" if function_code == 4 else "holding"
        wanted = range(address, address + count)
        p = config.pressure
        if p.table == table and p.address in wanted:
            if self.fault == "timeout":
                await asyncio.sleep(self.timeout_delay_s)
            with self.plant.lock:
                self.plant.catch_up()
                pressure, index = self._sample()
                angle = self.plant.rig.camera_angle_deg()
            raw = 0xFFFF if self.fault == "garbage" else p.encode(pressure)
            registers[p.address - start_address] = raw
            if p.counter_address is not None:
                registers[p.counter_address - start_address] = index & 0xFFFF
        else:
            angle = self.plant.read_angle_deg()
        a = config.angle
        if a is not None and a.table == table and a.address in wanted and angle == angle:
            registers[a.address - start_address] = a.encode(angle)
        return None

    def _write_coils(self, address: int, values: Sequence[int]) -> None:
        v = self.config.valves
        with self.plant.lock:
            self.plant.catch_up()
            rig = self.plant.rig
            inlet, outlet = rig.commanded
            for offset, value in enumerate(values):
                if address + offset == v.inlet_coil:
                    inlet = bool(value)
                elif address + offset == v.outlet_coil:
                    outlet = bool(value)
            rig.command(inlet, outlet)
