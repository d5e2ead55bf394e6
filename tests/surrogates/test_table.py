"""The table base: exact curves at simulated designs, a Gaussian process between them."""

from __future__ import annotations

import json

import numpy as np
import pytest

from softbend.errors import InputError, SchemaError
from softbend.surrogates.persistence import load_surrogate, save_surrogate
from softbend.surrogates.table import (
    MIN_POINTS_PER_CURVE,
    TableRegressor,
    gp_training_rows,
)

from .conftest import table1_inputs

PRESSURES = np.linspace(0.0, 0.5, 6)  # MPa


def _angle(X: np.ndarray) -> np.ndarray:
    """A curving, rising angle (degrees): steeper for long, thin designs."""
    length, t, p = X[:, 0], X[:, 2], X[:, -1]
    return 120.0 * (length / 130.0) / (t / 3.0) * p**1.5 / 0.5**1.5


def _table(n_designs: int, seed: int = 0) -> tuple[np.ndarray, np.ndarray]:
    designs = table1_inputs(n_designs, seed)[:, :6]
    X = np.array([[*d, p] for d in designs for p in PRESSURES])
    return X, _angle(X)


@pytest.fixture(scope="module")
def fitted() -> tuple[TableRegressor, np.ndarray, np.ndarray]:
    X, y = _table(16)
    return TableRegressor(n_restarts=0).fit(X, y), X, y


def test_exact_at_the_simulated_designs(fitted):
    model, X, y = fitted
    assert np.max(np.abs(model.predict(X) - y)) < 1e-9
    assert np.all(model.matched(X) >= 0)
    # the rows in another order, and a repeated pressure: the same angles
    order = np.random.default_rng(1).permutation(X.shape[0])
    assert np.max(np.abs(model.predict(X[order]) - y[order])) < 1e-9


def test_a_monotone_curve_stays_monotone_between_its_pressures(fitted):
    model, X, _ = fitted
    design = X[0, :-1]
    fine = np.linspace(0.0, 0.5, 401)
    rows = np.column_stack([np.tile(design, (fine.size, 1)), fine])
    angles = model.predict(rows)
    assert np.all(np.diff(angles) >= -1e-12)
    # within each interval, between its two simulated angles (no overshoot)
    simulated = _angle(np.column_stack([np.tile(design, (PRESSURES.size, 1)), PRESSURES]))
    assert angles.min() >= simulated.min() - 1e-12 and angles.max() <= simulated.max() + 1e-12


def test_past_the_top_pressure_linear_with_the_end_slope_or_clamped(fitted):
    model, X, y = fitted
    design = X[0, :-1]
    top, eps = PRESSURES[-1], 1e-6
    rows = np.array([[*design, p] for p in (top - eps, top, top + 0.1, top + 0.2)])
    below, at, far, farther = model.predict(rows)
    slope = (at - below) / eps
    assert at == pytest.approx(y[PRESSURES.size - 1])
    assert far == pytest.approx(at + 0.1 * slope, rel=1e-4)
    assert farther - far == pytest.approx(far - at, rel=1e-9)  # a straight line
    clamp = TableRegressor(extrapolation="clamp", n_restarts=0).fit(X, y)
    assert clamp.predict(rows[2:]) == pytest.approx([at, at])


def test_gp_uncertainty_grows_away_from_the_designs(fitted):
    model, X, _ = fitted
    design = X[0, :-1].copy()
    at_design = np.array([[*design, 0.3]])
    near = at_design.copy()
    near[0, 0] += 0.5  # half a millimetre longer: not simulated, close to one that is
    far = at_design.copy()
    far[0, :6] = [200.0, 20.0, 8.0, 8.0, 40.0, 30.0]  # far outside every design
    _, std_at = model.predict(at_design, return_std=True)
    _, std_near = model.predict(near, return_std=True)
    _, std_far = model.predict(far, return_std=True)
    assert model.matched(near)[0] == -1
    assert std_at[0] == pytest.approx(model.noise_std_)
    assert std_at[0] <= std_near[0] < std_far[0]
    low, high = model.predict_interval(far, 0.9)
    assert high[0] - low[0] == pytest.approx(2 * 1.6448536 * std_far[0], rel=1e-6)


def test_the_gp_predicts_an_unseen_design_from_the_others():
    X, y = _table(24, seed=2)
    held = np.arange(6)  # the first design's curve
    model = TableRegressor(n_restarts=0).fit(X[6:], y[6:])
    assert np.all(model.matched(X[held]) == -1)
    error = model.predict(X[held]) - y[held]
    assert np.sqrt(np.mean(error**2)) < 0.15 * y[held].max()


def test_save_and_load_predict_the_same(fitted, tmp_path):
    model, X, _ = fitted
    path = save_surrogate(model, tmp_path / "table.json")
    loaded = load_surrogate(path)
    assert loaded.kind == "table"
    rows = np.vstack([X, X + 0.05])
    for a, b in zip(model.predict(rows, return_std=True),
                    loaded.model.predict(rows, return_std=True), strict=True):  # fmt: skip
        assert np.array_equal(a, b)


def test_a_file_of_broken_curves_is_refused(fitted, tmp_path):
    model, _, _ = fitted
    path = save_surrogate(model, tmp_path / "table.json")
    document = json.loads(path.read_text(encoding="utf-8"))
    document["state"]["curve_offsets_"]["__ndarray__"][1] = 0  # a design of no point
    path.write_text(json.dumps(document), encoding="utf-8")
    with pytest.raises(SchemaError, match="curve_offsets_"):
        load_surrogate(path)


def test_the_gp_rows_keep_each_curves_ends_within_the_cap():
    offsets = np.arange(0, 11 * 1000 + 1, 11)  # 1000 curves of 11 points
    rows = gp_training_rows(offsets, 600, seed=0)
    assert rows.size <= 600 and np.all(np.diff(rows) > 0)
    curves = rows // 11
    assert np.unique(curves).size == 600 // MIN_POINTS_PER_CURVE
    firsts = set(offsets[:-1][np.unique(curves)])
    assert firsts <= set(rows.tolist())  # each drawn curve's first point
    few = gp_training_rows(np.arange(0, 11 * 20 + 1, 11), 600, seed=0)
    assert few.size == 220  # 20 curves: every point
    some = gp_training_rows(np.arange(0, 11 * 100 + 1, 11), 600, seed=0)
    assert some.size == 100 * 6 and set(range(0, 1100, 11)) <= set(some.tolist())
    assert np.array_equal(gp_training_rows(offsets, 600, 0), rows)  # seeded


@pytest.mark.parametrize(
    ("build", "key"),
    [
        (lambda X, y: TableRegressor(extrapolation="cubic").fit(X, y), "extrapolation"),
        (lambda X, y: TableRegressor(max_gp_points=2).fit(X, y), "max_gp_points"),
        (lambda X, y: TableRegressor(seed=-1).fit(X, y), "seed"),
        (lambda X, y: TableRegressor().fit(X[:, :1], y), "X"),
        (lambda X, y: TableRegressor().fit(np.where(X[3, 2] == X, np.nan, X), y), "X"),
        (lambda X, y: TableRegressor().fit(X, y[:-1]), "y"),
    ],
)
def test_bad_input_is_one_error_naming_the_field(build, key):
    X, y = _table(4)
    with pytest.raises(InputError) as raised:
        build(X, y)
    assert raised.value.key == key


def test_rows_of_another_width_are_refused(fitted):
    model, X, _ = fitted
    with pytest.raises(InputError, match=r"\(n, 7\)"):
        model.predict(X[:, :5])
