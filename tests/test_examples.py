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


def test_the_lab_s_own_actuator_end_to_end(tmp_path):
    # examples/lab_own_actuator.sh --quick: own silicone refitted, own design measured on two
    # days, refined with a calibrated interval, scored leave-one-actuator-out on seven and
    # eight actuators, predicted, and played as the plant of a control loop.
    import json
    import os
    import shutil
    import subprocess
    import sys

    bash = shutil.which("bash")
    if bash is None:
        pytest.skip("bash is needed to run the example script")
    bin_dir = Path(sys.executable).parent
    env = {
        **os.environ,
        "PATH": f"{bin_dir}{os.pathsep}{os.environ.get('PATH', '')}",
        "SOFTBEND": str(bin_dir / "softbend"),
        "PYTHON": sys.executable,
    }
    out = tmp_path / "lab"
    done = subprocess.run(
        [bash, str(EXAMPLES / "lab_own_actuator.sh"), str(out), "--quick"],
        env=env,
        capture_output=True,
        text=True,
        timeout=900,
        check=False,
    )
    assert done.returncode == 0, done.stderr[-3000:]

    from softbend.surrogates.persistence import load_surrogate
    from softbend.transfer.measurements import load_measurements

    days = [load_measurements(out / f"own_day{d}.csv") for d in (1, 2)]
    assert [sorted(set(day.frame["cycle"])) for day in days] == [[1], [2]]
    assert days[0].metadata["lab.material"].endswith("fit.json")
    refined = load_surrogate(out / "refined.json").metadata
    assert len(refined["measurement_files"]) == 3 and len(refined["actuators"]) == 8
    assert refined["interval"]["n_actuators"] == 8 and refined["interval"]["guaranteed"] is False
    assert "130,7,2.5,3,10,9" in refined["actuators"]
    predicted = json.loads((out / "predict.json").read_text())
    assert predicted["supported"] == [True, True, True]
    low, high = predicted["interval_low_deg"], predicted["interval_high_deg"]
    assert all(lo <= a <= hi for lo, a, hi in zip(low, predicted["angle_deg"], high, strict=True))
    for name, n in (("loco7", 7), ("loco8", 8)):
        loco = json.loads((out / f"{name}.json").read_text())
        assert {r["strategy"] for r in loco["summary"]} == {"refined", "scale-offset"}
        assert all(0.0 <= r["calibrated_coverage"] <= 1.0 for r in loco["summary"])
        assert loco["calibration"]["refined"]["n_actuators"] == n
    control = json.loads((out / "control" / "metrics.json").read_text())
    assert control["plant"] == str(out / "refined.json")
    assert control["metrics"]["mape_pct"] < 50.0
