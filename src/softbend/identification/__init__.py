"""Identification of pneumatic actuators from time series (paper A).

Generalized-Gaussian kernel SVR, NARX regressors, the synthetic curling actuator,
the experiment CSV format and the leave-one-experiment-out study. Names are
imported lazily so that ``import softbend.identification`` stays light.
"""

from __future__ import annotations

import importlib
from typing import Any

_EXPORTS = {
    "estimate_gg_shape": "kernels",
    "estimate_kernel_shape": "kernels",
    "generalized_gaussian_kernel": "kernels",
    "GeneralizedGaussianSVR": "svr",
    "NARXRegressor": "narx",
    "Experiment": "data",
    "load_experiments": "data",
    "save_experiments": "data",
    "CurlingActuator": "synthetic",
    "synthetic_dataset": "synthetic",
    "check_identify_memory": "resources",
}

__all__ = sorted(_EXPORTS)


def __getattr__(name: str) -> Any:
    if name in _EXPORTS:
        module = importlib.import_module(f"softbend.identification.{_EXPORTS[name]}")
        return getattr(module, name)
    raise AttributeError(f"module 'softbend.identification' has no attribute {name!r}")


def __dir__() -> list[str]:
    return __all__
