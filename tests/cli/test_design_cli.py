"""softbend design find: the ranked answers, their files, and one line for bad input."""

from __future__ import annotations

import json

import pytest

from softbend.cli import main

FIXED = ["--fix", "r=8", "--fix", "t=3", "--fix", "b=3", "--fix", "phi=10", "--fix", "lc=10"]


@pytest.fixture(scope="module")
def model(tmp_path_factory):
    from tests.design_search.conftest import save_model

    return save_model(tmp_path_factory.mktemp("cli") / "linear.json")


def test_find_prints_json_and_writes_its_files(model, tmp_path, capsys):
    out = tmp_path / "design"
    args = ["design", "find", "--model", str(model), "--angle", "90", "--at", "0.08",
            "--minimize", "l", *FIXED, "--out", str(out), "--json"]  # fmt: skip
    assert main(args) == 0
    payload = json.loads(capsys.readouterr().out)
    first = payload["candidates"][0]
    assert first["design"] == {"l": 109.0, "r": 8.0, "t": 3.0, "b": 3.0, "phi": 10.0, "lc": 10.0}
    assert first["angle_deg"] == pytest.approx(87.2, abs=1e-3) and first["meets"] is True
    for name in ("candidates.csv", "search.json", "front.png", "curves.png"):
        assert (out / name).is_file(), name
    assert main(args) == 0  # its own earlier results are replaced
    capsys.readouterr()


def test_a_table_on_the_terminal_and_a_spec_file_of_several(model, tmp_path, capsys):
    spec = tmp_path / "specs.toml"
    spec.write_text(
        '[[spec]]\nname = "short"\nangle = 90.0\nat = 0.08\nminimize = ["l"]\n'
        '[[spec]]\nname = "far"\nmax_angle_at = 0.05\n'
    )
    out = tmp_path / "many"
    assert main(["design", "find", "--model", str(model), "--spec", str(spec), "-o", str(out)]) == 0
    text = capsys.readouterr().out
    assert "short: 90° ± 3° at 0.08 MPa" in text and "far: the largest angle" in text
    assert (out / "short" / "candidates.csv").is_file() and (out / "far" / "front.png").is_file()
    assert len(json.loads((out / "search.json").read_text())["specs"]) == 2


def test_no_design_meets_it_is_a_warning_with_the_closest(model, tmp_path, capsys):
    args = ["design", "find", "--model", str(model), "--angle", "200", "--at", "0.08", *FIXED,
            "-o", str(tmp_path / "none"), "--json"]  # fmt: skip
    assert main(args) == 0
    captured = capsys.readouterr()
    assert json.loads(captured.out)["feasible"] is False
    assert (
        "No design in the ranges searched meets" in captured.err
        and "160,8,3,3,10,10" in captured.err
    )


@pytest.mark.parametrize(
    ("extra", "needle"),
    [
        ([], "The target must be one of"),
        (["--angle", "90", "--at", "80"], "kPa"),
        (["--angle", "90", "--at", "0.08", "--minimize", "speed"], "--minimize"),
        (["--angle", "90", "--at", "0.08", "--range", "t=1:3"], "--allow-extrapolation"),
        (["--angle", "90", "--at", "0.08", "--fix", "wall=3"], "--fix"),
        (["--angle", "90", "--at", "0.08", "--resolution", "fine"], "--resolution"),
        (["--angle", "90", "--at", "0.08", "--top", "0"], "--top"),
        (["--angle", "90", "--at", "0.08", "--verify", "1", "--backend", "nope"], "--backend"),
    ],
)
def test_bad_input_is_one_line_exit_2(model, tmp_path, capsys, extra, needle):
    args = ["design", "find", "--model", str(model), "-o", str(tmp_path / "x"), *extra]
    assert main(args) == 2
    captured = capsys.readouterr()
    lines = captured.err.strip().splitlines()
    assert len(lines) == 1 and needle in lines[0], captured.err
    assert not (tmp_path / "x").exists()
