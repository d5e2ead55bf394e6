"""A model-predictive pulse controller: the valves timed by a model of the pneumatics.

:class:`PredictivePulse` drives the pressure to the target ``p* = θ⁻¹(θr)``
(the surrogate inverted, as :class:`~softbend.control.controllers.PressureRelay`)
but decides, at every call (the loop's 1 ms tick), on a *prediction*:

- **Model.** With one valve open, the chamber of
  :class:`~softbend.control.rig.RigParams` (ISO 6358 flow, compliant volume)
  follows one autonomous ODE, so its whole response is one curve: the fill
  curve ``P_fill(τ)`` from atmosphere toward the supply and the vent curve
  ``P_vent(τ)`` from the supply toward atmosphere, integrated once (RK4, 20 µs)
  and tabulated. From any pressure ``p`` the pressure ``Δt`` later is
  ``P(T(p) + Δt)``, ``T`` the curve's inverse: a prediction costs two
  interpolations.
- **Observer.** The estimate ``p̂`` is carried forward on the curves with the
  valve states the controller knows it has commanded (each one taking effect
  ``valve_delay_s`` after its command), between samples (the sensor runs at
  100 Hz, the controller at 1 kHz) and across them; a new sample corrects it by
  ``p̂ += K·(p_measured − p̂)`` (``observer_gain`` K = 0.3: the noise of the
  estimate at rest is about 0.42·σ of the sensor's, so one noisy sample does
  not fire a pulse, while a model error is still corrected within a few
  samples).
- **Decision.** The pressure ``p_δ`` at ``t + valve_delay_s`` (when a command
  given now would act) is predicted under the commands already on their way.
  A valve that is open is closed as soon as ``p_δ`` reaches ``p*`` (less half
  of one tick's change, so the closing error is centred); with the valves shut,
  the inlet (outlet) opens when ``p* − p_δ`` is above (below minus) the
  ``deadband``. Over the prediction horizon this is the time-optimal pulse
  to ``p*`` with at most one switch on and one off per move, which is what the
  cost ``|θ(p) − θr|`` with a price on switching asks of two on/off valves.
- **Preview.** The controller sees θr only now; on a ramp it extrapolates it by
  ``preview`` (default: the valve delay plus the angle's time constant, the
  delay of a ramp through both) from the slope of the reference over its last
  calls, so the pressure leads as it must. A jump (a step or square edge) is
  not extrapolated.

The model is the rig's nominal model: on hardware, its parameters come from a
fill test (conductance, critical ratio, volume). Sensor noise enters only
through the samples; the deadband (four times the default sensor noise)
keeps the valves shut at rest.
"""

from __future__ import annotations

import math
from bisect import bisect_left
from collections.abc import Callable

from softbend.control._ranges import check_declared
from softbend.control.controllers import (
    _CLOSED,
    _FILL,
    _VENT,
    PRESSURE_BAND_RANGE,
    ControllerModel,
    ValveCommand,
    _PressureTarget,
)
from softbend.control.rig import (
    GAS_CONSTANT_J_KG_K,
    AngleTable,
    RigParams,
    chamber_pressure_rate_pa_s,
    iso6358_mass_flow_kg_s,
)
from softbend.parameters import Range, declare_ranges, declared_ranges

__all__ = ["PneumaticCurves", "PredictivePulse", "curve_step_s", "fill_time_constant_s"]


class PneumaticCurves:
    """The fill and vent responses of a rig's chamber, tabulated once (gauge MPa, s).

    Parameters
    ----------
    params : RigParams
        Supply, valves, chamber and gas of the rig (the valve delay is not used here).
    step_s : float, optional
        RK4 step of the integration; default 2e-5 s, or less for a chamber that
        fills in under 10 ms (:func:`curve_step_s`), or more for one that takes
        longer than a second, so that a curve takes tens of thousands of steps
        whatever the rig.
    """

    def __init__(self, params: RigParams, *, step_s: float | None = None) -> None:
        q = params
        step_s = curve_step_s(q) if step_s is None else step_s
        atm = q.atmosphere_mpa * 1e6
        supply = atm + q.supply_gauge_mpa * 1e6
        volume = q.volume_mm3 * 1e-9
        compliance = q.compliance_mm3_per_mpa * 1e-15

        def rate(p: float, inlet: bool) -> float:
            if inlet:
                flow = iso6358_mass_flow_kg_s(
                    supply, p, q.inlet_conductance_m3_s_pa, q.critical_ratio, q.temperature_k
                )
            else:
                flow = -iso6358_mass_flow_kg_s(
                    p, atm, q.outlet_conductance_m3_s_pa, q.critical_ratio, q.temperature_k
                )
            return chamber_pressure_rate_pa_s(
                p,
                flow,
                atmosphere_pa=atm,
                volume_m3=volume,
                compliance_m3_pa=compliance,
                temperature_k=q.temperature_k,
                polytropic_exponent=q.polytropic_exponent,
            )

        span = supply - atm
        self.fill_t, self.fill_p = _integrate(atm, supply - 1e-3 * span, True, rate, step_s, atm)
        self.vent_t, self.vent_p = _integrate(supply, atm + 1e-3 * span, False, rate, step_s, atm)
        # vent pressures fall: keep them rising for bisection
        self._vent_p_rising = self.vent_p[::-1]
        self._vent_t_rising = self.vent_t[::-1]

    def after(self, p_mpa: float, dt_s: float, command: ValveCommand) -> float:
        """Pressure ``dt_s`` after ``p_mpa`` with ``command`` held (gauge MPa)."""
        if dt_s <= 0.0:
            return p_mpa
        inlet, outlet = command
        if inlet and not outlet:
            tau = _interp(self.fill_p, self.fill_t, p_mpa)
            return _interp(self.fill_t, self.fill_p, tau + dt_s)
        if outlet and not inlet:
            tau = _interp(self._vent_p_rising, self._vent_t_rising, p_mpa)
            return _interp(self.vent_t, self.vent_p, tau + dt_s)
        return p_mpa  # shut (both open is never commanded: held as shut)


def fill_time_constant_s(params: RigParams) -> float:
    """The time the chamber takes to fill at its choked flow through the slower valve, s.

    ``(p_supply − p_atm)·V_max / (n·R·T·ṁ)`` with ``V_max`` the chamber's largest
    effective volume (compliance included) and ``ṁ`` the choked mass flow from
    the supply: an upper estimate of the scale of the fill and vent curves.
    """
    q = params
    atm = q.atmosphere_mpa * 1e6
    supply = atm + q.supply_gauge_mpa * 1e6
    span = supply - atm
    compliance = q.compliance_mm3_per_mpa * 1e-15
    n = q.polytropic_exponent
    volume = q.volume_mm3 * 1e-9 + compliance * span + n * supply * compliance
    conductance = min(q.inlet_conductance_m3_s_pa, q.outlet_conductance_m3_s_pa)
    flow = iso6358_mass_flow_kg_s(supply, 0.0, conductance, q.critical_ratio, q.temperature_k)
    return span * volume / (n * GAS_CONSTANT_J_KG_K * q.temperature_k * flow)


def curve_step_s(params: RigParams) -> float:
    """The RK4 step of :class:`PneumaticCurves` for ``params``, s.

    2e-5 s (the default rig fills in about 0.7 s), kept within 1/40 000 and
    1/500 of :func:`fill_time_constant_s`: a slow chamber takes at most about
    50 000 steps per curve, a fast one at least 500; and at most 10 ms, so a
    chamber too slow to fill within the 60 s a curve is followed for still has
    thousands of points on it.
    """
    tau = fill_time_constant_s(params)
    return min(max(2e-5, tau / 40_000.0), tau / 500.0, 0.01)


def _integrate(
    start_pa: float,
    stop_pa: float,
    inlet: bool,
    rate: Callable[[float, bool], float],
    h: float,
    atm: float,
) -> tuple[list[float], list[float]]:
    """RK4 from ``start_pa`` until ``stop_pa`` is passed; (times s, gauge MPa), every 5th step."""
    t, p = 0.0, start_pa
    times, pressures = [0.0], [(p - atm) * 1e-6]
    rising = stop_pa > start_pa
    i = 0
    while (p < stop_pa) if rising else (p > stop_pa):
        k1 = rate(p, inlet)
        k2 = rate(p + 0.5 * h * k1, inlet)
        k3 = rate(p + 0.5 * h * k2, inlet)
        k4 = rate(p + h * k3, inlet)
        p += h * (k1 + 2 * k2 + 2 * k3 + k4) / 6.0
        t += h
        i += 1
        if i % 5 == 0:
            times.append(t)
            pressures.append((p - atm) * 1e-6)
        if t > 60.0:  # pragma: no cover - a rig that never fills
            break
    return times, pressures


def _interp(xs: list[float], ys: list[float], x: float) -> float:
    """Linear interpolation on increasing ``xs``, clamped at the ends."""
    if x <= xs[0]:
        return ys[0]
    if x >= xs[-1]:
        return ys[-1]
    i = bisect_left(xs, x)
    x0, x1 = xs[i - 1], xs[i]
    return ys[i - 1] + (x - x0) / (x1 - x0) * (ys[i] - ys[i - 1])


@declare_ranges(
    deadband=PRESSURE_BAND_RANGE,
    observer_gain=Range(
        0.0, 1.0, "",
        "weight of a new sample against the prediction: 0 would ignore the sensor, 1 trusts "
        "each sample alone",
        low_inclusive=False,
    ),
    preview=Range(
        0.0, 2.0, "s",
        "how far a ramping reference is extrapolated: at most the longest valve delay (1 s) "
        "plus the longest angle lag (1 s) of the simulated rig",
    ),
    tick=Range(
        1e-5, 0.1, "s",
        "the period the controller is called at: from the rig's finest step (1e-5 s) to "
        "0.1 s, beyond which a pulse cannot be timed within a move",
    ),
)  # fmt: skip
class PredictivePulse(_PressureTarget):
    """Model-predictive pulses of the valves toward θ⁻¹(θr), timed by a model of the pneumatics.

    See the module's documentation.

    Parameters
    ----------
    angle_table : ControllerModel or AngleTable
        θ(p) of the controlled actuator (the surrogate), inverted on its rising
        branch; a :class:`~softbend.control.controllers.ControllerModel` gives
        its ``rig`` as ``params`` too.
    params : RigParams, optional
        The rig model (default :class:`RigParams`); its ``valve_delay_s`` is the
        prediction horizon.
    deadband : float, default 0.002
        Pressure error without a pulse, MPa: four times the default sensor
        noise (on a ramp, the size of the pulses: a trade of tracking error for
        switches; on the default rig 0.0015 gives triangle MAPE 2.3 % with 302
        switches, 0.002 2.85 % with 224).
    observer_gain : float, default 0.3
        Weight of a new sample against the prediction, in (0, 1].
    preview : float, optional
        How far a ramping reference is extrapolated, s (default
        ``valve_delay_s + angle_time_constant_s`` of ``params``; recorded as null).
    tick : float, default 0.001
        The period the controller is called at (the loop's tick), s.
    """

    def __init__(
        self,
        angle_table: ControllerModel | AngleTable,
        params: RigParams | None = None,
        *,
        deadband: float = 0.002,
        observer_gain: float = 0.3,
        preview: float | None = None,
        tick: float = 0.001,
    ) -> None:
        if params is None and isinstance(angle_table, ControllerModel):
            params = angle_table.rig
        super().__init__(angle_table)
        self.params = RigParams() if params is None else params
        ranges = declared_ranges(PredictivePulse)
        self.deadband = check_declared(deadband, "deadband", ranges["deadband"])
        self.observer_gain = check_declared(observer_gain, "observer_gain", ranges["observer_gain"])
        self.tick = check_declared(tick, "tick", ranges["tick"])
        self.delay_s = self.params.valve_delay_s
        default_preview = self.delay_s + self.params.angle_time_constant_s
        self.preview = check_declared(
            default_preview if preview is None else preview, "preview", ranges["preview"]
        )
        self.curves = PneumaticCurves(self.params)
        self.reset()

    def reset(self) -> None:
        self._command = _CLOSED
        self._queue: list[tuple[float, ValveCommand]] = []  # (time it acts, command)
        self._actual = _CLOSED
        self._last_meas = math.nan
        self._estimate = math.nan
        self._estimate_t = 0.0
        self._prev_ref = math.nan
        self._prev_ref_t = math.nan
        self._slope = 0.0
        self.predicted_deg = math.nan

    def _propagate(self, p: float, t0: float, t1: float) -> tuple[float, ValveCommand]:
        """Carry ``p`` from ``t0`` to ``t1`` through the commands on their way."""
        state = self._actual
        after = self.curves.after
        for t_act, command in self._queue:
            if t_act <= t0:
                state = command
                continue
            if t_act >= t1:
                break
            p = after(p, t_act - t0, state)
            t0, state = t_act, command
        return after(p, t1 - t0, state), state

    def _preview(self, reference_deg: float, t_s: float) -> float:
        """The reference's change over ``preview`` on a ramp; 0 after a jump or at rest."""
        dt = t_s - self._prev_ref_t
        if dt > 0.0:
            change = reference_deg - self._prev_ref
            # a ramp moves less than 1° per tick; a bigger change is an edge
            jump = abs(change) > max(1.0, 1000.0 * dt * 1.0)
            self._slope = 0.0 if jump else change / dt
            self._prev_ref, self._prev_ref_t = reference_deg, t_s
        elif self._prev_ref != self._prev_ref:
            self._prev_ref, self._prev_ref_t = reference_deg, t_s
        return self._slope * self.preview

    def step(self, measurement_mpa: float, reference_deg: float, t_s: float) -> ValveCommand:
        # retire the commands that have acted
        queue = self._queue
        while queue and queue[0][0] <= t_s:
            self._actual = queue.pop(0)[1]
        # observer: carry the estimate forward, correct it by a new sample
        if self._estimate != self._estimate:  # the first sample
            self._estimate = measurement_mpa
        else:
            self._estimate, _ = self._propagate(self._estimate, self._estimate_t, t_s)
        if measurement_mpa != self._last_meas:
            self._estimate += self.observer_gain * (measurement_mpa - self._estimate)
        self._last_meas = measurement_mpa
        self._estimate_t = t_s
        self.predicted_deg = self.angle_table(self._estimate)
        target = self.target_mpa(reference_deg + self._preview(reference_deg, t_s))
        # the pressure when a command given now would act
        ahead, _ = self._propagate(self._estimate, t_s, t_s + self.delay_s)
        command = self._command
        if command is _FILL:
            gain = self.curves.after(ahead, self.tick, _FILL) - ahead
            if ahead + 0.5 * gain >= target:
                command = _CLOSED
        elif command is _VENT:
            loss = ahead - self.curves.after(ahead, self.tick, _VENT)
            if ahead - 0.5 * loss <= target:
                command = _CLOSED
        if command is _CLOSED:
            error = target - ahead
            if error > self.deadband:
                command = _FILL
            elif error < -self.deadband:
                command = _VENT
        if command is not self._command:
            self._command = command
            queue.append((t_s + self.delay_s, command))
        return command
