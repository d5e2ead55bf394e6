"""Units checked, not trusted: column names against declared units, pressures against a model.

A column named in one unit and declared in another is refused naming both; measured
pressures far past the base model's trained range are refused (``--force`` proceeds and
is recorded); pressures asked of a model outside its range say so; the radians check
compares the measured curve with the model's own; a measurement file without an id
column is one actuator named by its file.
"""

from __future__ import annotations

import json

import pytest

from softbend.cli import main

from ..stand_ins import ACTUATOR_COLUMNS, actuator_law, actuator_plr_base, actuator_table
from .conftest import one_error_line

HEADER = "actuator,n_chambers,wall_mm,height_mm,layer,p_kpa,angle_deg"
BUILT = {"P1": (8, 1.5, 10.0, "paper"), "P2": (12, 2.5, 14.0, "fabric")}


@pytest.fixture(scope="module")
def sims(tmp_path_factory):
    """A simulation table of the stand-in actuator, p_kpa from 0 to 50."""
    path = tmp_path_factory.mktemp("sims") / "sims.csv"
    actuator_table(designs=30).to_csv(path, index=False)
    return path


@pytest.fixture(scope="module")
def base(sims):
    """A polynomial fitted to ``sims`` (its trained pressure range: 0-50 kPa)."""
    return actuator_plr_base(sims, sims.parent / "m")


def readings(path, scale=1.0, ids=True, actuators=BUILT, stiff=1.0):
    """Readings of ``actuators`` at 0-50 kPa written with pressures times ``scale``."""
    lines = [HEADER if ids else HEADER.split(",", 1)[1]]
    for name, (n, wall, height, layer) in actuators.items():
        for p in (0.0, 10.0, 20.0, 30.0, 40.0, 50.0):
            angle = stiff * 0.8 * actuator_law(n, wall, height, layer, p)
            row = f"{n},{wall},{height},{layer},{p * scale:g},{angle:.3f}"
            lines.append(f"{name},{row}" if ids else row)
    path.write_text("\n".join(lines) + "\n")
    return path


# ------------------------------------------------------------ a column's unit from its name
def test_a_pressure_column_named_in_psi_declared_in_kpa_is_refused_naming_both(tmp_path, capsys):
    table = actuator_table(designs=6).rename(columns={"p_kpa": "pressure_psi"})
    table.to_csv(tmp_path / "t.csv", index=False)
    argv = ["train", str(tmp_path / "t.csv"), "--design-columns", ACTUATOR_COLUMNS]
    argv += ["--pressure-column", "pressure_psi", "--pressure-unit", "kPa"]
    assert main([*argv, "--out", str(tmp_path / "o"), "--models", "plr"]) == 2
    line = one_error_line(capsys)
    assert "--pressure-unit: is kPa, but the column 'pressure_psi' is named in psi" in line
    assert not (tmp_path / "o").exists()


def test_an_actuator_description_whose_column_names_another_unit_is_refused(tmp_path, capsys):
    from softbend.actuators import Actuator, DesignParameter

    described = Actuator(
        name="bellows",
        title="a bellows",
        parameters=(DesignParameter("wall_mm", "mm", 1.0, 3.0),),
        pressure_column="p_kpa",
        pressure_unit="kPa",
    ).to_dict()
    described["pressure_unit"] = "psi"
    path = tmp_path / "bellows.json"
    path.write_text(json.dumps(described))
    table = tmp_path / "t.csv"
    table.write_text("wall_mm,p_kpa,angle_deg\n1,0,0\n")
    assert main(["train", str(table), "--actuator", str(path), "--out", str(tmp_path / "o")]) == 2
    line = one_error_line(capsys)
    assert "bellows.json: pressure_unit: is psi, but the column 'p_kpa' is named in kPa" in line
    described["pressure_unit"], described["angle_column"] = "kPa", "angle_rad"
    path.write_text(json.dumps(described))
    assert main(["train", str(table), "--actuator", str(path), "--out", str(tmp_path / "o")]) == 2
    assert "angle_column: 'angle_rad' is named in radians" in one_error_line(capsys)


# ------------------------------------------------ measured pressures against the base's range
def test_pressures_far_past_the_base_s_range_are_refused_with_both_ranges(base, tmp_path, capsys):
    bench = readings(tmp_path / "bench.csv", scale=7.0)  # 0-350 "kPa" for a 0-50 kPa model
    for command in (
        ["transfer", "loco", str(bench), "--base", str(base)],
        ["transfer", "refine", str(base), str(bench), "--strategy", "scale-offset"],
    ):
        out = tmp_path / "out.json"
        assert main([*command, "--out", str(out)]) == 2
        line = one_error_line(capsys)
        assert line.startswith("softbend: error: MEASUREMENTS: the pressures reach 350 kPa")
        assert "span 0–350 kPa; the base model was trained on 0–50 kPa" in line
        assert "'P1' in " in line and "--force" in line
        assert not out.exists()


def test_force_uses_pressures_past_the_range_and_records_it(base, tmp_path, capsys):
    bench = readings(tmp_path / "bench.csv", scale=7.0)
    argv = ["transfer", "loco", str(bench), "--base", str(base), "--out", str(tmp_path / "l")]
    argv += ["--strategies", "fem-only,scale-offset", "--no-learning-curve", "--json", "--force"]
    assert main(argv) == 0
    captured = capsys.readouterr()
    forced = json.loads(captured.out)["settings"]["forced"]
    assert forced == {
        "pressure": {
            "measured_range": [0.0, 350.0],
            "trained_range": [0.0, 50.0],
            "unit": "kPa",
            "forced": True,
        }
    }
    assert "softbend: warning: measurements: the pressures reach 350 kPa" in captured.err
    assert json.loads((tmp_path / "l" / "loco.json").read_text())["settings"]["forced"] == forced
    model = tmp_path / "m.json"
    argv = ["transfer", "refine", str(base), str(bench), "--out", str(model), "--force"]
    assert main([*argv, "--strategy", "scale-offset"]) == 0
    assert json.loads(model.read_text())["metadata"]["forced"] == forced


def test_kpa_numbers_in_a_psi_column_say_what_they_look_like(tmp_path, capsys):
    sims = tmp_path / "sims.csv"
    table = actuator_table(designs=12)
    table["p_psi"] = table.pop("p_kpa") / 6.894757  # 0-7.25 psi
    table.to_csv(sims, index=False)
    actuator_plr_base(sims, tmp_path / "m", pressure_column="p_psi")
    bench = readings(tmp_path / "bench.csv")  # kPa numbers in the psi column
    bench.write_text(bench.read_text().replace("p_kpa", "p_psi"))
    argv = ["transfer", "loco", str(bench), "--base", str(tmp_path / "m/models/plr.json")]
    assert main([*argv, "--out", str(tmp_path / "l")]) == 2
    line = one_error_line(capsys)
    assert "trained on 0–7.252 psi" in line and "they look like kPa" in line


def test_mpa_numbers_in_a_kpa_column_are_refused_as_too_small(base, tmp_path, capsys):
    bench = readings(tmp_path / "bench.csv", scale=1e-3)  # 0-0.05 "kPa" for a 0-50 kPa model
    argv = ["transfer", "loco", str(bench), "--base", str(base), "--out", str(tmp_path / "l")]
    assert main(argv) == 2
    line = one_error_line(capsys)
    assert "the pressures reach only 0.05 kPa" in line and "1/1000 of the top" in line
    assert "trained on 0–50 kPa; they look like MPa" in line
    low = readings(tmp_path / "low.csv", scale=0.08)  # a lab that measured low pressures only
    argv = ["transfer", "loco", str(low), "--base", str(base), "--out", str(tmp_path / "m")]
    assert main([*argv, "--strategies", "fem-only,scale-offset", "--no-learning-curve"]) == 0


# ------------------------------------------------------------- radians next to the prediction
def test_a_stiff_actuator_is_not_taken_for_radians(base, tmp_path, capsys):
    stiff = readings(tmp_path / "stiff.csv", stiff=0.15)  # 6.0° at the top, a tenth of the model
    argv = ["transfer", "loco", str(stiff), "--base", str(base), "--out", str(tmp_path / "l")]
    assert main([*argv, "--strategies", "fem-only,scale-offset", "--no-learning-curve"]) == 0
    assert "radians" not in capsys.readouterr().err


def test_angles_in_radians_next_to_the_prediction_are_refused(base, tmp_path, capsys):
    bench = readings(tmp_path / "bench.csv", stiff=1 / 57.2958)
    argv = ["transfer", "loco", str(bench), "--base", str(base), "--out", str(tmp_path / "l")]
    assert main(argv) == 2
    line = one_error_line(capsys)
    assert "bench.csv: angle_deg: the actuator 'P1' reaches only 0.70" in line
    assert "look like radians" in line and "--force" in line


# ------------------------------------------- pressures asked of a model outside its range
DESIGN = "n_chambers=10,wall_mm=2,height_mm=12,layer=fabric"


def test_predict_names_the_pressures_outside_the_trained_range(base, capsys):
    argv = ["predict", str(base), "--design", DESIGN, "--pressures", "10,90,345", "--json"]
    assert main(argv) == 0
    captured = capsys.readouterr()
    assert json.loads(captured.out)["outside_pressure_range"] == {
        "pressures": [90.0, 345.0],
        "trained_range": [0.0, 50.0],
        "unit": "kPa",
    }
    assert "softbend: warning: --pressures 90, 345 kPa: outside the pressures " in captured.err
    assert "trained on (0–50 kPa)" in captured.err
    assert main([*argv[:-2], "10,40", "--json"]) == 0
    assert json.loads(capsys.readouterr().out)["outside_pressure_range"] is None


def test_design_find_at_outside_the_range_says_so_and_takes_a_unit(base, tmp_path, capsys):
    argv = ["design", "find", "--model", str(base), "--angle", "60", "--json"]
    assert main([*argv, "--at", "103.4", "--out", str(tmp_path / "a")]) == 0
    captured = capsys.readouterr()
    record = json.loads(captured.out)
    assert record["outside_pressure_range"] == {
        "pressures": [103.4],
        "trained_range": [0.0, 50.0],
        "unit": "kPa",
    }
    assert "103.4 kPa lies outside the pressures the model was trained on (0–50 kPa)" in (
        captured.err
    )
    assert main([*argv, "--at", "7psi", "--out", str(tmp_path / "b")]) == 0  # 48.26 kPa
    record = json.loads(capsys.readouterr().out)
    assert record["spec"]["pressure_kpa"] == pytest.approx(48.263, abs=1e-3)
    assert record["outside_pressure_range"] is None and record["feasible"]
    assert main([*argv, "--at", "20 furlongs", "--out", str(tmp_path / "c")]) == 2
    assert "--at: unknown pressure unit 'furlongs'" in one_error_line(capsys)


# ----------------------------------------------------- one file per actuator, named by its file
def test_files_without_an_id_column_are_one_actuator_each_named_by_the_file(base, tmp_path, capsys):
    files = [
        readings(tmp_path / f"{name}.csv", ids=False, actuators={name: design})
        for name, design in BUILT.items()
    ]
    argv = ["transfer", "loco", *map(str, files), "--base", str(base), "--json"]
    argv += ["--out", str(tmp_path / "l"), "--strategies", "fem-only,scale-offset"]
    assert main([*argv, "--no-learning-curve"]) == 0
    assert json.loads(capsys.readouterr().out)["settings"]["actuators"] == ["P1", "P2"]


def test_actuator_id_is_an_id_column_and_a_missing_column_names_both(base, tmp_path, capsys):
    bench = readings(tmp_path / "bench.csv")
    bench.write_text(bench.read_text().replace("actuator,", "actuator_id,", 1))
    argv = ["transfer", "refine", str(base), str(bench), "--strategy", "scale-offset"]
    assert main([*argv, "--out", str(tmp_path / "m.json")]) == 0
    meta = json.loads((tmp_path / "m.json").read_text())["metadata"]
    assert meta["actuators"] == ["P1", "P2"]
    capsys.readouterr()
    bench.write_text(bench.read_text().replace("actuator_id,n_chambers,", "actuator_id,", 1))
    assert main([*argv, "--out", str(tmp_path / "n.json")]) == 2
    line = one_error_line(capsys)
    assert "lacks the column(s) n_chambers" in line and "(optional: actuator, actuator_id)" in line


def test_one_file_without_ids_holding_two_designs_says_how_to_name_them(base, tmp_path, capsys):
    bench = readings(tmp_path / "bench.csv", ids=False)
    argv = ["transfer", "loco", str(bench), "--base", str(base), "--out", str(tmp_path / "l")]
    assert main(argv) == 2
    line = one_error_line(capsys)
    assert "the actuator 'bench' has two designs" in line
    assert "a file without an actuator or actuator_id column is one actuator" in line
