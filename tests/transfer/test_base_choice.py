"""The choice of a transfer base: the table of every base × strategy and the pair it names."""

from __future__ import annotations

import math

import numpy as np
import pandas as pd
import pytest

from softbend.errors import InputError
from softbend.transfer import base_choice
from softbend.transfer.base_choice import (
    TIE_DEG,
    BaseChoice,
    Candidate,
    base_labels,
    best_pair,
    family_by_transfer,
    parse_bases,
    score_bases,
)
from softbend.transfer.loco import LocoResult


def _result(rmses: dict[str, float], failed: dict[str, int] | None = None) -> LocoResult:
    """A loco result whose summary holds ``rmses`` (strategy → mean RMSE, degrees)."""
    failed = failed or {}
    summary = pd.DataFrame(
        [
            {
                "strategy": name,
                "rmse_deg": rmse,
                "rmse_vs_baseline_pct": np.nan,
                "mape_pct": 2 * rmse,
                "max_error_deg": 3 * rmse,
                "coverage": np.nan,
                "worst_actuator": "A1",
                "worst_rmse_deg": 2 * rmse,
                "n_failed": failed.get(name, 0),
            }
            for name, rmse in rmses.items()
        ]
    )
    empty = pd.DataFrame()
    return LocoResult(per_actuator=empty, summary=summary, predictions=empty, learning_curve=empty)


def _candidate(label: str) -> Candidate:
    """A candidate whose model is its label (the fake evaluation's key)."""
    return Candidate(label, f"{label}.json", model=label, measurements=None, strategies=["x"])  # type: ignore[arg-type]


@pytest.fixture
def scored(monkeypatch):
    """:func:`score_bases` with each base's evaluation given: a result, or an error to raise."""

    def run(outcomes: dict[str, LocoResult | Exception]) -> BaseChoice:
        def fake(measurements, model, strategies, **kwargs):
            outcome = outcomes[model]
            if isinstance(outcome, Exception):
                raise outcome
            return outcome

        monkeypatch.setattr(base_choice, "leave_one_configuration_out", fake)
        return score_bases([_candidate(label) for label in outcomes])

    return run


def test_the_best_pair_is_the_minimum_over_every_base_and_strategy(scored):
    choice = scored(
        {
            "plr": _result({"fem-only": 20.0, "scale-offset": 4.5, "residual-gp": 7.2}),
            "xgb": _result({"fem-only": 25.0, "scale-offset": 6.3, "residual-gp": 3.9}),
        }
    )
    assert choice.best is not None
    assert (choice.best["base"], choice.best["strategy"]) == ("xgb", "residual-gp")
    assert choice.best["rmse_deg"] == 3.9 and choice.best["tied_with"] == []
    table = choice.table
    assert len(table) == 6 and table["rmse_deg"].min() == choice.best["rmse_deg"]
    assert table.loc[table["best"], "base"].tolist() == ["xgb"]
    ranks = table.set_index(["base", "strategy"])["rank"]
    assert ranks[("xgb", "residual-gp")] == 1 and ranks[("plr", "scale-offset")] == 2
    assert ranks[("xgb", "fem-only")] == 6
    assert family_by_transfer(choice) == {
        "plr": {
            "transfer_rmse_deg": 4.5,
            "transfer_strategy": "scale-offset",
            "transfer_error": None,
        },
        "xgb": {
            "transfer_rmse_deg": 3.9,
            "transfer_strategy": "residual-gp",
            "transfer_error": None,
        },
    }
    record = choice.to_dict()
    assert record["best"] == choice.best and len(record["table"]) == 6
    assert record["bases"]["plr"]["file"] == "plr.json"


def test_a_tie_goes_to_the_base_listed_first_and_is_recorded(scored):
    choice = scored(
        {
            "b": _result({"experimental": 5.0, "scale-offset": 6.0}),
            "a": _result({"experimental": 5.0 + TIE_DEG / 2, "scale-offset": 7.0}),
        }
    )
    assert choice.best is not None
    assert (choice.best["base"], choice.best["strategy"]) == ("b", "experimental")
    assert choice.best["tied_with"] == ["a/experimental"]


def test_a_pair_with_failed_fits_competes_only_when_every_pair_has_some(scored):
    choice = scored(
        {
            "plr": _result({"scale-offset": 1.0, "fem-only": 9.0}, failed={"scale-offset": 2}),
            "xgb": _result({"scale-offset": 3.0}),
        }
    )
    assert choice.best is not None
    assert (choice.best["base"], choice.best["strategy"]) == ("xgb", "scale-offset")
    assert choice.best["note"] is None
    row = choice.table[
        (choice.table["base"] == "plr") & (choice.table["strategy"] == "scale-offset")
    ]
    assert row["status"].item() == "some fits failed" and math.isnan(row["rank"].item())
    every = scored({"plr": _result({"scale-offset": 1.0}, failed={"scale-offset": 1})})
    assert every.best is not None and every.best["strategy"] == "scale-offset"
    assert "could not be fitted" in every.best["note"]


def test_a_base_whose_every_fit_fails_is_a_row_and_the_others_go_on(scored):
    choice = scored(
        {
            "bad": ValueError("every fit diverged"),
            "good": _result({"scale-offset": 4.0}),
        }
    )
    assert choice.errors == {"bad": "every fit diverged"}
    assert choice.best is not None and choice.best["base"] == "good"
    row = choice.table[choice.table["base"] == "bad"].iloc[0]
    assert row["status"] == "failed" and row["error"] == "every fit diverged"
    assert math.isnan(row["rank"])
    assert choice.to_dict()["bases"]["bad"] == {
        "file": "bad.json",
        "status": "failed",
        "error": "every fit diverged",
    }
    assert family_by_transfer(choice)["bad"]["transfer_error"] == "every fit diverged"
    with pytest.raises(ValueError, match="first"):  # every base failing: the first one's error
        scored({"a": ValueError("first"), "b": ValueError("second")})


def test_bad_input_to_a_run_is_not_taken_for_a_failed_base(scored):
    with pytest.raises(InputError, match="level"):
        scored({"a": InputError("must be in (0, 1)", key="level"), "b": _result({"x": 1.0})})


def test_no_finite_rmse_names_no_pair():
    table = pd.DataFrame(
        {
            "base": ["a"],
            "base_file": ["a.json"],
            "strategy": ["x"],
            "rmse_deg": [np.nan],
            "n_failed": [0],
        }
    )
    assert best_pair(table) is None


def test_labels_are_the_stems_made_unique(tmp_path):
    assert base_labels(["m/models/plr.json", "n/models/xgb.json"]) == ["plr", "xgb"]
    assert base_labels(["run1/models/mlp.json", "run2/models/mlp.json"]) == [
        "run1-mlp",
        "run2-mlp",
    ]
    assert base_labels(["a/mlp.json", "b/a/mlp.json"]) == ["a-mlp", "a-mlp-2"]


def test_the_base_text_is_split_and_checked(tmp_path):
    assert parse_bases(None) is None
    assert parse_bases("a.json") == [tmp_path.__class__("a.json")]
    assert [p.name for p in parse_bases(" a.json , b.json ")] == ["a.json", "b.json"]
    with pytest.raises(InputError, match="empty name") as error:
        parse_bases("a.json,,b.json")
    assert error.value.key == "base"
    with pytest.raises(InputError, match="twice"):
        parse_bases(f"{tmp_path}/a.json,{tmp_path}/../{tmp_path.name}/a.json")
    with pytest.raises(InputError, match="at least one"):
        score_bases([])
    with pytest.raises(InputError, match="unique"):
        score_bases([_candidate("a"), _candidate("a")])
