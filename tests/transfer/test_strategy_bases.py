"""Each strategy says which bases it takes; a batch fit goes on past one row set it cannot fit."""

from __future__ import annotations

import numpy as np
import pytest

from softbend.surrogates.polynomial import PolynomialRegressor
from softbend.transfer.refine import default_refine_strategy
from softbend.transfer.strategies import (
    BUILTIN_STRATEGIES,
    STRATEGIES,
    ScaledRefinedMLP,
    applicable_strategies,
    check_applicable,
    make_strategy,
    strategy_refusal,
)


@pytest.fixture(scope="module")
def plr_base(quick_measurements):
    X, y = quick_measurements.features, quick_measurements.angle_deg
    return PolynomialRegressor(degree=2).fit(X, y)


def test_an_mlp_base_takes_every_strategy(small_base):
    kept, left_out = applicable_strategies(BUILTIN_STRATEGIES, small_base)
    assert kept == list(BUILTIN_STRATEGIES) and left_out == {}
    assert default_refine_strategy(small_base) == ("refined", {})


def test_a_polynomial_base_leaves_out_what_trains_a_network_further(plr_base):
    kept, left_out = applicable_strategies(BUILTIN_STRATEGIES, plr_base)
    assert set(left_out) == {"refined", "refined-ensemble", "scaled-refined"}
    assert "experimental" in kept  # from scratch: it takes no base at all
    for reason in left_out.values():
        assert reason == (
            "trains the base's network further, and the base is a plr surrogate, not an mlp"
        )
    strategy, passed_over = default_refine_strategy(plr_base)
    assert strategy == "scale-offset" and set(passed_over) == {"refined"}
    with pytest.raises(
        ValueError,
        match=r"^strategy: 'refined-ensemble' trains the base's network further, .* not an mlp; "
        r"the strategies that apply to this plr base: fem-only, base-mean-residual, analytical, "
        r"experimental, scale-offset",
    ):
        check_applicable(["scale-offset", "refined-ensemble"], plr_base, key="strategy")


def test_a_registered_strategy_without_a_refusal_takes_any_base(plr_base):
    class Anything:
        def __init__(self, base=None):
            self.base = base

    STRATEGIES.register("anything", Anything)
    try:
        assert strategy_refusal("anything", plr_base) is None
    finally:
        STRATEGIES.unregister("anything")


def test_a_batch_goes_on_past_a_row_set_it_cannot_fit(small_base, quick_measurements):
    X, y = quick_measurements.features, quick_measurements.angle_deg
    at_rest = np.flatnonzero(X[:, -1] == 0.0)
    sets = [at_rest, np.arange(40)]
    with pytest.raises(ValueError, match=r"^X: must include a pressure above 0 MPa"):
        ScaledRefinedMLP.fit_batch(
            [make_strategy("scaled-refined", small_base, epochs=5) for _ in sets], X, y, sets
        )
    failed, fitted = ScaledRefinedMLP.fit_batch(
        [make_strategy("scaled-refined", small_base, epochs=5) for _ in sets],
        X,
        y,
        sets,
        keep_going=True,
    )
    assert "must include a pressure above 0 MPa" in str(failed.fit_error_)
    assert not hasattr(failed, "model_") and not hasattr(fitted, "fit_error_")
    alone = ScaledRefinedMLP(small_base, epochs=5).fit(X[sets[1]], y[sets[1]])
    np.testing.assert_allclose(fitted.predict(X), alone.predict(X), rtol=1e-9, atol=1e-9)
