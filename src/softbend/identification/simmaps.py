"""The NumPy side of the simulation-error NARX families: their settings, input filter and maps.

What a fitted ``arx-sim``, ``poly2-sim`` or ``nn-sim`` model
(:mod:`softbend.identification.simfit`) needs to run: the check of its settings,
the first-order filter on every input, and the neural map of ``nn-sim``,
evaluated with NumPy alone (no PyTorch to load or predict).
"""

from __future__ import annotations

import math
from collections.abc import Mapping, Sequence
from dataclasses import dataclass
from typing import Any

import numpy as np
from scipy import signal

from softbend._validation import check_range, must_be
from softbend.errors import InputError, SchemaError

__all__ = [
    "DEFAULT_LR",
    "MAX_DELAY_SAMPLES",
    "MAX_SEARCHED_DELAY",
    "MAX_TAU_SAMPLES",
    "SIM_DEFAULTS",
    "SIM_FAMILIES",
    "NeuralMap",
    "check_sim_params",
    "delay_inputs",
    "filter_inputs",
]

#: The families fitted by simulation error.
SIM_FAMILIES: tuple[str, ...] = ("arx-sim", "poly2-sim", "nn-sim")

#: The largest input time constant, in samples (a training window's filter reads 12 τ back).
MAX_TAU_SAMPLES = 50.0

#: The largest input delay given, in samples.
MAX_DELAY_SAMPLES = 50

#: The largest input delay searched (``delay=None``), in samples: 0 … this, per input.
MAX_SEARCHED_DELAY = 3

#: Default settings (``hidden`` and ``pretrain`` are read by ``nn-sim`` only).
SIM_DEFAULTS: dict[str, Any] = {
    "steps": 60,
    "epochs": 20,
    "window": 60,
    "batch": 64,
    "lr": None,
    "filter": False,
    "tau_init": None,
    "delay": 0,
    "hidden": 16,
    "pretrain": 200,
    "seed": 0,
}

#: Adam's step size by family when ``lr`` is not given (a degree-2 map's run is the touchiest).
DEFAULT_LR: dict[str, float] = {"arx-sim": 0.001, "poly2-sim": 0.0003, "nn-sim": 0.001}

_INTEGERS = {
    "steps": (0, 100_000),
    "epochs": (1, 100_000),
    "window": (2, 100_000),
    "batch": (1, 4096),
    "hidden": (1, 256),
    "pretrain": (0, 100_000),
    "seed": (0, 2**32 - 1),
}


def check_sim_params(params: Mapping[str, Any], family: str = "poly2-sim") -> dict[str, Any]:
    """The settings of a simulation-error fit of ``family``, defaults filled in.

    Raises
    ------
    InputError
        An unknown setting, or a value out of its range (naming the setting).
    """
    unknown = sorted(set(params) - set(SIM_DEFAULTS))
    if unknown:
        raise InputError(
            must_be(f"settings among {', '.join(SIM_DEFAULTS)}", ", ".join(unknown)),
            key="params",
        )
    out = {**SIM_DEFAULTS, **params}
    for key, (low, high) in _INTEGERS.items():
        value = out[key]
        if (
            isinstance(value, bool)
            or not isinstance(value, int | np.integer)
            or not (low <= value <= high)
        ):
            raise InputError(must_be(f"an integer in [{low}, {high}]", value), key=key)
        out[key] = int(value)
    if not isinstance(out["filter"], bool | np.bool_):
        raise InputError(must_be("true or false", out["filter"]), key="filter")
    out["filter"] = bool(out["filter"])
    lr = DEFAULT_LR[family] if out["lr"] is None else out["lr"]
    out["lr"] = check_range(lr, "lr", low=0.0, high=1.0, high_inclusive=True)
    delay = out["delay"]
    if delay is not None:
        if (
            isinstance(delay, bool)
            or not isinstance(delay, int | np.integer)
            or not (0 <= delay <= MAX_DELAY_SAMPLES)
        ):
            raise InputError(
                must_be(f"an integer in [0, {MAX_DELAY_SAMPLES}] (samples) or null", delay),
                key="delay",
            )
        out["delay"] = int(delay)
    if out["tau_init"] is not None:
        out["tau_init"] = check_range(
            out["tau_init"], "tau_init", low=0.0, high=MAX_TAU_SAMPLES,
            low_inclusive=True, high_inclusive=True,
        )  # fmt: skip
    return out


def filter_inputs(
    U: np.ndarray, starts: Sequence[int], lengths: Sequence[int], tau: np.ndarray
) -> np.ndarray:
    """Each input through its first-order filter, every experiment started at rest.

    Parameters
    ----------
    U : ndarray, shape (n, k)
        Inputs, experiments concatenated.
    starts, lengths : sequence of int
        First row and length of each experiment.
    tau : ndarray, shape (k,)
        Time constant of each input's filter, in samples (0: no filter).

    Returns
    -------
    ndarray, shape (n, k)
        ``u_f(t) = a·u_f(t−1) + (1−a)·u(t)``, ``a = exp(−1/τ)``, ``u_f = u`` at
        each experiment's first sample.
    """
    out = np.array(U, dtype=np.float64, copy=True)
    for j, t in enumerate(np.asarray(tau, dtype=np.float64)):
        a = math.exp(-1.0 / t) if t > 0 else 0.0
        for s, n in zip(starts, lengths, strict=True):
            x = U[s : s + n, j]
            out[s : s + n, j] = signal.lfilter([1.0 - a], [1.0, -a], x, zi=[a * x[0]])[0]
    return out


def delay_inputs(
    U: np.ndarray, starts: Sequence[int], lengths: Sequence[int], delay: Sequence[int]
) -> np.ndarray:
    """Each input delayed by its number of samples, every experiment held at its first sample
    before (at rest, as :func:`filter_inputs` starts: the two commute).

    Parameters
    ----------
    U : ndarray, shape (n, k)
        Inputs, experiments concatenated.
    starts, lengths : sequence of int
        First row and length of each experiment.
    delay : sequence of int, length k
        Each input's delay, in samples (0: none).

    Returns
    -------
    ndarray, shape (n, k)
        ``u_d(t) = u(max(t − d, start))``.
    """
    out = np.array(U, dtype=np.float64, copy=True)
    for j, d in enumerate(int(x) for x in delay):
        if d <= 0:
            continue
        for s, n in zip(starts, lengths, strict=True):
            shift = min(d, n)
            out[s + shift : s + n, j] = U[s : s + n - shift, j]
            out[s : s + shift, j] = U[s, j]
    return out


@dataclass
class NeuralMap:
    """One output of ``nn-sim``: ``y = φ·linear + intercept + tanh(φ·Wᵀ + b)·out``.

    In standardized units; evaluated with NumPy.
    """

    linear: np.ndarray
    intercept: float
    weights: np.ndarray
    biases: np.ndarray
    out: np.ndarray

    def predict(self, Phi: np.ndarray) -> np.ndarray:
        """The output of every regressor row ``Phi`` (rows, d)."""
        hidden = np.tanh(Phi @ self.weights.T + self.biases)
        return Phi @ self.linear + self.intercept + hidden @ self.out

    def state(self) -> dict[str, Any]:
        """JSON-ready lists (shortest round-trip floats reload bit for bit)."""
        return {
            "kind": "neural",
            "linear": self.linear.tolist(),
            "intercept": float(self.intercept),
            "weights": self.weights.tolist(),
            "biases": self.biases.tolist(),
            "out": self.out.tolist(),
        }

    @classmethod
    def from_state(cls, state: Mapping[str, Any], n_regressors: int) -> NeuralMap:
        """Rebuild from :meth:`state`, checking every array's shape."""
        if not isinstance(state, Mapping) or state.get("kind") != "neural":
            raise SchemaError("must be a neural map's state", key="maps")
        linear = np.asarray(state["linear"], dtype=np.float64)
        weights = np.asarray(state["weights"], dtype=np.float64)
        biases = np.asarray(state["biases"], dtype=np.float64)
        out = np.asarray(state["out"], dtype=np.float64)
        hidden = biases.shape[0] if biases.ndim == 1 else -1
        shapes = {
            "linear": (linear, (n_regressors,)),
            "weights": (weights, (hidden, n_regressors)),
            "biases": (biases, (hidden,)),
            "out": (out, (hidden,)),
        }
        for key, (values, shape) in shapes.items():
            if values.shape != shape or not np.isfinite(values).all():
                raise SchemaError(f"must hold {shape} finite numbers", key=f"maps.{key}")
        return cls(linear, float(state["intercept"]), weights, biases, out)
