"""Controllers by name: the registry :data:`CONTROLLERS` of controller factories.

A controller factory takes the controller's model (:class:`ControllerModel`:
the θ(p) table it inverts, its virtual angle sensor, the rig model) and its
public parameters as keyword-only arguments with defaults; those names are the
ones of ``--set NAME=VALUE`` and of a rig TOML's ``[controller]`` table
(:mod:`softbend.parameters`). Adding a controller is one factory and one
``CONTROLLERS.register(name, factory)`` call, from inside the package or out::

    def make_toy(model, *, gain: float = 1.0):
        return ToyController(model.angle_table, gain)

    CONTROLLERS.register("toy", make_toy)
"""

from __future__ import annotations

import inspect
from collections.abc import Callable, Mapping
from dataclasses import dataclass
from typing import Any

from softbend.control._ranges import ranges_of
from softbend.control.controllers import (
    BangBang,
    Controller,
    PressurePI,
    PressureRelay,
    mlp_virtual_sensor,
)
from softbend.control.designs import ModelDesign
from softbend.control.predictive import PredictivePulse
from softbend.control.rig import AngleTable, RigParams
from softbend.design import SFRBADesign
from softbend.parameters import (
    check_parameters,
    declare_ranges,
    declared_ranges,
    effective_parameters,
)
from softbend.registry import Registry

__all__ = [
    "CONTROLLERS",
    "DEFAULT_CONTROLLER",
    "ControllerModel",
    "bang_bang",
    "bang_bang_closed",
    "build_controller",
    "controller_catalog",
    "controller_parameters",
    "make_controller",
    "predictive",
    "pressure_pi",
    "pressure_relay",
]

#: Controller factories by name: ``factory(model, **params) -> Controller``.
CONTROLLERS: Registry[Callable[..., Controller]] = Registry("controller")

#: The controller of a run that names none: paper B's (§5, eq. 1).
DEFAULT_CONTROLLER = "bang-bang"


@dataclass(frozen=True)
class ControllerModel:
    """What a controller knows of the actuator and the rig.

    Attributes
    ----------
    angle_table : AngleTable
        θ(p) of the controller's model (inverted by the pressure controllers), degrees.
    virtual_sensor : callable
        θp(p), gauge MPa → degrees, of the bang-bang controllers (paper B: the MLP).
    rig : RigParams, optional
        The rig model of ``predictive`` (default :class:`RigParams`).
    """

    angle_table: Any
    virtual_sensor: Callable[[float], float]
    rig: RigParams | None = None

    @classmethod
    def from_surrogate(
        cls,
        model: Any,
        design: SFRBADesign | ModelDesign,
        rig: RigParams | None = None,
        *,
        pmax_mpa: float = 0.5,
    ) -> ControllerModel:
        """θ(p) of ``model`` for ``design``; its ``.predictor()`` is the virtual sensor, if any.

        ``design`` is paper B's, or a :class:`~softbend.control.designs.ModelDesign`
        of the model's actuator (its pressures converted from MPa); the table spans
        0 to ``pmax_mpa`` MPa gauge.
        """
        table = AngleTable.from_surrogate(model, design, pmax_mpa=pmax_mpa)
        sensor = mlp_virtual_sensor(model, design) if hasattr(model, "predictor") else table
        return cls(table, sensor, rig)


def _default(cls: type, name: str) -> Any:
    """The default of the constructor argument ``name`` of ``cls`` (one source of truth)."""
    return inspect.signature(cls).parameters[name].default


@declare_ranges(**ranges_of(BangBang, deadzone="deadzone_fraction", period="period_s"))
def bang_bang(
    model: ControllerModel,
    *,
    deadzone: float = _default(BangBang, "deadzone_fraction"),
    period: float = _default(BangBang, "period_s"),
) -> BangBang:
    """Paper B's deadzone bang-bang on the virtual angle; valves held in the deadzone.

    Parameters
    ----------
    model : ControllerModel
    deadzone : float, default 0.05
        Half-width of the deadzone as a fraction of ``|θr|`` (paper B: 5 %).
    period : float, default 0.01
        Sample period of the controller, s (paper B: 100 Hz).
    """
    return BangBang(model.virtual_sensor, deadzone_fraction=deadzone, mode="hold", period_s=period)


@declare_ranges(**ranges_of(BangBang, deadzone="deadzone_fraction", period="period_s"))
def bang_bang_closed(
    model: ControllerModel,
    *,
    deadzone: float = _default(BangBang, "deadzone_fraction"),
    period: float = _default(BangBang, "period_s"),
) -> BangBang:
    """The deadzone bang-bang with both valves closed inside the deadzone.

    Parameters
    ----------
    model : ControllerModel
    deadzone : float, default 0.05
        Half-width of the deadzone as a fraction of ``|θr|``.
    period : float, default 0.01
        Sample period of the controller, s.
    """
    return BangBang(
        model.virtual_sensor, deadzone_fraction=deadzone, mode="closed", period_s=period
    )


@declare_ranges(
    **ranges_of(
        PressurePI, kp="kp_per_mpa", ki="ki_per_mpa_s", deadband="deadband_mpa",
        pwm_period="pwm_period_s", period="period_s",
    )
)  # fmt: skip
def pressure_pi(
    model: ControllerModel,
    *,
    kp: float = _default(PressurePI, "kp_per_mpa"),
    ki: float = _default(PressurePI, "ki_per_mpa_s"),
    deadband: float = _default(PressurePI, "deadband_mpa"),
    pwm_period: float = _default(PressurePI, "pwm_period_s"),
    period: float = _default(PressurePI, "period_s"),
) -> PressurePI:
    """PI on the pressure toward θ⁻¹(θr), by PWM of the valves.

    Parameters
    ----------
    model : ControllerModel
    kp : float, default 50
        Proportional gain, duty per MPa of error.
    ki : float, default 5
        Integral gain, duty per MPa·s.
    deadband : float, default 0.002
        Pressure error without action, MPa.
    pwm_period : float, default 0.02
        PWM period of the valves, s.
    period : float, default 0.01
        Sample period of the PI, s.
    """
    return PressurePI(
        model.angle_table, kp_per_mpa=kp, ki_per_mpa_s=ki, deadband_mpa=deadband,
        pwm_period_s=pwm_period, period_s=period,
    )  # fmt: skip


@declare_ranges(
    **ranges_of(
        PressureRelay, hysteresis="hysteresis_mpa", lead="lead_s", min_on="min_on_s",
        period="period_s",
    )
)  # fmt: skip
def pressure_relay(
    model: ControllerModel,
    *,
    hysteresis: float = _default(PressureRelay, "hysteresis_mpa"),
    lead: float = _default(PressureRelay, "lead_s"),
    min_on: float = _default(PressureRelay, "min_on_s"),
    period: float = _default(PressureRelay, "period_s"),
) -> PressureRelay:
    """A three-state relay on the pressure toward θ⁻¹(θr), with lead and hysteresis.

    Parameters
    ----------
    model : ControllerModel
    hysteresis : float, default 0.002
        Pressure error that opens a valve, MPa.
    lead : float, default 0.012
        How long the pressure keeps moving after a close, s.
    min_on : float, default 0
        Shortest opening of a valve, s.
    period : float, default 0.01
        Sample period of the relay, s.
    """
    return PressureRelay(
        model.angle_table, hysteresis_mpa=hysteresis, lead_s=lead, min_on_s=min_on,
        period_s=period,
    )  # fmt: skip


@declare_ranges(
    **ranges_of(
        PredictivePulse, deadband="deadband_mpa", observer_gain="observer_gain",
        preview="preview_s", tick="tick_s",
    )
)  # fmt: skip
def predictive(
    model: ControllerModel,
    *,
    deadband: float = _default(PredictivePulse, "deadband_mpa"),
    observer_gain: float = _default(PredictivePulse, "observer_gain"),
    preview: float | None = _default(PredictivePulse, "preview_s"),
    tick: float = _default(PredictivePulse, "tick_s"),
) -> PredictivePulse:
    """Model-predictive pulses of the valves toward θ⁻¹(θr), timed by a model of the pneumatics.

    See :mod:`softbend.control.predictive`.

    Parameters
    ----------
    model : ControllerModel
        Its ``rig`` is the pneumatic model (default :class:`RigParams`).
    deadband : float, default 0.002
        Pressure error without a pulse, MPa.
    observer_gain : float, default 0.3
        Weight of a new sample against the prediction, in (0, 1].
    preview : float, optional
        How far a ramping reference is extrapolated, s (default: the rig's valve
        delay plus its angle time constant; recorded as null).
    tick : float, default 0.001
        The period the controller is called at, s.
    """
    return PredictivePulse(
        model.angle_table, model.rig, deadband_mpa=deadband, observer_gain=observer_gain,
        preview_s=preview, tick_s=tick,
    )  # fmt: skip


CONTROLLERS.register("bang-bang", bang_bang)
CONTROLLERS.register("bang-bang-closed", bang_bang_closed)
CONTROLLERS.register("pressure-pi", pressure_pi)
CONTROLLERS.register("pressure-relay", pressure_relay)
CONTROLLERS.register("predictive", predictive)


def controller_parameters(
    name: str,
    values: Mapping[str, Any] | None = None,
    *,
    field: str = "make_controller",
    from_text: bool = False,
) -> dict[str, Any]:
    """Every public parameter of the controller ``name``: its default or the value given.

    Parameters
    ----------
    name : str
        A name of :data:`CONTROLLERS`.
    values : mapping, optional
        ``{parameter: value}`` (see :func:`~softbend.parameters.check_parameters`).
    field : str
        Where the name and values came from, for messages (``"--set"``).
    from_text : bool, default False
        Parse the values as typed on a command line.

    Raises
    ------
    UnknownNameError
        An unknown controller or parameter; the message lists the known names.
    ParameterValueError
        A value of the wrong kind.
    """
    factory = CONTROLLERS.get(name, field=field)
    owner = f"controller {name!r}"
    checked = check_parameters(factory, values, owner=owner, field=field, from_text=from_text)
    return effective_parameters(factory, checked)


def controller_catalog() -> list[dict[str, Any]]:
    """Every registered controller: ``{"name", "summary", "params", "ranges"}``.

    ``params`` are the parameters and their defaults, ``ranges`` the declared
    range of each (with its unit); the summary is the first line of the
    factory's docstring.
    """
    rows = []
    for name, factory in CONTROLLERS.items():
        doc = inspect.getdoc(factory) or ""
        rows.append(
            {
                "name": name,
                "summary": doc.splitlines()[0] if doc else "",
                "params": effective_parameters(factory),
                "ranges": {k: r.describe() for k, r in declared_ranges(factory).items()},
            }
        )
    return rows


def make_controller(
    name: str,
    angle_table: Any,
    virtual_sensor: Callable[[float], float] | None = None,
    rig: RigParams | None = None,
    /,
    **params: Any,
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
        Public parameters of the controller (see its factory, e.g. ``deadzone=0.02``
        for ``bang-bang``); the others keep their defaults.
    """
    sensor = angle_table if virtual_sensor is None else virtual_sensor
    return build_controller(name, ControllerModel(angle_table, sensor, rig), params)


def build_controller(
    name: str,
    model: ControllerModel,
    params: Mapping[str, Any] | None = None,
    *,
    field: str = "make_controller",
) -> Controller:
    """The controller ``name`` on ``model`` with ``params`` (see :func:`make_controller`).

    A value the controller refuses (out of range) is one line naming the parameters given.
    """
    effective = controller_parameters(name, params, field=field)
    try:
        return CONTROLLERS.get(name)(model, **effective)
    except ValueError as exc:
        if not params:
            raise
        given = ", ".join(f"{k}={v!r}" for k, v in params.items())
        raise ValueError(f"The controller {name!r} refuses {given} (in {field}): {exc}") from None
