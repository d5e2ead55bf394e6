"""The control loop on a model of any actuator: its design by name, its pressure unit, its chamber.

Two polynomial models of one made-up four-parameter actuator are trained once:
the same table with the pressure in kPa (its description gives the chamber
volume and its growth) and in MPa (a description without them).
"""

from __future__ import annotations

import json

import numpy as np
import pandas as pd
import pytest

from softbend.actuators import SFRBA, Actuator, Design, DesignParameter
from softbend.cli import main
from softbend.control.designs import control_design
from softbend.control.runs import simulate_control
from softbend.control.setup import prepare_control
from softbend.design import parse_sfrba

#: A design inside the training data, given by name.
DESIGN = "n_chambers=10,wall_mm=2,height_mm=10,layer=paper"
#: The rig's supply for the actuator (60 kPa: past the 50 kPa it was swept to), with its
#: unit: a bare number would be in the unit of the plant (kPa or MPa).
SUPPLY = "60kPa"
SHIPPED_MLP = "src/softbend/data/transfer/table1_fem_mlp.json"


def law(n: int, wall: float, height: float, layer: str, p_kpa: np.ndarray) -> np.ndarray:
    """A made-up bending law, degrees: about 1.1°/kPa at the design above, pre-curved by -2°."""
    slope = 0.4 + 0.08 * n - 0.3 * wall + 0.05 * height - (0.2 if layer == "fabric" else 0.0)
    return -2.0 + slope * p_kpa + 0.004 * p_kpa**2


def table(pressure_column: str, scale: float) -> pd.DataFrame:
    """24 designs swept 0–50 kPa, the pressure column in kPa times ``scale``."""
    rows = []
    for n in (8, 10, 12):
        for wall in (1.5, 2.5):
            for height in (8.0, 12.0):
                for layer in ("paper", "fabric"):
                    p = np.linspace(0.0, 50.0, 11)
                    for q, angle in zip(p, law(n, wall, height, layer, p), strict=True):
                        rows.append(
                            {
                                "design_id": f"{n}-{wall}-{height}-{layer}",
                                "n_chambers": n,
                                "wall_mm": wall,
                                "height_mm": height,
                                "layer": layer,
                                pressure_column: q * scale,
                                "angle_deg": angle,
                            }
                        )
    return pd.DataFrame(rows)


def describe(pressure_column: str, unit: str, **chamber: float) -> Actuator:
    """The description: ranges wider than the data (n_chambers 6–14, the data 8–12)."""
    return Actuator(
        name="test-pneunet",
        title="a made-up PneuNet",
        parameters=(
            DesignParameter("n_chambers", "", 6, 14, kind="integer"),
            DesignParameter("wall_mm", "mm", 1.0, 3.0),
            DesignParameter("height_mm", "mm", 6.0, 14.0),
            DesignParameter("layer", "", kind="categorical", levels=("fabric", "paper")),
        ),
        pressure_column=pressure_column,
        pressure_unit=unit,
        **chamber,
    )


@pytest.fixture(scope="module")
def models(tmp_path_factory):
    """``{"kPa": path, "MPa": path}``: the same actuator's model in each pressure unit."""
    from softbend.surrogates.simulation_table import table_training_data
    from softbend.surrogates.workflow import train_surrogates

    root = tmp_path_factory.mktemp("pneunet")
    out = {}
    for unit, column, scale, chamber in (
        ("kPa", "p_kpa", 1.0, {"chamber_volume_mm3": 12000.0, "volume_growth_mm3_per_mpa": 1.5e5}),
        ("MPa", "p_mpa", 1e-3, {}),
    ):
        csv = root / f"sims_{unit}.csv"
        table(column, scale).to_csv(csv, index=False)
        data = table_training_data(csv, actuator=describe(column, unit, **chamber))
        train_surrogates(data, root / unit, models="plr", export_onnx=False)
        out[unit] = root / unit / "models" / "plr.json"
    return out


def test_the_loop_tracks_a_step_on_a_model_of_another_actuator(models):
    run = simulate_control(
        reference="step:40", design=DESIGN, plant=str(models["kPa"]), duration_s=3.0,
        supply_mpa=0.06,
    )  # fmt: skip
    frame = run.run.frame()
    late = frame[frame["t_s"] > 2.0]
    # Paper B's bang-bang holds the valves inside a deadzone of 5 % of the reference (2°);
    # the pressure sensor's noise (0.5 kPa, about 0.6° here) and the camera's (0.2°) add
    # under 1°: the angle stays within 3° of 40° once settled.
    assert np.abs(late["angle_deg"] - 40.0).max() < 3.0
    assert run.summary["metrics"]["rising_edges"] == 1
    summary = run.summary
    assert summary["actuator"] == "test-pneunet"
    assert summary["design_parameters"] == {
        "n_chambers": 10, "wall_mm": 2.0, "height_mm": 10.0, "layer": "paper",
    }  # fmt: skip
    assert summary["design"] == "n_chambers=10, wall_mm=2 mm, height_mm=10 mm, layer=paper"
    assert summary["model_pressure_unit"] == "kPa"
    # The chamber is the description's (12 000 mm³) plus the default tubing (2000 mm³).
    assert summary["rig"]["volume_mm3"] == pytest.approx(14000.0)
    assert summary["rig"]["compliance_mm3_per_mpa"] == pytest.approx(1.5e5)


def test_the_rig_converts_the_models_pressure_unit(models):
    rig = ["volume_mm3=14000", "compliance_mm3_per_mpa=150000"]
    runs = {}
    for unit, path in models.items():
        runs[unit] = simulate_control(
            reference="step:40", design=DESIGN, plant=str(path), duration_s=1.5,
            supply_mpa=0.06, rig_assignments=rig,
        )  # fmt: skip
    kpa, mpa = runs["kPa"].setup, runs["MPa"].setup
    # θ(p) of the rig at 30 kPa = 0.03 MPa is the law's at 30 kPa, in both units.
    expected = law(10, 2.0, 10.0, "paper", np.array([30.0]))[0]
    assert kpa.plant_table(0.03) == pytest.approx(expected, abs=1e-3)
    np.testing.assert_allclose(kpa.plant_table.angles_deg, mpa.plant_table.angles_deg, atol=1e-6)
    np.testing.assert_allclose(
        [kpa.model.virtual_sensor(q) for q in (0.01, 0.03)],
        [mpa.model.virtual_sensor(q) for q in (0.01, 0.03)],
        atol=1e-6,
    )
    a, b = runs["kPa"].run.frame(), runs["MPa"].run.frame()
    np.testing.assert_allclose(a["angle_deg"], b["angle_deg"], atol=1e-6)
    assert runs["MPa"].summary["model_pressure_unit"] == "MPa"


@pytest.mark.parametrize(
    ("unit", "role", "supply"),
    [
        ("kPa", "--plant", "60"),  # a bare number in the plant's unit
        ("kPa", "--model", "60"),  # ... or the controller's model's, the plant its own
        ("MPa", "--plant", "0.06"),
        ("MPa", "--plant", "60kPa"),  # a unit wins
        ("kPa", "--plant", "8.70226psi"),
    ],
)
def test_a_bare_supply_is_in_the_models_pressure_unit(models, tmp_path, capsys, unit, role, supply):
    args = ["control", "simulate", "--design", DESIGN, role, str(models[unit]),
            "--supply", supply, "--rig-param", "volume_mm3=14000", "--duration", "0.3",
            "--reference", "step:40"]  # fmt: skip
    assert main([*args, "--json", "-o", str(tmp_path / "a")]) == 0
    payload = json.loads(capsys.readouterr().out)
    assert payload["rig"]["supply_gauge_mpa"] == pytest.approx(0.06, rel=1e-5)
    assert payload["model_pressure_unit"] == unit


def test_a_bare_supply_past_the_plausible_names_the_models_unit(models, tmp_path, capsys):
    args = ["control", "simulate", "--design", DESIGN, "--plant", str(models["kPa"]),
            "--supply", "5000", "-o", str(tmp_path / "a")]  # fmt: skip
    assert main(args) == 2
    err = capsys.readouterr().err.strip().splitlines()
    assert len(err) == 1 and "--supply: must be a gauge pressure in (0, 2] MPa" in err[0], err
    assert "got 5000 kPa (5 MPa)" in err[0], err


def test_the_plant_alone_is_the_controllers_model_too(models, tmp_path, capsys):
    plant = str(models["kPa"])
    args = ["control", "simulate", "--design", DESIGN, "--plant", plant, "--supply", SUPPLY,
            "--duration", "1", "--reference", "step:40"]  # fmt: skip
    assert main([*args, "--json", "-o", str(tmp_path / "a")]) == 0
    payload = json.loads(capsys.readouterr().out)
    assert payload["plant"] == plant and payload["model"] == plant
    assert payload["model_from"] == "plant"
    assert main([*args, "-o", str(tmp_path / "b")]) == 0
    out = capsys.readouterr().out
    assert "n_chambers=10" in out and "layer=paper" in out
    assert "plant and controller's model" in out


def test_paper_bs_saved_plant_alone_is_its_own_soft_sensor(tmp_path, capsys):
    args = ["control", "simulate", "--plant", SHIPPED_MLP, "--duration", "0.5", "--json"]
    assert main([*args, "-o", str(tmp_path / "a")]) == 0
    payload = json.loads(capsys.readouterr().out)
    assert payload["model"] == SHIPPED_MLP and payload["model_from"] == "plant"
    assert (
        main(["control", "simulate", "--duration", "0.5", "--json", "-o", str(tmp_path / "b")]) == 0
    )
    payload = json.loads(capsys.readouterr().out)
    assert payload["model_from"] == "shipped" and payload["model"].endswith("table1_fem_mlp.json")


def test_a_model_mismatch_names_both_models(models, tmp_path, capsys, monkeypatch):
    # Short names, so that the table's cells hold them on one line.
    monkeypatch.chdir(tmp_path)
    for unit, path in models.items():
        (tmp_path / f"{unit}.json").write_bytes(path.read_bytes())
    plant, model = "kPa.json", "MPa.json"
    args = ["control", "simulate", "--design", DESIGN, "--plant", plant, "--model", model,
            "--supply", SUPPLY, "--rig-param", "volume_mm3=14000", "--duration", "1",
            "--reference", "step:40"]  # fmt: skip
    assert main([*args, "--json", "-o", "a"]) == 0
    payload = json.loads(capsys.readouterr().out)
    assert payload["plant"] == plant and payload["model"] == model
    assert payload["model_from"] == "model"
    assert main([*args, "-o", "b"]) == 0
    out = capsys.readouterr().out
    assert "model mismatch" in " ".join(out.split())
    rows = [line.split("│")[1:3] for line in out.splitlines() if line.count("│") == 3]
    rows = {name.strip(): value.strip() for name, value in rows}
    assert rows["plant"] == plant and rows["controller's model"] == model


def test_the_same_file_as_plant_and_model_is_no_mismatch(models):
    path = models["kPa"]
    setup = prepare_control(design=DESIGN, plant=str(path), model=path, supply_mpa=0.06)
    assert setup.plant_is_model and not setup.mismatch and setup.model_from == "model"
    with pytest.warns(UserWarning, match="rigid"):
        other = prepare_control(
            design=DESIGN, plant=str(path), model=models["MPa"], supply_mpa=0.06,
            rig_settings={"volume_mm3": 14000.0},
        )  # fmt: skip
    assert other.mismatch and not other.plant_is_model


def test_a_design_outside_the_training_data_warns_and_strict_refuses(models, tmp_path, capsys):
    # n_chambers 13 is in the description (6–14) but past the data (8–12).
    design = "n_chambers=13,wall_mm=2,height_mm=10,layer=paper"
    args = ["control", "simulate", "--design", design, "--plant", str(models["kPa"]),
            "--supply", SUPPLY, "--duration", "0.5", "--reference", "step:40"]  # fmt: skip
    assert main([*args, "-o", str(tmp_path / "a")]) == 0
    err = capsys.readouterr().err
    warning = [line for line in err.splitlines() if "training ranges" in line]
    assert len(warning) == 1
    assert str(models["kPa"]) in warning[0] and "n_chambers 13 outside [8, 12]" in warning[0]
    assert main([*args, "--strict", "-o", str(tmp_path / "b")]) == 2
    err = capsys.readouterr().err.strip().splitlines()
    assert len(err) == 1 and "--strict" in err[0] and "n_chambers" in err[0]
    assert not (tmp_path / "b").exists()


def test_paper_bs_design_outside_the_mlps_data_warns_too():
    with pytest.warns(UserWarning, match=r"l_mm 90 outside \[100, 160\]"):
        setup = prepare_control(design="90,6,2,2,5,8")
    assert any("l_mm 90" in note for note in setup.support_notes)
    with pytest.raises(ValueError, match=r"--strict.*l_mm 90"):
        prepare_control(design="90,6,2,2,5,8", strict=True)


def test_a_chamber_volume_neither_described_nor_given_is_refused(models, tmp_path, capsys):
    args = ["control", "simulate", "--design", DESIGN, "--plant", str(models["MPa"]),
            "--supply", SUPPLY, "--duration", "0.5"]  # fmt: skip
    assert main([*args, "-o", str(tmp_path / "a")]) == 2
    err = capsys.readouterr().err.strip().splitlines()
    assert len(err) == 1
    assert "test-pneunet" in err[0] and "--rig-param volume_mm3=" in err[0]
    # A measured volume runs; a chamber growth neither described nor given is rigid, said so.
    assert main([*args, "--rig-param", "volume_mm3=14000", "-o", str(tmp_path / "b")]) == 0
    assert "rigid" in capsys.readouterr().err


def test_a_hardware_rig_needs_the_chamber_only_for_the_predictive_controller(models):
    from softbend.control.runs import plan_loop

    options = {"rig": "modbus", "design": DESIGN, "model": models["MPa"], "supply_mpa": 0.06}
    plan = plan_loop(**options)
    assert plan.setup.design.record()["layer"] == "paper"
    with pytest.raises(ValueError, match="volume_mm3"):
        plan_loop(controller="predictive", **options)


@pytest.mark.parametrize(
    ("extra", "needle"),
    [
        ([], "must be given for the model"),
        (["--design", "100,6,2,2,5,8"], "(4 values)"),
        (["--design", "n_chambers=10,wall_mm=2,height_mm=10,layer=silk"], "fabric, paper"),
        (["--design", DESIGN, "--plant", "fem"], f"is of {SFRBA.title} only"),
        (["--design", DESIGN, "--plant", "lab"], f"is of {SFRBA.title} only"),
    ],
)
def test_a_design_or_plant_not_of_the_models_actuator_is_one_line(
    models, tmp_path, capsys, extra, needle
):
    args = ["control", "simulate", "--model", str(models["kPa"]), "--supply", SUPPLY,
            "--duration", "0.5", "-o", str(tmp_path / "o")]  # fmt: skip
    assert main([*args, *extra]) == 2
    err = capsys.readouterr().err.strip().splitlines()
    assert len(err) == 1 and needle in err[0], err


def test_a_plant_of_other_parameters_than_the_model_is_refused(models):
    with pytest.raises(ValueError, match="same design parameters"):
        prepare_control(design=DESIGN, model=models["kPa"], plant=SHIPPED_MLP, supply_mpa=0.06)


def test_designs_are_read_by_the_actuator_of_the_model(models):
    from softbend.actuators import SFRBA

    named = control_design("l_mm=100,r_mm=6,t_mm=2,b_mm=2,phi_deg=5,lc_mm=8", SFRBA)
    assert named == parse_sfrba("100,6,2,2,5,8") == control_design(None, SFRBA)
    actuator = describe("p_kpa", "kPa")
    design = control_design("10,2,10,paper", actuator)
    assert isinstance(design, Design)
    np.testing.assert_array_equal(design.as_array(), [10.0, 2.0, 10.0, 1.0])
    # The rows a model takes: the pressure in its unit (kPa) from the rig's MPa.
    np.testing.assert_allclose(
        design.feature_rows([0.03], unit="MPa")[0], [10.0, 2.0, 10.0, 1.0, 30.0]
    )
