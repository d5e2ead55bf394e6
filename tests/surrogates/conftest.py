"""Shared data of the surrogate tests: inputs over paper B's design space and a smooth angle."""

from __future__ import annotations

import numpy as np
import pytest

# Paper B Table 1: l, r, t, b, phi, lc, and the pressure range, in FEATURES order.
LOW = np.array([100.0, 6.0, 2.0, 2.0, 5.0, 8.0, 0.0])
HIGH = np.array([160.0, 10.0, 4.0, 4.0, 15.0, 12.0, 0.5])


def table1_inputs(n: int, seed: int) -> np.ndarray:
    """``n`` rows drawn uniformly over Table 1's ranges and 0–0.5 MPa."""
    return LOW + (HIGH - LOW) * np.random.default_rng(seed).random((n, LOW.size))


def smooth_angle(X: np.ndarray) -> np.ndarray:
    """A smooth stand-in for the bending angle (degrees) with the physical trends."""
    length, r, t, b, phi, lc, p = X.T
    return 250.0 * p * (length / 130.0) * (r / 8.0) / (t * (1.0 + 0.02 * phi)) - 0.3 * b + 0.1 * lc


@pytest.fixture(scope="module")
def one_torch_thread():
    """One torch thread while a module's tiny networks train.

    OpenMP threads only add synchronization to them, and on a loaded 2-core
    machine their spinning slows training by orders of magnitude.
    """
    import torch

    before = torch.get_num_threads()
    torch.set_num_threads(1)
    yield
    torch.set_num_threads(before)
