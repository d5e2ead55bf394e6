"""Controllers by name: the one place that knows every controller class."""

from __future__ import annotations

from collections.abc import Callable
from typing import Any

from softbend._validation import check_choice
from softbend.control.controllers import (
    CONTROLLERS,
    BangBang,
    PressurePI,
    PressureRelay,
)
from softbend.control.predictive import PredictivePulse

__all__ = ["make_controller"]


def make_controller(
    name: str,
    angle_table: Any,
    virtual_sensor: Callable[[float], float] | None = None,
    params: Any = None,
) -> Any:
    """The controller called ``name`` (one of :data:`CONTROLLERS`), with its defaults.

    Parameters
    ----------
    name : str
    angle_table : AngleTable
        θ(p) of the controller's model (inverted by the pressure controllers).
    virtual_sensor : callable, optional
        θp(p) of the bang-bang controllers (default ``angle_table``; paper B:
        :func:`~softbend.control.controllers.mlp_virtual_sensor`).
    params : RigParams, optional
        The rig model of ``predictive`` (default :class:`~softbend.control.rig.RigParams`).
    """
    check_choice(name, "controller", "make_controller", CONTROLLERS)
    sensor = angle_table if virtual_sensor is None else virtual_sensor
    if name == "bang-bang":
        return BangBang(sensor, mode="hold")
    if name == "bang-bang-closed":
        return BangBang(sensor, mode="closed")
    if name == "pressure-pi":
        return PressurePI(angle_table)
    if name == "pressure-relay":
        return PressureRelay(angle_table)
    return PredictivePulse(angle_table, params)
