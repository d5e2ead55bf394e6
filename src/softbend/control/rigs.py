"""Rigs by name: the registry :data:`RIGS` of rig factories for the control loop.

A rig factory takes a :class:`RigSetup` (the rig TOML, the simulated plant and
its parameters, the noise seed) and returns a connected
:class:`~softbend.control.rig.Rig`, ready for
:func:`~softbend.control.loop.run_loop`. Built in: ``sim`` (the simulated rig
in simulated time), ``sim-realtime`` (the same, kept in step with the wall
clock) and ``modbus`` (hardware over Modbus, from the TOML's connection and
register map). Adding one is one ``RIGS.register(name, factory)`` call.
"""

from __future__ import annotations

from collections.abc import Callable
from dataclasses import dataclass, field
from pathlib import Path
from typing import Any

from softbend.control.rig import AngleTable, Rig, RigParams, SimulatedRig
from softbend.control.rigconfig import RigConfig
from softbend.registry import Registry

__all__ = [
    "DEFAULT_RIG",
    "RIGS",
    "RigSetup",
    "make_rig",
    "modbus_rig",
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
    command : str
        The command asking, for messages.
    """

    config: RigConfig = field(default_factory=RigConfig)
    config_path: Path | None = None
    plant_table: AngleTable | None = None
    params: RigParams | None = None
    seed: int = 0
    command: str = "make_rig"


def sim_rig(setup: RigSetup) -> SimulatedRig:
    """The simulated rig in simulated time (the loop's sleeps integrate the model)."""
    if setup.plant_table is None:
        raise ValueError(
            f"The simulated rig of {setup.command} needs the actuator's θ(p) (plant_table). "
            "Got none."
        )
    return SimulatedRig(setup.plant_table, setup.params, seed=setup.seed)


def sim_realtime_rig(setup: RigSetup) -> Any:
    """The simulated rig kept in step with the wall clock (a rehearsal of the real timing)."""
    from softbend.control.realtime import WallClockRig

    return WallClockRig(sim_rig(setup))


def modbus_rig(setup: RigSetup) -> Any:
    """A Modbus rig from the TOML's connection and register map, connected and probed."""
    if setup.config_path is None:
        raise ValueError(
            f"The '--config' of {setup.command} must name a rig TOML file with --rig "
            "modbus (write a template with 'softbend control rig-config --out rig.toml')."
        )
    from softbend.control.modbus import ModbusRig

    return ModbusRig(setup.config).connect()


RIGS.register("sim", sim_rig)
RIGS.register("sim-realtime", sim_realtime_rig)
RIGS.register("modbus", modbus_rig)


def make_rig(name: str, setup: RigSetup, *, field: str = "make_rig") -> Rig:
    """The rig ``name`` (one of :data:`RIGS`) built from ``setup``.

    An unknown name raises :class:`~softbend.registry.UnknownNameError` listing the
    known ones (``field`` names where it came from, e.g. ``"--rig"``).
    """
    return RIGS.get(name, field=field)(setup)
