"""A surrogate whose answers are known in closed form: θ = 10·p·l (degrees, MPa, mm).

A degree-2 polynomial fits it exactly (the term p·l), so every question has a
closed-form answer: at 0.08 MPa the angle is 0.8·l, so 90° is l = 112.5 mm,
and the designs within ± 3° are l ∈ [108.75, 116.25] mm.
"""

from __future__ import annotations

import itertools

import numpy as np
import pytest

from softbend.surrogates.features import training_ranges
from softbend.surrogates.persistence import save_surrogate
from softbend.surrogates.polynomial import PolynomialRegressor
from softbend.surrogates.support import support_from_rows

LEVELS = {
    "l": (100.0, 130.0, 160.0),
    "r": (6.0, 10.0),
    "t": (2.0, 4.0),
    "b": (2.0, 4.0),
    "phi": (5.0, 15.0),
    "lc": (8.0, 12.0),
}


def angle(X: np.ndarray) -> np.ndarray:
    """θ = 10·p·l, degrees."""
    return 10.0 * X[:, 6] * X[:, 0]


def _rows(swept_to) -> np.ndarray:
    """Every corner design of LEVELS, each swept from 0 to ``swept_to(design)`` MPa."""
    rows = []
    for design in itertools.product(*LEVELS.values()):
        for p in np.linspace(0.0, swept_to(design), 11):
            rows.append([*design, p])
    return np.asarray(rows)


def save_model(path, swept_to=lambda design: 0.5):
    X = _rows(swept_to)
    model = PolynomialRegressor(degree=2).fit(X, angle(X))
    metadata = {
        "training_ranges": training_ranges(X),
        "support": support_from_rows(X, angle(X)).to_dict(),
    }
    return save_surrogate(model, path, metadata=metadata)


@pytest.fixture(scope="session")
def linear_model(tmp_path_factory):
    """θ = 10·p·l, every design swept to 0.5 MPa (800° at most)."""
    return save_model(tmp_path_factory.mktemp("design") / "linear.json")


@pytest.fixture(scope="session")
def short_sweeps_model(tmp_path_factory):
    """θ = 10·p·l, but the 160 mm designs swept to 0.05 MPa only."""
    return save_model(
        tmp_path_factory.mktemp("design") / "short.json",
        swept_to=lambda design: 0.05 if design[0] == 160.0 else 0.5,
    )
