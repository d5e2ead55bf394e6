"""The scripts in ``examples/`` run and give physically sensible numbers."""

from __future__ import annotations

import importlib.util
import warnings
from pathlib import Path

import pytest

EXAMPLES = Path(__file__).resolve().parents[1] / "examples"


def _load(name: str):
    spec = importlib.util.spec_from_file_location(name, EXAMPLES / f"{name}.py")
    module = importlib.util.module_from_spec(spec)
    spec.loader.exec_module(module)
    return module


def test_identify_curling_actuator_example(capsys):
    with warnings.catch_warnings():
        warnings.simplefilter("ignore")  # shape clipped to 2 on this data: expected
        metrics = _load("identify_curling_actuator").main(seed=0)
    assert metrics["nrmse"] < 0.10
    assert "free-run NRMSE" in capsys.readouterr().out


def test_design_campaign_example_resumes(tmp_path, capsys):
    example = _load("design_campaign")
    db = tmp_path / "c.duckdb"
    loadings = example.main(db, seed=0)
    assert loadings["pressure_mpa"] > 0.5 and loadings["t_mm"] < 0.0
    again = example.main(db, seed=0)
    assert again == pytest.approx(loadings)
    assert "0 designs run, 40 already" in capsys.readouterr().out


def test_custom_controller_example_registers_and_runs(capsys):
    from softbend.control import CONTROLLERS

    try:
        results = _load("custom_controller").main(duration_s=6.0)
        assert "lead-bang-bang" in CONTROLLERS
        paper, lead = results["bang-bang"], results["lead-bang-bang"]
        assert 0 < paper["mape_pct"] < 20 and 0 < lead["mape_pct"] < 20
        # The unfiltered lead chatters: more valve switches than paper B's controller.
        assert lead["switches"] > paper["switches"]
        assert "'lead': 0.05" in capsys.readouterr().out
    finally:
        if "lead-bang-bang" in CONTROLLERS:
            CONTROLLERS.unregister("lead-bang-bang")
