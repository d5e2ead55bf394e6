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

    [controller]              # optional: the controller of `control run`
    name = "bang-bang"        # a name of softbend.control.CONTROLLERS
    deadzone = 0.05           # its parameters (see its factory), as --set NAME=VALUE

    [simulation]              # optional: the simulated rig of `control run` and `serve`
    valve_delay_s = 0.005     # names of softbend.control.rigs.RIG_SETTINGS, as --rig-param
    tubing_mm3 = 2000.0       # NAME=VALUE (which overrides); a hardware rig ignores it

:func:`load_rig_config` reads and checks a file before anything uses it: a
TOML syntax error, an unknown section or key, a missing required key (the
``address`` and ``scale`` of [pressure] and of [angle]: no default fits every
sensor), a value of the wrong TOML type, out of range, not finite, or a [safety]
pressure that is not a plausible gauge pressure (:mod:`softbend.plausibility`)
is one :class:`~softbend.errors.DatasetError` naming the file, the line and the
key, and the allowed values; so is an unknown controller name or parameter of
[controller], or a parameter value of the wrong kind (the message lists the
known names); and so is an unknown name of [simulation], a value of the wrong
kind or out of the range of :class:`~softbend.control.rig.RigParams`.
:meth:`RigConfig.to_toml` writes one back.
"""

from __future__ import annotations

import datetime
import inspect
import math
import re
from collections.abc import Iterator, Mapping
from contextlib import contextmanager
from dataclasses import dataclass, field, fields
from pathlib import Path
from typing import Any

from softbend._io import read_input_text
from softbend._tomltext import parse_toml
from softbend._validation import check_choice, check_int, check_range, must_be, short_repr
from softbend.errors import DatasetError, InputError, SoftbendError, keyed
from softbend.plausibility import RANGES, implausible_index

__all__ = [
    "DEFAULT_TUBING_MM3",
    "ConnectionConfig",
    "ControllerConfig",
    "RegisterConfig",
    "RigConfig",
    "SafetyLimits",
    "ValveConfig",
    "check_simulation_settings",
    "load_rig_config",
    "rig_config_template",
    "simulation_settings_entry",
]

#: The tubing volume between the inlet valve and the actuator, mm³ (:meth:`RigParams.for_design`).
DEFAULT_TUBING_MM3 = 2000.0


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
        check_choice(self.transport, "transport", ("tcp", "rtu"))
        check_choice(self.parity, "parity", ("N", "E", "O"))
        check_choice(self.stopbits, "stopbits", (1, 2))
        _check_integer(self.port, "port", 0xFFFF)
        check_int(self.baudrate, "baudrate", low=1)
        check_int(self.retries, "retries", low=0)
        _check_integer(self.device_id, "device_id", 247)
        check_range(self.timeout_s, "timeout_s", low=0.0, high=10.0, high_inclusive=True)
        if self.transport == "tcp" and not (isinstance(self.host, str) and self.host.strip()):
            raise InputError(
                must_be(
                    "the rig's address (e.g. '192.168.0.10') when transport is 'tcp'", self.host
                ),
                key="host",
            )
        if self.transport == "rtu" and not self.serial_port:
            raise InputError(
                must_be(
                    "a serial device (e.g. '/dev/ttyUSB0') when transport is 'rtu'",
                    self.serial_port,
                ),
                key="serial_port",
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
        check_choice(self.table, "table", ("input", "holding"))
        _check_integer(self.address, "address", 0xFFFF)
        if self.counter_address is not None:
            _check_integer(self.counter_address, "counter_address", 0xFFFF)
            if self.counter_address == self.address:
                raise InputError(
                    must_be(
                        f"another register than the address ({self.address})", self.counter_address
                    ),
                    key="counter_address",
                )
        if not isinstance(self.signed, bool):
            raise InputError(must_be("true or false", self.signed), key="signed")
        scale = self.scale
        if (
            isinstance(scale, bool)
            or not isinstance(scale, int | float)
            or not math.isfinite(scale)
            or scale == 0.0
        ):
            raise InputError(must_be("a finite non-zero number", scale), key="scale")
        check_range(self.offset, "offset", low=-1e9, high=1e9)

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
        _check_integer(self.inlet_coil, "inlet_coil", 0xFFFF)
        _check_integer(self.outlet_coil, "outlet_coil", 0xFFFF)
        if self.inlet_coil == self.outlet_coil:
            raise InputError(
                must_be(f"another coil than the inlet_coil ({self.inlet_coil})", self.outlet_coil),
                key="outlet_coil",
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
        check_range(self.max_pressure_mpa, "max_pressure_mpa", low=0.0, high=10.0)
        check_range(self.valid_min_mpa, "valid_min_mpa", low=-10.0, high=10.0)
        check_range(self.valid_max_mpa, "valid_max_mpa", low=-10.0, high=10.0)
        if not self.valid_min_mpa < self.max_pressure_mpa < self.valid_max_mpa:
            raise InputError(
                f"must lie between valid_min_mpa and valid_max_mpa (valid_min_mpa < "
                f"max_pressure_mpa < valid_max_mpa); got {self.valid_min_mpa:g}, "
                f"{self.max_pressure_mpa:g}, {self.valid_max_mpa:g}",
                key="max_pressure_mpa",
            )
        check_range(self.stale_after_s, "stale_after_s", low=0.0, high=60.0)
        check_int(self.max_missed_reads, "max_missed_reads", low=1)


@dataclass(frozen=True)
class ControllerConfig:
    """The [controller] table: a controller's name and the parameters given for it.

    Attributes
    ----------
    name : str
        A name of :data:`softbend.control.factory.CONTROLLERS`.
    params : tuple of (str, value)
        The parameters given, checked against the controller's factory (a mapping
        is accepted and stored as pairs); the others keep their defaults.
    """

    name: str
    params: tuple[tuple[str, Any], ...] = ()

    def __post_init__(self) -> None:
        from softbend.control.factory import CONTROLLERS, controller_parameters

        with keyed("name"):
            CONTROLLERS.check(self.name)
        given = dict(self.params)
        checked = controller_parameters(self.name, given)
        object.__setattr__(self, "params", tuple((k, checked[k]) for k in given))

    def as_dict(self) -> dict[str, Any]:
        """The parameters given, ``{name: value}``."""
        return dict(self.params)


@dataclass(frozen=True)
class RigConfig:
    """A whole rig: connection, registers, valves, safety, loop tick and sensor period (s).

    ``simulation`` holds the [simulation] table: ``(name, value)`` pairs of the
    simulated rig's settings (:func:`softbend.control.rigs.rig_settings`), checked.
    """

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
    controller: ControllerConfig | None = None
    simulation: tuple[tuple[str, Any], ...] = ()

    def __post_init__(self) -> None:
        given = dict(self.simulation)
        checked = check_simulation_settings(given)
        object.__setattr__(self, "simulation", tuple((k, checked[k]) for k in given))
        check_range(self.period_s, "period_s", low=0.0, high=1.0, high_inclusive=True)
        check_range(
            self.sensor_period_s, "sensor_period_s", low=self.period_s, high=10.0,
            low_inclusive=True, high_inclusive=True,
        )  # fmt: skip
        used = {(self.pressure.table, self.pressure.address): "pressure.address"}
        others = []
        if self.pressure.counter_address is not None:
            others.append(
                ((self.pressure.table, self.pressure.counter_address), "pressure.counter_address")
            )
        if self.angle is not None:
            others.append(((self.angle.table, self.angle.address), "angle.address"))
        for register, name in others:
            if register in used:
                raise InputError(
                    f"must not share {register[0]} register {register[1]} with {used[register]}",
                    key=name,
                )
            used[register] = name

    @classmethod
    def from_dict(
        cls, data: dict[str, Any], *, source: str = "the rig config", text: str | None = None
    ) -> RigConfig:
        """Build from parsed TOML, every section and key checked.

        Parameters
        ----------
        data : dict
            The parsed file.
        source : str, default ``"the rig config"``
            The file, for messages.
        text : str, optional
            The file's text, to give the line of a bad key in messages.

        Raises
        ------
        DatasetError
            One line naming ``source`` (and the line, when ``text`` is given) and
            the key at fault as its TOML path (``connection.port``; its ``key``):
            an unknown section or key, a section that is not a table, a missing
            required key (``address`` and ``scale`` of [pressure] and of [angle]),
            a value of the wrong type (a string for a number, a float for an
            integer, a boolean for a number, ...), or a value out of range, not
            finite or not a plausible gauge pressure (the [safety] pressures,
            :mod:`softbend.plausibility`).
        """
        try:
            return cls._from_checked(data)
        except SoftbendError as exc:
            section, _, key = (exc.key or "").strip("[]").partition(".")
            line = _line_of(text, section, key) if text is not None and section else None
            message = " ".join(exc.detail.split())
            raise DatasetError(message, key=exc.key, file=source, line=line) from None

    @classmethod
    def _from_checked(cls, data: object) -> RigConfig:
        sections = set(_SECTIONS) | {"loop", "controller", "simulation"}
        if not isinstance(data, dict):
            raise InputError(must_be("a table of keys", data))
        unknown = sorted(set(data) - sections)
        if unknown:
            raise InputError(
                f"is not a section of a rig config; allowed: {', '.join(sorted(sections))}",
                key=f"[{unknown[0]}]",
            )
        if "pressure" not in data:
            raise InputError("must have a [pressure] section (table, address, scale, ...)")
        for name in (*_SECTIONS, "loop"):
            if name in data:
                with _in_section(name):
                    _check_table(name, data[name])

        def build(name: str, extra: dict[str, Any] | None = None) -> Any:
            with _in_section(name):
                return _SECTIONS[name](**data.get(name, {}), **(extra or {}))

        loop = data.get("loop", {})
        parts = {
            "connection": build("connection"),
            "pressure": build("pressure", {"section": "pressure"}),
            "angle": build("angle", {"section": "angle"}) if "angle" in data else None,
            "valves": build("valves"),
            "safety": build("safety"),
        }
        with _in_section("controller"):
            controller = _controller(data["controller"]) if "controller" in data else None
        with _in_section("simulation"):
            simulation = _simulation(data["simulation"]) if "simulation" in data else ()
        with _in_section("loop"):
            config = cls(
                **parts,
                period_s=loop.get("period_s", 0.001),
                sensor_period_s=loop.get("sensor_period_s", 0.01),
                controller=controller,
                simulation=simulation,
            )
        for name, keys in _REQUIRED.items():
            missing = [key for key in keys if name in data and key not in data[name]]
            if missing:
                given = ", ".join(map(repr, data[name]))
                raise InputError(
                    f"must give {', '.join(map(repr, missing))} (no default fits every "
                    f"sensor); got {f'only {given}' if given else 'none'}",
                    key=f"[{name}]",
                )
        for key in _PRESSURE_KEYS:
            value = data.get("safety", {}).get(key)
            if value is not None and implausible_index([value], "pressure_mpa") is not None:
                bounds = RANGES["pressure_mpa"]
                requirement = (
                    f"a plausible {bounds.label} ({bounds.low:g} to {bounds.high:g} {bounds.unit})"
                )
                raise InputError(must_be(requirement, value), key=f"safety.{key}")
        return config

    def to_toml(self) -> str:
        """The config as TOML text that :func:`load_rig_config` reads back to an equal config."""
        lines: list[str] = []

        def section(
            name: str, obj: ConnectionConfig | RegisterConfig | ValveConfig | SafetyLimits
        ) -> None:
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
        if self.controller is not None:
            lines.append("[controller]")
            lines.append(f"name = {_toml_value(self.controller.name)}")
            lines += [f"{k} = {_toml_value(v)}" for k, v in self.controller.params]
            lines.append("")
        if self.simulation:
            lines.append("[simulation]")
            lines += [f"{k} = {_toml_value(v)}" for k, v in self.simulation]
            lines.append("")
        return "\n".join(lines)


def rig_config_template(host: str = "127.0.0.1", port: int = 5020) -> str:
    """A rig TOML to edit: the built-in register map, reached at ``host:port`` (Modbus TCP).

    The defaults of :class:`RigConfig`, with a header naming the units and a
    commented-out [controller] and [simulation] table.
    """
    from dataclasses import replace

    settings = RigConfig()
    settings = replace(settings, connection=replace(settings.connection, host=host, port=port))
    header = (
        "# softbend rig: connection, register map, scaling (value = offset + scale*count),\n"
        "# safety limits and loop period. Units: MPa gauge, degrees, seconds.\n\n"
    )
    footer = (
        "# [controller]            # optional: the controller of `softbend control run`\n"
        '# name = "bang-bang"      # bang-bang, bang-bang-closed, pressure-pi, ...\n'
        "# deadzone = 0.05         # its parameters, as --set NAME=VALUE (which overrides)\n"
        "\n# [simulation]            # optional: the simulated rig (control run --rig sim, serve)\n"
        "# valve_delay_s = 0.005   # as --rig-param NAME=VALUE (which overrides); names:\n"
        "# tubing_mm3 = 2000.0     # 'softbend control rig-parameters'\n"
    )
    return header + settings.to_toml() + footer


def load_rig_config(path: str | Path) -> RigConfig:
    """Read and check a rig's TOML file (see the module doc for its keys).

    Raises
    ------
    FileNotFoundError
        No such file.
    LimitError
        The file is larger than the ``file_mib`` limit of :mod:`softbend.limits`.
    DatasetError
        One line naming the file: not UTF-8 text, arrays or tables nested deeper
        than the ``nesting`` limit (counted on the text before it is parsed, as
        for JSON files: :func:`softbend._tomltext.parse_toml`), not valid TOML
        (with the line and column of the syntax error), or a section, key or
        value that is not allowed (with the line and the key; see
        :meth:`RigConfig.from_dict`). A ``ValueError``, as before.
    """
    p = Path(path)
    if not p.is_file():
        raise FileNotFoundError(f"The rig config {str(p)!r} does not exist or is not a file.")
    text = read_input_text(p, f"{p}: the rig config")
    if "\x00" in text:
        raise DatasetError(f"{p}: the rig config is not text (it holds NUL bytes).")
    data = parse_toml(text, str(p), DatasetError)  # the nesting limit, then line and column
    return RigConfig.from_dict(data, source=str(p), text=text)


#: The sections of a rig TOML (besides [loop]) and the dataclasses they build.
_SECTIONS: dict[str, type] = {
    "connection": ConnectionConfig,
    "pressure": RegisterConfig,
    "angle": RegisterConfig,
    "valves": ValveConfig,
    "safety": SafetyLimits,
}
#: The keys without a default: a register and its scaling depend on the sensor.
_REQUIRED: dict[str, tuple[str, ...]] = {
    "pressure": ("address", "scale"),
    "angle": ("address", "scale"),
}
#: The [safety] keys that are gauge pressures, MPa.
_PRESSURE_KEYS: tuple[str, ...] = ("max_pressure_mpa", "valid_min_mpa", "valid_max_mpa")
#: The TOML type each key must have, from the annotations of the dataclasses.
_KINDS: dict[str, str] = {"str": "a string", "int": "an integer", "float": "a number"}
_KINDS.update({"bool": "true or false", "int | None": "an integer"})


def _controller(table: object) -> ControllerConfig:
    """The [controller] table: a string ``name`` and scalar parameters."""
    if not isinstance(table, dict):
        raise InputError(_not_a_table("controller", table))
    if "name" not in table:
        given = ", ".join(map(repr, table))
        raise InputError(
            "must give 'name' (a controller, e.g. \"bang-bang\"); "
            f"got {f'only {given}' if given else 'none'}"
        )
    name = table["name"]
    if not isinstance(name, str):
        raise InputError(
            f"must be a string; got {short_repr(name)} ({_toml_type(name)})", key="name"
        )
    params = {k: v for k, v in table.items() if k != "name"}
    return ControllerConfig(name, tuple(params.items()))


def _settings_signature() -> inspect.Signature:
    """The names a simulated rig takes, with their defaults: RigParams's fields and tubing_mm3."""
    from softbend.control.rig import RigParams

    defaults = {f.name: f.default for f in fields(RigParams)}
    defaults["tubing_mm3"] = DEFAULT_TUBING_MM3
    keyword = inspect.Parameter.KEYWORD_ONLY
    return inspect.Signature(
        [inspect.Parameter(name, keyword, default=value) for name, value in defaults.items()]
    )


def simulation_settings_entry(**settings: object) -> None:
    """The settings of a simulated rig, as a signature that ``check_parameters`` reads.

    Its declared ranges are those of :class:`~softbend.control.rig.RigParams`
    (:data:`~softbend.control.rig.RIG_RANGES`) and
    :data:`~softbend.control.rig.TUBING_RANGE`.
    """


def _declare_settings() -> None:
    from softbend.control.rig import RIG_RANGES, TUBING_RANGE
    from softbend.parameters import declare_ranges

    simulation_settings_entry.__signature__ = _settings_signature()  # type: ignore[attr-defined]
    declare_ranges(**RIG_RANGES, tubing_mm3=TUBING_RANGE)(simulation_settings_entry)


_declare_settings()


def check_simulation_settings(
    values: Mapping[str, object], *, from_text: bool = False
) -> dict[str, Any]:
    """Settings of a simulated rig (the [simulation] table, ``--rig-param``), checked.

    Names, kinds and declared ranges by
    :func:`softbend.parameters.check_parameters` against the fields of
    :class:`~softbend.control.rig.RigParams` and ``tubing_mm3``
    (:func:`simulation_settings_entry`): the ranges RigParams itself holds its
    fields to.

    Raises
    ------
    UnknownParameterError
        An unknown name; the message lists the known ones.
    ParameterValueError
        A value of the wrong kind, not finite or out of range (``key`` names it).
    """
    from softbend.parameters import check_parameters

    return check_parameters(simulation_settings_entry, values, from_text=from_text)


def _simulation(table: object) -> tuple[tuple[str, Any], ...]:
    """The [simulation] table: settings of the simulated rig, checked."""
    if not isinstance(table, dict):
        raise InputError(_not_a_table("simulation", table))
    checked = check_simulation_settings(table)
    return tuple((k, checked[k]) for k in table)


@contextmanager
def _in_section(name: str) -> Iterator[None]:
    """Key an error raised about the section ``name`` by its TOML path.

    ``[name]`` for the section itself, ``name.key`` for one of its keys: never
    the name of a command-line option.
    """
    try:
        yield
    except SoftbendError as error:
        if error.key is None:
            error.key = f"[{name}]"
        elif "." not in error.key:
            error.key = f"{name}.{error.key}"
        raise
    except ValueError as error:  # a check outside softbend's vocabulary
        raise InputError(" ".join(str(error).split()), key=f"[{name}]") from None


def _not_a_table(name: str, value: object) -> str:
    return (
        f"must be a table ([{name}] followed by its keys); got {short_repr(value)} "
        f"({_toml_type(value)})"
    )


def _section_kinds(name: str) -> dict[str, str]:
    """Key -> expected kind (a key of :data:`_KINDS`) of the section ``name``."""
    if name == "loop":
        return {"period_s": "float", "sensor_period_s": "float"}
    return {f.name: str(f.type) for f in fields(_SECTIONS[name]) if f.name != "section"}


def _toml_type(value: object) -> str:
    if isinstance(value, bool):
        return "a boolean"
    if isinstance(value, int):
        return "an integer"
    if isinstance(value, float):
        return "a float"
    if isinstance(value, str):
        return "a string"
    if isinstance(value, list):
        return "an array"
    if isinstance(value, dict):
        return "a table"
    if isinstance(value, datetime.date | datetime.time):
        return "a date or time"
    return type(value).__name__


def _has_kind(value: object, kind: str) -> bool:
    if kind == "str":
        return isinstance(value, str)
    if kind == "bool":
        return isinstance(value, bool)
    if kind in ("int", "int | None"):
        return type(value) is int
    return type(value) in (int, float)  # a number: TOML integers and floats, not booleans


def _check_table(name: str, table: object) -> None:
    """Unknown keys and wrong TOML types of the section ``name``."""
    if not isinstance(table, dict):
        raise InputError(_not_a_table(name, table))
    kinds = _section_kinds(name)
    unknown = sorted(set(table) - set(kinds))
    if unknown:
        raise InputError(
            f"is not a key of [{name}]; allowed: {', '.join(sorted(kinds))}", key=unknown[0]
        )
    for key, value in table.items():
        kind = kinds[key]
        if not _has_kind(value, kind):
            raise InputError(
                f"must be {_KINDS[kind]}; got {short_repr(value)} ({_toml_type(value)})", key=key
            )


_HEADER = re.compile(r"\[\s*([A-Za-z0-9_-]+)\s*\]")
_ASSIGN = re.compile(r"(?:([A-Za-z0-9_-]+)\s*\.\s*)?\"?([A-Za-z0-9_-]+)\"?\s*=")


def _line_of(text: str, section: str, key: str) -> int | None:
    """The line of ``key`` in ``section`` of a TOML text (else of the section), or None.

    ``key`` empty: the line of the section (its header, or a top-level key of that name).
    """
    current: str | None = None
    header = None
    for number, line in enumerate(text.splitlines(), start=1):
        stripped = line.strip()
        match = _HEADER.match(stripped)
        if match:
            current = match.group(1)
            if current == section and header is None:
                header = number
            continue
        match = _ASSIGN.match(stripped)
        if match is None:
            continue
        table = match.group(1) if match.group(1) and current is None else current
        if key and table == section and match.group(2) == key:
            return number
        if not key and current is None and match.group(2) == section:
            return number
    return header


def _check_integer(value: object, key: str, high: int) -> int:
    """``value`` if it is an integer in [0, high] (a register address, a port), else raise."""
    if isinstance(value, bool) or not isinstance(value, int) or not 0 <= value <= high:
        raise InputError(must_be(f"an integer in [0, {high}]", value), key=key)
    return value


def _toml_value(value: object) -> str:
    if isinstance(value, bool):
        return "true" if value else "false"
    if isinstance(value, str):
        return '"' + value.replace("\\", "\\\\").replace('"', '\\"') + '"'
    return repr(value)
