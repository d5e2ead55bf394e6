"""Plants unlike the controller's model: the FEM sweep, the lab readings, model mismatch."""

import numpy as np
import pytest

from softbend.cli import main
from softbend.control.controllers import PressureRelay
from softbend.control.experiments import simulate
from softbend.control.plants import fem_angle_table, lab_angle_table, plant_table
from softbend.control.rig import AngleTable, RigParams, SimulatedRig
from softbend.datasets import table1_fem
from softbend.design import sfrba_design
from softbend.transfer.lab import shipped_measurements

DESIGN = sfrba_design(100, 6, 2, 2, 5, 8)


def test_fem_plant_passes_through_the_sweep_and_extends_it_linearly():
    table = fem_angle_table(DESIGN)
    data = table1_fem()
    rows = data[data["design_id"] == data.loc[_design_rows(data).index[0], "design_id"]]
    rows = rows[rows["converged"]]
    for p, a in zip(rows["pressure_mpa"], rows["angle_deg"], strict=True):
        assert table(p) == pytest.approx(a, abs=1e-6)
    p = rows["pressure_mpa"].to_numpy()
    a = rows["angle_deg"].to_numpy()
    slope = (a[-1] - a[-2]) / (p[-1] - p[-2])
    assert table(p[-1] + 0.02) == pytest.approx(a[-1] + 0.02 * slope, rel=1e-6)


def _design_rows(data):
    mask = np.ones(len(data), dtype=bool)
    for name, value in DESIGN.as_dict().items():
        mask &= np.isclose(data[name], value)
    return data[mask]


def test_fem_plant_of_a_design_outside_table1_is_one_error():
    with pytest.raises(ValueError, match=r"not in the FEM dataset \(Table 1: l_mm in 100, 120"):
        fem_angle_table(sfrba_design(105, 6, 2, 2, 5, 8))


def test_lab_plant_follows_the_readings_within_the_camera_noise():
    table = lab_angle_table(DESIGN)
    frame = shipped_measurements().frame
    rows = frame[(frame["actuator_id"] == "100,6,2,2,5,8") & (frame["direction"] == "loading")]
    residual = np.array([table(p) for p in rows["pressure_mpa"]]) - rows["angle_deg"].to_numpy()
    assert np.sqrt(np.mean(residual**2)) < 2.0  # the lab's camera noise is 1°
    with pytest.raises(ValueError, match="has no measured loading curve"):
        lab_angle_table(sfrba_design(160, 10, 4, 4, 15, 12))


def test_model_mismatch_sets_the_steady_state_of_a_pressure_controller():
    """The relay regulates p* = model⁻¹(θr), so the actuator settles at plant(p*), not θr."""
    model = AngleTable.from_callable(lambda p: 6.0 + 1000.0 * p)
    plant = AngleTable.from_callable(lambda p: 6.0 + 1150.0 * p)  # 15 % more bend per MPa
    run = simulate(
        SimulatedRig(plant, RigParams(), seed=0), PressureRelay(model), "step:90:0.2", 3.0
    )
    p_star = (90.0 - 6.0) / 1000.0
    expected = 6.0 + 1150.0 * p_star
    late = run.t_s > 2.0
    assert np.mean(run.angle_deg[late]) == pytest.approx(expected, abs=1.5)
    assert np.mean(run.angle_deg[late]) - 90.0 > 10.0  # the error is the model's, not noise


def test_cli_plant_option(tmp_path, capsys):
    import json

    out = tmp_path / "lab"
    args = ["control", "simulate", "--plant", "lab", "--controller", "pressure-relay"]
    assert main([*args, "--duration", "2", "--out", str(out), "--json"]) == 0
    payload = json.loads(capsys.readouterr().out)
    assert payload["plant"] == "lab" and payload["metrics"]["mape_pct"] > 8.0
    assert main(["control", "simulate", "--plant", "camera", "--out", str(out)]) == 2
    err = capsys.readouterr().err
    assert "--plant: Unknown plant 'camera'; known: surrogate, fem, lab." in err
    assert len(err.strip().splitlines()) == 1


def test_plant_table_by_name():
    model = AngleTable.from_callable(lambda p: 6.0 + 1000.0 * p)
    assert plant_table("surrogate", DESIGN, model) is model
    assert plant_table("fem", DESIGN, model)(0.1) == pytest.approx(fem_angle_table(DESIGN)(0.1))
    assert plant_table("lab", DESIGN, model)(0.1) == pytest.approx(lab_angle_table(DESIGN)(0.1))
    with pytest.raises(ValueError, match=r"^plant: Unknown plant 'camera'; known: "):
        plant_table("camera", DESIGN, model)


def test_serve_checks_its_plant(capsys):
    # --plant was once accepted by serve and ignored
    assert main(["control", "serve", "--plant", "camera", "--duration", "0.1"]) == 2
    assert "--plant: Unknown plant 'camera'; known: surrogate" in capsys.readouterr().err
    code = main(["control", "serve", "--plant", "lab", "--design", "160,10,4,4,15,12"])
    assert code == 2 and "no measured loading curve" in capsys.readouterr().err


def test_a_plant_is_parsed_once_into_its_kind(tmp_path):
    from softbend.control.plant_choice import PlantChoice
    from softbend.control.plants import parse_plant, plant_compliance
    from softbend.registry import UnknownNameError

    readings = tmp_path / "readings.csv"
    readings.write_text("l\n", encoding="utf-8")
    model = tmp_path / "model.json"
    model.write_text("{}", encoding="utf-8")
    assert parse_plant("fem") == PlantChoice("named", "fem")
    assert parse_plant(str(readings)) == PlantChoice("measurements", str(readings), readings)
    surrogate = parse_plant(str(model))
    assert (surrogate.kind, surrogate.surrogate_file, surrogate.model_file) == (
        "surrogate",
        model,
        model,
    )
    assert parse_plant(surrogate) is surrogate
    assert parse_plant("lab").identified() is None and parse_plant("lab").pressure_unit() is None
    with pytest.raises(UnknownNameError, match="saved surrogate") as caught:
        parse_plant(str(tmp_path / "missing.json"))
    assert caught.value.key == "plant"
    # a design of Table 1 keeps the rig's default chamber; a plant without one gives none
    assert plant_compliance("fem", DESIGN, 0.2) is None
    assert plant_compliance(str(model), DESIGN, 0.2) is None


def test_a_plant_of_paper_b_s_actuator_alone_refuses_another_actuator_s_design():
    from softbend.actuators import SFRBA, Actuator, Design, DesignParameter
    from softbend.control.plants import PLANT_ACTUATORS, check_plant_actuator
    from softbend.errors import InputError

    other = Actuator("other", "another actuator", (DesignParameter("w_mm", "mm", 1.0, 2.0),))
    design = Design.checked(other, np.array([1.5]))
    assert {PLANT_ACTUATORS[name].name for name in ("fem", "lab", "measurements")} == {SFRBA.name}
    check_plant_actuator("surrogate", design)
    check_plant_actuator("fem", DESIGN)
    with pytest.raises(InputError, match=rf"'lab' is of {SFRBA.title} only; the design") as caught:
        check_plant_actuator("lab", design)
    assert caught.value.key == "plant"
