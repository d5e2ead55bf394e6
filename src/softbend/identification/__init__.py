"""Identification of pneumatic actuators from time series (paper A).

Generalized-Gaussian kernel SVR, NARX regressors, the synthetic curling actuator,
the experiment CSV format and the leave-one-experiment-out study. Names are
imported lazily so that ``import softbend.identification`` stays light.
"""

from __future__ import annotations

from typing import TYPE_CHECKING, Any

from softbend._lazy import export as _export

if TYPE_CHECKING:
    from softbend.identification.arm import SoftArm, arm_experiments
    from softbend.identification.data import Experiment, load_experiments, save_experiments
    from softbend.identification.dynamics import (
        IdentifiedModel,
        StepReading,
        is_identified_model,
        load_identified,
        step_readings,
    )
    from softbend.identification.kernels import (
        estimate_gg_shape,
        estimate_kernel_shape,
        generalized_gaussian_kernel,
    )
    from softbend.identification.multi import MultiNARX, load_multi_narx, save_multi_narx
    from softbend.identification.narx import NARXRegressor
    from softbend.identification.resources import check_identify_memory
    from softbend.identification.selection import Selection, select_model
    from softbend.identification.svr import GeneralizedGaussianSVR
    from softbend.identification.synthetic import CurlingActuator, synthetic_dataset
    from softbend.identification.timeseries import Series, TimeSeriesSet, from_experiments
    from softbend.identification.timeseries_io import load_timeseries, save_timeseries

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
    "IdentifiedModel": "dynamics",
    "StepReading": "dynamics",
    "is_identified_model": "dynamics",
    "load_identified": "dynamics",
    "step_readings": "dynamics",
    "CurlingActuator": "synthetic",
    "synthetic_dataset": "synthetic",
    "check_identify_memory": "resources",
    "SoftArm": "arm",
    "arm_experiments": "arm",
    "MultiNARX": "multi",
    "load_multi_narx": "multi",
    "save_multi_narx": "multi",
    "Selection": "selection",
    "select_model": "selection",
    "Series": "timeseries",
    "TimeSeriesSet": "timeseries",
    "from_experiments": "timeseries",
    "load_timeseries": "timeseries_io",
    "save_timeseries": "timeseries_io",
}

__all__ = [
    "CurlingActuator",
    "Experiment",
    "GeneralizedGaussianSVR",
    "IdentifiedModel",
    "MultiNARX",
    "NARXRegressor",
    "Selection",
    "Series",
    "SoftArm",
    "StepReading",
    "TimeSeriesSet",
    "arm_experiments",
    "check_identify_memory",
    "estimate_gg_shape",
    "estimate_kernel_shape",
    "from_experiments",
    "generalized_gaussian_kernel",
    "is_identified_model",
    "load_experiments",
    "load_identified",
    "load_multi_narx",
    "load_timeseries",
    "save_experiments",
    "save_multi_narx",
    "save_timeseries",
    "select_model",
    "step_readings",
    "synthetic_dataset",
]


def __getattr__(name: str) -> Any:
    return _export(__name__, _EXPORTS, name)


def __dir__() -> list[str]:
    return list(__all__)
