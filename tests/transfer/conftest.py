"""Shared pieces of the transfer tests: a quick virtual lab and a small MLP base."""

from __future__ import annotations

import itertools

import numpy as np
import pytest

from softbend.analytical import AnalyticalModel
from softbend.design import sfrba_design
from softbend.models import default_pressures_mpa
from softbend.transfer.lab import LAB_ACTUATORS, VirtualLab


@pytest.fixture(scope="session")
def quick_lab():
    """Four actuators of Fig. 7 measured on the analytical plant (seconds, not minutes)."""
    return VirtualLab(actuators=LAB_ACTUATORS[:4], plant="analytical", pmax_mpa=0.15)


@pytest.fixture(scope="session")
def quick_measurements(quick_lab):
    return quick_lab.measure()


@pytest.fixture(scope="session")
def small_base():
    """An MLP trained briefly on paper B's analytical model over a few designs.

    Stands in for the FEM-trained MLP: refining it must still help, and the
    tests do not depend on the shipped model.
    """
    from softbend.surrogates.mlp import NormalizedMLPRegressor

    model = AnalyticalModel()
    rows, angles = [], []
    grid = default_pressures_mpa(0.2, 0.01)
    others = [sfrba_design(140, 8, 3, 3, 10, 10), sfrba_design(110, 7, 2.5, 2.5, 8, 9)]
    for design in [*LAB_ACTUATORS, *others]:
        sweep = model.sweep(design, grid)
        ok = np.asarray(sweep.converged, dtype=bool)
        rows.append(design.feature_rows(sweep.pressure_mpa[ok]))
        angles.append(sweep.angle_deg[ok])
    X, y = np.vstack(rows), np.concatenate(angles)
    return NormalizedMLPRegressor(
        hidden_sizes=(16, 16), epochs=300, batch_size=64, learning_rate=3e-3, seed=0, device="cpu"
    ).fit(X, y)


@pytest.fixture
def random_mlp():
    """A 7-16-16-1 MLP with random weights, seeded: a base for the refits' own tests."""
    from softbend.surrogates.mlp import NormalizedMLPRegressor

    rng = np.random.default_rng(0)
    sizes = (7, 16, 16, 1)
    return NormalizedMLPRegressor.from_arrays(
        x_mean=rng.uniform(1.0, 10.0, 7),
        x_scale=rng.uniform(0.5, 2.0, 7),
        y_mean=90.0,
        y_scale=60.0,
        coefs=[rng.normal(0.0, 0.4, (a, b)) for a, b in itertools.pairwise(sizes)],
        intercepts=[rng.normal(0.0, 0.1, b) for b in sizes[1:]],
    )
