"""Rigs by name: the registry :data:`RIGS` of rig factories for the control loop.

A rig factory takes a :class:`RigSetup` (the rig TOML, the simulated plant and
its parameters, the noise seed) and returns a connected
:class:`~softbend.control.rig.Rig`, ready for
:func:`~softbend.control.loop.run_loop`. Built in: ``sim`` (the simulated rig
in simulated time), ``sim-realtime`` (the same, kept in step with the wall
clock) and ``modbus`` (hardware over Modbus, from the TOML's connection and
register map). Adding one is one ``RIGS.register(name, factory)`` call.

A simulated rig is described by :class:`~softbend.control.rig.RigParams`:
:func:`rig_settings` checks ``NAME=VALUE`` text (``--rig-param``) and a rig
TOML's [simulation] table against its fields (plus ``tubing_mm3``, the tubing
volume added to the design's cavity) and :func:`rig_params_for` builds the
parameters of a design from them (paper B's cavity from its geometry; another
actuator's chamber from its description or a measured ``volume_mm3``);
:data:`RIG_SETTINGS` says what each name means.
"""

from __future__ import annotations

import inspect
import math
import re
from collections.abc import Callable, Mapping, Sequence
from dataclasses import dataclass, field
from pathlib import Path
from typing import TYPE_CHECKING, Any

from softbend.actuators import SFRBA, Design
from softbend.control.rig import AngleDynamics, AngleTable, Rig, RigParams, SimulatedRig
from softbend.control.rigconfig import (
    DEFAULT_TUBING_MM3,
    RigConfig,
    check_simulation_settings,
    simulation_settings_entry,
)
from softbend.errors import InputError, SoftbendError, keyed
from softbend.parameters import declared_ranges, parse_assignments
from softbend.registry import Registry

if TYPE_CHECKING:
    from softbend.control.modbus import ModbusRig
    from softbend.control.realtime import WallClockRig

__all__ = [
    "DEFAULT_RIG",
    "DEFAULT_TUBING_MM3",
    "HARDWARE_RIGS",
    "RIGS",
    "RIG_SETTINGS",
    "RigSetup",
    "has_cavity",
    "make_rig",
    "modbus_rig",
    "pressures_in_mpa",
    "rig_parameter_catalog",
    "rig_params_for",
    "rig_settings",
    "sim_realtime_rig",
    "sim_rig",
]

#: Rig factories by name: ``factory(setup: RigSetup) -> Rig``.
RIGS: Registry[Callable[[RigSetup], Rig]] = Registry("rig")

#: The rig of a run that names none.
DEFAULT_RIG = "sim"


@dataclass(frozen=True)
class RigSetup:
    """What a rig factory may use.

    Attributes
    ----------
    config : RigConfig
        The rig TOML (connection, registers, safety, loop), or its defaults.
    config_path : Path, optional
        The TOML file; ``None`` when none was given (a hardware rig needs one).
    plant_table : AngleTable, optional
        θ(p) of a simulated actuator, degrees.
    params : RigParams, optional
        Pneumatics of a simulated rig (default :class:`RigParams`).
    seed : int, default 0
        Seed of a simulated rig's sensor and camera noise.
    dynamics : AngleDynamics, optional
        A dynamic model of a simulated actuator's angle (an identified model) that
        replaces ``plant_table`` and the angle lag (:class:`~softbend.control.rig.SimulatedRig`).
    """

    config: RigConfig = field(default_factory=RigConfig)
    config_path: Path | None = None
    plant_table: AngleTable | None = None
    params: RigParams | None = None
    seed: int = 0
    dynamics: AngleDynamics | None = None


def sim_rig(setup: RigSetup) -> SimulatedRig:
    """The simulated rig in simulated time (the loop's sleeps integrate the model)."""
    if setup.plant_table is None:
        raise InputError(
            "must be given for a simulated rig (the actuator's θ(p))", key="plant_table"
        )
    return SimulatedRig(setup.plant_table, setup.params, seed=setup.seed, dynamics=setup.dynamics)


def sim_realtime_rig(setup: RigSetup) -> WallClockRig:
    """The simulated rig kept in step with the wall clock (a rehearsal of the real timing)."""
    from softbend.control.realtime import WallClockRig

    return WallClockRig(sim_rig(setup))


def modbus_rig(setup: RigSetup) -> ModbusRig:
    """A Modbus rig from the TOML's connection and register map, connected and probed."""
    if setup.config_path is None:
        raise InputError(
            "must name a rig TOML file for the rig modbus (write a template with "
            "'softbend control rig-config --out rig.toml')",
            key="config",
        )
    from softbend.control.modbus import ModbusRig

    return ModbusRig(setup.config).connect()


RIGS.register("sim", sim_rig)
RIGS.register("sim-realtime", sim_realtime_rig)
RIGS.register("modbus", modbus_rig)


def make_rig(name: str, setup: RigSetup) -> Rig:
    """The rig ``name`` (one of :data:`RIGS`) built from ``setup``.

    An unknown name raises :class:`~softbend.registry.UnknownNameError` listing the
    known ones.
    """
    return RIGS.get(name)(setup)


#: Rigs that are hardware: the parameters of a simulated rig mean nothing to them.
HARDWARE_RIGS: frozenset[str] = frozenset({"modbus"})

#: What each setting of a simulated rig is (its unit is in its name; :mod:`softbend.control.rig`).
RIG_SETTINGS: dict[str, str] = {
    "supply_gauge_mpa": "supply pressure behind the inlet valve (same as --supply)",
    "atmosphere_mpa": "absolute pressure of the atmosphere the outlet vents to",
    "temperature_k": "temperature of the air",
    "inlet_conductance_m3_s_pa": "ISO 6358 sonic conductance C of the inlet valve + throttle",
    "outlet_conductance_m3_s_pa": "ISO 6358 sonic conductance C of the outlet valve + throttle",
    "critical_ratio": "ISO 6358 critical pressure ratio b of both valves",
    "valve_delay_s": "delay from a valve command to the valve switching",
    "volume_mm3": "whole chamber volume at 0 MPa gauge (default: the design's cavity + tubing; "
    "another actuator's: its description's chamber_volume_mm3 + tubing)",
    "tubing_mm3": "tubing volume added to the design's cavity (or give volume_mm3)",
    "compliance_mm3_per_mpa": "growth of the chamber volume with gauge pressure, dV/dp "
    "(another actuator's default: its description's volume_growth_mm3_per_mpa, else 0)",
    "polytropic_exponent": "of the gas in the chamber: 1 isothermal to 1.4 adiabatic",
    "angle_time_constant_s": "first-order lag of the angle behind its quasi-static θ(p)",
    "sensor_noise_mpa": "standard deviation of the pressure sensor's Gaussian noise",
    "sensor_bits": "resolution of the pressure sensor over its range (0: no quantisation)",
    "sensor_range_mpa": "full scale of the pressure sensor, gauge",
    "camera_fps": "frame rate of the camera that records the true angle",
    "camera_latency_s": "delay of the camera's angle",
    "camera_noise_deg": "standard deviation of the camera's Gaussian angle noise",
    "step_s": "integration step of the rig model",
}


def rig_parameter_catalog() -> list[dict[str, Any]]:
    """Every setting of a simulated rig: ``{"name", "default", "range", "what"}``.

    The names are the fields of :class:`~softbend.control.rig.RigParams` and
    ``tubing_mm3``; ``default`` is the default of RigParams (``volume_mm3``:
    that of paper B's (100,6,2,2,5,8) actuator; a run computes it for its design
    from ``tubing_mm3``); ``range`` is the declared range with its unit.
    """
    ranges = declared_ranges(simulation_settings_entry)
    return [
        {
            "name": p.name,
            "default": p.default,
            "range": ranges[p.name].describe(),
            "what": RIG_SETTINGS.get(p.name, ""),
        }
        for p in inspect.signature(simulation_settings_entry).parameters.values()
    ]


def rig_settings(
    rig_assignments: Sequence[str] | None = (),
    values: Mapping[str, object] | None = None,
    *,
    supply_mpa: float | None = None,
) -> dict[str, Any]:
    """The settings of a simulated rig that differ from the defaults, checked.

    Parameters
    ----------
    rig_assignments : sequence of str, optional
        ``NAME=VALUE`` text, read by the kind of each name: a field of
        :class:`~softbend.control.rig.RigParams` or ``tubing_mm3``
        (:data:`RIG_SETTINGS`). A pressure (a setting in MPa, ``supply_gauge_mpa``)
        may carry a unit suffix, ``20psi`` or ``138kPa`` (:func:`pressures_in_mpa`).
    values : mapping, optional
        Data values of the same names (a rig TOML's [simulation] table);
        ``rig_assignments`` override them.
    supply_mpa : float, optional
        The supply pressure given on its own, MPa gauge: the same as
        ``supply_gauge_mpa``; it overrides ``values`` too.

    Returns
    -------
    dict
        ``{name: value}`` of the names given, typed (``float``, ``int`` for
        ``sensor_bits``); :func:`rig_params_for` builds the parameters from it.

    Raises
    ------
    UnknownParameterError
        An unknown name; the message lists the known names.
    ParameterValueError
        A value of the wrong kind, or out of the range that RigParams allows.
    InputError
        An assignment that is not ``NAME=VALUE`` or gives a name twice, a
        ``supply_mpa`` that differs from ``supply_gauge_mpa`` of the assignments,
        or both ``volume_mm3`` and ``tubing_mm3``. The key of each error is the
        parameter the value came by (``rig_assignments``, ``values``, ``supply_mpa``).
        (Whether the supply is a plausible gauge pressure is for
        :func:`~softbend.control.setup.check_supply`.)
    """
    with keyed("values"):
        table = check_simulation_settings(values or {}, from_text=False)
    with keyed("rig_assignments"):
        typed = parse_assignments(rig_assignments)
        texts = pressures_in_mpa(typed)
        try:
            given = check_simulation_settings(texts, from_text=True)
        except SoftbendError as error:  # a converted pressure: name it as it was typed
            if error.key in texts and texts[error.key] != typed[error.key]:
                error.args = (f"{error.detail} (given as {typed[error.key]!r})",)
            raise
    if supply_mpa is not None:
        with keyed("supply_mpa"):
            supply = check_simulation_settings({"supply_gauge_mpa": supply_mpa}, from_text=False)
        other = given.get("supply_gauge_mpa", supply["supply_gauge_mpa"])
        if not math.isclose(other, supply["supply_gauge_mpa"], rel_tol=1e-12):
            raise InputError(
                "must equal the rig setting supply_gauge_mpa (the same supply pressure, MPa "
                f"gauge: give one, or the same value); got {supply_mpa!r} and {other!r}",
                key="supply_mpa",
            )
        given.update(supply)
    merged = {**table, **given}
    if "volume_mm3" in merged and "tubing_mm3" in merged:
        raise InputError(
            "volume_mm3 (the whole chamber) and tubing_mm3 (added to the design's cavity) "
            "both set the chamber volume of the simulated rig: give one; got both",
            key="rig_assignments" if {"volume_mm3", "tubing_mm3"} & set(given) else "values",
        )
    return merged


#: A number followed by a unit (``20psi``, ``1.5e2 kPa``): what :func:`pressures_in_mpa` reads.
_WITH_UNIT = re.compile(r"^\s*[-+]?(?:\d+\.?\d*|\.\d+)(?:[eE][-+]?\d+)?\s*[A-Za-z]+\s*$")


def pressures_in_mpa(texts: Mapping[str, str]) -> dict[str, str]:
    """``{name: text}`` of rig settings with every pressure given with a unit in MPa.

    A pressure is a setting whose declared range is in MPa (``supply_gauge_mpa``,
    ``atmosphere_mpa``, ``sensor_noise_mpa``, ``sensor_range_mpa``); its name says
    MPa, so a bare number is MPa, and a number with a unit suffix (``20psi``,
    ``138 kPa``) is converted (:func:`softbend.units.parse_pressure`). Other text
    is left to the settings' own checks.

    Raises
    ------
    InputError
        A pressure with an unknown unit (the message names the setting and lists
        the units).
    """
    from softbend.control.rig import RIG_RANGES
    from softbend.units import parse_pressure

    out = dict(texts)
    for name, text in texts.items():
        known = RIG_RANGES.get(name)
        if known is None or known.unit != "MPa" or not _WITH_UNIT.match(text):
            continue
        out[name] = repr(parse_pressure(text, "MPa", name))
    return out


def has_cavity(design: object) -> bool:
    """Whether ``design`` gives its own cavity volume (``cavity_volume_mm3``, mm³, from its
    geometry, as paper B's designs do), from which the rig's chamber follows."""
    return getattr(design, "cavity_volume_mm3", None) is not None


def rig_params_for(
    design: Design,
    settings: Mapping[str, Any] | None = None,
    **defaults: float,
) -> RigParams:
    """The simulated rig of ``design`` with ``settings`` (:func:`rig_settings`) applied.

    Paper B's design: the chamber volume is the design's cavity plus
    ``tubing_mm3`` (:meth:`RigParams.for_design`) unless ``volume_mm3`` is given.
    A design of another actuator (:class:`~softbend.actuators.Design`):
    the chamber volume is ``volume_mm3`` when given (measured: the whole air
    volume, tubing included), else the description's ``chamber_volume_mm3`` plus
    ``tubing_mm3``; its growth with pressure is ``compliance_mm3_per_mpa`` when
    given, else the description's ``volume_growth_mm3_per_mpa``, else 0 (a
    rigid chamber, with a warning). ``defaults`` are RigParams fields the
    library derives (an FEM compliance), which ``settings`` override.

    Raises
    ------
    ValueError
        A design of another actuator whose description gives no chamber volume,
        without ``volume_mm3`` (one line saying to give ``--rig-param volume_mm3=...``).
    """
    chosen = {**defaults, **(settings or {})}
    tubing = chosen.pop("tubing_mm3", DEFAULT_TUBING_MM3)
    if design.actuator != SFRBA:
        return _rig_of_actuator(design, chosen, tubing)
    if "volume_mm3" in chosen:
        return RigParams(**chosen)
    return RigParams.for_design(design, tubing_mm3=tubing, **chosen)


def _rig_of_actuator(design: Design, chosen: dict[str, Any], tubing: float) -> RigParams:
    """The rig of a design of an actuator other than paper B's: its described chamber."""
    import warnings

    from softbend.control._ranges import check_declared
    from softbend.control.rig import RIG_RANGES, TUBING_RANGE

    actuator = design.actuator
    if "volume_mm3" not in chosen:
        if actuator.chamber_volume_mm3 is None:
            raise ValueError(
                f"The simulated rig needs the chamber volume of the actuator {actuator.name}, "
                "which its description does not give (chamber_volume_mm3): give --rig-param "
                "volume_mm3=V, the air volume at 0 MPa gauge with the tubing, in mm³ (or "
                "volume_mm3 in the [simulation] table of the rig config)."
            )
        tubing = check_declared(tubing, "tubing_mm3", TUBING_RANGE)
        volume = actuator.chamber_volume_mm3 + tubing
        declared = RIG_RANGES["volume_mm3"]
        if not declared.contains(volume):
            raise ValueError(
                f"The chamber of the actuator {actuator.name} (chamber_volume_mm3 "
                f"{actuator.chamber_volume_mm3:.4g} mm³ of its description, plus tubing_mm3 "
                f"{tubing:g}) is {volume:.4g} mm³; the 'volume_mm3' of a simulated rig must be "
                f"in {declared.describe()}: give more tubing_mm3, or volume_mm3."
            )
        chosen["volume_mm3"] = volume
    if "compliance_mm3_per_mpa" not in chosen:
        growth = actuator.volume_growth_mm3_per_mpa
        if growth is None:
            warnings.warn(
                f"The description of the actuator {actuator.name} gives no growth of its "
                "chamber with pressure (volume_growth_mm3_per_mpa): the simulated chamber is "
                "rigid (compliance_mm3_per_mpa 0); give --rig-param compliance_mm3_per_mpa=K "
                "(mm³/MPa) if it was measured.",
                UserWarning,
                stacklevel=4,
            )
            growth = 0.0
        chosen["compliance_mm3_per_mpa"] = growth
    return RigParams(**chosen)
