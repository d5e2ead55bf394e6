"""Identification of pneumatic actuators from time series (paper A).

Generalized-Gaussian kernel SVR, NARX regressors, the synthetic curling actuator,
the experiment CSV format and the leave-one-experiment-out study. Names are
imported lazily so that ``import softbend.identification`` stays light.
"""

from __future__ import annotations

from typing import TYPE_CHECKING, Any

from softbend._lazy import export as _export

if TYPE_CHECKING:
    from softbend.identification.data import Experiment, load_experiments, save_experiments
    from softbend.identification.kernels import (
        estimate_gg_shape,
        estimate_kernel_shape,
        generalized_gaussian_kernel,
    )
    from softbend.identification.narx import NARXRegressor
    from softbend.identification.resources import check_identify_memory
    from softbend.identification.svr import GeneralizedGaussianSVR
    from softbend.identification.synthetic import CurlingActuator, synthetic_dataset

#: Public name → submodule that defines it.
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

__all__ = [
    "CurlingActuator",
    "Experiment",
    "GeneralizedGaussianSVR",
    "NARXRegressor",
    "check_identify_memory",
    "estimate_gg_shape",
    "estimate_kernel_shape",
    "generalized_gaussian_kernel",
    "load_experiments",
    "save_experiments",
    "synthetic_dataset",
]


def __getattr__(name: str) -> Any:
    return _export(__name__, _EXPORTS, name)


def __dir__() -> list[str]:
    return list(__all__)
