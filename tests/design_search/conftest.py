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


# -- another actuator: a PneuNet-like description, θ known in closed form ------------------

#: θ = p·(0.4·n − 0.5·w + 0.2·L) degrees, p in kPa, n chambers, w the wall (mm), L the
#: layer's index (fabric 0, paper 1): linear in p·n, p·w and p·L, so a degree-2
#: polynomial fits it exactly. At 30 kPa: θ = 12·n − 15·w + 6·L.
PNEUNET_COEFFICIENTS = (0.4, -0.5, 0.2)


def pneunet_angle(n, wall, layer, p_kpa):
    """The closed-form angle of the synthetic PneuNet, degrees."""
    a, b, c = PNEUNET_COEFFICIENTS
    return p_kpa * (a * n + b * wall + c * layer)


def write_pneunet_table(path, designs):
    """A simulation table of ``designs`` ((n, wall, level name) each), swept 0 to 50 kPa."""
    import pandas as pd

    rows = []
    for i, (n, wall, layer) in enumerate(designs):
        index = 1 if layer == "paper" else 0
        for p in np.linspace(0.0, 50.0, 6):
            rows.append(
                {"design_id": f"d{i:02d}", "n_chambers": n, "wall_mm": wall, "layer": layer,
                 "p_kpa": p, "angle_deg": pneunet_angle(n, wall, index, p)}
            )  # fmt: skip
    pd.DataFrame(rows).to_csv(path, index=False)
    return path


def train_pneunet(folder, designs, actuator=None):
    """A polynomial surrogate of :func:`write_pneunet_table` (with ``actuator``'s description,
    else the one read off the table); the path of its ``plr.json``."""
    from softbend.surrogates.simulation_table import table_training_data
    from softbend.surrogates.workflow import train_surrogates

    table = write_pneunet_table(folder / "sims.csv", designs)
    if actuator is None:
        data = table_training_data(
            table,
            design_columns="n_chambers,wall_mm,layer",
            pressure_column="p_kpa",
            pressure_unit="kPa",
        )
    else:
        data = table_training_data(table, actuator=actuator)
    train_surrogates(data, folder / "m", models="plr", grid_name="quick", export_onnx=False)
    return folder / "m" / "models" / "plr.json"


#: The designs of the table-described PneuNet (no constraint, no resolution).
PNEUNET_DESIGNS = list(itertools.product((6, 9, 12), (0.5, 1.75, 3.0), ("fabric", "paper")))


@pytest.fixture(scope="session")
def pneunet_model(tmp_path_factory):
    """The PneuNet described by its table's columns: n_chambers 6–12 (integer), wall_mm
    0.5–3 mm (continuous), layer fabric/paper; pressure p_kpa in kPa."""
    return train_pneunet(tmp_path_factory.mktemp("pneunet"), PNEUNET_DESIGNS)
