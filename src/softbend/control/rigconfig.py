"""A rig's register map, scaling, safety limits and loop period, read from a TOML file.

One file describes one Modbus rig: how to reach it (TCP, or RTU over RS485 as
paper B), where the pressure sensor, the optional angle sensor and the two
valve coils live, how raw counts become MPa and degrees, and the limits that
stop the loop. Every value has a unit in its name or its comment::

    [connection]
    transport = "tcp"         # "tcp" or "rtu"
    host = "127.0.0.1"        # tcp
    port = 502                # tcp
    serial_port = "/dev/ttyUSB0"  # rtu
    baudrate = 115200         # rtu, bit/s
    parity = "N"              # rtu: "N", "E" or "O"
    stopbits = 1              # rtu
    device_id = 1             # Modbus unit id
    timeout_s = 0.05          # per request, s
    retries = 0               # extra tries per request

    [pressure]                # gauge pressure = offset + scale * count
    table = "input"           # "input" (FC 4) or "holding" (FC 3)
    address = 0
    signed = false            # 16-bit two's complement when true
    scale = 0.0001            # MPa per count
    offset = 0.0              # MPa at count 0
    counter_address = 2       # optional: a register the device increments per new sample

    [angle]                   # optional: a camera or encoder, for evaluation only
    table = "input"
    address = 1
    signed = true
    scale = 0.01              # degrees per count
    offset = 0.0              # degrees at count 0

    [valves]
    inlet_coil = 0
    outlet_coil = 1

    [safety]
    max_pressure_mpa = 0.25   # above it: vent and stop
    valid_min_mpa = -0.02     # a reading outside [valid_min, valid_max] is garbage
    valid_max_mpa = 0.6
    stale_after_s = 0.05      # no fresh sample for this long: vent and stop
    max_missed_reads = 3      # consecutive failed reads before the loop stops

    [loop]
    period_s = 0.001          # tick of the controller and the valves, s
    sensor_period_s = 0.01    # pressure readings, s (paper B: 100 Hz)

:func:`load_rig_config` reads and checks a file (unknown sections or keys, a
wrong type, a value out of range: one error naming the field and the allowed
values); :meth:`RigConfig.to_toml` writes one back.
"""

from __future__ import annotations

import math
import tomllib
from dataclasses import dataclass, field, fields
from pathlib import Path
from typing import Any

from softbend._validation import check_choice, check_int, check_range
from softbend.errors import DatasetError

__all__ = [
    "ConnectionConfig",
    "RegisterConfig",
    "RigConfig",
    "SafetyLimits",
    "ValveConfig",
    "load_rig_config",
]

_OWNER = "rig config"


@dataclass(frozen=True)
class ConnectionConfig:
    """How to reach the rig: Modbus TCP or RTU (RS485)."""

    transport: str = "tcp"
    host: str = "127.0.0.1"
    port: int = 502
    serial_port: str = ""
    baudrate: int = 115_200
    parity: str = "N"
    stopbits: int = 1
    device_id: int = 1
    timeout_s: float = 0.05
    retries: int = 0

    def __post_init__(self) -> None:
        owner = f"[connection] of the {_OWNER}"
        check_choice(self.transport, "transport", owner, ("tcp", "rtu"))
        check_choice(self.parity, "parity", owner, ("N", "E", "O"))
        check_choice(self.stopbits, "stopbits", owner, (1, 2))
        check_int(self.port, "port", owner, low=0)
        if self.port > 65535:
            raise ValueError(
                f"The 'port' of {owner} must be an integer in [0, 65535]. "
                f"Got {self.port!r} instead."
            )
        check_int(self.baudrate, "baudrate", owner, low=1)
        check_int(self.retries, "retries", owner, low=0)
        device = check_int(self.device_id, "device_id", owner, low=0)
        if device > 247:
            raise ValueError(
                f"The 'device_id' of {owner} must be an integer in [0, 247]. "
                f"Got {self.device_id!r} instead."
            )
        check_range(self.timeout_s, "timeout_s", owner, low=0.0, high=10.0, high_inclusive=True)
        if self.transport == "rtu" and not self.serial_port:
            raise ValueError(
                f"The 'serial_port' of {owner} must name a serial device (e.g. "
                "'/dev/ttyUSB0') when transport is 'rtu'. Got nothing instead."
            )

    @property
    def where(self) -> str:
        """The rig's address for messages: ``tcp://host:port`` or ``rtu:///dev/ttyUSB0``."""
        if self.transport == "tcp":
            return f"tcp://{self.host}:{self.port}"
        return f"rtu://{self.serial_port}"


@dataclass(frozen=True)
class RegisterConfig:
    """One 16-bit register and its scaling: value = ``offset + scale·count``."""

    table: str = "input"
    address: int = 0
    signed: bool = False
    scale: float = 1.0
    offset: float = 0.0
    counter_address: int | None = None
    section: str = field(default="pressure", compare=False)

    def __post_init__(self) -> None:
        owner = f"[{self.section}] of the {_OWNER}"
        check_choice(self.table, "table", owner, ("input", "holding"))
        _check_address(self.address, "address", owner)
        if self.counter_address is not None:
            _check_address(self.counter_address, "counter_address", owner)
            if self.counter_address == self.address:
                raise ValueError(
                    f"The 'counter_address' of {owner} must differ from its 'address' "
                    f"({self.address}). Got {self.counter_address} instead."
                )
        if not isinstance(self.signed, bool):
            raise ValueError(
                f"The 'signed' of {owner} must be true or false. Got {self.signed!r} instead."
            )
        if isinstance(self.scale, bool) or not isinstance(self.scale, int | float):
            raise ValueError(f"The 'scale' of {owner} must be a number. Got {self.scale!r}.")
        if not math.isfinite(self.scale) or self.scale == 0.0:
            raise ValueError(
                f"The 'scale' of {owner} must be a finite non-zero number. Got {self.scale!r}."
            )
        check_range(self.offset, "offset", owner, low=-1e9, high=1e9)

    def decode(self, count: int) -> float:
        """Engineering value of a raw 16-bit register ``count``."""
        raw = count - 0x10000 if self.signed and count >= 0x8000 else count
        return self.offset + self.scale * raw

    def encode(self, value: float) -> int:
        """Raw 16-bit register for ``value`` (rounded, saturated to the register's range)."""
        raw = round((value - self.offset) / self.scale)
        if self.signed:
            raw = min(max(raw, -0x8000), 0x7FFF)
            return raw & 0xFFFF
        return min(max(raw, 0), 0xFFFF)


@dataclass(frozen=True)
class ValveConfig:
    """The coils of the inlet and outlet on/off valves (``True`` = open)."""

    inlet_coil: int = 0
    outlet_coil: int = 1

    def __post_init__(self) -> None:
        owner = f"[valves] of the {_OWNER}"
        _check_address(self.inlet_coil, "inlet_coil", owner)
        _check_address(self.outlet_coil, "outlet_coil", owner)
        if self.inlet_coil == self.outlet_coil:
            raise ValueError(
                f"The 'outlet_coil' of {owner} must differ from its 'inlet_coil' "
                f"({self.inlet_coil}). Got {self.outlet_coil} instead."
            )


@dataclass(frozen=True)
class SafetyLimits:
    """When the loop vents the actuator and stops (see :mod:`softbend.control.loop`).

    Attributes
    ----------
    max_pressure_mpa : float
        A reading above this (gauge MPa) vents and stops the loop.
    valid_min_mpa, valid_max_mpa : float
        A reading outside this range (gauge MPa) is garbage: a failed read.
    stale_after_s : float
        No fresh sample for this long (s) vents and stops the loop.
    max_missed_reads : int
        Consecutive failed reads (error, timeout, garbage) that stop the loop.
    """

    max_pressure_mpa: float = 0.25
    valid_min_mpa: float = -0.02
    valid_max_mpa: float = 0.6
    stale_after_s: float = 0.05
    max_missed_reads: int = 3

    def __post_init__(self) -> None:
        owner = f"[safety] of the {_OWNER}"
        check_range(self.max_pressure_mpa, "max_pressure_mpa", owner, low=0.0, high=10.0)
        check_range(self.valid_min_mpa, "valid_min_mpa", owner, low=-10.0, high=10.0)
        check_range(self.valid_max_mpa, "valid_max_mpa", owner, low=-10.0, high=10.0)
        if not self.valid_min_mpa < self.max_pressure_mpa < self.valid_max_mpa:
            raise ValueError(
                f"The limits of {owner} must satisfy valid_min_mpa < max_pressure_mpa < "
                f"valid_max_mpa. Got {self.valid_min_mpa:g}, {self.max_pressure_mpa:g}, "
                f"{self.valid_max_mpa:g} instead."
            )
        check_range(self.stale_after_s, "stale_after_s", owner, low=0.0, high=60.0)
        check_int(self.max_missed_reads, "max_missed_reads", owner, low=1)


@dataclass(frozen=True)
class RigConfig:
    """A whole rig: connection, registers, valves, safety, loop tick and sensor period (s)."""

    connection: ConnectionConfig = field(default_factory=ConnectionConfig)
    pressure: RegisterConfig = field(
        default_factory=lambda: RegisterConfig(scale=1e-4, counter_address=2)
    )
    angle: RegisterConfig | None = field(
        default_factory=lambda: RegisterConfig(address=1, signed=True, scale=0.01, section="angle")
    )
    valves: ValveConfig = field(default_factory=ValveConfig)
    safety: SafetyLimits = field(default_factory=SafetyLimits)
    period_s: float = 0.001
    sensor_period_s: float = 0.01

    def __post_init__(self) -> None:
        loop = f"[loop] of the {_OWNER}"
        check_range(self.period_s, "period_s", loop, low=0.0, high=1.0, high_inclusive=True)
        check_range(
            self.sensor_period_s, "sensor_period_s", loop, low=self.period_s, high=10.0,
            low_inclusive=True, high_inclusive=True,
        )  # fmt: skip
        used = {(self.pressure.table, self.pressure.address): "[pressure] address"}
        others = []
        if self.pressure.counter_address is not None:
            others.append(
                ((self.pressure.table, self.pressure.counter_address), "[pressure] counter_address")
            )
        if self.angle is not None:
            others.append(((self.angle.table, self.angle.address), "[angle] address"))
        for key, name in others:
            if key in used:
                raise ValueError(
                    f"The {name} of the {_OWNER} must not share {key[0]} register {key[1]} "
                    f"with the {used[key]}."
                )
            used[key] = name

    @classmethod
    def from_dict(cls, data: dict[str, Any]) -> RigConfig:
        """Build from parsed TOML; unknown sections or keys are errors that name them."""
        sections = {"connection", "pressure", "angle", "valves", "safety", "loop"}
        _check_keys(data, sections, "the rig config", "section")
        if "pressure" not in data:
            raise ValueError(
                "The rig config must have a [pressure] section (table, address, scale, ...)."
            )

        def build(kind: type, name: str, extra: dict[str, Any] | None = None) -> Any:
            table = data.get(name, {})
            if not isinstance(table, dict):
                raise ValueError(f"The [{name}] of the {_OWNER} must be a table.")
            allowed = {f.name for f in fields(kind)} - {"section"}
            _check_keys(table, allowed, f"[{name}] of the {_OWNER}", "key")
            return kind(**table, **(extra or {}))

        loop = data.get("loop", {})
        _check_keys(loop, {"period_s", "sensor_period_s"}, f"[loop] of the {_OWNER}", "key")
        return cls(
            connection=build(ConnectionConfig, "connection"),
            pressure=build(RegisterConfig, "pressure", {"section": "pressure"}),
            angle=build(RegisterConfig, "angle", {"section": "angle"}) if "angle" in data else None,
            valves=build(ValveConfig, "valves"),
            safety=build(SafetyLimits, "safety"),
            period_s=loop.get("period_s", 0.001),
            sensor_period_s=loop.get("sensor_period_s", 0.01),
        )

    def to_toml(self) -> str:
        """The config as TOML text that :func:`load_rig_config` reads back to an equal config."""
        lines: list[str] = []

        def section(name: str, obj: Any) -> None:
            lines.append(f"[{name}]")
            for f in fields(obj):
                value = getattr(obj, f.name)
                if f.name == "section" or value is None:
                    continue
                lines.append(f"{f.name} = {_toml_value(value)}")
            lines.append("")

        section("connection", self.connection)
        section("pressure", self.pressure)
        if self.angle is not None:
            section("angle", self.angle)
        section("valves", self.valves)
        section("safety", self.safety)
        lines += [
            "[loop]",
            f"period_s = {_toml_value(self.period_s)}",
            f"sensor_period_s = {_toml_value(self.sensor_period_s)}",
            "",
        ]
        return "\n".join(lines)


def load_rig_config(path: str | Path) -> RigConfig:
    """Read and check a rig's TOML file (see the module doc for its keys).

    Raises
    ------
    FileNotFoundError
        No such file.
    DatasetError
        The file is not valid TOML.
    ValueError
        A section, key or value is not allowed (the message names it).
    """
    p = Path(path)
    if not p.is_file():
        raise FileNotFoundError(f"The rig config {str(p)!r} does not exist or is not a file.")
    try:
        data = tomllib.loads(p.read_text(encoding="utf-8"))
    except (tomllib.TOMLDecodeError, UnicodeDecodeError) as exc:
        raise DatasetError(f"The rig config {str(p)!r} is not valid TOML: {exc}.") from None
    return RigConfig.from_dict(data)


def _check_address(value: Any, name: str, owner: str) -> int:
    address = check_int(value, name, owner, low=0)
    if address > 0xFFFF:
        raise ValueError(
            f"The '{name}' of {owner} must be an integer in [0, 65535]. Got {value!r} instead."
        )
    return address


def _check_keys(data: Any, allowed: set[str], owner: str, what: str) -> None:
    if not isinstance(data, dict):
        raise ValueError(f"The {owner} must be a table of keys. Got {data!r} instead.")
    unknown = sorted(set(data) - allowed)
    if unknown:
        raise ValueError(
            f"The {what} {unknown[0]!r} of {owner} is not known; allowed: "
            f"{', '.join(sorted(allowed))}."
        )


def _toml_value(value: Any) -> str:
    if isinstance(value, bool):
        return "true" if value else "false"
    if isinstance(value, str):
        return '"' + value.replace("\\", "\\\\").replace('"', '\\"') + '"'
    return repr(value)
