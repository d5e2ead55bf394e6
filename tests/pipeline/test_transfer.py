"""Transfer learning on the shipped virtual lab: leave one configuration out, tables written."""

from __future__ import annotations

import json

import pandas as pd
import pytest

from softbend.pipeline.transfer import run_transfer

from .conftest import Phases, pictures

#: Strategies without a network or a Gaussian process to train: seconds, not a minute.
FAST = ("fem-only", "analytical", "scale-offset")


@pytest.fixture(scope="module")
def transfer(tmp_path_factory):
    out = tmp_path_factory.mktemp("transfer")
    phases = Phases()
    result = run_transfer(out, 0, phases, strategies=FAST)
    return out, result, phases


def test_scores_each_strategy_on_held_out_actuators(transfer):
    _, result, phases = transfer
    s = result.summary
    assert s["n_measurements"] == len(result.measurements) >= 70
    assert set(s["summary"]) == set(FAST) and s["best"] in FAST
    fem_only = s["summary"]["fem-only"]
    assert fem_only["coverage"] is None and s["summary"]["analytical"]["coverage"] is None
    assert 0.0 <= s["summary"]["scale-offset"]["coverage"] <= 1.0  # its interval
    # The FEM-trained MLP is nearer the lab than the analytical model (no gravity, no bulging).
    assert fem_only["rmse_deg"] < s["summary"]["analytical"]["rmse_deg"]
    for row in s["summary"].values():
        assert 0.0 < row["rmse_deg"] <= row["max_error_deg"]
    # Learning from the lab's readings beats the FEM-trained MLP on unseen actuators.
    best = s["summary"][s["best"]]
    assert best["rmse_deg"] <= fem_only["rmse_deg"]
    assert s["best"] != "fem-only"
    assert phases.all_finished()


def test_writes_the_tables_but_no_figures(transfer):
    out, result, _ = transfer
    assert result.files == result.summary["files"]
    table = pd.read_csv(result.files["summary"])
    assert sorted(table["strategy"]) == sorted(FAST)
    loco = json.loads((out / "transfer" / "loco.json").read_text(encoding="utf-8"))
    assert loco["settings"]
    assert pictures(out) == []
