"""Main effects of a design space (softbend.analysis.effects): closed forms and bad input."""

from __future__ import annotations

import numpy as np
import pandas as pd
import pytest

from softbend.analysis import angle_at_pressure, main_effects
from softbend.errors import DatasetError, InputError


def _designs(n: int = 3000, seed: int = 0) -> pd.DataFrame:
    rng = np.random.default_rng(seed)
    return pd.DataFrame(
        {
            "wall_mm": rng.uniform(1.0, 3.0, n),
            "gap_mm": rng.uniform(1.0, 5.0, n),
            "n_chambers": rng.integers(3, 6, n).astype(float),  # three values
        }
    )


def test_an_additive_response_gives_each_parameter_its_own_slope_times_its_spread():
    designs = _designs()
    # angle = 10 (3 − wall) + 2 n: gap plays no part
    angle = 10.0 * (3.0 - designs["wall_mm"]) + 2.0 * designs["n_chambers"]
    effects = main_effects(designs, ["wall_mm", "gap_mm", "n_chambers"], {"angle": angle})
    e, trends = effects.effects["angle"], effects.trends["angle"]
    # wall: 4 quartile bins of a uniform on [1, 3]: centres 1.25 … 2.75, slope −10
    assert e["wall_mm"] == pytest.approx(-15.0, abs=1.0) and trends["wall_mm"] == "falls"
    # n_chambers: its three values are the groups, slope +2 from 3 to 5 → 4
    assert e["n_chambers"] == pytest.approx(4.0, abs=0.6) and trends["n_chambers"] == "rises"
    groups = effects.table.query("parameter == 'n_chambers' and response == 'angle'")
    assert list(groups["low"]) == list(groups["high"]) == [3.0, 4.0, 5.0]
    # gap's groups differ only by the others' sampling noise
    assert abs(e["gap_mm"]) < 1.5
    assert effects.ranking("angle") == ["wall_mm", "n_chambers", "gap_mm"]


def test_group_counts_cover_every_design_and_missing_responses_are_left_out():
    designs = _designs(200)
    response = designs["gap_mm"].copy()
    response.iloc[:50] = np.nan  # designs whose sweep stopped before the pressure
    effects = main_effects(designs, ["gap_mm"], {"r": response}, bins=5)
    table = effects.table
    assert len(table) == 5 and table["n"].sum() == 150
    assert effects.effects.loc["gap_mm", "r"] > 0
    assert effects.trends.loc["gap_mm", "r"] == "rises"
    # a response is a group mean of its own values: the identity response's means
    # lie inside their groups' ranges
    assert (table["mean"] >= table["low"] - 1e-12).all()
    assert (table["mean"] <= table["high"] + 1e-12).all()


def test_a_response_aligned_by_index_not_position():
    designs = _designs(100).set_axis([f"d{i}" for i in range(100)])
    response = (designs["wall_mm"] * 2.0).iloc[::-1]  # same values, reversed order
    forward = main_effects(designs, ["wall_mm"], {"r": designs["wall_mm"] * 2.0})
    backward = main_effects(designs, ["wall_mm"], {"r": response})
    pd.testing.assert_frame_equal(forward.table, backward.table)


def test_angle_at_pressure_is_linear_between_samples_and_nan_past_the_sweep():
    rows = []
    for design, k, last in (("a", 1000.0, 0.02), ("b", 500.0, 0.004)):
        for p in np.arange(0.0, last + 1e-9, 0.002):
            rows.append({"design_id": design, "pressure_mpa": p, "angle_deg": k * p})
    rows.append({"design_id": "a", "pressure_mpa": 0.03, "angle_deg": 99.0, "converged": False})
    samples = pd.DataFrame(rows).fillna({"converged": True})
    angle = angle_at_pressure(samples, 0.005)
    assert angle["a"] == pytest.approx(5.0)
    assert np.isnan(angle["b"])  # stopped at 4 kPa
    # the unconverged point past the end is not a result
    assert np.isnan(angle_at_pressure(samples, 0.025)["a"])


@pytest.mark.parametrize(
    ("call", "error", "key"),
    [
        (lambda d: main_effects(d, ["wall_mm"], {"r": d["wall_mm"]}, bins=1), InputError, "bins"),
        (lambda d: main_effects(d, ["wall_mm"], {"r": d["wall_mm"]}, bins=21), InputError, "bins"),
        (lambda d: main_effects(d, ["height_mm"], {"r": d["wall_mm"]}), DatasetError, None),
        (lambda d: main_effects(d, ["wall_mm"], {"r": np.ones(3)}), InputError, "r"),
        (lambda d: main_effects(d, ["wall_mm"], {}), InputError, "parameters"),
        (
            lambda d: main_effects(d, ["wall_mm"], {"r": np.full(len(d), np.nan)}),
            DatasetError,
            None,
        ),
    ],
)
def test_bad_input_is_one_clear_error(call, error, key):
    with pytest.raises(error) as caught:
        call(_designs(50))
    if key is not None:
        assert caught.value.key == key


def test_angle_at_pressure_refuses_a_bad_pressure_and_names_missing_columns():
    samples = pd.DataFrame({"design_id": ["a"], "pressure_mpa": [0.0], "angle_deg": [0.0]})
    with pytest.raises(InputError, match="pressure"):
        angle_at_pressure(samples, float("nan"))
    with pytest.raises(DatasetError, match="angle_deg"):
        angle_at_pressure(samples.drop(columns="angle_deg"), 0.0)
