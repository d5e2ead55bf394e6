"""A simulated pneumatic rig of paper B §5 (Fig. 8): supply, two on/off valves, chamber, sensors.

The hardware of paper B: compressor → reducing valve → flow-control valve → inlet
on/off valve → actuator; actuator → outlet on/off valve → flow-control valve →
atmosphere; a pressure sensor read at 100 Hz; a high-speed camera that records
the true angle for evaluation only. Paper B does not give the supply pressure,
the flow settings, the chamber volume or the camera rate, so this rig states its
own (every one a field of :class:`RigParams`, with its unit in its name):

- supply 0.2 MPa gauge (the shipped MLP bends the (100,6,2,2,5,8) actuator to about 370° there,
  more than any reference used), atmosphere 0.101325 MPa absolute, air at
  293.15 K;
- each valve with its flow-control valve in series is one ISO 6358 restriction
  (:func:`iso6358_mass_flow_kg_s`) of sonic conductance 4e-10 m³/(s·Pa)
  (0.04 dm³/(s·bar): a throttled needle valve) and critical pressure ratio 0.3;
  with these, paper B's bang-bang takes the actuator from rest to 90° in about
  0.1 s, the order of paper B's 0.104 s rise time;
- the valves switch 5 ms after the command;
- the chamber holds ideal gas in ``V(p) = V0 + (dV/dp)·p`` (p gauge); ``V0`` =
  7655 mm³ = the semicircular cavity ½·π·r²·l of the (100,6,2,2,5,8) actuator
  (5655 mm³) plus 2000 mm³ of tubing (:meth:`RigParams.for_design` recomputes
  it for another design; :func:`softbend.control.rigs.rig_params_for` takes another
  actuator's from its description or a measured value); ``dV/dp`` = 50 600 mm³/MPa,
  the FEM's: the cavity volume of the (100,6,2,2,5,8) actuator integrated from
  its FEM sweep's dV/dp and fitted by a line up to the supply
  (:func:`cavity_compliance_mm3_per_mpa`, :meth:`RigParams.from_fem_sweep`; the
  cavity grows 2.7-fold by 0.18 MPa);
  isothermal (polytropic exponent 1.0) unless set;
- the angle follows the quasi-static θ(p) through a first-order lag of 30 ms
  (or, given an :class:`AngleDynamics`, a dynamic model such as an identified
  one: :mod:`softbend.control.identified_plant`);
- the pressure sensor has 0.5 kPa Gaussian noise and 12-bit quantisation over
  0–0.5 MPa gauge; the camera runs at 240 fps, no latency, 0.2° noise.

Integration uses a fixed step (1 ms default): Heun's method for the chamber
pressure, clamped to [atmosphere, supply] (no valve can push the chamber beyond
its sources, so the clamp keeps a choked fill into a small volume from
overshooting), and the exact discretisation of the angle lag. Pressures are in
pascal inside the rig and in MPa gauge at its interface.
"""

from __future__ import annotations

import math
import random
from bisect import bisect_right
from collections.abc import Callable
from dataclasses import dataclass, fields, replace
from typing import TYPE_CHECKING, Any, Protocol, runtime_checkable

import numpy as np
from numpy.typing import ArrayLike

from softbend._validation import check_int, check_range
from softbend.actuators import Design
from softbend.control._ranges import check_declared
from softbend.parameters import Range, declare_ranges
from softbend.plausibility import RANGES as PLAUSIBLE

if TYPE_CHECKING:
    from softbend.models import BendingModel, SweepResult
    from softbend.surrogates.protocol import Surrogate

__all__ = [
    "ANR_DENSITY_KG_M3",
    "ANR_TEMPERATURE_K",
    "GAS_CONSTANT_J_KG_K",
    "RIG_RANGES",
    "TUBING_RANGE",
    "AngleDynamics",
    "AngleTable",
    "Rig",
    "RigParams",
    "SimulatedRig",
    "cavity_compliance_mm3_per_mpa",
    "chamber_pressure_rate_pa_s",
    "iso6358_mass_flow_kg_s",
]

#: Specific gas constant of dry air, J/(kg·K).
GAS_CONSTANT_J_KG_K = 287.05
#: ISO 6358 reference (ANR) conditions: 293.15 K, 100 kPa, 1.185 kg/m³.
ANR_TEMPERATURE_K = 293.15
ANR_DENSITY_KG_M3 = 1.185


def iso6358_mass_flow_kg_s(
    p_up_pa: float,
    p_down_pa: float,
    conductance_m3_s_pa: float,
    critical_ratio: float,
    temperature_k: float = ANR_TEMPERATURE_K,
) -> float:
    """Mass flow through a restriction by ISO 6358, kg/s, from ``p_up`` to ``p_down``.

    Choked when ``p_down/p_up <= b``: ``q = C·p_up·ρ0·sqrt(T0/T)``, independent
    of the downstream pressure; subsonic otherwise: that times
    ``sqrt(1 - ((p_down/p_up - b)/(1 - b))²)``, which is continuous at the
    critical ratio and zero at equal pressures. Reverse flow (``p_down > p_up``)
    is returned negative with the roles swapped.

    Parameters
    ----------
    p_up_pa, p_down_pa : float
        Absolute pressures, Pa.
    conductance_m3_s_pa : float
        Sonic conductance C, m³/(s·Pa) (ANR).
    critical_ratio : float
        Critical pressure ratio b, in [0, 1).
    temperature_k : float
        Upstream temperature, K.
    """
    if p_down_pa > p_up_pa:
        return -iso6358_mass_flow_kg_s(
            p_down_pa, p_up_pa, conductance_m3_s_pa, critical_ratio, temperature_k
        )
    if p_up_pa <= 0.0 or p_down_pa == p_up_pa:
        return 0.0
    choked = (
        conductance_m3_s_pa
        * p_up_pa
        * ANR_DENSITY_KG_M3
        * math.sqrt(ANR_TEMPERATURE_K / temperature_k)
    )
    ratio = p_down_pa / p_up_pa
    if ratio <= critical_ratio:
        return choked
    x = (ratio - critical_ratio) / (1.0 - critical_ratio)
    return choked * math.sqrt(max(0.0, 1.0 - x * x))


def chamber_pressure_rate_pa_s(
    p_pa: float,
    mass_flow_kg_s: float,
    *,
    atmosphere_pa: float,
    volume_m3: float,
    compliance_m3_pa: float,
    temperature_k: float = ANR_TEMPERATURE_K,
    polytropic_exponent: float = 1.0,
) -> float:
    """dp/dt of gas in a compliant chamber, Pa/s.

    With ``V = V0 + k·(p - p_atm)`` and ``p·V = m·R·T`` (isothermal, ``n = 1``),
    ``d(pV)/dt = R·T·ṁ`` gives ``dp/dt = R·T·ṁ / (V + p·k)``. For a polytropic
    exponent ``n`` this uses ``dp/dt = n·(R·T·ṁ − p·dV/dt)/V``, i.e.
    ``n·R·T·ṁ / (V + n·p·k)``, with the gas temperature held at ``T`` (a common
    simplification: the wall exchanges heat, the fill compresses).
    """
    volume = volume_m3 + compliance_m3_pa * (p_pa - atmosphere_pa)
    n = polytropic_exponent
    return (
        n
        * GAS_CONSTANT_J_KG_K
        * temperature_k
        * mass_flow_kg_s
        / (volume + n * p_pa * compliance_m3_pa)
    )


def cavity_compliance_mm3_per_mpa(
    pressures_mpa: ArrayLike, volume_rates_mm3_per_mpa: ArrayLike, up_to_mpa: float
) -> float:
    """The slope k of ``V(p) ≈ V0 + k·p`` fitted to an FEM sweep's cavity volume, mm³/MPa.

    ``V(p) − V(0)`` is integrated from the sweep's ``dV/dp`` at its converged
    steps (trapezoids) and fitted by least squares through the origin on the
    steps up to ``up_to_mpa`` (the supply). The FEM's dV/dp varies along the
    sweep (stiff at first, softer as the walls thin): this is the best straight
    line over the range the rig uses.
    """
    p = np.asarray(pressures_mpa, dtype=float)
    rate = np.asarray(volume_rates_mm3_per_mpa, dtype=float)
    keep = np.isfinite(p) & np.isfinite(rate)
    p, rate = p[keep], rate[keep]
    if p.size < 2:
        raise ValueError(
            "The FEM sweep must have at least two converged steps with a cavity dV/dp to fit "
            f"the rig's compliance. Got {p.size} instead."
        )
    volume = np.concatenate([[0.0], np.cumsum(0.5 * (rate[1:] + rate[:-1]) * np.diff(p))])
    volume -= np.interp(0.0, p, volume)
    inside = p <= up_to_mpa + 1e-12
    q, v = p[inside], volume[inside]
    return float(np.dot(q, v) / np.dot(q, q))


#: The range of each field of :class:`RigParams` (declared on it; ``--rig-param``, a rig
#: TOML's [simulation] table and RigParams itself are held to them).
RIG_RANGES: dict[str, Range] = {
    "supply_gauge_mpa": Range(
        0.0, PLAUSIBLE["pressure_mpa"].high, "MPa",
        "gauge, behind the inlet valve; "
        f"{PLAUSIBLE['pressure_mpa'].high:g} MPa bursts any silicone actuator",
        low_inclusive=False,
    ),
    "atmosphere_mpa": Range(
        0.03, 0.11, "MPa",
        "absolute: from a mountain top (0.034 MPa on the highest) to the highest sea-level "
        "pressure on record (0.108 MPa)",
    ),
    "temperature_k": Range(
        223.15, 373.15, "K", "−50 °C to 100 °C: compressed air within an elastomer's service range"
    ),
    "inlet_conductance_m3_s_pa": Range(
        1e-12, 1e-7, "m³/(s·Pa)",
        "ISO 6358 sonic conductance C from a needle valve nearly shut (1e-12: 1e-4 dm³/(s·bar)) "
        "to a large solenoid valve (1e-7: 10 dm³/(s·bar))",
    ),
    "outlet_conductance_m3_s_pa": Range(
        1e-12, 1e-7, "m³/(s·Pa)",
        "as the inlet's: a needle valve nearly shut to a large solenoid valve",
    ),
    "critical_ratio": Range(
        0.0, 0.95, "",
        "ISO 6358 critical pressure ratio b: real valves lie in 0.1–0.6, and at 1 the "
        "subsonic law divides by zero",
    ),
    "valve_delay_s": Range(
        0.0, 1.0, "s",
        "from a valve command to the valve switching: solenoid valves take 1–50 ms; a second "
        "is beyond any valve",
    ),
    "volume_mm3": Range(
        1.0, 1e8, "mm³",
        "the chamber at 0 MPa gauge, from a droplet to 100 L, which holds the largest "
        "design's cavity (½·π·100²·1000 mm³) with its tubing",
    ),
    "compliance_mm3_per_mpa": Range(
        0.0, 1e9, "mm³/MPa",
        "growth of the chamber with pressure: 0 is rigid; 1e9 (a cubic metre per MPa) is "
        "beyond any design's cavity",
    ),
    "polytropic_exponent": Range(
        1.0, 1.4, "", "1 isothermal to 1.4 adiabatic (air's ratio of specific heats)"
    ),
    "angle_time_constant_s": Range(
        0.0, 1.0, "s",
        "lag of the angle behind θ(p): tens of ms for an elastomer; an angle that has not "
        "followed its pressure within a second is no longer quasi-static",
    ),
    "sensor_noise_mpa": Range(
        0.0, 0.1, "MPa",
        "standard deviation of the pressure reading: above 0.1 MPa, half the default supply, "
        "a reading says nothing",
    ),
    "sensor_bits": Range(
        0, 32, "bits", "resolution of the pressure sensor (0: none); 32 is finer than any ADC"
    ),
    "sensor_range_mpa": Range(
        0.01, 10.0, "MPa", "full scale of the pressure sensor: transducers span 10 kPa to 10 MPa"
    ),
    "camera_fps": Range(
        1.0, 1e5, "frames/s", "from one frame a second to a high-speed camera's 100 000"
    ),
    "camera_latency_s": Range(
        0.0, 1.0, "s", "delay of the camera's angle; the frames in flight are queued"
    ),
    "camera_noise_deg": Range(
        0.0, 10.0, "°",
        "standard deviation of the camera angle: beyond 10° it says little of a 90° bend",
    ),
    "step_s": Range(
        1e-5, 0.01, "s",
        "integration step of the rig model: below 1e-5 s a run of the documented duration "
        "would allocate gigabytes; above 0.01 s the step is longer than the valve timing and "
        "the angle lag it resolves",
    ),
}  # fmt: skip

#: The range of the tubing volume added to a design's cavity (:meth:`RigParams.for_design`).
TUBING_RANGE = Range(
    0.0, 1e6, "mm³",
    "tubing between the inlet valve and the actuator: up to 1 L (80 m of 4 mm bore)",
)  # fmt: skip


@declare_ranges(**RIG_RANGES)
@dataclass(frozen=True)
class RigParams:
    """Every parameter of :class:`SimulatedRig`, with units in the names (see the module doc).

    Each field is held to its declared range (:data:`RIG_RANGES`); a value out of
    it, not finite or of the wrong kind is one ``ValueError`` naming it.
    """

    supply_gauge_mpa: float = 0.2
    atmosphere_mpa: float = 0.101325
    temperature_k: float = ANR_TEMPERATURE_K
    inlet_conductance_m3_s_pa: float = 4e-10
    outlet_conductance_m3_s_pa: float = 4e-10
    critical_ratio: float = 0.3
    valve_delay_s: float = 0.005
    volume_mm3: float = 7655.0
    compliance_mm3_per_mpa: float = 50_600.0
    polytropic_exponent: float = 1.0
    angle_time_constant_s: float = 0.03
    sensor_noise_mpa: float = 0.0005
    sensor_bits: int = 12
    sensor_range_mpa: float = 0.5
    camera_fps: float = 240.0
    camera_latency_s: float = 0.0
    camera_noise_deg: float = 0.2
    step_s: float = 0.001

    def __post_init__(self) -> None:
        for f in fields(self):
            value = check_declared(
                getattr(self, f.name), f.name, RIG_RANGES[f.name], integer=f.name == "sensor_bits",
            )  # fmt: skip
            object.__setattr__(self, f.name, value)

    @classmethod
    def from_fem_sweep(
        cls, result: SweepResult, *, tubing_mm3: float = 2000.0, **kwargs: Any
    ) -> RigParams:
        """Parameters whose chamber is the FEM's: ``V0`` of the design, ``dV/dp`` of its sweep.

        ``result`` is a :class:`softbend.models.SweepResult` of the FEM (its
        ``stats`` hold the steps' pressures and cavity ``dV/dp``); the compliance
        is :func:`cavity_compliance_mm3_per_mpa` up to the supply pressure.
        """
        stats = getattr(result, "stats", None) or {}
        if "step_volume_rate_mm3_per_mpa" not in stats:
            raise ValueError(
                "The 'result' of RigParams.from_fem_sweep must be an FEM sweep (its stats "
                "record step_volume_rate_mm3_per_mpa); this one does not."
            )
        if getattr(result.design, "cavity_volume_mm3", None) is None:
            family = result.design.actuator.name
            raise ValueError(
                "The 'result' of RigParams.from_fem_sweep must be a sweep of a design whose "
                "geometry gives its cavity volume (the rig's chamber), as paper B's does; got a "
                f"design of {family!r}."
            )
        supply = kwargs.get("supply_gauge_mpa", cls.supply_gauge_mpa)
        compliance = cavity_compliance_mm3_per_mpa(
            stats["steps_mpa"], stats["step_volume_rate_mm3_per_mpa"], supply
        )
        design = result.design  # a design with a cavity, checked above
        return cls.for_design(
            design, tubing_mm3=tubing_mm3, compliance_mm3_per_mpa=compliance, **kwargs
        )

    @classmethod
    def for_design(cls, design: Design, *, tubing_mm3: float = 2000.0, **kwargs: Any) -> RigParams:
        """Parameters with ``volume_mm3`` = ½·π·r²·l of ``design`` plus ``tubing_mm3``."""
        tubing = check_declared(tubing_mm3, "tubing_mm3", TUBING_RANGE)
        volume = design.cavity_volume_mm3 + tubing
        declared = RIG_RANGES["volume_mm3"]
        if not declared.contains(volume):
            raise ValueError(
                f"The chamber of the design {design} (its cavity, {design.cavity_volume_mm3:.4g} "
                f"mm³, plus tubing_mm3 {tubing:g}) is {volume:.4g} mm³; the 'volume_mm3' of a "
                f"simulated rig must be in {declared.describe()}: give more tubing_mm3, or "
                "volume_mm3."
            )
        return cls(volume_mm3=volume, **kwargs)

    def replace(self, **changes: Any) -> RigParams:
        """A copy with some fields changed (validated again)."""
        return replace(self, **changes)

    def as_dict(self) -> dict[str, float]:
        return {f.name: getattr(self, f.name) for f in fields(self)}


class AngleTable:
    """A quasi-static angle map θ(p) as a uniform lookup table over ``[0, pmax]`` MPa gauge.

    The plant reads it every integration step, so a lookup is plain-float linear
    interpolation (clamped at the ends), far cheaper than a network call.
    :meth:`inverse` gives the pressure of an angle on the rising branch (up to
    the largest angle), by interpolation of the table.
    """

    def __init__(self, pressures_mpa: np.ndarray, angles_deg: np.ndarray) -> None:
        p = np.asarray(pressures_mpa, dtype=float)
        a = np.asarray(angles_deg, dtype=float)
        if p.ndim != 1 or p.size < 2 or a.shape != p.shape:
            raise ValueError(
                "The 'pressures_mpa' and 'angles_deg' of AngleTable must be 1-D of the same "
                f"length >= 2. Got shapes {p.shape} and {a.shape} instead."
            )
        if not (np.all(np.isfinite(p)) and np.all(np.isfinite(a))):
            raise ValueError("The 'angles_deg' of AngleTable must be finite. Got NaN or inf.")
        steps = np.diff(p)
        if p[0] != 0.0 or not np.allclose(steps, steps[0], rtol=1e-9, atol=1e-15) or steps[0] <= 0:
            raise ValueError(
                "The 'pressures_mpa' of AngleTable must be a uniform increasing grid from 0. "
                f"Got {p[:3].tolist()}... instead."
            )
        self.pressures_mpa = p
        self.angles_deg = a
        self.pmax_mpa = float(p[-1])
        self._step = float(steps[0])
        self._values = a.tolist()
        self._last = len(self._values) - 1
        peak = int(np.argmax(a))
        # rising branch, made strictly increasing for the inverse
        rise = np.maximum.accumulate(a[: peak + 1])
        self._rise_p = p[: peak + 1]
        self._rise_a = rise
        self._rise_p_list = self._rise_p.tolist()
        self._rise_a_list = rise.tolist()
        self.max_angle_deg = float(a[peak])
        self.min_angle_deg = float(a[0])

    @classmethod
    def from_callable(
        cls,
        angle_of_pressure: Callable[[np.ndarray], Any],
        pmax_mpa: float = 0.5,
        points: int = 501,
    ) -> AngleTable:
        """Tabulate a vectorised ``θ(p)`` (array of MPa gauge → degrees) on ``points`` values."""
        pmax = check_range(pmax_mpa, "pmax_mpa", low=0.0)
        n = check_int(points, "points", low=2)
        p = np.linspace(0.0, pmax, n)
        return cls(p, np.asarray(angle_of_pressure(p), dtype=float).reshape(-1))

    @classmethod
    def from_surrogate(
        cls,
        model: Surrogate,
        design: Design,
        pmax_mpa: float = 0.5,
        points: int = 501,
    ) -> AngleTable:
        """Tabulate a fitted surrogate (``.predict`` on the rows ``design.feature_rows(p)``).

        ``design`` is paper B's :class:`~softbend.actuators.Design` (rows of
        :data:`softbend.design.FEATURES`) or a
        :class:`~softbend.actuators.Design` of another actuator (rows of
        its design codes and the pressure in its model's unit); the table is in MPa.
        """
        return cls.from_callable(
            lambda p: model.predict(design.feature_rows(p, unit="MPa")),
            pmax_mpa=pmax_mpa,
            points=points,
        )

    @classmethod
    def from_bending_model(
        cls, model: BendingModel, design: Design, pmax_mpa: float = 0.5, points: int = 101
    ) -> AngleTable:
        """Tabulate a :class:`softbend.models.BendingModel` by one sweep (converged at every p)."""
        p = np.round(np.linspace(0.0, pmax_mpa, points), 12)
        sweep = model.sweep(design, p)
        angles = np.asarray(sweep.angle_deg, dtype=float)
        if angles.shape != p.shape or not np.all(np.isfinite(angles)):
            raise ValueError(
                f"The bending model must converge on the whole grid 0–{pmax_mpa:g} MPa to "
                f"tabulate θ(p); it stopped after {int(np.isfinite(angles).sum())} of "
                f"{p.size} pressures."
            )
        return cls(p, angles)

    def __call__(self, p_mpa: float) -> float:
        """θ at gauge pressure ``p_mpa`` (clamped to the table), degrees."""
        x = p_mpa / self._step
        if x <= 0.0:
            return self._values[0]
        i = int(x)
        if i >= self._last:
            return self._values[self._last]
        lo = self._values[i]
        return lo + (x - i) * (self._values[i + 1] - lo)

    def inverse(self, angle_deg: float) -> float:
        """Gauge pressure (MPa) of ``angle_deg`` on the rising branch, clamped to it.

        Plain-float bisection (a controller calls it at every change of a ramping
        reference); equal to ``numpy.interp`` on the branch.
        """
        a, p = self._rise_a_list, self._rise_p_list
        if not angle_deg > a[0]:
            return p[0]
        if angle_deg >= a[-1]:
            return p[-1]
        i = bisect_right(a, angle_deg)
        a0, a1 = a[i - 1], a[i]
        if a1 == a0:
            return p[i]
        return p[i - 1] + (angle_deg - a0) / (a1 - a0) * (p[i] - p[i - 1])


@runtime_checkable
class AngleDynamics(Protocol):
    """A dynamic model of the angle that replaces θ(p) and its first-order lag in the rig.

    :class:`SimulatedRig` calls :meth:`reset` at its own reset (the angle at
    rest, degrees) and :meth:`advance` after every integration step with the
    true gauge pressure at its end (MPa) and the step (s); it returns the true
    angle then, degrees. One object serves one rig at a time (it holds the state).
    :class:`softbend.control.identified_plant.NARXAngle` is one: an identified
    NARX model stepped at its sample period.
    """

    def reset(self) -> float: ...

    def advance(self, pressure_mpa: float, dt_s: float) -> float: ...


@runtime_checkable
class Rig(Protocol):
    """What the fixed-period loop (:func:`softbend.control.loop.run_loop`) needs from a rig.

    Implemented by :class:`SimulatedRig` (simulated time: ``sleep_until``
    integrates), :class:`softbend.control.realtime.WallClockRig` (the simulation
    kept in step with the wall clock) and :class:`softbend.control.modbus.ModbusRig`
    (hardware over Modbus: ``sleep_until`` waits).

    ``clock_s()`` is the rig's time, s; ``sleep_until(t)`` returns at rig time
    ``t`` or just after; ``read_pressure_mpa()`` is one sensor reading, gauge
    MPa (a failed, garbage or stale reading raises
    :class:`softbend.errors.RigError`); ``read_angle_deg()`` is the latest angle
    of an evaluation sensor (camera), NaN where the rig has none;
    ``command(inlet, outlet)`` sets the valves (``True`` = open); ``close()``
    releases the rig (the loop vents it first). Optional, for the record of a
    run: ``synthetic`` (``True`` for a simulation) and ``where`` (its address,
    e.g. ``"tcp://10.0.0.5:502"``, or ``"simulated"``).
    """

    def clock_s(self) -> float: ...

    def sleep_until(self, t_s: float) -> None: ...

    def read_pressure_mpa(self) -> float: ...

    def read_angle_deg(self) -> float: ...

    def command(self, inlet: bool, outlet: bool) -> None: ...

    def close(self) -> None: ...


class SimulatedRig:
    """The simulated rig: state, one fixed-step integrator, sensors.

    Parameters
    ----------
    angle_map : callable
        Quasi-static θ(p), gauge MPa → degrees; an :class:`AngleTable` is fastest
        (:func:`softbend.control.plants.shipped_angle_table` gives the shipped MLP's).
    params : RigParams, optional
    seed : int
        Seed of the sensor and camera noise.
    dynamics : AngleDynamics, optional
        A dynamic model of the angle (an identified model): when given, the true
        angle is its output for the chamber pressure, and ``angle_map`` and
        ``angle_time_constant_s`` are not used for it.

    Attributes (state, SI inside): ``t_s``, ``p_pa`` (absolute), ``angle_deg``
    (true), ``inlet_open``, ``outlet_open`` (actual valve states), ``air_used_kg``
    (mass drawn from the supply), ``switches`` (valve state changes).
    """

    synthetic = True
    where = "simulated"

    def __init__(
        self,
        angle_map: Callable[[float], float],
        params: RigParams | None = None,
        *,
        seed: int = 0,
        dynamics: AngleDynamics | None = None,
    ) -> None:
        if not callable(angle_map):
            raise ValueError(
                f"The 'angle_map' of SimulatedRig must be callable. Got {angle_map!r} instead."
            )
        if dynamics is not None and not isinstance(dynamics, AngleDynamics):
            raise ValueError(
                "The 'dynamics' of SimulatedRig must have reset() and advance(pressure_mpa, "
                f"dt_s). Got {dynamics!r} instead."
            )
        self.params = RigParams() if params is None else params
        self.angle_map = angle_map
        self.dynamics = dynamics
        self.step_s = self.params.step_s
        self.seed = check_int(seed, "seed", low=0)
        self._derive()
        self.reset(seed)

    def _derive(self) -> None:
        q = self.params
        self._patm = q.atmosphere_mpa * 1e6
        self._psup = (q.atmosphere_mpa + q.supply_gauge_mpa) * 1e6
        scale = ANR_DENSITY_KG_M3 * math.sqrt(ANR_TEMPERATURE_K / q.temperature_k)
        self._cin = q.inlet_conductance_m3_s_pa * scale
        self._cout = q.outlet_conductance_m3_s_pa * scale
        self._b = q.critical_ratio
        self._v0 = q.volume_mm3 * 1e-9
        self._k = q.compliance_mm3_per_mpa * 1e-9 * 1e-6  # m³/Pa
        self._n = q.polytropic_exponent
        self._rt = GAS_CONSTANT_J_KG_K * q.temperature_k
        self._lag = (
            1.0 - math.exp(-q.step_s / q.angle_time_constant_s)
            if q.angle_time_constant_s > 0
            else 1.0
        )
        self._delay_steps = round(q.valve_delay_s / q.step_s)
        self._lsb = q.sensor_range_mpa / (2**q.sensor_bits - 1) if q.sensor_bits > 0 else 0.0
        self._frame_s = 1.0 / q.camera_fps
        self._latency_steps = round(q.camera_latency_s / q.step_s)

    def reset(self, seed: int | None = None) -> None:
        """Back to rest: atmospheric pressure, valves closed, angle at θ(0), time 0."""
        self._rng = random.Random(self.seed if seed is None else seed)
        self.t_s = 0.0
        self._i = 0
        self.p_pa = self._patm
        if self.dynamics is None:
            self.angle_deg = float(self.angle_map(0.0))
        else:
            self.angle_deg = float(self.dynamics.reset())
        self.inlet_open = False
        self.outlet_open = False
        self._pending: list[tuple[int, bool, bool]] = []
        self.air_used_kg = 0.0
        self.switches = 0
        self._frames: list[tuple[int, float]] = []
        self._camera = math.nan
        self._next_frame = 0.0
        self._frame_now()

    @property
    def pressure_mpa(self) -> float:
        """True gauge pressure, MPa."""
        return (self.p_pa - self._patm) * 1e-6

    def read_pressure_mpa(self) -> float:
        """One sensor reading: gauge MPa + noise, quantised, clipped to the range."""
        q = self.params
        value = (self.p_pa - self._patm) * 1e-6
        if q.sensor_noise_mpa > 0.0:
            value += self._rng.gauss(0.0, q.sensor_noise_mpa)
        if self._lsb > 0.0:
            value = round(value / self._lsb) * self._lsb
        return min(max(value, 0.0), q.sensor_range_mpa)

    @property
    def commanded(self) -> tuple[bool, bool]:
        """The latest commanded (inlet, outlet), applied or still within the valve delay."""
        if self._pending:
            return self._pending[-1][1], self._pending[-1][2]
        return self.inlet_open, self.outlet_open

    def command(self, inlet: bool, outlet: bool) -> None:
        """Command the valves; they switch ``valve_delay_s`` later."""
        if self._delay_steps == 0:
            self._apply(bool(inlet), bool(outlet))
        else:
            self._pending.append((self._i + self._delay_steps, bool(inlet), bool(outlet)))

    def _apply(self, inlet: bool, outlet: bool) -> None:
        self.switches += (inlet != self.inlet_open) + (outlet != self.outlet_open)
        self.inlet_open = inlet
        self.outlet_open = outlet

    def advance(self, steps: int = 1) -> None:
        """Integrate ``steps`` fixed steps of ``step_s``."""
        h = self.step_s
        lo, hi = self._patm, self._psup
        angle_map = self.angle_map
        lag = self._lag
        b = self._b
        span = 1.0 - b
        cin, cout = self._cin, self._cout
        v0, k, n = self._v0, self._k, self._n
        nrt = n * self._rt
        sqrt = math.sqrt
        dynamics = self.dynamics
        for _ in range(steps):
            pending = self._pending
            while pending and pending[0][0] <= self._i:
                _, inlet, outlet = pending.pop(0)
                self._apply(inlet, outlet)
            inlet, outlet = self.inlet_open, self.outlet_open
            p = self.p_pa
            if inlet or outlet:
                # Heun's method on dp/dt (chamber_pressure_rate_pa_s) with the flows of
                # iso6358_mass_flow_kg_s: supply -> chamber (p <= supply, so never
                # reversed) and chamber -> atmosphere (p >= atmosphere).
                rate0 = flow0 = 0.0
                q = p
                for stage in (0, 1):
                    qin = 0.0
                    if inlet and q < hi:
                        r = q / hi
                        qin = cin * hi
                        if r > b:
                            x = (r - b) / span
                            qin *= sqrt(max(0.0, 1.0 - x * x))
                    qout = 0.0
                    if outlet and q > lo:
                        r = lo / q
                        qout = cout * q
                        if r > b:
                            x = (r - b) / span
                            qout *= sqrt(max(0.0, 1.0 - x * x))
                    rate = nrt * (qin - qout) / (v0 + k * (q - lo) + n * q * k)
                    if stage == 0:
                        rate0, flow0 = rate, qin
                        q = min(max(p + h * rate, lo), hi)
                p = min(max(p + 0.5 * h * (rate0 + rate), lo), hi)
                self.air_used_kg += 0.5 * h * (flow0 + qin)
                self.p_pa = p
            if dynamics is None:
                target = angle_map((p - lo) * 1e-6)
                self.angle_deg += lag * (target - self.angle_deg)
            else:
                self.angle_deg = dynamics.advance((p - lo) * 1e-6, h)
            self._i += 1
            self.t_s = self._i * h
            if self.t_s >= self._next_frame - 1e-12:
                self._frame_now()
            elif self._frames and self._frames[0][0] <= self._i:
                self._camera = self._frames.pop(0)[1]

    def _frame_now(self) -> None:
        noise = self.params.camera_noise_deg
        value = self.angle_deg + (self._rng.gauss(0.0, noise) if noise > 0.0 else 0.0)
        self._next_frame += self._frame_s
        if self._latency_steps == 0:
            self._camera = value
        else:
            self._frames.append((self._i + self._latency_steps, value))
        frames = self._frames
        while frames and frames[0][0] <= self._i:
            self._camera = frames.pop(0)[1]

    def camera_angle_deg(self) -> float:
        """The latest camera frame available now (NaN before the first), degrees."""
        return self._camera

    # The Rig protocol of the fixed-period loop, in simulated time.

    def clock_s(self) -> float:
        """Simulated time since :meth:`reset`, s."""
        return self.t_s

    def sleep_until(self, t_s: float) -> None:
        """Integrate up to simulated time ``t_s`` (the first step boundary at or after it)."""
        steps = math.ceil((t_s - self.t_s) / self.step_s - 1e-9)
        if steps > 0:
            self.advance(steps)

    def read_angle_deg(self) -> float:
        """The camera angle (:meth:`camera_angle_deg`), degrees."""
        return self._camera

    def close(self) -> None:
        """Nothing to release."""
