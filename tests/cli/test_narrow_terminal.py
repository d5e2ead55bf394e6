"""Tables on an 80-column terminal: cells wrap, nothing is cut short with "…"."""

from __future__ import annotations

from types import SimpleNamespace

import pandas as pd
import pytest
from rich.console import Console

from softbend.cli import _common, _console, main

WIDTH = 80


@pytest.fixture
def narrow(monkeypatch):
    """The CLI's stdout console as on an 80-column terminal."""
    console = Console(width=WIDTH)
    monkeypatch.setattr(_console, "console", console)
    monkeypatch.setattr(_common, "console", console)
    return console


def _check_whole(text: str) -> None:
    assert "…" not in text, text
    for line in text.splitlines():
        assert len(line) <= WIDTH, (len(line), line)


@pytest.mark.parametrize(
    "argv",
    [
        ["transfer", "strategies"],
        ["control", "controllers"],
        ["materials", "list"],
    ],
    ids=" ".join,
)
def test_listings_wrap_on_80_columns(narrow, capsys, argv):
    assert main(argv) == 0
    _check_whole(capsys.readouterr().out)


def test_campaign_status_wraps_on_80_columns(narrow, tmp_path, capsys):
    db = tmp_path / "a-campaign-database-with-a-rather-long-name-to-wrap.duckdb"
    run = ["campaign", "run", str(db), "--space", "lhs:2", "--pmax", "0.1", "--pstep", "0.05"]
    assert main([*run, "--workers", "0", "--json"]) == 0
    capsys.readouterr()
    assert main(["campaign", "status", str(db)]) == 0
    _check_whole(capsys.readouterr().out)


def test_train_summary_wraps_on_80_columns(narrow, capsys):
    from softbend.cli.train import print_summary

    row = {
        "r2": 0.999876,
        "rmse_deg": 1.2345,
        "mape_pct": 2.345,
        "max_abs_error_deg": 12.5,
        "inference_single_us": 35.2,
        "inference_batch_ms": 4.56,
    }
    summary = {
        "models": {
            "mlp": {
                **row,
                "params": "hidden_sizes=(63, 65), learning_rate=0.0006, batch_size=256",
                "paper_b": {"r2": 0.9999, "mape_pct": 0.54, "inference_ms": 0.21},
            },
            "a-registered-family-with-a-long-name": {**row, "params": "{}", "paper_b": None},
        }
    }
    print_summary(summary)
    _check_whole(capsys.readouterr().out)


def test_loco_summary_wraps_on_80_columns(narrow, capsys):
    from softbend.cli.transfer_loco import print_loco_summary

    summary = pd.DataFrame(
        {
            "strategy": ["refined-ensemble", "scale-offset"],
            "rmse_deg": [7.1234, 12.5],
            "mape_pct": [5.5, 9.25],
            "max_error_deg": [30.5, 41.0],
            "coverage": [0.875, float("nan")],
            "worst_actuator": ["100,6,2,2,5,8", "160,10,4,4,15,12"],
            "worst_rmse_deg": [15.25, 20.5],
        }
    )
    result = SimpleNamespace(
        summary=summary,
        settings={"actuators": ["a"] * 7, "n_measurements": 139},
        level=0.9,
        calibrations={},
    )
    print_loco_summary(result)
    _check_whole(capsys.readouterr().out)
