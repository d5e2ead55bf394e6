"""softbend design find on a model of another actuator: its names, units and levels.

The model is the conftest's PneuNet described by its table (n_chambers, wall_mm,
layer; pressure p_kpa in kPa): θ = 12·n − 15·w + 6·L degrees at 30 kPa.
"""

from __future__ import annotations

import csv
import json

import pytest

from softbend.cli import main

TARGET = ["--angle", "90", "--at", "30"]


@pytest.fixture(scope="module")
def model(tmp_path_factory):
    from tests.design_search.conftest import PNEUNET_DESIGNS, train_pneunet

    return train_pneunet(tmp_path_factory.mktemp("pneunet-cli"), PNEUNET_DESIGNS)


def test_find_by_the_model_s_own_names(model, tmp_path, capsys):
    out = tmp_path / "design"
    args = ["design", "find", "--model", str(model), *TARGET, "--minimize", "n_chambers",
            "--fix", "layer=paper", "--range", "wall_mm=0.5:2",
            "-o", str(out), "--json"]  # fmt: skip
    assert main(args) == 0
    payload = json.loads(capsys.readouterr().out)
    assert payload["actuator"] == "sims" and payload["pressure_unit"] == "kPa"
    assert payload["spec"]["target"] == "90° ± 3° at 30 kPa"
    assert payload["spec"]["pressure_kpa"] == 30.0
    assert payload["spec"]["ranges"]["layer"] == {"levels": ["paper"]}
    assert payload["spec"]["ranges"]["wall_mm"] == {
        "low": 0.5, "high": 2.0, "step": 0.025, "unit": "mm"
    }  # fmt: skip
    best = payload["candidates"][0]
    # 12·n − 15·w + 6 within 90 ± 3: n = 7 reaches 82.5° at most, n = 8 with w in [0.6, 1]
    assert best["design"]["n_chambers"] == 8 and best["design"]["layer"] == "paper"
    assert 0.6 - 1e-9 <= best["design"]["wall_mm"] <= 1.0 + 1e-9
    assert abs(best["angle_deg"] - 90.0) <= 3.0 and best["pressure_kpa"] == 30.0
    assert all(isinstance(c["design"]["n_chambers"], int) for c in payload["candidates"])
    with open(out / "candidates.csv", encoding="utf-8") as handle:
        rows = list(csv.DictReader(handle))
    assert list(rows[0])[:5] == ["rank", "n_chambers", "wall_mm", "layer", "pressure_kpa"]
    assert rows[0]["n_chambers"] == "8" and rows[0]["layer"] == "paper"
    assert not any(name in rows[0] for name in ("l_mm", "r_mm", "pressure_mpa"))
    record = json.loads((out / "search.json").read_text())
    assert record["candidates"][0]["design"] == best["design"]
    for name in ("front.png", "curves.png"):
        assert (out / name).is_file(), name


def test_the_table_names_the_parameters_and_the_pressure_unit(model, tmp_path, capsys):
    args = ["design", "find", "--model", str(model), "--max-angle-at", "20",
            "--fix", "wall_mm=1", "-o", str(tmp_path / "far")]  # fmt: skip
    assert main(args) == 0
    text = capsys.readouterr().out
    assert "the largest angle at 20 kPa" in text
    assert "n_chambers=12, wall_mm=1 mm, layer=paper" in " ".join(text.split())
    assert "l,r,t,b" not in text


def test_verify_is_skipped_with_one_line_and_recorded(model, tmp_path, capsys):
    out = tmp_path / "verify"
    args = ["design", "find", "--model", str(model), *TARGET, "--verify", "2",
            "--backend", "analytical", "-o", str(out), "--json"]  # fmt: skip
    assert main(args) == 0
    captured = capsys.readouterr()
    lines = captured.err.strip().splitlines()
    assert lines == [
        "softbend: warning: --verify skipped: the analytical backend does not model actuator "
        "sims; the answers are the surrogate's."
    ]
    payload = json.loads(captured.out)
    assert payload["verified"] is None
    assert payload["verify_skipped"] == "the analytical backend does not model actuator sims"
    assert all("fem_angle_deg" not in c for c in payload["candidates"])
    assert json.loads((out / "search.json").read_text())["verify_skipped"]


def test_a_spec_file_names_the_model_s_parameters(model, tmp_path, capsys):
    spec = tmp_path / "specs.toml"
    spec.write_text(
        '[[spec]]\nname = "finger"\nangle = 90.0\nat = 30.0\nminimize = ["n_chambers"]\n'
        'fix = {layer = "fabric"}\n'
        '[[spec]]\nname = "reach"\nangle = 90.0\nmax_pressure = 40.0\nminimize = "pressure"\n'
        "fix = {n_chambers = 10}\n"
    )
    out = tmp_path / "many"
    assert main(["design", "find", "--model", str(model), "--spec", str(spec), "-o", str(out)]) == 0
    capsys.readouterr()
    finger = json.loads((out / "finger" / "search.json").read_text())
    # fabric: 12·n − 15·w within 87–93 with w >= 0.5: n = 8 (w in [0.2, 0.6])
    assert finger["candidates"][0]["design"]["n_chambers"] == 8
    reach = json.loads((out / "reach" / "search.json").read_text())
    best = reach["candidates"][0]
    # 10 chambers, 90° = p·(4 − 0.5·w + 0.2·L): the thinnest wall on paper needs least
    assert best["design"] == {"n_chambers": 10, "wall_mm": 0.5, "layer": "paper"}
    assert best["pressure_kpa"] == pytest.approx(90.0 / (4.0 - 0.25 + 0.2), abs=1e-3)


@pytest.mark.parametrize(
    ("extra", "needles"),
    [
        (["--range", "wall=1:2"], ["--range: names 'wall'", "n_chambers, wall_mm, layer"]),
        (["--fix", "chambers=8"], ["--fix: names 'chambers'", "n_chambers, wall_mm, layer"]),
        (["--range", "wall_mm=2:1"], ["--range: wall_mm: ", "LOW <= HIGH"]),
        # the table's walls are its training range, not a wall of the description
        (
            ["--range", "wall_mm=0.1:2"],
            ["--allow-extrapolation: ", "'wall_mm' (0.1:2 mm)", "training range [0.5, 3]"],
        ),
        (["--range", "n_chambers=6.5:9"], ["--range: n_chambers: 6.5 is", "not a whole number"]),
        (["--fix", "n_chambers=7.5"], ["--fix: n_chambers: 7.5 is", "not a whole number"]),
        (["--fix", "layer=wood"], ["--fix: layer: must be one of", "fabric, paper"]),
        (["--range", "layer=0:1"], ["--range: ", "categorical parameter 'layer'"]),
        (["--resolution", "n_chambers=0.5"], ["--resolution: n_chambers (0.5)", "whole"]),
        (["--minimize", "volume"], ["--minimize: ", "n_chambers, wall_mm, pressure"]),
        (["--minimize", "l"], ["--minimize: ", 'got "l"']),
    ],
)
def test_bad_input_is_one_line_exit_2(model, tmp_path, capsys, extra, needles):
    args = ["design", "find", "--model", str(model), "-o", str(tmp_path / "x"), *TARGET, *extra]
    assert main(args) == 2
    captured = capsys.readouterr()
    lines = captured.err.strip().splitlines()
    assert len(lines) == 1 and lines[0].startswith("softbend: error: "), captured.err
    for needle in needles:
        assert needle in lines[0], lines[0]
    assert not (tmp_path / "x").exists()


def test_a_pressure_is_read_in_the_model_s_unit(model, tmp_path, capsys):
    args = ["design", "find", "--model", str(model), "--angle", "90", "--at", "3000",
            "-o", str(tmp_path / "x")]  # fmt: skip
    assert main(args) == 2
    line = capsys.readouterr().err.strip()
    assert "--at: " in line and "(0, 1000] kPa" in line and "got 3000" in line


def test_a_model_whose_constraint_divides_by_zero_is_one_line(model, tmp_path, capsys):
    from .conftest import one_error_line

    text = model.read_text()
    assert '"constraints": []' in text
    bad = tmp_path / "bad.json"
    bad.write_text(text.replace('"constraints": []', '"constraints": ["1 / 0 < wall_mm"]'))
    out = tmp_path / "design"
    assert main(["design", "find", "--model", str(bad), *TARGET, "-o", str(out)]) == 2
    line = one_error_line(capsys)
    assert "bad.json" in line and "'1 / 0 < wall_mm' divides by zero (1 / 0)" in line
    assert not out.exists()
