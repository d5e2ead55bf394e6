"""``softbend fem run|mesh-study --family pneunet``: the PneuNet through the same commands."""

import json

import pytest

from softbend.cli import main

from .conftest import one_error_line


@pytest.mark.parametrize(
    ("design", "needle"),
    [
        ("n_chambers=0", "n_chambers: must be a whole number of chambers >= 1; got 0"),
        ("gap_mm=0", "gap_mm: must be > 0 mm; got 0"),
        ("wall_mm=5", "wall_mm: must be < chamber_length_mm / 2 = 4 mm"),
        ("outer_wall_mm=16", "outer_wall_mm: must be < chamber_width_mm / 2"),
        ("chambers=4", "--design: chambers is not a parameter of the pneunet family"),
        ("wall_mm", "--design: must be NAME=VALUE pairs"),
        ("n_chambers=6,n_chambers=7", "--design: gives 'n_chambers' twice (6 and 7); give it once"),
    ],
)
def test_a_bad_pneunet_design_is_one_line_naming_the_parameter(tmp_path, capsys, design, needle):
    args = ["fem", "run", "--family", "pneunet", "--design", design, "--out", str(tmp_path)]
    assert main(args) == 2
    assert needle in one_error_line(capsys)


def test_an_unknown_family_and_a_tiny_mesh_are_one_line(tmp_path, capsys):
    assert main(["fem", "run", "--family", "pneunets", "--out", str(tmp_path)]) == 2
    assert "--family: Unknown FEM actuator family 'pneunets'" in one_error_line(capsys)
    args = ["fem", "mesh-study", "--family", "pneunet", "--maxh", "3,0.1"]
    assert main(args) == 2
    assert "--maxh: must give at most" in one_error_line(capsys)


def test_a_campaign_s_mesh_too_fine_for_a_design_is_refused_before_any_sweep(tmp_path, capsys):
    db = tmp_path / "c.duckdb"
    args = ["campaign", "run", str(db), "--family", "pneunet", "--space", "lhs:4", "--maxh", "0.05"]
    assert main(args) == 2
    line = one_error_line(capsys)
    assert line.startswith("softbend: error: --maxh: must give at most 400000 elements for design ")
    assert "got 0.05 mm (about " in line
    assert not db.exists()


def test_fem_run_pneunet_json_prints_pressures_and_angles_and_writes_vtk(tmp_path, capsys):
    out = tmp_path / "run"
    code = main(
        [
            "fem",
            "run",
            "--family",
            "pneunet",
            "--design",
            "n_chambers=3,chamber_height_mm=12",
            "--pmax",
            "0.004",
            "--pstep",
            "0.002",
            "--maxh",
            "3",
            "--shapes",
            "2",
            "--out",
            str(out),
            "--json",
        ]
    )
    assert code == 0
    payload = json.loads(capsys.readouterr().out)
    assert payload["family"] == "pneunet" and payload["design"].startswith("n_chambers=3,")
    assert "chamber_height_mm=12," in payload["design"]
    assert payload["pressure_mpa"] == [0.0, 0.002, 0.004]
    assert payload["angle_deg"][0] == pytest.approx(0.0, abs=1e-9)
    assert payload["angle_deg"][2] > payload["angle_deg"][1] > 0.0
    assert payload["stats"]["step_volume_mm3"][-1] > payload["stats"]["step_volume_mm3"][0]
    # Contact is on by default; these walls stay apart at 4 kPa.
    assert payload["stats"]["options"]["contact"] == "on"
    assert payload["stats"]["step_contact_force_n"] == [0.0] * len(payload["stats"]["steps_mpa"])
    lines = (out / "sweep.csv").read_text().splitlines()
    assert len(lines) == 4
    assert (out / "angle_pressure.png").stat().st_size > 1000
    vtks = sorted(p.name for p in (out / "vtk").glob("*.vtu"))
    assert vtks[0] == "shape_p0.000MPa.vtu" and len(vtks) == 2
    text = (out / "vtk" / vtks[-1]).read_text()
    assert 'Name="model_half"' in text and "displacement" in text


@pytest.mark.parametrize(
    ("family", "value", "needle"),
    [
        ("pneunet", "yes", "--contact: must be one of 'off', 'on'; got \"yes\""),
        ("sfrba", "on", "--contact: must be off for the sfrba family (none of its walls touch)"),
    ],
)
def test_a_bad_contact_mode_is_one_line(tmp_path, capsys, family, value, needle):
    args = ["fem", "run", "--family", family, "--contact", value, "--out", str(tmp_path / "o")]
    assert main(args) == 2
    assert needle in one_error_line(capsys)


def test_the_mesh_study_takes_the_same_contact_flag(capsys):
    assert main(["fem", "mesh-study", "--family", "sfrba", "--contact", "on"]) == 2
    assert "--contact: must be off for the sfrba family" in one_error_line(capsys)


def test_contact_off_stops_where_the_walls_touch_and_reports_no_contact(tmp_path, capsys):
    args = [
        "fem",
        "run",
        "--family",
        "pneunet",
        "--design",
        "n_chambers=3,chamber_height_mm=12,gap_mm=1",
        "--pmax",
        "0.008",
        "--pstep",
        "0.001",
        "--maxh",
        "3",
        "--shapes",
        "1",
        "--contact",
        "off",
        "--out",
        str(tmp_path / "off"),
        "--json",
    ]
    assert main(args) == 0
    payload = json.loads(capsys.readouterr().out)
    assert payload["stop_reason"].startswith("neighbouring chamber walls touch at 4.")
    assert "step_contact_force_n" not in payload["stats"]
    assert "contact" not in payload["stats"]["options"]
