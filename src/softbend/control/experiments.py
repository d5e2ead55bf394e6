"""References, the closed loop and its metrics (paper B §5, Fig. 9).

References are parsed from short specs:

- ``step:AMP[:T0_S]``: 0° before ``T0_S`` (default 0.5 s), ``AMP`` after;
- ``square:AMP:PERIOD_S[:LOW]``: ``LOW`` (default 0°) for the first half of each
  period, ``AMP`` for the second, starting at t = 0;
- ``triangle:FREQ_HZ:AMP[:LOW]``: a triangle between ``LOW`` (default 0°) at t = 0
  and ``AMP`` at half a period.

:func:`simulate` runs a controller on a :class:`~softbend.control.rig.SimulatedRig`
and records every rig step; :func:`run_metrics` scores it on the camera angle
(as paper B did): MAPE where the reference is >= 5°, 10–90 % rise time and
settling in a ±5 % band of each rising edge, overshoot, tracking delay by
cross-correlation, valve switches and air used.
"""

from __future__ import annotations

import itertools
import math
import time
from dataclasses import dataclass, field
from typing import Any

import numpy as np

from softbend._validation import check_range

__all__ = [
    "ControlRun",
    "Reference",
    "cross_correlation_delay_s",
    "parse_reference",
    "rise_time_s",
    "run_metrics",
    "simulate",
]


@dataclass(frozen=True)
class Reference:
    """A reference angle θr(t), degrees; ``kind`` is ``step``, ``square`` or ``triangle``."""

    kind: str
    amplitude_deg: float
    period_s: float = math.inf
    low_deg: float = 0.0
    start_s: float = 0.0
    spec: str = ""

    def values(self, t_s: np.ndarray) -> np.ndarray:
        """θr at the times ``t_s`` (s), degrees."""
        t = np.asarray(t_s, dtype=float)
        if self.kind == "step":
            return np.where(t >= self.start_s, self.amplitude_deg, self.low_deg)
        phase = np.mod(t, self.period_s) / self.period_s
        if self.kind == "square":
            return np.where(phase < 0.5, self.low_deg, self.amplitude_deg)
        span = self.amplitude_deg - self.low_deg
        return self.low_deg + span * (1.0 - np.abs(2.0 * phase - 1.0))

    def __str__(self) -> str:
        return self.spec or self.kind


_USAGE = "step:AMP[:T0_S], square:AMP:PERIOD_S[:LOW] or triangle:FREQ_HZ:AMP[:LOW]"


def parse_reference(spec: str) -> Reference:
    """Parse a reference spec (see the module doc); errors name the field and its allowed values."""
    if not isinstance(spec, str) or ":" not in spec:
        raise ValueError(f"The 'reference' must be one of {_USAGE}. Got {spec!r} instead.")
    kind, *parts = spec.strip().split(":")
    kind = kind.strip().lower()
    names = {
        "step": (("amplitude_deg", "t0_s"), 1),
        "square": (("amplitude_deg", "period_s", "low_deg"), 2),
        "triangle": (("freq_hz", "amplitude_deg", "low_deg"), 2),
    }
    if kind not in names:
        raise ValueError(
            f"The 'reference' kind must be one of 'step', 'square', 'triangle' ({_USAGE}). "
            f"Got {kind!r} instead."
        )
    fields_, required = names[kind]
    if not required <= len(parts) <= len(fields_):
        raise ValueError(
            f"The 'reference' {kind} takes {required}–{len(fields_)} values "
            f"({':'.join(f.upper() for f in fields_)}). Got {len(parts)} in {spec!r} instead."
        )
    values: dict[str, float] = {}
    owner = f"reference {kind}"
    bounds = {
        "amplitude_deg": (0.0, 720.0, False),
        "low_deg": (0.0, 720.0, True),
        "t0_s": (0.0, 3600.0, True),
        "period_s": (0.0, 3600.0, False),
        "freq_hz": (0.0, 50.0, False),
    }
    for name, text in zip(fields_, parts, strict=False):
        try:
            number = float(text)
        except ValueError:
            low, high, inclusive = bounds[name]
            bracket = "[" if inclusive else "("
            raise ValueError(
                f"The '{name}' of {owner} must be a number in {bracket}{low:g}, {high:g}]. "
                f"Got {text!r} instead."
            ) from None
        low, high, inclusive = bounds[name]
        values[name] = check_range(
            number, name, owner, low=low, high=high, low_inclusive=inclusive, high_inclusive=True
        )
    low = values.get("low_deg", 0.0)
    if low >= values["amplitude_deg"]:
        raise ValueError(
            f"The 'low_deg' of {owner} must be below its 'amplitude_deg'. "
            f"Got low_deg={low:g} and amplitude_deg={values['amplitude_deg']:g} instead."
        )
    if kind == "step":
        return Reference(
            "step", values["amplitude_deg"], start_s=values.get("t0_s", 0.5), spec=spec
        )
    if kind == "square":
        return Reference("square", values["amplitude_deg"], values["period_s"], low, spec=spec)
    return Reference("triangle", values["amplitude_deg"], 1.0 / values["freq_hz"], low, spec=spec)


@dataclass(frozen=True, eq=False)
class ControlRun:
    """One closed-loop run, one row per rig step.

    Arrays: ``t_s``, ``reference_deg``, ``angle_deg`` (true), ``camera_deg``
    (camera, held between frames), ``predicted_deg`` (the controller's virtual
    angle), ``pressure_mpa`` (true, gauge), ``measured_mpa`` (sensor), ``inlet``,
    ``outlet`` (actual valve states). Scalars: ``air_used_kg``, ``switches``,
    ``wall_s`` (simulation time on the clock), ``realtime_factor``.
    """

    t_s: np.ndarray
    reference_deg: np.ndarray
    angle_deg: np.ndarray
    camera_deg: np.ndarray
    predicted_deg: np.ndarray
    pressure_mpa: np.ndarray
    measured_mpa: np.ndarray
    inlet: np.ndarray
    outlet: np.ndarray
    air_used_kg: float
    switches: int
    wall_s: float
    reference: Reference | None = None
    metadata: dict[str, Any] = field(default_factory=dict)

    @property
    def realtime_factor(self) -> float:
        """Simulated seconds per wall-clock second."""
        duration = float(self.t_s[-1] + (self.t_s[1] - self.t_s[0])) if self.t_s.size > 1 else 0.0
        return duration / self.wall_s if self.wall_s > 0 else math.inf

    def frame(self):  # -> pandas.DataFrame
        """The run as a table (one row per step)."""
        import pandas as pd

        return pd.DataFrame(
            {
                "t_s": self.t_s,
                "reference_deg": self.reference_deg,
                "angle_deg": self.angle_deg,
                "camera_deg": self.camera_deg,
                "predicted_deg": self.predicted_deg,
                "pressure_mpa": self.pressure_mpa,
                "measured_mpa": self.measured_mpa,
                "inlet": self.inlet.astype(int),
                "outlet": self.outlet.astype(int),
            }
        )


def simulate(
    rig: Any,
    controller: Any,
    reference: Reference | str,
    duration_s: float,
    *,
    sensor_period_s: float = 0.01,
    seed: int | None = None,
) -> ControlRun:
    """Run ``controller`` on ``rig`` for ``duration_s`` from rest.

    The pressure sensor is read every ``sensor_period_s`` (paper B: 100 Hz) and
    held; the controller is called at every rig step with the held reading. The
    rig and the controller are reset first (``seed`` reseeds the rig's noise).
    """
    ref = parse_reference(reference) if isinstance(reference, str) else reference
    duration = check_range(
        duration_s, "duration_s", "simulate", low=0.0, high=86400.0, high_inclusive=True
    )
    h = rig.step_s
    sensor_every = max(
        1, round(check_range(sensor_period_s, "sensor_period_s", "simulate", low=0.0) / h)
    )
    n = max(1, round(duration / h))
    t = np.arange(n) * h
    r = ref.values(t)
    r_list = r.tolist()
    rig.reset(seed)
    controller.reset()
    angle = [0.0] * n
    camera = [0.0] * n
    predicted = [0.0] * n
    pressure = [0.0] * n
    measured = [0.0] * n
    inlet = [False] * n
    outlet = [False] * n
    step = controller.step
    advance = rig.advance
    command = rig.command
    read = rig.read_pressure_mpa
    m = 0.0
    last = None
    start = time.perf_counter()
    for i in range(n):
        if i % sensor_every == 0:
            m = read()
        cmd = step(m, r_list[i], i * h)
        if cmd != last:
            command(cmd[0], cmd[1])
            last = cmd
        advance(1)
        angle[i] = rig.angle_deg
        camera[i] = rig._camera
        predicted[i] = controller.predicted_deg
        pressure[i] = rig.p_pa
        measured[i] = m
        inlet[i] = rig.inlet_open
        outlet[i] = rig.outlet_open
    wall = time.perf_counter() - start
    t_after = t + h  # states are recorded at the end of each step
    return ControlRun(
        t_s=t_after,
        reference_deg=ref.values(t_after),
        angle_deg=np.array(angle),
        camera_deg=np.array(camera),
        predicted_deg=np.array(predicted),
        pressure_mpa=(np.array(pressure) - rig.params.atmosphere_mpa * 1e6) * 1e-6,
        measured_mpa=np.array(measured),
        inlet=np.array(inlet, dtype=bool),
        outlet=np.array(outlet, dtype=bool),
        air_used_kg=float(rig.air_used_kg),
        switches=int(rig.switches),
        wall_s=wall,
        reference=ref,
    )


def rise_time_s(
    t_s: np.ndarray,
    y: np.ndarray,
    start: float,
    final: float,
    *,
    low: float = 0.1,
    high: float = 0.9,
) -> float:
    """Time from ``start + low·Δ`` to ``start + high·Δ``, ``Δ = final − start`` (first crossings).

    NaN when a level is never reached. Crossing times are interpolated linearly.
    """
    t = np.asarray(t_s, dtype=float)
    y = np.asarray(y, dtype=float)
    span = final - start
    if span == 0.0:
        return math.nan
    s = (y - start) / span  # rises from 0 to 1 either way

    def crossing(level: float) -> float:
        above = np.flatnonzero(s >= level)
        if above.size == 0:
            return math.nan
        i = int(above[0])
        if i == 0:
            return float(t[0])
        f = (level - s[i - 1]) / (s[i] - s[i - 1])
        return float(t[i - 1] + f * (t[i] - t[i - 1]))

    return crossing(high) - crossing(low)


def cross_correlation_delay_s(
    t_s: np.ndarray, reference: np.ndarray, response: np.ndarray, *, max_delay_s: float = 1.0
) -> float:
    """Delay of ``response`` behind ``reference`` maximising their cross-correlation, s.

    For each lag from 0 to ``max_delay_s`` on the uniform grid ``t_s`` the
    Pearson correlation of the overlapping parts is computed; the best lag is
    refined by a parabola through it and its neighbours.
    """
    t = np.asarray(t_s, dtype=float)
    x = np.asarray(reference, dtype=float)
    y = np.asarray(response, dtype=float)
    h = float(t[1] - t[0])
    lags = int(min(round(max_delay_s / h), len(x) // 2))

    def corr(k: int) -> float:
        a = x[: len(x) - k] - np.mean(x[: len(x) - k])
        b = y[k:] - np.mean(y[k:])
        denom = math.sqrt(float(np.dot(a, a)) * float(np.dot(b, b)))
        return float(np.dot(a, b)) / denom if denom > 0 else 0.0

    scores = np.array([corr(k) for k in range(lags + 1)])
    k = int(np.argmax(scores))
    shift = 0.0
    if 0 < k < lags:
        a, b, c = scores[k - 1], scores[k], scores[k + 1]
        denom = a - 2 * b + c
        if denom != 0:
            shift = 0.5 * (a - c) / denom
    return float((k + shift) * h)


def _edges(reference: np.ndarray) -> list[int]:
    return [int(i) + 1 for i in np.flatnonzero(np.diff(reference) != 0)]


def run_metrics(
    run: ControlRun, *, mape_min_deg: float = 5.0, band: float = 0.05
) -> dict[str, float]:
    """Scores of a run on its camera angle (what paper B measured).

    - ``mape_pct``: mean ``|θe − θr|/θr``·100 over the samples with θr >= ``mape_min_deg``;
    - ``predicted_mape_pct``: the same for the virtual angle θp;
    - for steps and squares, over the rising edges (reference jumping up) and
      the segment until the next edge: ``rise_s`` (10–90 % of the jump, from the
      angle before the edge to the new reference), ``settling_s`` (from the edge
      to the last entry into ``±band·θr``; an edge that never settles is left
      out of the mean and counted in ``unsettled_edges``), ``overshoot_pct`` (of
      the jump); means over edges (an edge with fewer than 10 samples after it is
      left out);
    - for triangles ``delay_s`` by cross-correlation of θe with θr (and
      ``predicted_delay_s`` for θp);
    - ``switches`` (valve state changes), ``air_used_kg``, ``realtime_factor``.
    """
    t = run.t_s
    r = run.reference_deg
    y = run.camera_deg
    ok = (r >= mape_min_deg) & np.isfinite(y)
    out: dict[str, float] = {
        "mape_pct": float(np.mean(np.abs(y[ok] - r[ok]) / r[ok]) * 100) if ok.any() else math.nan,
        "predicted_mape_pct": float(np.mean(np.abs(run.predicted_deg[ok] - r[ok]) / r[ok]) * 100)
        if ok.any()
        else math.nan,
        "switches": int(run.switches),
        "air_used_kg": float(run.air_used_kg),
        "realtime_factor": float(run.realtime_factor),
    }
    kind = run.reference.kind if run.reference is not None else "step"
    if kind == "triangle":
        finite = np.isfinite(y)
        out["delay_s"] = cross_correlation_delay_s(t[finite], r[finite], y[finite])
        pf = np.isfinite(run.predicted_deg)
        out["predicted_delay_s"] = cross_correlation_delay_s(t[pf], r[pf], run.predicted_deg[pf])
        return out
    edges = _edges(r)
    bounds = [*edges, len(r)]
    rises, settles, overs = [], [], []
    for a, b in itertools.pairwise(bounds):
        final, before = float(r[a]), float(r[a - 1])
        if final <= before or b - a < 10:
            continue
        seg_t, seg_y = t[a:b], y[a:b]
        start = float(y[a - 1])
        rises.append(rise_time_s(seg_t, seg_y, start, final))
        outside = np.flatnonzero(np.abs(seg_y - final) > band * abs(final))
        if outside.size == 0:
            settles.append(0.0)
        elif outside[-1] == seg_y.size - 1:
            settles.append(math.nan)
        else:
            settles.append(float(seg_t[outside[-1] + 1] - t[a - 1]))
        overs.append(max(0.0, float(np.max(seg_y) - final)) / (final - start) * 100)
    out["rising_edges"] = len(rises)
    out["unsettled_edges"] = int(sum(1 for v in settles if math.isnan(v)))
    for name, values in (("rise_s", rises), ("settling_s", settles), ("overshoot_pct", overs)):
        vals = np.array(values, dtype=float)
        vals = vals[np.isfinite(vals)]
        out[name] = float(np.mean(vals)) if vals.size else math.nan
    return out
