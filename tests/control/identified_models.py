"""Identified models of a known system, saved as ``softbend identify`` saves them.

A first-order-plus-dead-time (FOPDT) actuator sampled every ``PERIOD_S``:
``θ(n) = a·θ(n−1) + (1 − a)·GAIN·p(n − 1 − DEAD)`` with ``a = exp(−PERIOD_S/TAU_S)``,
which an ARX with one output lag and ``DEAD + 2`` input lags holds exactly. Its
step reading is a gain of ``GAIN``, a time constant of ``TAU_S`` and a delay of
``(DEAD + 1)·PERIOD_S``.
"""

from pathlib import Path

import numpy as np

from softbend.identification.multi import MultiNARX, save_multi_narx

PERIOD_S = 0.01  # s
TAU_S = 0.05  # s
GAIN = 500.0  # °/MPa
DEAD = 2  # samples before the one-sample lag of the recursion
DELAY_S = (DEAD + 1) * PERIOD_S


def fopdt_series(pressure_mpa: np.ndarray, tau_s: float = TAU_S, period_s: float = PERIOD_S):
    """The FOPDT angle (°) of a pressure series (MPa) sampled every ``period_s``, from rest."""
    a = np.exp(-period_s / tau_s)
    angle = np.zeros(pressure_mpa.size)
    for n in range(1, pressure_mpa.size):
        k = n - 1 - DEAD
        angle[n] = a * angle[n - 1] + (1 - a) * GAIN * (pressure_mpa[k] if k >= 0 else 0.0)
    return angle


def save_fopdt(
    path: Path,
    *,
    inputs: tuple[str, ...] = ("pressure_mpa",),
    outputs: tuple[str, ...] = ("angle_deg",),
    time: str = "time_s",
    scale: float = 1.0,
    tau_s: float = TAU_S,
    period_s: float = PERIOD_S,
) -> Path:
    """An ARX fitted on the FOPDT's response to random pressure steps, saved at ``path``.

    ``scale`` converts MPa to the unit of the input column; every input column
    is the same pressure, every output column the same angle.
    """
    rng = np.random.default_rng(0)
    p = np.repeat(rng.uniform(0.0, 0.2, 60), 50)
    angle = fopdt_series(p, tau_s, period_s)
    U = np.tile(p[:, None] * scale, (1, len(inputs)))
    Y = np.tile(angle[:, None], (1, len(outputs)))
    if len(inputs) > 1:  # not collinear, so the fit is well posed
        U[:, 1:] += rng.normal(0.0, 0.01 * scale, U[:, 1:].shape)
    model = MultiNARX("arx", output_lags=1, input_lags=DEAD + 2).fit(U, Y)
    metadata = {
        "inputs": list(inputs),
        "outputs": list(outputs),
        "time": time,
        "sample_period": period_s,
    }
    return save_multi_narx(model, path, metadata=metadata)
