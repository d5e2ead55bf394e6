import json

import pytest

from softbend.cli import main

from .conftest import one_error_line


@pytest.mark.parametrize(
    ("args", "needle"),
    [
        (["--design", "100,6,-2,2,5,10"], "t_mm: must be a number in (0, 50]"),
        (["--design", "100,6,2"], "A design needs 6 values"),
        (["--maxh", "0"], "--maxh: must be a number in (0, 20]"),
        (["--gravity", "up"], "--gravity: must be one of"),
        (["--pmax", "nan"], "--pmax: must be a number in"),
        (["--pmax", "0.1", "--pstep", "0.03"], "whole number of steps of 0.03 MPa"),
        (["--shapes", "0"], "--shapes: must be an integer in [1, inf)"),
    ],
)
def test_fem_run_bad_input_is_one_line_and_exit_2(tmp_path, capsys, args, needle):
    assert main(["fem", "run", "--out", str(tmp_path), *args]) == 2
    assert needle in one_error_line(capsys)


def test_mesh_study_bad_sizes_exit_2(capsys):
    assert main(["fem", "mesh-study", "--maxh", "4,x"]) == 2
    assert "--maxh: must be comma-separated numbers" in one_error_line(capsys)


def test_fem_run_writes_the_sweep_figures_and_vtk(tmp_path, capsys):
    out = tmp_path / "run"
    code = main(
        [
            "fem",
            "run",
            "--pmax",
            "0.01",
            "--maxh",
            "6",
            "--shapes",
            "2",
            "--out",
            str(out),
            "--json",
        ]
    )
    assert code == 0
    payload = json.loads(capsys.readouterr().out)
    assert payload["pressure_mpa"] == [0.0, 0.005, 0.01]
    assert payload["angle_deg"][2] > payload["angle_deg"][0] > 0
    lines = (out / "sweep.csv").read_text().splitlines()
    assert lines[0] == "pressure_mpa,angle_deg,tip_x_mm,tip_z_mm,converged,newton_iterations"
    assert len(lines) == 4
    for name in ("angle_pressure.png", "shapes.png", "sweep.json"):
        assert (out / name).stat().st_size > 1000
    vtks = sorted(p.name for p in (out / "vtk").glob("*.vtu"))
    assert vtks[0] == "shape_p0.000MPa.vtu" and len(vtks) == 2
    assert b"displacement" in (out / "vtk" / vtks[0]).read_bytes()


def test_maxh_has_one_rule_in_run_and_mesh_study(tmp_path, monkeypatch, capsys):
    from types import SimpleNamespace

    import softbend.fem.sfrba.sweep as sweep

    message = "--maxh: must be a number in (0, 20]; got 20.5"
    for argv in (
        ["fem", "run", "--out", str(tmp_path / "o"), "--maxh", "20.5"],
        ["fem", "mesh-study", "--maxh", "4,20.5"],
    ):
        assert main(argv) == 2
        assert message in one_error_line(capsys)
    sizes = []

    def fake_run_sweep(design, pressures, options, **kwargs):
        sizes.append(options.maxh_mm)
        stats = {"ndof": 30, "stop_reason": "reached pmax"}
        result = SimpleNamespace(angle_deg=[1.0], mesh_size=10, stats=stats, wall_time_s=0.1)
        return result, None, None

    monkeypatch.setattr(sweep, "run_sweep", fake_run_sweep)
    assert main(["fem", "mesh-study", "--maxh", "20", "--pressures", "0", "--json"]) == 0
    assert sizes == [20.0]


@pytest.mark.parametrize("design", ["100,6,7,2,5,10", "100,1,50,2,5,10"])
def test_a_wall_thicker_than_the_radius_is_refused_before_solving(tmp_path, capsys, design):
    assert main(["fem", "run", "--design", design, "--out", str(tmp_path / "o")]) == 2
    assert "--design: t_mm: must be less than r_mm" in one_error_line(capsys)
    assert not (tmp_path / "o").exists()
