"""Transfer learning on another actuator: plain CSV readings, loco against the baseline, refine."""

from __future__ import annotations

import json

import numpy as np
import pytest

from softbend.cli import main
from softbend.surrogates.persistence import load_surrogate
from softbend.surrogates.predict import predict_angles
from softbend.transfer.loco import BASELINE_STRATEGY, leave_one_configuration_out
from softbend.transfer.measurements import load_actuator_measurements
from softbend.transfer.refine import refine_surrogate

from ..stand_ins import actuator_law, actuator_plr_base, actuator_table

BUILT = {  # id: (n_chambers, wall_mm, height_mm, layer); stiffer than simulated, more so if thin
    "P1": (8, 1.5, 10.0, "paper"),
    "P2": (12, 2.5, 14.0, "fabric"),
    "P3": (10, 2.0, 12.0, "paper"),
    "P4": (7, 2.8, 9.0, "fabric"),
}


def measured(n, wall, height, layer, p):
    """The built actuators bend less than simulated, by a factor that depends on the wall."""
    return 0.6 * (1 + 0.1 * wall) * actuator_law(n, wall, height, layer, p)


@pytest.fixture(scope="module")
def lab(tmp_path_factory):
    folder = tmp_path_factory.mktemp("other")
    sims = folder / "sims.csv"
    actuator_table(designs=30).to_csv(sims, index=False)
    base = actuator_plr_base(sims, folder / "m")
    lines = ["# synthetic: true", "actuator,n_chambers,wall_mm,height_mm,layer,p_kpa,angle_deg"]
    for name, (n, wall, height, layer) in BUILT.items():
        for p in (0.0, 10.0, 20.0, 30.0, 40.0, 50.0):
            angle = measured(n, wall, height, layer, p)
            lines.append(f"{name},{n},{wall},{height},{layer},{p},{angle:.3f}")
    readings = folder / "readings.csv"
    readings.write_text("\n".join(lines) + "\n")
    return base, readings


def test_loco_scores_every_strategy_against_the_baseline(lab):
    base, readings = lab
    saved = load_surrogate(base)
    data = load_actuator_measurements(readings, saved.actuator)
    result = leave_one_configuration_out(
        data,
        saved.model,
        ["fem-only", BASELINE_STRATEGY, "scale-offset"],
        learning_curve=False,
    )
    summary = result.summary.set_index("strategy")
    # the gap is a scale that depends on the design: a scale beats a mean residual
    assert summary.loc["scale-offset", "rmse_deg_mean"] < summary.loc[BASELINE_STRATEGY, "rmse_deg"]
    assert summary.loc[BASELINE_STRATEGY, "rmse_deg_mean"] < summary.loc["fem-only", "rmse_deg"]
    per = result.per_actuator
    mean = per[per["strategy"] == "scale-offset"]["rmse_deg"].mean()
    assert summary.loc["scale-offset", "rmse_deg_mean"] == pytest.approx(mean)
    assert result.settings["pressure_unit"] == "kPa"


def test_loco_refuses_the_analytical_baseline_for_another_actuator(lab):
    base, readings = lab
    saved = load_surrogate(base)
    data = load_actuator_measurements(readings, saved.actuator)
    with pytest.raises(
        ValueError, match=r"^strategies: 'analytical' models paper B's actuator only"
    ):
        leave_one_configuration_out(data, saved.model, ["analytical"], learning_curve=False)


def test_refine_saves_a_model_of_the_same_actuator_that_predicts_by_name(lab, tmp_path):
    base, readings = lab
    refined = refine_surrogate(base, readings, "scale-offset", calibrated=False)
    path = refined.save(tmp_path / "refined.json")
    saved = load_surrogate(path)
    assert saved.actuator == load_surrogate(base).actuator
    n, wall, height, layer = BUILT["P3"]
    design = f"n_chambers={n},wall_mm={wall},height_mm={height},layer={layer}"
    got = predict_angles(path, design, [30.0]).angle_deg[0]
    assert got == pytest.approx(measured(n, wall, height, layer, 30.0), abs=3.0)


def test_loco_cli_on_another_actuator(lab, tmp_path, capsys):
    base, readings = lab
    out = tmp_path / "loco"
    code = main(
        [
            "transfer",
            "loco",
            str(readings),
            "--base",
            str(base),
            "--out",
            str(out),
            "--strategies",
            f"fem-only,{BASELINE_STRATEGY},scale-offset",
            "--no-learning-curve",
            "--json",
        ]
    )
    assert code == 0
    record = json.loads(capsys.readouterr().out)
    assert record["settings"]["actuator"]["name"] == "sims"
    rows = {r["strategy"]: r for r in record["summary"]}
    assert np.isfinite(rows["scale-offset"]["rmse_deg_mean"])
    assert (out / "fig7_actuators.png").is_file()


def test_a_readings_file_with_another_column_is_one_line(lab, tmp_path, capsys):
    base, readings = lab
    bad = tmp_path / "bad.csv"
    bad.write_text(readings.read_text().replace("wall_mm", "wall"))
    code = main(["transfer", "loco", str(bad), "--base", str(base), "--out", str(tmp_path / "o")])
    assert code == 2
    err = capsys.readouterr().err.strip().splitlines()
    assert len(err) == 1
    assert (
        "lacks the column(s) wall_mm" in err[0] and "has column(s) wall the measurement" in err[0]
    )


def test_loco_mape_leaves_out_the_readings_below_the_floor(lab):
    from softbend.metrics import mape_floor, thresholded_mape

    base, readings = lab
    saved = load_surrogate(base)
    data = load_actuator_measurements(readings, saved.actuator)
    result = leave_one_configuration_out(data, saved.model, ["fem-only"], learning_curve=False)
    floor = result.settings["mape_floor_deg"]
    assert floor == mape_floor(data.angle_deg) >= 5.0
    predictions = result.predictions
    for _, row in result.per_actuator.iterrows():
        part = predictions[predictions["actuator_id"] == row["actuator_id"]]
        expected, left_out = thresholded_mape(
            part["angle_deg"], part["predicted_deg"], threshold=floor
        )
        assert row["mape_pct"] == pytest.approx(expected)
        assert row["n_mape_used"] == len(part) - left_out < len(part)  # the 0 kPa readings
    summary = result.summary.set_index("strategy")
    assert summary.loc["fem-only", "n_mape_used"] == result.per_actuator["n_mape_used"].sum()


def test_loco_cli_with_an_xgb_base_of_another_actuator(lab, tmp_path, capsys):
    """An XGBoost base of another actuator's table loads for transfer: it takes that
    actuator's inputs, not paper B's seven (it stopped with "Feature shape mismatch")."""
    from softbend.surrogates.simulation_table import table_training_data
    from softbend.surrogates.workflow import train_surrogates

    from ..stand_ins import ACTUATOR_COLUMNS

    plr, readings = lab
    data = table_training_data(
        plr.parent.parent.parent / "sims.csv",
        design_columns=ACTUATOR_COLUMNS,
        pressure_column="p_kpa",
        pressure_unit="kPa",
    )
    train_surrogates(
        data, tmp_path / "xgb", models="xgb", grid_name="quick", folds=2, export_onnx=False
    )
    base = tmp_path / "xgb" / "models" / "xgb.json"
    saved = load_surrogate(base)
    assert saved.model.n_features_in_ == len(saved.actuator.features) == 5
    code = main(
        [
            "transfer",
            "loco",
            str(readings),
            "--base",
            str(base),
            "--out",
            str(tmp_path / "loco"),
            "--strategies",
            f"fem-only,{BASELINE_STRATEGY},scale-offset",
            "--no-learning-curve",
            "--json",
        ]
    )
    assert code == 0, capsys.readouterr().err
    record = json.loads(capsys.readouterr().out)
    assert record["settings"]["pressure_unit"] == "kPa"
    rows = {r["strategy"]: r for r in record["summary"]}
    assert np.isfinite(rows["scale-offset"]["rmse_deg_mean"])
    assert np.isfinite(rows["fem-only"]["rmse_deg_mean"])
