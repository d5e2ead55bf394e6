"""A rig on Modbus (TCP, or RTU over RS485 as paper B): pressure sensor, valves, angle.

:class:`ModbusRig` answers the :class:`~softbend.control.rig.Rig` protocol over
a pymodbus client, with the register map and scaling of a
:class:`~softbend.control.rigconfig.RigConfig`. Each reading is one request
when the pressure, its sample counter and the angle sit within 16 registers of
one table (the angle of that request is kept for :meth:`ModbusRig.read_angle_deg`).
Everything that goes wrong on the wire becomes one
:class:`~softbend.errors.RigError` naming the rig and what failed:

- ``connection``: the rig cannot be reached or the link dropped;
- ``timeout``: no answer within ``timeout_s``;
- ``protocol``: the rig answered with a Modbus exception;
- ``garbage``: the pressure decodes outside ``[valid_min_mpa, valid_max_mpa]``;
- ``stale``: the sample counter has not moved for longer than ``stale_after_s``.
"""

from __future__ import annotations

import contextlib
import logging
import math
import time
from typing import Any

from softbend._extras import require
from softbend.control.realtime import sleep_until_monotonic
from softbend.control.rigconfig import RegisterConfig, RigConfig
from softbend.errors import RigError

__all__ = ["ModbusRig", "quiet_pymodbus"]

_SPAN = 16  # registers read in one request at most


def quiet_pymodbus() -> None:
    """Silence pymodbus's own log (unless configured): its failures come back as RigError."""
    logger = logging.getLogger("pymodbus")
    if logger.level == logging.NOTSET:
        logger.setLevel(logging.CRITICAL)


def _client(config: RigConfig) -> Any:
    require("pymodbus", "The Modbus rig (softbend control run --rig modbus)")
    from pymodbus.client import ModbusSerialClient, ModbusTcpClient

    quiet_pymodbus()

    c = config.connection
    if c.transport == "tcp":
        return ModbusTcpClient(
            c.host, port=c.port, timeout=c.timeout_s, retries=c.retries, reconnect_delay=0.0
        )
    return ModbusSerialClient(
        c.serial_port,
        baudrate=c.baudrate,
        parity=c.parity,
        stopbits=c.stopbits,
        bytesize=8,
        timeout=c.timeout_s,
        retries=c.retries,
        reconnect_delay=0.0,
    )


class ModbusRig:
    """The :class:`~softbend.control.rig.Rig` of a Modbus pressure/valve controller.

    Parameters
    ----------
    config : RigConfig
        Connection, register map, scaling and safety limits.
    client : object, optional
        A pymodbus client (default: built from ``config.connection``).

    Notes
    -----
    Use as a context manager, or call :meth:`connect` and :meth:`close`.
    ``requests`` counts the requests sent; ``round_trips_s`` keeps the
    duration of every reading request (for the loop's report).
    """

    synthetic = False

    def __init__(self, config: RigConfig, *, client: Any | None = None) -> None:
        self.config = config
        self._client = _client(config) if client is None else client
        self._where = config.connection.where
        self._device = config.connection.device_id
        self._t0 = time.monotonic()
        self._angle = math.nan
        self._counter: int | None = None
        self._counter_changed_s = 0.0
        self.requests = 0
        self.round_trips_s: list[float] = []
        self._plan = self._read_plan()

    @property
    def where(self) -> str:
        """The rig's address: ``tcp://host:port`` or ``rtu:///dev/ttyUSB0``."""
        return self._where

    # -- the register map -------------------------------------------------

    def _read_plan(self) -> list[tuple[str, int, int, list[tuple[str, int]]]]:
        """Requests of one reading: (table, start, count, [(what, address)])."""
        p = self.config.pressure
        wanted: list[tuple[str, str, int]] = [(p.table, "pressure", p.address)]
        if p.counter_address is not None:
            wanted.append((p.table, "counter", p.counter_address))
        a = self.config.angle
        if a is not None:
            wanted.append((a.table, "angle", a.address))
        plan: list[tuple[str, int, int, list[tuple[str, int]]]] = []
        for table in ("input", "holding"):
            items = sorted((addr, what) for t, what, addr in wanted if t == table)
            while items:
                start = items[0][0]
                group = [(w, ad) for ad, w in items if ad - start < _SPAN]
                items = [(ad, w) for ad, w in items if ad - start >= _SPAN]
                count = max(ad for _, ad in group) - start + 1
                plan.append((table, start, count, group))
        return plan

    # -- connection -------------------------------------------------------

    def connect(self, *, probe: bool = True) -> ModbusRig:
        """Open the link and, with ``probe``, check the register map and vent.

        The probe takes one reading (a rig that does not answer, or whose first
        reading is garbage, raises :class:`RigError` before any valve is
        touched), then commands the safe state (inlet closed, outlet open), so
        the rig starts from rest and the first requests of each kind are
        answered before the loop's clock starts.
        """
        try:
            ok = self._client.connect()
        except Exception as exc:  # pymodbus and serial raise many kinds
            raise RigError(f"Cannot connect to the rig at {self._where}: {exc}.") from None
        if not ok:
            raise RigError(
                f"Cannot connect to the rig at {self._where}: no answer "
                f"(is it on, and is the [connection] of the rig config right?)."
            )
        self._t0 = time.monotonic()
        self._counter = None
        if probe:
            self.read_pressure_mpa()
            self.command(False, True)
            self.round_trips_s.clear()
        return self

    def close(self) -> None:
        """Close the link."""
        with contextlib.suppress(Exception):  # closing a dead link
            self._client.close()

    def __enter__(self) -> ModbusRig:
        return self.connect()

    def __exit__(self, *exc: object) -> None:
        self.close()

    # -- the Rig protocol ---------------------------------------------------

    def clock_s(self) -> float:
        """Seconds since :meth:`connect`."""
        return time.monotonic() - self._t0

    def sleep_until(self, t_s: float) -> None:
        """Wait until ``t_s`` seconds after :meth:`connect`."""
        sleep_until_monotonic(self._t0 + t_s)

    def _call(self, what: str, method: str, *args: Any, **kwargs: Any) -> Any:
        from pymodbus.exceptions import ConnectionException, ModbusException, ModbusIOException

        self.requests += 1
        try:
            response = getattr(self._client, method)(*args, device_id=self._device, **kwargs)
        except ConnectionException as exc:
            raise RigError(
                f"Lost the rig at {self._where} while {what}: {_short(exc)}.", kind="connection"
            ) from None
        except ModbusIOException as exc:
            raise RigError(
                f"The rig at {self._where} did not answer within "
                f"{self.config.connection.timeout_s:g} s while {what}: {_short(exc)}.",
                kind="timeout",
            ) from None
        except (ModbusException, OSError) as exc:
            raise RigError(
                f"The rig at {self._where} failed while {what}: {_short(exc)}.", kind="connection"
            ) from None
        if response.isError():
            raise RigError(f"The rig at {self._where} refused {what}: {response}.", kind="protocol")
        return response

    def _read_block(self) -> dict[str, int]:
        values: dict[str, int] = {}
        for table, start, count, group in self._plan:
            method = "read_input_registers" if table == "input" else "read_holding_registers"
            began = time.monotonic()
            response = self._call(
                f"reading {table} registers {start}-{start + count - 1}",
                method,
                start,
                count=count,
            )
            self.round_trips_s.append(time.monotonic() - began)
            registers = list(response.registers)
            if len(registers) < count:
                raise RigError(
                    f"The rig at {self._where} sent {len(registers)} of {count} {table} "
                    f"registers from {start}.",
                    kind="protocol",
                )
            for what, address in group:
                values[what] = int(registers[address - start])
        return values

    def read_pressure_mpa(self) -> float:
        """One pressure reading, gauge MPa (the angle of the same request is kept).

        Raises
        ------
        RigError
            On a lost link, a timeout, a Modbus exception, a value outside the
            valid range (garbage) or a sample counter that stopped (stale).
        """
        values = self._read_block()
        p: RegisterConfig = self.config.pressure
        a = self.config.angle
        if a is not None:
            self._angle = a.decode(values["angle"])
        pressure = p.decode(values["pressure"])
        limits = self.config.safety
        if not limits.valid_min_mpa <= pressure <= limits.valid_max_mpa:
            raise RigError(
                f"The pressure reading of the rig at {self._where} is garbage: register "
                f"{p.address} = {values['pressure']} decodes to {pressure:.4g} MPa, outside "
                f"the valid range [{limits.valid_min_mpa:g}, {limits.valid_max_mpa:g}] MPa.",
                kind="garbage",
            )
        if p.counter_address is not None:
            now = self.clock_s()
            counter = values["counter"]
            if counter != self._counter:
                self._counter = counter
                self._counter_changed_s = now
            elif now - self._counter_changed_s > limits.stale_after_s:
                raise RigError(
                    f"The pressure of the rig at {self._where} is stale: its sample counter "
                    f"(register {p.counter_address}) has not changed for "
                    f"{now - self._counter_changed_s:.3f} s (stale_after_s "
                    f"{limits.stale_after_s:g}).",
                    kind="stale",
                )
        return pressure

    def read_angle_deg(self) -> float:
        """The angle read with the last pressure reading, degrees (NaN without [angle])."""
        return self._angle

    def command(self, inlet: bool, outlet: bool) -> None:
        """Set both valves (one request when their coils are adjacent)."""
        v = self.config.valves
        what = f"setting the valves (inlet {int(inlet)}, outlet {int(outlet)})"
        if v.outlet_coil == v.inlet_coil + 1:
            self._call(what, "write_coils", v.inlet_coil, [bool(inlet), bool(outlet)])
        elif v.inlet_coil == v.outlet_coil + 1:
            self._call(what, "write_coils", v.outlet_coil, [bool(outlet), bool(inlet)])
        else:
            self._call(what, "write_coil", v.inlet_coil, bool(inlet))
            self._call(what, "write_coil", v.outlet_coil, bool(outlet))


def _short(exc: BaseException) -> str:
    text = " ".join(str(exc).split())
    return text if len(text) <= 160 else text[:157] + "..."
