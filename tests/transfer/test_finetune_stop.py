"""The refits' stop on a held-out plateau (:class:`softbend.transfer.finetune.EarlyStop`)."""

from __future__ import annotations

import numpy as np
import pytest

from softbend.errors import InputError
from softbend.transfer.finetune import EarlyStop, fine_tune_many, held_out_rows, row_weights

pytest.importorskip("torch")


@pytest.fixture
def base(random_mlp):
    return random_mlp


def _rows(base, n=60, seed=3):
    rng = np.random.default_rng(seed)
    X = base.x_mean_ + base.x_scale_ * rng.uniform(-1.0, 1.0, size=(n, base.n_features_in_))
    noise = rng.normal(0.0, 8.0, n)  # noisy readings: the held-out loss plateaus, then rises
    return X, base.predict(X) * 1.05 + 1.0 + noise


def _folds(n):
    return row_weights([np.arange(n)[np.arange(n) % 3 != k] for k in range(3)], n)


def _same(a, b):
    return all(np.array_equal(p, q) for p, q in zip(a.coefs_, b.coefs_, strict=True)) and all(
        np.array_equal(p, q) for p, q in zip(a.intercepts_, b.intercepts_, strict=True)
    )


def test_a_patience_past_the_cap_trains_exactly_as_without_the_stop(base):
    X, y = _rows(base)
    w = _folds(y.size)
    plain = fine_tune_many(base, X, y, w, epochs=60, learning_rate=1e-2, device="cpu")
    watched = fine_tune_many(
        base, X, y, w, epochs=60, learning_rate=1e-2, device="cpu", stop=EarlyStop(60)
    )
    for a, b in zip(plain, watched, strict=True):
        assert _same(a, b)
        assert a.loss_curve_ == b.loss_curve_
        assert b.epochs == 60


def test_a_stopped_variant_keeps_its_weights_of_the_shadows_best_epoch(base):
    """Stopped after e steps, a variant is what e steps without the stop give: the
    variant trains on all its rows; only its shadow holds rows out."""
    X, y = _rows(base)
    w = _folds(y.size)
    cap = 2000
    stopped = fine_tune_many(
        base, X, y, w, epochs=cap, learning_rate=1e-2, device="cpu", stop=EarlyStop(30, 1e-3)
    )
    kept = [m.epochs for m in stopped]
    assert all(1 <= e < cap for e in kept), kept
    for k, model in enumerate(stopped):
        assert len(model.loss_curve_) == model.epochs + 1
        again = fine_tune_many(
            base, X, y, w[k : k + 1], epochs=model.epochs, learning_rate=1e-2, device="cpu"
        )[0]
        np.testing.assert_allclose(again.coefs_[0], model.coefs_[0], rtol=1e-10, atol=1e-12)
        np.testing.assert_allclose(again.predict(X), model.predict(X), rtol=1e-10, atol=1e-9)


def test_the_stop_does_not_depend_on_the_folds_beside(base):
    X, y = _rows(base)
    w = _folds(y.size)
    stop = EarlyStop(30, 1e-3, seed=4)
    together = fine_tune_many(
        base, X, y, w, epochs=800, learning_rate=1e-2, device="cpu", stop=stop
    )
    # The folds stop at different epochs, so the batch sheds the first ones stopped.
    assert len({m.epochs for m in together}) > 1
    for i, fold in enumerate(together):
        alone = fine_tune_many(
            base, X, y, w[i : i + 1], epochs=800, learning_rate=1e-2, device="cpu", stop=stop
        )[0]
        assert fold.epochs == alone.epochs
        np.testing.assert_allclose(fold.predict(X), alone.predict(X), rtol=1e-10, atol=1e-9)
        np.testing.assert_allclose(fold.loss_curve_, alone.loss_curve_, rtol=1e-10)


def test_the_held_out_draw_is_seeded_and_of_its_share():
    a = held_out_rows(10_000, 0.2, 0)
    assert np.array_equal(a, held_out_rows(10_000, 0.2, 0))
    assert not np.array_equal(a, held_out_rows(10_000, 0.2, 1))
    assert abs(a.mean() - 0.2) < 0.02


@pytest.mark.parametrize(
    ("kwargs", "key"),
    [
        ({"patience": 0}, "patience"),
        ({"patience": 10, "min_delta": -0.1}, "min_delta"),
        ({"patience": 10, "validation_share": 1.0}, "validation_share"),
        ({"patience": 10, "validation_share": 0.0}, "validation_share"),
    ],
)
def test_a_bad_stop_is_one_error_naming_the_field(kwargs, key):
    with pytest.raises(InputError) as error:
        EarlyStop(**kwargs)
    assert error.value.key == key


def test_the_experimental_mlp_stops_before_its_cap(quick_measurements):
    from softbend.transfer.strategies import ExperimentalMLP

    default = ExperimentalMLP()
    assert (default.epochs, default.patience, default.min_delta) == (15000, 200, 0.01)
    X, y = quick_measurements.features, quick_measurements.angle_deg
    model = ExperimentalMLP(hidden_sizes=(8, 8), patience=20, min_delta=0.05, device="cpu")
    model.fit(X, y)
    assert 1 <= model.model_.epochs < 15000
    assert len(model.loss_curve_) == model.model_.epochs + 1
    assert np.all(np.isfinite(model.predict(X)))
