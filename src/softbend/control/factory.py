"""Controllers by name: the registry :data:`CONTROLLERS` of controller classes.

A controller is registered as its class. The class takes the controller's
model (:class:`~softbend.control.controllers.ControllerModel`: the θ(p) table
it inverts, its virtual angle sensor, the rig model) as its first argument and
its public parameters as keyword-only arguments with defaults; those names are
the ones of ``--set NAME=VALUE`` and of a rig TOML's ``[controller]`` table,
and the ranges it declares (:func:`softbend.parameters.declare_ranges`) are
the ones they are held to. Adding a controller is one class and one
``CONTROLLERS.register(name, cls)`` call, from inside the package or out::

    @declare_ranges(limit=Range(0.0, 0.5, "MPa", "the pressure to fill to"))
    class HoldPressure:
        \"\"\"Fill to a fixed pressure and hold it.\"\"\"

        def __init__(self, model: ControllerModel, *, limit: float = 0.03) -> None:
            self.limit = limit
            self.reset()

        def reset(self) -> None:
            self.predicted_deg = math.nan

        def step(self, measurement_mpa, reference_deg, t_s) -> ValveCommand:
            return ValveCommand(measurement_mpa < self.limit, False)

    CONTROLLERS.register("hold", HoldPressure)

Any callable ``entry(model, **params)`` that returns a controller may be
registered the same way (a factory function).
"""

from __future__ import annotations

import inspect
from collections.abc import Callable, Mapping
from typing import Any

from softbend.control.controllers import (
    BangBang,
    BangBangClosed,
    Controller,
    ControllerModel,
    PressurePI,
    PressureRelay,
)
from softbend.control.predictive import PredictivePulse
from softbend.control.rig import AngleTable, RigParams
from softbend.parameters import check_parameters, declared_ranges, effective_parameters
from softbend.registry import Registry

__all__ = [
    "CONTROLLERS",
    "DEFAULT_CONTROLLER",
    "ControllerModel",
    "build_controller",
    "controller_catalog",
    "controller_parameters",
    "make_controller",
]

#: Controller classes by name: ``entry(model, **params) -> Controller``.
CONTROLLERS: Registry[Callable[..., Controller]] = Registry("controller")

#: The controller of a run that names none: paper B's (§5, eq. 1).
DEFAULT_CONTROLLER = "bang-bang"

CONTROLLERS.register("bang-bang", BangBang)
CONTROLLERS.register("bang-bang-closed", BangBangClosed)
CONTROLLERS.register("pressure-pi", PressurePI)
CONTROLLERS.register("pressure-relay", PressureRelay)
CONTROLLERS.register("predictive", PredictivePulse)


def controller_parameters(
    name: str, values: Mapping[str, object] | None = None, *, from_text: bool = False
) -> dict[str, Any]:
    """Every public parameter of the controller ``name``: its default or the value given.

    The one check of a controller's parameters: each name given must be a public
    parameter of the class, each value of its kind and in its declared range
    (:func:`~softbend.parameters.check_parameters`).

    Parameters
    ----------
    name : str
        A name of :data:`CONTROLLERS`.
    values : mapping, optional
        ``{parameter: value}`` (see :func:`~softbend.parameters.check_parameters`).
    from_text : bool, default False
        Parse the values as typed on a command line.

    Returns
    -------
    dict
        Every public parameter of the class: the checked value given, else its default.

    Raises
    ------
    UnknownNameError
        An unknown controller or parameter; the message lists the known names.
    ParameterValueError
        A value of the wrong kind or out of its range; its key is the parameter.
    """
    entry = CONTROLLERS.get(name)
    checked = check_parameters(entry, values, from_text=from_text)
    return effective_parameters(entry, checked)


def controller_catalog() -> list[dict[str, Any]]:
    """Every registered controller: ``{"name", "summary", "params", "ranges"}``.

    ``params`` are the parameters and their defaults, ``ranges`` the declared
    range of each (with its unit); the summary is the first line of the
    class's docstring.
    """
    rows = []
    for name, entry in CONTROLLERS.items():
        doc = inspect.getdoc(entry) or ""
        rows.append(
            {
                "name": name,
                "summary": doc.splitlines()[0] if doc else "",
                "params": effective_parameters(entry),
                "ranges": {k: r.describe() for k, r in declared_ranges(entry).items()},
            }
        )
    return rows


def build_controller(
    name: str, model: ControllerModel, params: Mapping[str, object] | None = None
) -> Controller:
    """The controller ``name`` on ``model`` with ``params`` checked (the others: defaults)."""
    return CONTROLLERS.get(name)(model, **controller_parameters(name, params))


def make_controller(
    name: str,
    angle_table: AngleTable,
    virtual_sensor: Callable[[float], float] | None = None,
    rig: RigParams | None = None,
    /,
    **params: object,
) -> Controller:
    """The controller called ``name`` (one of :data:`CONTROLLERS`), with ``params`` applied.

    Parameters
    ----------
    name : str
    angle_table : AngleTable
        θ(p) of the controller's model (inverted by the pressure controllers).
    virtual_sensor : callable, optional
        θp(p) of the bang-bang controllers (default ``angle_table``; paper B:
        :func:`~softbend.control.controllers.mlp_virtual_sensor`).
    rig : RigParams, optional
        The rig model of ``predictive`` (default :class:`~softbend.control.rig.RigParams`).
    **params
        Public parameters of the controller (see its class, e.g. ``deadzone=0.02``
        for ``bang-bang``); the others keep their defaults.
    """
    sensor = angle_table if virtual_sensor is None else virtual_sensor
    return build_controller(name, ControllerModel(angle_table, sensor, rig), params)
