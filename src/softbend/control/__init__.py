"""Closed-loop control of a bending actuator (paper B §5): rig, controllers, experiments.

The controller's model and the plant are θ(p) of any actuator (a saved surrogate records
its description: the design is given by its parameters, its pressures converted from the
rig's MPa); paper B's actuator and its shipped FEM-trained MLP are the default.

- :mod:`softbend.control.rig`: the simulated pneumatic rig (ISO 6358 valves, compliant
  chamber, lagged θ(p), sensors) and the :class:`~softbend.control.rig.Rig` protocol;
- :mod:`softbend.control.controllers`: paper B's deadzone bang-bang and pressure-based
  alternatives behind one ``step(measurement, reference, t) -> ValveCommand`` interface;
- :mod:`softbend.control.experiments`: references, the loop and its metrics.

Named extension points (:class:`softbend.registry.Registry`): :data:`CONTROLLERS`
(controller classes, :mod:`softbend.control.factory`), :data:`PLANTS` (θ(p)
of the actuator, :mod:`softbend.control.plants`; ``--plant`` is parsed once by
:func:`parse_plant` into a :class:`PlantChoice`) and :data:`RIGS` (what the loop
runs on, :mod:`softbend.control.rigs`). The names below are imported on first
use, so ``import softbend.control`` stays light.
"""

from __future__ import annotations

from typing import Any

from softbend._lazy import export as _export

#: Public name -> the module that defines it.
_EXPORTS: dict[str, str] = {
    "CONTROLLERS": "factory",
    "DEFAULT_CONTROLLER": "factory",
    "ControllerModel": "controllers",
    "build_controller": "factory",
    "controller_parameters": "factory",
    "make_controller": "factory",
    "BangBang": "controllers",
    "BangBangClosed": "controllers",
    "Controller": "controllers",
    "PressurePI": "controllers",
    "PressureRelay": "controllers",
    "ValveCommand": "controllers",
    "mlp_virtual_sensor": "controllers",
    "PredictivePulse": "predictive",
    "PLANTS": "plants",
    "PlantChoice": "plant_choice",
    "parse_plant": "plants",
    "plant_table": "plants",
    "RIGS": "rigs",
    "RigSetup": "rigs",
    "make_rig": "rigs",
    "AngleTable": "rig",
    "Rig": "rig",
    "RigParams": "rig",
    "SimulatedRig": "rig",
    "ControllerConfig": "rigconfig",
    "RigConfig": "rigconfig",
    "load_rig_config": "rigconfig",
    "ControlRun": "experiments",
    "parse_reference": "experiments",
    "run_metrics": "experiments",
    "simulate": "experiments",
    "run_loop": "loop",
    "control_design": "designs",
    "ControlSetup": "setup",
    "prepare_control": "setup",
    "plan_loop": "runs",
    "simulate_control": "runs",
    "control_study": "study",
}

__all__ = sorted(_EXPORTS)


def __getattr__(name: str) -> Any:
    return _export(__name__, _EXPORTS, name)


def __dir__() -> list[str]:
    return list(__all__)
