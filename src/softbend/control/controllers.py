"""Controllers of the on/off valves: one small, pure interface.

``controller.step(measurement_mpa, reference_deg, t_s) -> ValveCommand`` takes the
latest pressure-sensor reading (gauge MPa, held between samples), the reference
angle and the time, and returns which valves to open. The loop calls it at every
step of the rig (1 ms: the PLC's timing), so a controller can time PWM pulses
finer than the 100 Hz sensor; each controller decides on its own sample period
``period`` (paper B: 100 Hz) and holds its decision in between. No I/O;
``reset()`` forgets all state.

- :class:`BangBang`: paper B §5 eq. (1), a deadzone relay on the angle error
  ``θd = θr − θp`` with θp the virtual angle sensor ``f(p)`` (the MLP);
- :class:`PressurePI`: the surrogate inverted to a target pressure, PI on the
  pressure with anti-windup, PWM of the valves;
- :class:`PressureRelay`: the same target pressure, a three-state relay with
  hysteresis that closes the valve early by the pressure it will still gain
  during the valve delay, with a minimum on-time.
"""

from __future__ import annotations

import math
from collections.abc import Callable
from dataclasses import dataclass
from typing import TYPE_CHECKING, NamedTuple, Protocol, cast, runtime_checkable

import numpy as np

from softbend._validation import check_choice
from softbend.actuators import Design
from softbend.control._ranges import check_declared
from softbend.control.rig import AngleTable, RigParams
from softbend.errors import InputError
from softbend.parameters import Range, declare_ranges, declared_ranges

if TYPE_CHECKING:
    from softbend.surrogates.protocol import FastSurrogate, Surrogate

__all__ = [
    "PERIOD_RANGE",
    "PRESSURE_BAND_RANGE",
    "BangBang",
    "BangBangClosed",
    "Controller",
    "ControllerModel",
    "PressurePI",
    "PressureRelay",
    "ValveCommand",
    "mlp_virtual_sensor",
]


class ValveCommand(NamedTuple):
    """Valve states to apply: ``True`` = open."""

    inlet: bool
    outlet: bool


_CLOSED = ValveCommand(False, False)
_FILL = ValveCommand(True, False)
_VENT = ValveCommand(False, True)


@runtime_checkable
class Controller(Protocol):
    """The interface every controller answers."""

    predicted_deg: float

    def step(self, measurement_mpa: float, reference_deg: float, t_s: float) -> ValveCommand: ...

    def reset(self) -> None: ...


def mlp_virtual_sensor(model: FastSurrogate, design: Design) -> Callable[[float], float]:
    """Paper B's virtual angle sensor: θp = MLP(design, p), one fast call per reading.

    ``model`` is a fitted :class:`softbend.surrogates.mlp.NormalizedMLPRegressor`
    (its ``.predictor()`` is used); returns ``f(p_mpa) -> degrees``. ``design``
    is paper B's :class:`~softbend.actuators.Design` or a
    :class:`~softbend.actuators.Design` of another actuator, whose
    model takes the pressure in its own unit (the reading in MPa is converted).
    """
    predict = model.predictor()
    codes = design.as_array()
    row = np.empty(codes.size + 1)
    row[:-1] = codes
    scale = 1.0 / design.actuator.to_mpa  # MPa to the model's pressure unit
    last = codes.size

    if scale == 1.0:

        def sensor(p_mpa: float) -> float:
            row[last] = p_mpa
            return predict(row)

        return sensor

    def scaled(p_mpa: float) -> float:
        row[last] = p_mpa * scale
        return predict(row)

    return scaled


@dataclass(frozen=True)
class ControllerModel:
    """What a controller knows of the actuator and the rig: the first argument of each.

    Every controller class takes one as its first argument (or just the part it
    uses: a θ(p) table, a virtual sensor), so a class is registered as it is
    (:data:`softbend.control.factory.CONTROLLERS`).

    Attributes
    ----------
    angle_table : AngleTable
        θ(p) of the controller's model (inverted by the pressure controllers), degrees.
    virtual_sensor : callable
        θp(p), gauge MPa → degrees, of the bang-bang controllers (paper B: the MLP).
    rig : RigParams, optional
        The rig model of ``predictive`` (default :class:`RigParams`).
    """

    angle_table: AngleTable
    virtual_sensor: Callable[[float], float]
    rig: RigParams | None = None

    @classmethod
    def from_surrogate(
        cls,
        model: Surrogate,
        design: Design,
        rig: RigParams | None = None,
        *,
        pmax_mpa: float = 0.5,
    ) -> ControllerModel:
        """θ(p) of ``model`` for ``design``; its ``.predictor()`` is the virtual sensor, if any.

        ``design`` is paper B's, or a :class:`~softbend.actuators.Design`
        of the model's actuator (its pressures converted from MPa); the table spans
        0 to ``pmax_mpa`` MPa gauge.
        """
        table = AngleTable.from_surrogate(model, design, pmax_mpa=pmax_mpa)
        fast = hasattr(model, "predictor")  # a FastSurrogate
        sensor = mlp_virtual_sensor(cast("FastSurrogate", model), design) if fast else table
        return cls(table, sensor, rig)


def _sensor_of(source: ControllerModel | Callable[[float], float]) -> Callable[[float], float]:
    """The virtual angle sensor of ``source`` (a model, or the sensor itself)."""
    sensor = source.virtual_sensor if isinstance(source, ControllerModel) else source
    if not callable(sensor):
        raise InputError("must be callable (gauge MPa -> degrees)", key="virtual_sensor")
    return sensor


def _table_of(source: ControllerModel | AngleTable) -> AngleTable:
    """The θ(p) table of ``source`` (a model, or the table itself)."""
    table = source.angle_table if isinstance(source, ControllerModel) else source
    if not (callable(table) and hasattr(table, "inverse")):
        raise InputError(
            f"must be an AngleTable (callable with .inverse); got {table!r}", key="angle_table"
        )
    return table


#: The sample period of every controller, s.
PERIOD_RANGE = Range(
    1e-4, 1.0, "s",
    "from 10 kHz, finer than any on/off valve switches, to 1 Hz: the actuator rises in about "
    "0.1 s, so a slower controller leaves it unwatched for whole moves",
)  # fmt: skip
#: A pressure error a controller leaves alone (deadband, hysteresis), MPa.
PRESSURE_BAND_RANGE = Range(
    0.0, 0.1, "MPa",
    "0 acts on any error (the sensor's noise included); above 0.1 MPa, half the default "
    "supply, most targets would never be approached",
)  # fmt: skip


def _check(cls: type, value: object, name: str) -> float:
    """``value`` of the constructor argument ``name`` of ``cls``, held to its declared range."""
    return float(check_declared(value, name, declared_ranges(cls)[name]))


@declare_ranges(
    deadzone=Range(
        0.0, 0.5, "fraction of |θr|",
        "half-width of the deadzone: 0 switches the valves at every sample; beyond 0.5 any "
        "angle from half to one and a half times the reference would count as reached",
    ),
    period=PERIOD_RANGE,
)  # fmt: skip
class BangBang:
    """Paper B's deadzone bang-bang on the virtual angle; valves held in the deadzone.

    Every ``period`` (100 Hz): ``θp = virtual_sensor(p)``, ``θd = θr − θp``,
    ``dz = deadzone·|θr|``; ``θd > dz`` → inlet open, outlet closed;
    ``θd < −dz`` → outlet open, inlet closed; inside the deadzone the valves keep
    their last state (``mode="hold"``) or both close (``mode="closed"``,
    :class:`BangBangClosed`): paper B "allowed the state of the valves to remain
    unchanged", read both ways.

    Parameters
    ----------
    virtual_sensor : ControllerModel or callable
        Gauge MPa → degrees (:func:`mlp_virtual_sensor`, or an angle table), or
        the controller's model whose ``virtual_sensor`` it is.
    mode : {"hold", "closed"}, optional
        Default: the class's (``"hold"``; ``"closed"`` for :class:`BangBangClosed`).
    deadzone : float, default 0.05
        Half-width of the deadzone as a fraction of ``|θr|`` (paper B: 5 %).
    period : float, default 0.01
        Sample period of the controller, s (paper B: 100 Hz).
    """

    default_mode = "hold"

    def __init__(
        self,
        virtual_sensor: ControllerModel | Callable[[float], float],
        mode: str | None = None,
        *,
        deadzone: float = 0.05,
        period: float = 0.01,
    ) -> None:
        self.virtual_sensor = _sensor_of(virtual_sensor)
        self.deadzone = _check(BangBang, deadzone, "deadzone")
        chosen = self.default_mode if mode is None else mode
        self.mode = check_choice(chosen, "mode", ("hold", "closed"))
        self.period = _check(BangBang, period, "period")
        self.reset()

    def reset(self) -> None:
        self._command = _CLOSED
        self._next_s = -math.inf
        self.predicted_deg = math.nan

    def step(self, measurement_mpa: float, reference_deg: float, t_s: float) -> ValveCommand:
        if t_s < self._next_s:
            return self._command
        self._next_s = t_s + self.period - 1e-9
        theta = self.virtual_sensor(measurement_mpa)
        self.predicted_deg = theta
        error = reference_deg - theta
        band = self.deadzone * abs(reference_deg)
        if error > band:
            self._command = _FILL
        elif error < -band:
            self._command = _VENT
        elif self.mode == "closed":
            self._command = _CLOSED
        return self._command


class BangBangClosed(BangBang):
    """The deadzone bang-bang with both valves closed inside the deadzone.

    :class:`BangBang` with ``mode="closed"``; the same parameters.
    """

    default_mode = "closed"


class _PressureTarget:
    """Shared part: θr → target pressure by the inverse of an angle table."""

    def __init__(self, angle_table: ControllerModel | AngleTable) -> None:
        self.angle_table = _table_of(angle_table)
        self._ref = math.nan
        self._target = 0.0

    def target_mpa(self, reference_deg: float) -> float:
        if reference_deg != self._ref:
            self._ref = reference_deg
            self._target = self.angle_table.inverse(reference_deg)
        return self._target


@declare_ranges(
    kp=Range(
        0.0, 1e4, "1/MPa",
        "duty per MPa of pressure error: 0 never opens a valve; at 1e4 full duty comes from "
        "0.1 kPa, below the sensor's resolution (a relay, not a PI)",
        low_inclusive=False,
    ),
    ki=Range(
        0.0, 1e4, "1/(MPa·s)",
        "duty per MPa·s of integrated error: 0 is P control; at 1e4 the integral alone "
        "saturates within one sample of the smallest resolvable error",
    ),
    deadband=PRESSURE_BAND_RANGE,
    pwm_period=Range(
        1e-4, 1.0, "s",
        "the valves' PWM period: below 0.1 ms no on/off valve follows; beyond 1 s one pulse "
        "outlasts a whole move of the actuator",
    ),
    period=PERIOD_RANGE,
)  # fmt: skip
class PressurePI(_PressureTarget):
    """PI on the pressure toward θ⁻¹(θr), by PWM of the valves.

    Every ``period`` the PI output ``u = kp·e + ki·∫e`` (``e = p* − p`` in MPa)
    is computed; ``|e| <= deadband`` gives ``u = 0`` (valves shut at rest).
    The integral is frozen while ``|u| >= 1`` or inside the deadband (conditional
    integration: anti-windup) and clamped to ``±1/ki``. Every
    ``pwm_period`` the duty ``|u|`` (clipped to 1) is latched; the inlet
    (``u > 0``) or outlet (``u < 0``) is open for the first ``duty·pwm_period``
    of the PWM period, timed at the resolution of the calls (the rig's step).

    Parameters
    ----------
    angle_table : ControllerModel or AngleTable
        θ(p) of the controlled actuator (the surrogate), inverted on its rising branch.
    kp : float, default 50
        Proportional gain, duty per MPa of error: full duty from 0.02 MPa (tuned
        on the default rig: about twice the gain that would close a PWM period's
        error in one period).
    ki : float, default 5
        Integral gain, duty per MPa·s.
    deadband : float, default 0.002
        Pressure error without action, MPa: about 4× the sensor noise, so the
        valves stay shut at rest (≈ 3° at 90°).
    pwm_period : float, default 0.02
        PWM period of the valves, s.
    period : float, default 0.01
        Sample period of the PI, s (the sensor's rate).
    """

    def __init__(
        self,
        angle_table: ControllerModel | AngleTable,
        *,
        kp: float = 50.0,
        ki: float = 5.0,
        deadband: float = 0.002,
        pwm_period: float = 0.02,
        period: float = 0.01,
    ) -> None:
        super().__init__(angle_table)
        self.kp = _check(PressurePI, kp, "kp")
        self.ki = _check(PressurePI, ki, "ki")
        self.deadband = _check(PressurePI, deadband, "deadband")
        self.pwm_period = _check(PressurePI, pwm_period, "pwm_period")
        self.period = _check(PressurePI, period, "period")
        self.reset()

    def reset(self) -> None:
        self._integral = 0.0
        self._u = 0.0
        self._next_s = -math.inf
        self._pwm_start = -math.inf
        self._on_s = 0.0
        self._open = _CLOSED
        self.predicted_deg = math.nan

    def step(self, measurement_mpa: float, reference_deg: float, t_s: float) -> ValveCommand:
        if t_s >= self._next_s:
            self._next_s = t_s + self.period - 1e-9
            self.predicted_deg = self.angle_table(measurement_mpa)
            error = self.target_mpa(reference_deg) - measurement_mpa
            if abs(error) <= self.deadband:
                u = 0.0
            else:
                u = self.kp * error + self.ki * self._integral
                if abs(u) < 1.0 and self.ki > 0.0:
                    self._integral += error * self.period
                    limit = 1.0 / self.ki
                    self._integral = min(max(self._integral, -limit), limit)
            # a reversal of sign ends the running pulse at once
            if u * self._u < 0.0:
                self._pwm_start = -math.inf
            self._u = u
        if t_s >= self._pwm_start + self.pwm_period - 1e-9:
            self._pwm_start = t_s
            u = self._u
            self._on_s = min(abs(u), 1.0) * self.pwm_period
            self._open = _FILL if u > 0.0 else _VENT if u < 0.0 else _CLOSED
        if t_s - self._pwm_start < self._on_s - 1e-9:
            return self._open
        return _CLOSED


@declare_ranges(
    hysteresis=PRESSURE_BAND_RANGE,
    lead=Range(
        0.0, 1.5, "s",
        "how long the pressure keeps moving after a close: the valve delay (at most 1 s on "
        "the simulated rig) plus half a sample (at most 0.5 s)",
    ),
    min_on=Range(
        0.0, 1.0, "s",
        "shortest opening of a valve: beyond 1 s one pulse overfills any move of the actuator",
    ),
    period=PERIOD_RANGE,
)  # fmt: skip
class PressureRelay(_PressureTarget):
    """A three-state relay on the pressure toward θ⁻¹(θr), with lead and hysteresis.

    Every ``period``: with ``e = p* − p`` and the rate ``ṗ`` estimated from the
    last two samples, the valve opens when ``|e| > hysteresis`` and closes
    when the pressure it will still gain before the valve shuts
    (``ṗ·lead``) would reach the target; a valve once opened stays open for at
    least ``min_on``.

    Parameters
    ----------
    angle_table : ControllerModel or AngleTable
    hysteresis : float, default 0.002
        Pressure error that opens a valve, MPa.
    lead : float, default 0.012
        Valve delay plus half a sample: how long the pressure keeps moving after a close, s.
    min_on : float, default 0.0
        Shortest opening of a valve, s.
    period : float, default 0.01
        Sample period of the relay, s.
    """

    def __init__(
        self,
        angle_table: ControllerModel | AngleTable,
        *,
        hysteresis: float = 0.002,
        lead: float = 0.012,
        min_on: float = 0.0,
        period: float = 0.01,
    ) -> None:
        super().__init__(angle_table)
        self.hysteresis = _check(PressureRelay, hysteresis, "hysteresis")
        self.lead = _check(PressureRelay, lead, "lead")
        self.min_on = _check(PressureRelay, min_on, "min_on")
        self.period = _check(PressureRelay, period, "period")
        self.reset()

    def reset(self) -> None:
        self._command = _CLOSED
        self._opened_s = -math.inf
        self._next_s = -math.inf
        self._last_p = math.nan
        self._last_t = math.nan
        self.predicted_deg = math.nan

    def step(self, measurement_mpa: float, reference_deg: float, t_s: float) -> ValveCommand:
        if t_s < self._next_s:
            return self._command
        self._next_s = t_s + self.period - 1e-9
        self.predicted_deg = self.angle_table(measurement_mpa)
        rate = 0.0
        if self._last_t == self._last_t and t_s > self._last_t:
            rate = (measurement_mpa - self._last_p) / (t_s - self._last_t)
        self._last_p, self._last_t = measurement_mpa, t_s
        error = self.target_mpa(reference_deg) - measurement_mpa
        ahead = error - rate * self.lead  # error left once the valve really shuts
        command = self._command
        held = t_s - self._opened_s < self.min_on - 1e-9
        if command is _FILL:
            if ahead <= 0.0 and not held:
                command = _CLOSED
        elif command is _VENT and ahead >= 0.0 and not held:
            command = _CLOSED
        if command is _CLOSED:
            if error > self.hysteresis and ahead > 0.0:
                command = _FILL
            elif error < -self.hysteresis and ahead < 0.0:
                command = _VENT
            if command is not _CLOSED:
                self._opened_s = t_s
        self._command = command
        return command
