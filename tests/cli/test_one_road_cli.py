"""Every surrogate family of another actuator walks the road paper B's actuator walks.

Each family (plr, xgb, mlp, table) is trained once on the PneuNet table of ``examples/pneunet``
(``simulations.csv`` with its ``actuator.json``: four parameters, pressure in kPa; the table base
on every third of its designs) with the smallest budget that fits it, and the saved model then
runs through ``predict``, ``transfer loco`` (every strategy that applies to it), ``transfer
refine``, ``design find`` and ``control simulate --plant``: one test per family and command, all
through the command line.
"""

from __future__ import annotations

import csv
import json
import math
from pathlib import Path

import numpy as np
import pandas as pd
import pytest

from softbend.cli import main

EXAMPLE = Path(__file__).resolve().parents[2] / "examples" / "pneunet"
SIMULATIONS = EXAMPLE / "simulations.csv"
MEASUREMENTS = EXAMPLE / "measurements.csv"
ACTUATOR = EXAMPLE / "actuator.json"

#: The description's parameters, in model-input order, and the pressure column.
NAMES = ("n_chambers", "n_layers", "wall_mm", "height_mm")
PRESSURE = "p_kpa"

#: A simulated design of the table (d000) and its angles there, read in the tests.
DESIGN_ID = "d000"

FAMILIES = ("plr", "xgb", "mlp", "table")


def _run(*args: str) -> int:
    return main([str(arg) for arg in args])


@pytest.fixture(scope="module")
def trained(tmp_path_factory):
    """A function ``family -> model path``: each family trained once, on first use."""
    folder = tmp_path_factory.mktemp("one-road")
    models: dict[str, Path] = {}
    # The table base on every third design of the table (50 designs, d000 among them): its
    # GP's cost grows as the cube of the rows (three fits of 1 000 rows took about 30 s on
    # the whole table, 550 rows a few seconds), and what the tests check of it (its answers
    # at a simulated design, its answers between designs through every command) does not
    # depend on the table's size.
    table = pd.read_csv(SIMULATIONS)
    designs = table["design_id"].drop_duplicates().iloc[::3]
    every_third = folder / "simulations_every_third.csv"
    table[table["design_id"].isin(designs)].to_csv(every_third, index=False)
    data = {"table": every_third}

    def model(family: str) -> Path:
        if family not in models:
            out = folder / family
            # two folds, the quick grid, 30 MLP epochs: seconds, and enough to follow the data
            code = _run("train", data.get(family, SIMULATIONS), "--actuator", ACTUATOR,
                        "--models", family,
                        "--grid", "quick", "--folds", "2", "--epochs", "30", "--workers", "1",
                        "--device", "cpu", "--seed", "0", "--no-onnx", "--no-interpolation",
                        "-o", out)  # fmt: skip
            assert code == 0, family
            models[family] = out / "models" / f"{family}.json"
        return models[family]

    return model


def _simulated(design_id: str) -> pd.DataFrame:
    table = pd.read_csv(SIMULATIONS)
    return table[table["design_id"] == design_id].sort_values(PRESSURE)


def _design_text(rows: pd.DataFrame) -> str:
    first = rows.iloc[0]
    return ",".join(f"{name}={first[name]:g}" for name in NAMES)


def _json_out(capsys) -> dict:
    return json.loads(capsys.readouterr().out)


def _model(trained, family: str, capsys) -> Path:
    """The trained model of ``family``, its training's output cleared."""
    model = trained(family)
    capsys.readouterr()
    return model


@pytest.mark.parametrize("family", FAMILIES)
def test_predict(trained, family, capsys):
    model = _model(trained, family, capsys)
    rows = _simulated(DESIGN_ID)
    pressures = rows[PRESSURE].to_numpy()
    assert _run("predict", model, "--design", _design_text(rows),
                "--pressures", ",".join(f"{p:g}" for p in pressures), "--json") == 0  # fmt: skip
    payload = _json_out(capsys)
    assert payload["kind"] == family and payload["actuator"] == "pneunet_synthetic"
    assert list(payload["design"]) == list(NAMES)  # the model's own names, in its order
    assert isinstance(payload["design"]["n_chambers"], int)
    assert payload["p_kpa"] == pytest.approx(list(pressures))
    angles = np.asarray(payload["angle_deg"], dtype=float)
    assert np.all(np.isfinite(angles)) and all(payload["supported"])
    truth = rows["angle_deg"].to_numpy()
    # the surrogate follows the simulated design: small error, rising from rest to its top
    assert float(np.sqrt(np.mean((angles - truth) ** 2))) < 0.25 * truth.max()
    assert abs(angles[0]) < 0.2 * truth.max()
    assert angles[-1] - angles[0] > 0.5 * (truth[-1] - truth[0])
    halves = angles[: len(angles) // 2].mean(), angles[len(angles) // 2 :].mean()
    assert halves[1] > halves[0]


@pytest.mark.parametrize("family", FAMILIES)
def test_transfer_loco(trained, family, tmp_path, capsys):
    from softbend.transfer import STRATEGIES

    model = _model(trained, family, capsys)
    out = tmp_path / "loco"
    assert _run("transfer", "loco", MEASUREMENTS, "--base", model, "-o", out,
                "--no-learning-curve", "--set", "epochs=20", "--set", "n_restarts=0",
                "--json") == 0  # fmt: skip
    payload = _json_out(capsys)
    record = json.loads((out / "loco.json").read_text(encoding="utf-8"))
    left_out = record["settings"]["left_out"]
    assert "analytical" in left_out  # paper B's analytical model: not this actuator
    if family != "mlp":  # the strategies that train the base's network further need one
        assert {"refined", "refined-ensemble", "scaled-refined"} <= set(left_out)
    # every strategy that applies ran, and scored every built actuator
    ran = {row["strategy"] for row in payload["summary"]}
    assert ran == set(STRATEGIES.names()) - set(left_out)
    assert not record["settings"]["failed"]
    for row in payload["summary"]:
        assert math.isfinite(row["rmse_deg"]) and row["rmse_deg"] >= 0, row
    actuators = {row["actuator_id"] for row in record["per_actuator"]}
    assert actuators == {f"A{i}" for i in range(1, 7)}
    assert record["settings"]["actuator"]["name"] == "pneunet_synthetic"
    with open(out / "predictions.csv", encoding="utf-8") as handle:
        header = next(csv.reader(handle))
    assert header[1:6] == [*NAMES, PRESSURE]
    assert "l_mm" not in header and "pressure_mpa" not in header


@pytest.mark.parametrize("family", FAMILIES)
def test_transfer_refine(trained, family, tmp_path, capsys):
    model = _model(trained, family, capsys)
    out = tmp_path / "refined.json"
    epochs = ["--epochs", "20"] if family == "mlp" else []
    assert _run("transfer", "refine", model, MEASUREMENTS, "-o", out, *epochs) == 0
    capsys.readouterr()
    saved = json.loads(out.read_text(encoding="utf-8"))
    assert saved["metadata"]["actuator"]["name"] == "pneunet_synthetic"
    # the refined model plugs into predict, by the actuator's names and in its unit
    rows = pd.read_csv(MEASUREMENTS)
    built = rows[rows["actuator"] == "A2"].sort_values(PRESSURE)
    pressures = [0.0, 25.0, 50.0, 75.0]
    assert _run("predict", out, "--design", _design_text(built),
                "--pressures", ",".join(f"{p:g}" for p in pressures), "--json") == 0  # fmt: skip
    payload = _json_out(capsys)
    assert list(payload["design"]) == list(NAMES) and payload["p_kpa"] == pressures
    angles = np.asarray(payload["angle_deg"], dtype=float)
    assert np.all(np.isfinite(angles)) and angles[-1] > angles[0]
    measured_top = float(built["angle_deg"].iloc[-1])
    assert abs(angles[-1] - measured_top) < 0.35 * measured_top


@pytest.mark.parametrize("family", FAMILIES)
def test_design_find(trained, family, tmp_path, capsys):
    model = _model(trained, family, capsys)
    out = tmp_path / "design"
    assert _run("design", "find", "--model", model, "--angle", "90", "--at", "40",
                "--minimize", "n_chambers", "-o", out, "--json") == 0  # fmt: skip
    payload = _json_out(capsys)
    assert payload["actuator"] == "pneunet_synthetic" and payload["pressure_unit"] == "kPa"
    assert payload["feasible"] is True and list(payload["spec"]["ranges"]) == list(NAMES)
    best = payload["candidates"][0]
    assert list(best["design"]) == list(NAMES)
    assert isinstance(best["design"]["n_chambers"], int)
    assert 6 <= best["design"]["n_chambers"] <= 14
    assert 2 * best["design"]["wall_mm"] < best["design"]["height_mm"]  # the constraint
    assert abs(best["angle_deg"] - 90.0) <= 3.0 and best["pressure_kpa"] == 40.0
    # least chambers first: no candidate meeting the target has fewer than the best
    meeting = [c for c in payload["candidates"] if c["meets"]]
    assert min(c["design"]["n_chambers"] for c in meeting) == best["design"]["n_chambers"]
    record = json.loads((out / "search.json").read_text(encoding="utf-8"))
    assert record["candidates"][0]["design"] == best["design"]
    with open(out / "candidates.csv", encoding="utf-8") as handle:
        header = next(csv.reader(handle))
    assert header[1:6] == [*NAMES, "pressure_kpa"]


@pytest.mark.parametrize("family", FAMILIES)
def test_control_simulate_with_the_model_as_plant(trained, family, tmp_path, capsys):
    model = _model(trained, family, capsys)
    out = tmp_path / "control"
    design = "n_chambers=10,n_layers=2,wall_mm=2,height_mm=12"
    assert _run("control", "simulate", "--plant", model, "--design", design,
                "--reference", "step:60", "--rig-param", "volume_mm3=20000",
                "-o", out, "--json") == 0  # fmt: skip
    payload = _json_out(capsys)
    assert payload["actuator"] == "pneunet_synthetic" and payload["model_from"] == "plant"
    assert payload["model_pressure_unit"] == "kPa"
    assert payload["design_parameters"] == {
        "n_chambers": 10, "n_layers": 2, "wall_mm": 2.0, "height_mm": 12.0
    }  # fmt: skip
    assert payload["design_supported"] is True
    metrics = payload["metrics"]
    assert metrics["rising_edges"] == 1 and metrics["switches"] > 0
    assert math.isfinite(metrics["mape_pct"]) and math.isfinite(metrics["rise_s"])
    saved = json.loads((out / "metrics.json").read_text(encoding="utf-8"))
    assert saved["metrics"] == metrics
    run = pd.read_csv(out / "run.csv")
    assert np.all(np.isfinite(run["angle_deg"])) and np.all(np.diff(run["t_s"]) > 0)
    # the loop fills the chamber and the angle reaches the step's neighbourhood
    late = run[run["t_s"] > run["t_s"].iloc[-1] / 2]
    assert abs(float(late["angle_deg"].mean()) - 60.0) < 15.0
    assert (out / "run.png").is_file()
