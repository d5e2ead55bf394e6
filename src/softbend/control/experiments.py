"""References, the closed loop and its metrics (paper B §5, Fig. 9).

References are parsed from short specs:

- ``step:AMP[:T0_S]``: 0° before ``T0_S`` (default 0.5 s), ``AMP`` after;
- ``square:AMP:PERIOD_S[:LOW]``: ``LOW`` (default 0°) for the first half of each
  period, ``AMP`` for the second, starting at t = 0;
- ``triangle:FREQ_HZ:AMP[:LOW]``: a triangle between ``LOW`` (default 0°) at t = 0
  and ``AMP`` at half a period;
- ``sine:AMP:PERIOD_S[:OFFSET]``: a sine between ``OFFSET`` (default 0°) at t = 0 and
  ``AMP`` at half a period, ``OFFSET + (AMP − OFFSET)·(1 − cos 2πt/PERIOD_S)/2``: like the
  square and the triangle it spans ``OFFSET``..``AMP`` (an actuator bends one way, so no
  negative angle), and it starts at rest with zero slope.

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
from array import array
from dataclasses import dataclass, field, replace
from typing import TYPE_CHECKING, Any

import numpy as np

from softbend._validation import check_range, interval_text, must_be
from softbend.errors import InputError

if TYPE_CHECKING:
    from softbend.control.controllers import Controller
    from softbend.control.rig import SimulatedRig

__all__ = [
    "ControlRun",
    "Reference",
    "cross_correlation_delay_s",
    "parse_reference",
    "rise_time_s",
    "run_metrics",
    "simulate",
    "summary_metrics",
]


@dataclass(frozen=True)
class Reference:
    """A reference angle θr(t), degrees; ``kind`` is ``step``, ``square``, ``triangle`` or
    ``sine``; ``low_deg`` is the square's and triangle's LOW and the sine's OFFSET."""

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
        if self.kind == "sine":
            return self.low_deg + span * 0.5 * (1.0 - np.cos(2.0 * np.pi * phase))
        return self.low_deg + span * (1.0 - np.abs(2.0 * phase - 1.0))

    def __str__(self) -> str:
        return self.spec or self.kind


#: Each kind of reference: its fields (as named in errors) and how many are required.
_KINDS: dict[str, tuple[tuple[str, ...], int]] = {
    "step": (("amplitude_deg", "t0_s"), 1),
    "square": (("amplitude_deg", "period_s", "low_deg"), 2),
    "triangle": (("freq_hz", "amplitude_deg", "low_deg"), 2),
    "sine": (("amplitude_deg", "period_s", "offset_deg"), 2),
}
#: How each field is written in a spec.
_SPELLED = {
    "amplitude_deg": "AMP",
    "t0_s": "T0_S",
    "period_s": "PERIOD_S",
    "low_deg": "LOW",
    "freq_hz": "FREQ_HZ",
    "offset_deg": "OFFSET",
}


def _form(kind: str) -> str:
    """The spec of ``kind`` (``square:AMP:PERIOD_S[:LOW]``)."""
    fields_, required = _KINDS[kind]
    words = [_SPELLED[f] for f in fields_]
    optional = "".join(f"[:{w}" for w in words[required:]) + "]" * (len(words) - required)
    return ":".join([kind, *words[:required]]) + optional


_USAGE = ", ".join(_form(k) for k in list(_KINDS)[:-1]) + f" or {_form(list(_KINDS)[-1])}"


def parse_reference(reference: str) -> Reference:
    """Parse a reference spec (see the module doc); errors name the field and its allowed values.

    Raises
    ------
    InputError
        Key ``reference``; the message names the value at fault (``amplitude_deg``, ...).
    """
    spec = reference
    if not isinstance(spec, str) or ":" not in spec:
        raise InputError(must_be(f"one of {_USAGE}", spec), key="reference")
    kind, *parts = spec.strip().split(":")
    kind = kind.strip().lower()
    if kind not in _KINDS:
        raise InputError(
            f"kind must be one of {', '.join(map(repr, _KINDS))} ({_USAGE}); got {kind!r}",
            key="reference",
        )
    fields_, required = _KINDS[kind]
    if not required <= len(parts) <= len(fields_):
        raise InputError(
            f"{kind} takes {required}–{len(fields_)} values ({_form(kind)}); "
            f"got {len(parts)} in {spec!r}",
            key="reference",
        )
    values: dict[str, float] = {}
    bounds = {
        "amplitude_deg": (0.0, 720.0, False),
        "low_deg": (0.0, 720.0, True),
        "offset_deg": (0.0, 720.0, True),
        "t0_s": (0.0, 3600.0, True),
        "period_s": (0.0, 3600.0, False),
        "freq_hz": (0.0, 50.0, False),
    }
    for name, text in zip(fields_, parts, strict=False):
        low, high, inclusive = bounds[name]
        interval = interval_text(low, high, low_inclusive=inclusive, high_inclusive=True)
        try:
            values[name] = check_range(
                float(text), name, low=low, high=high, low_inclusive=inclusive, high_inclusive=True
            )
        except (ValueError, InputError):
            raise InputError(
                f"{name} of the {kind} {must_be(f'a number in {interval}', text)} ({_form(kind)})",
                key="reference",
            ) from None
    low_name = "offset_deg" if kind == "sine" else "low_deg"
    low = values.get(low_name, 0.0)
    if low >= values["amplitude_deg"]:
        raise InputError(
            f"{low_name} of the {kind} must be below its amplitude_deg; got {low_name}={low:g} "
            f"and amplitude_deg={values['amplitude_deg']:g} ({_form(kind)})",
            key="reference",
        )
    if kind == "step":
        return Reference(
            "step", values["amplitude_deg"], start_s=values.get("t0_s", 0.5), spec=spec
        )
    if kind in ("square", "sine"):
        return Reference(kind, values["amplitude_deg"], values["period_s"], low, spec=spec)
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

    def decimated(self, max_points: int = 20_000) -> ControlRun:
        """The run on at most about ``max_points`` of its rows, for a figure.

        The rows are cut into buckets; each keeps its first row and the rows of
        the smallest and largest camera angle and pressure, so the envelope of
        the lines survives (a figure is about a thousand pixels wide). A run of
        no more rows is returned as it is. Scores are computed on the whole run.
        """
        n = int(self.t_s.size)
        if n <= max_points:
            return self
        width = math.ceil(n / max(1, max_points // 5))
        keep = [np.arange(0, n, width), np.array([n - 1])]
        for values in (self.camera_deg, self.pressure_mpa):
            keep += [_bucket_extreme(values, width, True), _bucket_extreme(values, width, False)]
        rows = np.unique(np.concatenate(keep))
        arrays = (
            "t_s", "reference_deg", "angle_deg", "camera_deg", "predicted_deg",
            "pressure_mpa", "measured_mpa", "inlet", "outlet",
        )  # fmt: skip
        return replace(self, **{name: getattr(self, name)[rows] for name in arrays})

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


def _bucket_extreme(values: np.ndarray, width: int, largest: bool) -> np.ndarray:
    """The index of the largest (smallest) value of each run of ``width`` values (NaN skipped)."""
    n = values.size
    buckets = math.ceil(n / width)
    fill = -math.inf if largest else math.inf
    padded = np.full(buckets * width, fill)
    padded[:n] = np.where(np.isnan(values), fill, values)
    pick = np.argmax if largest else np.argmin
    found = pick(padded.reshape(buckets, width), axis=1) + np.arange(buckets) * width
    return np.minimum(found, n - 1)


def simulate(
    rig: SimulatedRig,
    controller: Controller,
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

    Every rig step is logged, so the run is sized first
    (:func:`~softbend.control.budget.check_run_size`): a ``duration_s`` outside
    (0, 86400] s, more steps than the ``loop_ticks`` limit, or more memory than
    the machine has left is refused (``ValueError``, ``LimitError``) before any
    step.
    """
    from softbend.control.budget import SIMULATE_BYTES_PER_STEP, check_run_size

    ref = parse_reference(reference) if isinstance(reference, str) else reference
    h = rig.step_s
    n = check_run_size(
        duration_s, h, SIMULATE_BYTES_PER_STEP, what="A simulated run", unit="rig steps"
    ).ticks
    sensor_every = max(1, round(check_range(sensor_period_s, "sensor_period_s", low=0.0) / h))
    # The log is kept in preallocated arrays of machine numbers (8 bytes a value, 1 a
    # valve state), not lists of Python floats (32): a long run's memory is known in
    # advance (softbend.control.budget) and four times smaller.
    r_list = array("d")
    r_list.frombytes(ref.values(np.arange(n) * h).tobytes())
    rig.reset(seed)
    controller.reset()
    angle = array("d", [0.0]) * n
    camera = array("d", [0.0]) * n
    predicted = array("d", [0.0]) * n
    pressure = array("d", [0.0]) * n
    measured = array("d", [0.0]) * n
    inlet = array("b", [0]) * n
    outlet = array("b", [0]) * n
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
    del r_list
    t_after = np.arange(n) * h + h  # states are recorded at the end of each step
    gauge = np.frombuffer(pressure, dtype=float)
    gauge -= rig.params.atmosphere_mpa * 1e6
    gauge *= 1e-6
    return ControlRun(
        t_s=t_after,
        reference_deg=ref.values(t_after),
        angle_deg=np.frombuffer(angle, dtype=float),
        camera_deg=np.frombuffer(camera, dtype=float),
        predicted_deg=np.frombuffer(predicted, dtype=float),
        pressure_mpa=gauge,
        measured_mpa=np.frombuffer(measured, dtype=float),
        inlet=np.frombuffer(inlet, dtype=np.int8).view(bool),
        outlet=np.frombuffer(outlet, dtype=np.int8).view(bool),
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
    refined by a parabola through it and its neighbours. NaN with fewer than
    two samples. A long run with many lags (more than 1e9 lags × samples) has
    its correlations computed at once by FFT (:func:`_pearson_by_lag`), the same
    to rounding.
    """
    t = np.asarray(t_s, dtype=float)
    x = np.asarray(reference, dtype=float)
    y = np.asarray(response, dtype=float)
    if t.size < 2:
        return math.nan
    h = float(t[1] - t[0])
    lags = int(min(round(max_delay_s / h), len(x) // 2))

    def corr(k: int) -> float:
        a = x[: len(x) - k] - np.mean(x[: len(x) - k])
        b = y[k:] - np.mean(y[k:])
        denom = math.sqrt(float(np.dot(a, a)) * float(np.dot(b, b)))
        return float(np.dot(a, b)) / denom if denom > 0 else 0.0

    if (lags + 1) * x.size > 1e9:
        scores = _pearson_by_lag(x, y, lags)
    else:
        scores = np.array([corr(k) for k in range(lags + 1)])
    k = int(np.argmax(scores))
    shift = 0.0
    if 0 < k < lags:
        a, b, c = scores[k - 1], scores[k], scores[k + 1]
        denom = a - 2 * b + c
        if denom != 0:
            shift = 0.5 * (a - c) / denom
    return float((k + shift) * h)


def _pearson_by_lag(x: np.ndarray, y: np.ndarray, lags: int) -> np.ndarray:
    """Pearson correlation of ``x[:n-k]`` with ``y[k:]`` for every lag ``k`` in 0..``lags``.

    The sums of products come from one FFT (``O(n log n)`` instead of ``O(n·lags)``),
    the sums and sums of squares from cumulative sums; 0 where a part is constant.
    """
    n = x.size
    size = 1 << int(n + lags).bit_length()
    spectrum = np.conj(np.fft.rfft(x, size)) * np.fft.rfft(y, size)
    products = np.fft.irfft(spectrum, size)[: lags + 1]
    del spectrum
    k = np.arange(lags + 1)
    m = (n - k).astype(float)
    sx = np.concatenate([[0.0], np.cumsum(x)])
    sxx = np.concatenate([[0.0], np.cumsum(x * x)])
    sy = np.concatenate([[0.0], np.cumsum(y)])
    syy = np.concatenate([[0.0], np.cumsum(y * y)])
    sum_a, sum_aa = sx[n - k], sxx[n - k]
    sum_b, sum_bb = sy[n] - sy[k], syy[n] - syy[k]
    cov = products - sum_a * sum_b / m
    var = np.maximum(sum_aa - sum_a**2 / m, 0.0) * np.maximum(sum_bb - sum_b**2 / m, 0.0)
    scores = np.zeros(lags + 1)
    positive = var > 0
    scores[positive] = cov[positive] / np.sqrt(var[positive])
    return scores


def _edges(reference: np.ndarray) -> list[int]:
    return [int(i) + 1 for i in np.flatnonzero(np.diff(reference) != 0)]


def run_metrics(
    run: ControlRun,
    *,
    mape_min_deg: float = 5.0,
    band: float = 0.05,
    reasons: dict[str, str] | None = None,
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
    - for triangles and sines ``delay_s`` by cross-correlation of θe with θr (and
      ``predicted_delay_s`` for θp);
    - ``switches`` (valve state changes), ``air_used_kg``, ``realtime_factor``.

    A score the run does not define is NaN (``realtime_factor``: inf when the
    run took no measurable time): an angle that never settled within the run,
    no rising edge, no angle reading. ``reasons``, when given, receives why, by
    name (:func:`summary_metrics` puts both in a run's summary).
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
    why = {} if reasons is None else reasons
    if not ok.any():
        for name in ("mape_pct", "predicted_mape_pct"):
            why[name] = (
                f"no sample with a reference of at least {mape_min_deg:g}° and an angle reading"
            )
    elif math.isnan(out["predicted_mape_pct"]):
        why["predicted_mape_pct"] = "the controller predicted no angle at some of those samples"
    if math.isinf(out["realtime_factor"]):
        why["realtime_factor"] = "the run took no measurable time on the clock"
    if math.isnan(out["air_used_kg"]):
        why["air_used_kg"] = "the rig does not measure the air it uses"
    kind = run.reference.kind if run.reference is not None else "step"
    if kind in ("triangle", "sine"):
        finite = np.isfinite(y)
        out["delay_s"] = cross_correlation_delay_s(t[finite], r[finite], y[finite])
        pf = np.isfinite(run.predicted_deg)
        out["predicted_delay_s"] = cross_correlation_delay_s(t[pf], r[pf], run.predicted_deg[pf])
        for name, count in (("delay_s", finite.sum()), ("predicted_delay_s", pf.sum())):
            if count < 2:
                why[name] = "fewer than two angle readings within the run"
        return out
    edges = _edges(r)
    bounds = [*edges, len(r)]
    rises, settles, overs = [], [], []
    read: list[bool] = []  # whether each edge has angle readings
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
        jump = final - start
        peak = float(np.max(seg_y))
        overs.append(max(0.0, peak - final) / jump * 100 if jump != 0 else math.nan)
        read.append(bool(np.isfinite(seg_y).any()) and start == start)
    out["rising_edges"] = len(rises)
    out["unsettled_edges"] = int(sum(1 for v in settles if math.isnan(v)))
    for name, values in (("rise_s", rises), ("settling_s", settles), ("overshoot_pct", overs)):
        vals = np.array(values, dtype=float)
        vals = vals[np.isfinite(vals)]
        out[name] = float(np.mean(vals)) if vals.size else math.nan
    if reasons is not None:
        reasons.update(_edge_reasons(out, read, band))
    return out


def _edge_reasons(out: dict[str, float], read: list[bool], band: float) -> dict[str, str]:
    """Why ``rise_s``, ``settling_s`` or ``overshoot_pct`` of a step or square run is NaN."""
    found: dict[str, str] = {}
    if not read:
        why = "no rising edge of the reference with 10 samples after it within the run"
        return {name: why for name in ("rise_s", "settling_s", "overshoot_pct")}
    if not any(read):
        why = "no angle reading around a rising edge of the reference"
        return {name: why for name in ("rise_s", "settling_s", "overshoot_pct")}
    if math.isnan(out["rise_s"]):
        found["rise_s"] = "the angle did not rise from 10 % to 90 % of a step within the run"
    if math.isnan(out["settling_s"]):
        found["settling_s"] = (
            f"the angle did not settle within ±{band * 100:g} % of the reference before the "
            "run ended"
        )
    if math.isnan(out["overshoot_pct"]):
        found["overshoot_pct"] = "the angle was already at the new reference at each edge"
    return found


def summary_metrics(
    metrics: dict[str, float], reasons: dict[str, str]
) -> tuple[dict[str, float | int | None], dict[str, str]]:
    """The scores of a run as its summary gives them: every one a finite number or None.

    A score that is not a finite number (NaN, inf) is None, and the second
    dict says why, by name (from ``reasons`` of :func:`run_metrics`, else
    "not defined by this run"): a summary never shows NaN or inf.
    """
    values: dict[str, float | int | None] = {}
    why: dict[str, str] = {}
    for name, value in metrics.items():
        if isinstance(value, float) and not math.isfinite(value):
            values[name] = None
            why[name] = reasons.get(name, "not defined by this run")
        else:
            values[name] = value
    return values, why
