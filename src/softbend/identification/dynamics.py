"""An identified model read physically, and run on a new input.

:func:`load_identified` turns the ``model.json`` of ``softbend identify`` into an
:class:`IdentifiedModel`: the fitted :class:`~softbend.identification.multi.MultiNARX`
with the names of its inputs, outputs and time column and its sampling period,
which runs free on any input series (:meth:`IdentifiedModel.free_run`) and
holds a constant input until the outputs settle
(:meth:`IdentifiedModel.steady_state`).

:func:`step_readings` reads the model as a control engineer would: from the
operating point (every input at its training mean, the outputs settled there)
each input steps by one training standard deviation, the others held, and each
output's response gives

- the **gain**: the settled change of the output per unit change of the input
  (output unit / input unit);
- the **delay** (dead time): the first sample after the step where the output's
  change exceeds 2 % of its final change;
- the **time constant** τ: the time from the last sample before the response
  (the end of the dead time) to 63.2 % of the final change, the remaining
  change taken as decaying exponentially between two samples.

For a first-order discrete system y(t) = a·y(t−1) + b·u(t−d) these are b/(1−a),
d samples and −Δt/ln(a), whatever the model's family: the delay is read to
the sample, τ to a fraction of one.
Times are in the time column's unit and, when its name carries a known suffix
(``time_s``, ``t_ms``, ``clock_min``; :func:`seconds_per_unit`), in seconds too;
without a time column they are in samples.
"""

from __future__ import annotations

import json
import math
import os
from collections.abc import Mapping
from dataclasses import dataclass, field
from pathlib import Path
from typing import TYPE_CHECKING, Any

import numpy as np
from numpy.typing import ArrayLike

from softbend import units
from softbend._validation import check_finite_array, must_be
from softbend.errors import InputError, SchemaError
from softbend.units import unit_from_name

if TYPE_CHECKING:
    from softbend.identification.multi import MultiNARX
    from softbend.identification.timeseries import TimeSeriesSet

__all__ = [
    "MAX_SETTLE_STEPS",
    "IdentifiedModel",
    "StepReading",
    "identified_model",
    "is_identified_model",
    "load_identified",
    "median_sample_period",
    "seconds_per_unit",
    "step_readings",
    "unit_from_name",
]

#: The most samples a constant input is held for the outputs to settle.
MAX_SETTLE_STEPS = 20_000

#: Name of the time column of a model identified without one (the sample index).
SAMPLE_TIME_NAME = "sample"

# The format of softbend.identification.multi's files, named here so that this
# module (and is_identified_model) imports without scikit-learn.
_FORMAT = "softbend-multi-narx"

_CHUNK = 500  # samples simulated per call while waiting for the outputs to settle
_SETTLED = 1e-7  # largest change over the last half chunk, in output standard deviations
_RESPONSE = 1e-9  # smallest final change that is a response, in output standard deviations
_DEAD_BAND = 0.02  # fraction of the final change that ends the dead time
_TAU_LEVEL = 1.0 - math.exp(-1.0)  # 63.2 % of the final change


def seconds_per_unit(time_name: str) -> float | None:
    """Seconds per unit of a time column, from its name (``time_s`` → 1.0, ``t_ms`` → 0.001).

    None when the name carries no time unit, and for the sample index (``"sample"``)
    (:func:`softbend.units.seconds_per_unit`).
    """
    if time_name == SAMPLE_TIME_NAME:
        return None
    return units.seconds_per_unit(time_name)


def median_sample_period(data: TimeSeriesSet) -> float:
    """The median interval between samples over every experiment, in the time column's unit.

    1.0 (one sample) when no experiment has two samples.
    """
    steps = [np.diff(e.time) for e in data.experiments if e.n_samples > 1]
    if not steps:
        return 1.0
    return float(np.median(np.concatenate(steps)))


@dataclass(frozen=True)
class IdentifiedModel:
    """A fitted multi-output NARX with the names and timing of the data it was identified on.

    Attributes
    ----------
    model : MultiNARX
        The fitted model.
    metadata : dict
        The metadata saved with it (empty for a model built in memory).
    input_names, output_names : tuple of str
        Its input and output columns, in the model's order.
    time_name : str
        The time column's name; ``"sample"`` when the data had none (the time is
        then the sample index).
    sample_period : float
        Median sampling interval, in the time column's unit (1.0 = one sample
        without a time column).
    time_unit_s : float or None
        Seconds per unit of the time column, from its name's suffix
        (:func:`seconds_per_unit`); None when unknown or the sample index.
    """

    model: MultiNARX
    metadata: dict[str, Any]
    input_names: tuple[str, ...]
    output_names: tuple[str, ...]
    time_name: str
    sample_period: float
    time_unit_s: float | None

    @property
    def sample_period_s(self) -> float | None:
        """The sampling interval in seconds, or None when the time unit is unknown."""
        return None if self.time_unit_s is None else self.sample_period * self.time_unit_s

    @property
    def max_lag(self) -> int:
        """Samples of initial conditions a free run needs."""
        return self.model.max_lag

    def _inputs(self, inputs: ArrayLike) -> np.ndarray:
        U = check_finite_array(inputs, "inputs")
        U = U[:, None] if U.ndim == 1 and len(self.input_names) == 1 else U
        k = len(self.input_names)
        if U.ndim != 2 or U.shape[1] != k:
            raise InputError(
                must_be(f"an array (n, {k}) of the inputs {', '.join(self.input_names)}",
                        f"shape {U.shape}"),
                key="inputs",
            )  # fmt: skip
        return U

    def free_run(self, inputs: ArrayLike, initial_outputs: ArrayLike | None = None) -> np.ndarray:
        """The outputs of the model run free on ``inputs``.

        Parameters
        ----------
        inputs : array_like, shape (n, k)
            The inputs, in :attr:`input_names` order and units, one row per sample
            (n ≥ max_lag + 1).
        initial_outputs : array_like, shape (max_lag, m), optional
            The outputs of the first ``max_lag`` samples. Default: at rest, the
            steady state of the first input row held (:meth:`steady_state`).

        Returns
        -------
        ndarray, shape (n, m)
            The outputs, in :attr:`output_names` order and units (the initial
            conditions copied into the first ``max_lag`` rows).
        """
        U = self._inputs(inputs)
        lag, m = self.max_lag, len(self.output_names)
        if U.shape[0] < lag + 1:
            raise InputError(
                must_be(f"at least max_lag + 1 = {lag + 1} rows", U.shape[0]), key="inputs"
            )
        if initial_outputs is None:
            start = np.tile(self.steady_state(U[0]), (lag, 1))
        else:
            start = check_finite_array(initial_outputs, "initial_outputs")
            start = start[:, None] if start.ndim == 1 and m == 1 else start
            if start.shape != (lag, m):
                raise InputError(
                    must_be(f"an array ({lag}, {m}): max_lag rows of the outputs",
                            f"shape {start.shape}"),
                    key="initial_outputs",
                )  # fmt: skip
        Y = np.empty((U.shape[0], m))
        Y[:lag] = start
        Y[lag:] = start[-1]
        return self.model.simulate(U, Y)

    def steady_state(self, inputs: ArrayLike) -> np.ndarray:
        """The outputs the model settles at with ``inputs`` held constant from rest.

        Parameters
        ----------
        inputs : array_like, shape (k,)
            One value per input, in :attr:`input_names` order and units.

        Returns
        -------
        ndarray, shape (m,)
            As one row of :meth:`steady_states`.
        """
        u = check_finite_array(inputs, "inputs").ravel()
        if u.size != len(self.input_names):
            raise InputError(
                must_be(f"{len(self.input_names)} values ({', '.join(self.input_names)})",
                        f"{u.size}"),
                key="inputs",
            )  # fmt: skip
        return self.steady_states(u[None, :])[0]

    def steady_states(self, inputs: ArrayLike) -> np.ndarray:
        """The outputs settled at under each row of ``inputs`` held, all run together.

        Parameters
        ----------
        inputs : array_like, shape (g, k)
            One row of input values per steady state, in :attr:`input_names` order.

        Returns
        -------
        ndarray, shape (g, m)
            Started at the training outputs' means, each row's input is held for
            at most :data:`MAX_SETTLE_STEPS` samples, until no output of any row
            moves by more than 1e-7 of its training standard deviation over the
            last half of a chunk (the last outputs reached when they never settle).
        """
        model = self.model
        u = check_finite_array(inputs, "inputs")
        u = u.reshape(-1, len(self.input_names))
        g, lag, m = u.shape[0], model.max_lag, model.n_outputs_
        rows = np.tile(model.y_mean_, (g, lag, 1))
        n = _CHUNK + lag
        U = np.repeat(u, n, axis=0)
        groups = np.repeat(np.arange(g), n)
        for _ in range(max(1, MAX_SETTLE_STEPS // _CHUNK)):
            Y = np.empty((g, n, m))
            Y[:, :lag] = rows
            Y[:, lag:] = rows[:, -1:]
            out = model.simulate(U, Y.reshape(g * n, m), groups).reshape(g, n, m)
            rows = out[:, -lag:]
            change = np.ptp(out[:, -_CHUNK // 2 :], axis=1) / model.y_std_
            if np.all(change <= _SETTLED):
                break
        return rows[:, -1].copy()


def _hold(
    model: MultiNARX,
    u: np.ndarray,
    start: np.ndarray,
    before: np.ndarray | None = None,
    max_steps: int = MAX_SETTLE_STEPS,
) -> tuple[np.ndarray, str]:
    """Outputs with ``u`` held from the initial rows ``start`` (max_lag, m), and how they end.

    ``before`` is the input during the initial rows (default ``u``), so that a
    step happens at row max_lag. Returns the trajectory (initial rows included)
    and ``"settled"``, ``"diverges"`` (stuck at a free-run bound) or ``"drifts"``.
    """
    lag = model.max_lag
    before = u if before is None else before
    scale = model.y_std_
    pieces: list[np.ndarray] = []
    rows = np.asarray(start, dtype=np.float64)
    first = True
    status = "drifts"
    simulated = 0
    while simulated < max_steps:
        n = min(_CHUNK, max_steps - simulated) + lag
        U = np.tile(u, (n, 1))
        if first:
            U[:lag] = before
        Y = np.empty((n, rows.shape[1]))
        Y[:lag] = rows
        Y[lag:] = rows[-1]
        out = model.simulate(U, Y)
        pieces.append(out if first else out[lag:])
        simulated += n - lag
        first = False
        rows = out[-lag:]
        window = out[-max(2, (n - lag) // 2) :]
        change = np.ptp(window, axis=0) / scale
        if np.all(change <= _SETTLED):
            span = model.y_high_ - model.y_low_
            at_bound = (np.abs(out[-1] - model.y_low_) <= 1e-9 * span) | (
                np.abs(out[-1] - model.y_high_) <= 1e-9 * span
            )
            status = "diverges" if at_bound.any() else "settled"
            break
    return np.vstack(pieces), status


@dataclass(frozen=True)
class StepReading:
    """The response of one output to a step of one input (:func:`step_readings`).

    Attributes
    ----------
    input, output : str
        The input stepped and the output read.
    gain : float
        Settled change of the output per unit change of the input, around the
        operating point (output unit / input unit); NaN when the response does
        not settle (:attr:`note` says why).
    time_constant : float or None
        Time from the end of the dead time to 63.2 % of the final change, in the
        time column's unit; None when undefined (:attr:`note`).
    delay : float or None
        Dead time, in the time column's unit: the first sample after the step
        where the output's change exceeds 2 % of its final change; None when
        undefined (:attr:`note`).
    time_unit_s : float or None
        Seconds per unit of the time column (None when unknown).
    operating_point : float
        The input's value before the step (its training mean), input unit.
    step : float
        The step of the input (its training standard deviation), input unit.
    note : str
        Why a value is undefined: ``"no response"``, ``"does not settle"``,
        ``"diverges"`` or ``"no steady operating point"``; empty when all are defined.
    """

    input: str
    output: str
    gain: float
    time_constant: float | None
    delay: float | None
    time_unit_s: float | None = None
    operating_point: float = math.nan
    step: float = math.nan
    note: str = ""
    gain_unit: str = field(default="")

    @property
    def time_constant_s(self) -> float | None:
        """:attr:`time_constant` in seconds (None when it or the time unit is unknown)."""
        if self.time_constant is None or self.time_unit_s is None:
            return None
        return self.time_constant * self.time_unit_s

    @property
    def delay_s(self) -> float | None:
        """:attr:`delay` in seconds (None when it or the time unit is unknown)."""
        if self.delay is None or self.time_unit_s is None:
            return None
        return self.delay * self.time_unit_s

    def to_dict(self) -> dict[str, Any]:
        """JSON-ready: every figure, its unit, and None (never NaN) for an undefined one."""
        return {
            "input": self.input,
            "output": self.output,
            "gain": self.gain if math.isfinite(self.gain) else None,
            "gain_unit": self.gain_unit,
            "time_constant": self.time_constant,
            "time_constant_s": self.time_constant_s,
            "delay": self.delay,
            "delay_s": self.delay_s,
            "time_unit_s": self.time_unit_s,
            "operating_point": self.operating_point,
            "step": self.step,
            "note": self.note,
        }


def _gain_unit(output: str, input: str) -> str:
    out_unit, in_unit = unit_from_name(output), unit_from_name(input)
    if not out_unit and not in_unit:
        return ""
    return f"{out_unit or '1'}/{in_unit or '1'}"


def step_readings(identified: IdentifiedModel) -> list[StepReading]:
    """Gain, time constant and delay of every (input, output) pair (module docstring).

    From the operating point (the training input means, outputs settled there),
    each input steps by its training standard deviation, the others held; one
    reading per pair, input by input.
    """
    model = identified.model
    lag, period = model.max_lag, identified.sample_period
    u0 = np.asarray(model.u_mean_, dtype=np.float64)
    rest, status0 = _hold(model, u0, np.tile(model.y_mean_, (lag, 1)))
    y0 = rest[-1]
    start = np.tile(y0, (lag, 1))
    readings = []
    for i, name in enumerate(identified.input_names):
        du = float(model.u_std_[i])
        u1 = u0.copy()
        u1[i] += du
        trajectory, status = _hold(model, u1, start, before=u0)
        for j, output in enumerate(identified.output_names):
            common: dict[str, Any] = {
                "input": name,
                "output": output,
                "time_unit_s": identified.time_unit_s,
                "operating_point": float(u0[i]),
                "step": du,
                "gain_unit": _gain_unit(output, name),
            }
            if status0 != "settled" or status != "settled":
                note = "no steady operating point" if status0 != "settled" else status
                note = "does not settle" if note == "drifts" else note
                readings.append(StepReading(gain=math.nan, time_constant=None, delay=None,
                                            note=note, **common))  # fmt: skip
                continue
            change = trajectory[lag:, j] - y0[j]
            final = float(change[-1])
            if abs(final) <= _RESPONSE * model.y_std_[j]:
                readings.append(StepReading(gain=final / du, time_constant=None, delay=None,
                                            note="no response", **common))  # fmt: skip
                continue
            delay, tau = _delay_and_tau(change / final)
            readings.append(
                StepReading(gain=final / du, time_constant=tau * period, delay=delay * period,
                            **common)
            )  # fmt: skip
    return readings


def _delay_and_tau(response: np.ndarray) -> tuple[int, float]:
    """Dead time and time constant, in samples, of a response normalized to end at 1.

    ``response[0]`` is the step's sample. The dead time is the first sample whose
    magnitude exceeds :data:`_DEAD_BAND`; τ runs from the sample before it (the
    last one at rest) to the first crossing of 63.2 %, between two samples where
    the remaining change decays exponentially (exact for a first-order response),
    linearly where it changes sign.
    """
    z = np.concatenate(([0.0], response))  # z[0]: the last sample before the step
    delay = int(np.flatnonzero(np.abs(z) > _DEAD_BAND)[0]) - 1
    c = int(np.flatnonzero(z >= _TAU_LEVEL)[0])
    low, high = z[c - 1], z[c]
    left, right, target = 1.0 - low, 1.0 - high, 1.0 - _TAU_LEVEL  # remaining change
    if right > 0.0 and left > right:
        fraction = math.log(left / target) / math.log(left / right)
    else:
        fraction = (_TAU_LEVEL - low) / (high - low) if high > low else 1.0
    return delay, float(c - 1 + fraction - delay)


def identified_model(
    model: MultiNARX, data: TimeSeriesSet, metadata: Mapping[str, Any] | None = None
) -> IdentifiedModel:
    """The model fitted on ``data`` with the data's names and timing."""
    return IdentifiedModel(
        model=model,
        metadata=dict(metadata or {}),
        input_names=tuple(data.input_names),
        output_names=tuple(data.output_names),
        time_name=data.time_name,
        sample_period=median_sample_period(data),
        time_unit_s=seconds_per_unit(data.time_name),
    )


def is_identified_model(path: str | os.PathLike[str]) -> bool:
    """Whether ``path`` is a ``.json`` file holding a saved multi-output NARX (read once)."""
    file = Path(path)
    if file.suffix.lower() != ".json" or not file.is_file():
        return False
    try:
        text = file.read_text(encoding="utf-8")
        if _FORMAT not in text:  # another model (a surrogate): no need to parse it
            return False
        data = json.loads(text)
    except (OSError, UnicodeDecodeError, ValueError, RecursionError):
        return False
    return isinstance(data, dict) and data.get("format") == _FORMAT


def _names(metadata: Mapping[str, Any], key: str, size: int, prefix: str, file: str) -> tuple:
    names = metadata.get(key)
    if names is None:
        return tuple(f"{prefix}{i + 1}" for i in range(size))
    if (
        not isinstance(names, list)
        or len(names) != size
        or not all(isinstance(n, str) and n for n in names)
    ):
        raise SchemaError(
            must_be(f"a list of {size} names (one per {key[:-1]} of the model)", names),
            key=f"metadata.{key}",
            file=file,
        )
    return tuple(names)


def _positive(value: object) -> bool:
    """Whether a JSON value is a positive finite number."""
    if isinstance(value, bool) or not isinstance(value, int | float):
        return False
    return math.isfinite(value) and value > 0


def load_identified(path: str | os.PathLike[str]) -> IdentifiedModel:
    """The ``model.json`` of ``softbend identify`` (or any :func:`save_multi_narx` file).

    A file written before the timing was recorded loads with the sample index
    as its time (``sample_period`` 1.0, ``time_unit_s`` None); one without
    names gets ``u1, u2, …`` and ``y1, y2, …``.

    Raises
    ------
    FileNotFoundError
        No such file.
    SchemaError
        Not a saved model, or a broken entry (naming the file and the key).
    """
    from softbend.identification.multi import load_multi_narx

    file = str(path)
    model, metadata = load_multi_narx(path)
    inputs = _names(metadata, "inputs", model.n_inputs_, "u", file)
    outputs = _names(metadata, "outputs", model.n_outputs_, "y", file)
    time_name = metadata.get("time", SAMPLE_TIME_NAME)
    if not isinstance(time_name, str) or not time_name:
        raise SchemaError(must_be("a column name", time_name), key="metadata.time", file=file)
    period = metadata.get("sample_period", 1.0)
    if not _positive(period):
        raise SchemaError(
            must_be("a positive finite number", period), key="metadata.sample_period", file=file
        )
    unit = metadata.get("time_unit_s", seconds_per_unit(time_name))
    if unit is not None and not _positive(unit):
        raise SchemaError(
            must_be("a positive finite number or null", unit),
            key="metadata.time_unit_s",
            file=file,
        )
    return IdentifiedModel(
        model=model,
        metadata=metadata,
        input_names=inputs,
        output_names=outputs,
        time_name=time_name,
        sample_period=float(period),
        time_unit_s=None if unit is None else float(unit),
    )


def dynamics_metadata(identified: IdentifiedModel) -> dict[str, Any]:
    """What ``softbend identify`` records beside a model: timing and step readings."""
    return {
        "time": identified.time_name,
        "sample_period": identified.sample_period,
        "time_unit_s": identified.time_unit_s,
        "dynamics": [r.to_dict() for r in step_readings(identified)],
    }
