"""Transfer learning: refine a simulation-trained surrogate on a few measurements.

Paper B §4.2–4.3: measurements as data (:mod:`~softbend.transfer.measurements`),
a virtual lab with a reality gap (:mod:`~softbend.transfer.lab`), the surrogate
the refinement starts from (:mod:`~softbend.transfer.base`), the refinement
strategies (:mod:`~softbend.transfer.strategies`, registered by name in
:data:`STRATEGIES`, their parameters in :mod:`~softbend.transfer.strategies.parameters`),
one strategy fitted and saved (:mod:`~softbend.transfer.refine`) and their
leave-one-configuration-out evaluation (:mod:`~softbend.transfer.loco`).

The measurements name the base model's actuator's own parameters and pressure unit
(its description travels with the model); paper B's virtual lab of its fiber-reinforced
actuator is one example, the PneuNet's built actuators (``examples/pneunet``) another.

Names are imported lazily, so that ``import softbend.transfer`` imports neither
scikit-learn nor PyTorch.
"""

from __future__ import annotations

from typing import Any

from softbend._lazy import export as _export

_EXPORTS = {
    "BASE_HIDDEN_SIZES": "base",
    "load_base": "base",
    "shipped_base_path": "base",
    "train_base_mlp": "base",
    "LAB_ACTUATORS": "lab",
    "LAB_MODELS": "lab",
    "VirtualLab": "lab",
    "actuator_id": "lab",
    "shipped_measurements": "lab",
    "BASELINE_STRATEGY": "loco",
    "DEFAULT_STRATEGIES": "loco",
    "LocoResult": "loco",
    "leave_one_configuration_out": "loco",
    "strategy_options": "loco",
    "Measurements": "measurements",
    "format_measurements": "measurements",
    "load_measurements": "measurements",
    "load_measurements_files": "measurements",
    "files_record": "measurements",
    "synthetic_label": "measurements",
    "save_measurements": "measurements",
    "check_parameters": "strategies.parameters",
    "parameter_defaults": "strategies.parameters",
    "fit_pressure_scale": "pressure_map",
    "scale_mlp_pressure": "pressure_map",
    "REFINE_DEFAULTS": "refine",
    "Refinement": "refine",
    "default_refine_strategy": "refine",
    "refinable_strategies": "refine",
    "refine_surrogate": "refine",
    "BUILTIN_STRATEGIES": "strategies",
    "NETWORK_STRATEGIES": "strategies",
    "STRATEGIES": "strategies",
    "applicable_strategies": "strategies",
    "check_applicable": "strategies",
    "describe_strategies": "strategies",
    "fit_strategy": "strategies",
    "has_interval": "strategies",
    "make_strategy": "strategies",
    "strategy_parameters": "strategies",
    "strategy_refusal": "strategies",
}

__all__ = sorted(_EXPORTS)


def __getattr__(name: str) -> Any:
    return _export(__name__, _EXPORTS, name)


def __dir__() -> list[str]:
    return list(__all__)
