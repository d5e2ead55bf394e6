"""``residual-gp`` on many readings: hyperparameters on a seeded draw, the posterior on all."""

from __future__ import annotations

import numpy as np
import pytest

from softbend.transfer.strategies import ResidualGP
from softbend.transfer.strategies.corrections import hyper_rows


def test_every_row_when_few_else_a_seeded_draw_without_repeats():
    assert np.array_equal(hyper_rows(30, 30, 0), np.arange(30))
    drawn = hyper_rows(1000, 100, 0)
    assert drawn.size == 100 and np.unique(drawn).size == 100
    assert np.all(np.diff(drawn) > 0) and drawn[-1] < 1000
    assert np.array_equal(drawn, hyper_rows(1000, 100, 0))
    assert not np.array_equal(drawn, hyper_rows(1000, 100, 1))


def _gap(small_base, X):
    """A smooth gap of the base: grows with the pressure, as a softer elastomer's would."""
    p = X[:, -1] / X[:, -1].max()
    return small_base.predict(X) + 6.0 * p**2 + 2.0 * np.sin(3.0 * p)


def test_few_readings_are_all_used(small_base, quick_measurements):
    X = quick_measurements.features
    model = ResidualGP(small_base, n_restarts=0).fit(X, _gap(small_base, X))
    assert np.array_equal(model.hyper_rows_, np.arange(len(X)))


def test_a_draw_of_the_readings_learns_the_gap_and_the_posterior_holds_every_one(
    small_base, quick_measurements
):
    X = quick_measurements.features
    rng = np.random.default_rng(0)
    y = _gap(small_base, X) + rng.normal(0.0, 0.5, len(X))
    most = max(len(X) // 3, 10)
    drawn = ResidualGP(small_base, n_restarts=0, hyper_points=most, seed=2).fit(X, y)
    full = ResidualGP(small_base, n_restarts=0).fit(X, y)
    assert drawn.hyper_rows_.size == most
    assert drawn.model_.inputs_.shape[0] == len(X)  # the exact posterior on every reading
    truth = _gap(small_base, X)
    error_drawn = np.sqrt(np.mean((drawn.predict(X) - truth) ** 2))
    error_full = np.sqrt(np.mean((full.predict(X) - truth) ** 2))
    assert error_drawn < 0.5  # below the readings' noise: the gap is learned
    assert error_drawn == pytest.approx(error_full, abs=0.15)
    again = ResidualGP(small_base, n_restarts=0, hyper_points=most, seed=2).fit(X, y)
    np.testing.assert_array_equal(again.model_.kernel_theta_, drawn.model_.kernel_theta_)
