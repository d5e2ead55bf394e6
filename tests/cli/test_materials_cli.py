"""``softbend materials``: fits of the hyperelastic models to tensile data (paper B Fig. 2a)."""

import json

import pytest

from softbend.cli import main
from softbend.materials import fit_models, load_shipped

from .conftest import one_error_line

PNG_MAGIC = b"\x89PNG\r\n\x1a\n"
MODELS = ("neo-hookean", "yeoh", "arruda-boyce")


def test_default_fit_prints_a_table_and_writes_figure_and_json(tmp_path, capsys):
    out = tmp_path / "materials"
    assert main(["materials", "fit", "--out", str(out)]) == 0
    stdout = capsys.readouterr().out
    assert "Dragon Skin 30" in stdout and "R²" in stdout and "RMSE (MPa)" in stdout
    for name in MODELS:
        assert name in stdout
    assert "Best fit (highest R²): yeoh" in stdout
    assert "Marechal" in stdout
    assert (out / "fit.png").read_bytes()[:8] == PNG_MAGIC
    saved = json.loads((out / "fit.json").read_text(encoding="utf-8"))
    assert [f["model"] for f in saved["fits"]] == list(MODELS)
    assert saved["best_model"] == "yeoh"
    assert saved["test"]["name"] == "dragon-skin-30" and saved["test"]["n_points"] == 311
    assert saved["max_stretch"] is None
    assert not list(out.glob(".*.tmp"))  # the atomic write left no temporary file


def test_json_output_matches_the_library(tmp_path, capsys):
    out = tmp_path / "o"
    assert main(["materials", "fit", "--json", "--out", str(out)]) == 0
    payload = json.loads(capsys.readouterr().out)
    expected = fit_models(load_shipped("dragon-skin-30"))
    for fit in payload["fits"]:
        result = expected[fit["model"]]
        assert fit["r2"] == pytest.approx(result.r2, rel=1e-12)
        assert fit["rmse_mpa"] == pytest.approx(result.rmse_mpa, rel=1e-12)
        assert fit["parameters"] == pytest.approx(result.parameters, rel=1e-12)
    assert payload["files"]["figure"] == str(out / "fit.png")
    assert json.loads((out / "fit.json").read_text(encoding="utf-8")) == payload


def test_models_max_stretch_and_a_shipped_name(tmp_path, capsys):
    out = tmp_path / "o"
    args = ["materials", "fit", "ecoflex-0030", "--models", "yeoh, neo-hookean"]
    assert main([*args, "--max-stretch", "4", "--json", "--out", str(out)]) == 0
    payload = json.loads(capsys.readouterr().out)
    assert payload["test"]["material"] == "Ecoflex 00-30"
    assert [f["model"] for f in payload["fits"]] == ["yeoh", "neo-hookean"]
    assert all(f["stretch_max"] <= 4.0 for f in payload["fits"])
    assert payload["max_stretch"] == 4.0
    assert (out / "fit.png").is_file()


def test_user_csv_file(tmp_path, capsys):
    csv = tmp_path / "My_Rubber.csv"
    rows = [f"{0.2 * i:.3f};{0.4 * (0.2 * i) ** 1.1:.5f}" for i in range(1, 21)]
    csv.write_text(
        "Material;MyRubber\n\nEngineering Strain;Engineering Stress (MPa)\n" + "\n".join(rows)
    )
    assert main(["materials", "fit", str(csv), "--json", "--out", str(tmp_path / "o")]) == 0
    payload = json.loads(capsys.readouterr().out)
    assert payload["test"]["name"] == "my-rubber" and payload["test"]["attribution"] == ""
    assert payload["test"]["source"] == str(csv)


def test_unknown_model_is_one_line_exit_2_naming_allowed_models(tmp_path, capsys):
    out = tmp_path / "o"
    assert main(["materials", "fit", "--models", "yeoh,mooney", "--out", str(out)]) == 2
    line = one_error_line(capsys)
    assert "Unknown material model 'mooney'" in line
    assert f"known: {', '.join(MODELS)}." in line
    assert not out.exists()


def test_missing_column_is_one_line_exit_2(tmp_path, capsys):
    csv = tmp_path / "bad.csv"
    rows = "\n".join(f"{0.1 * i};{0.05 * i}" for i in range(1, 10))
    csv.write_text("Engineering Strain;Stress (MPa)\n" + rows + "\n")
    out = tmp_path / "o"
    assert main(["materials", "fit", str(csv), "--out", str(out)]) == 2
    line = one_error_line(capsys)
    assert "'Engineering Stress (MPa)'" in line and "bad.csv" in line
    assert "'Stress (MPa)'" in line
    assert not out.exists()


def test_missing_file_and_bad_max_stretch_exit_2(tmp_path, capsys):
    assert main(["materials", "fit", str(tmp_path / "nope.csv"), "--out", str(tmp_path)]) == 2
    line = one_error_line(capsys)
    assert "nope.csv" in line and "dragon-skin-30" in line
    assert main(["materials", "fit", "--max-stretch", "0.5", "--out", str(tmp_path / "o")]) == 2
    assert "--max-stretch: must be a number in (1, inf); got 0.5" in one_error_line(capsys)


def test_list_shipped_tests(capsys):
    assert main(["materials", "list"]) == 0
    stdout = capsys.readouterr().out
    assert "dragon-skin-30" in stdout and "ecoflex-0050" in stdout and "Marechal" in stdout
    assert main(["materials", "list", "--json"]) == 0
    payload = json.loads(capsys.readouterr().out)
    assert [t["name"] for t in payload["tests"]] == [
        "dragon-skin-10-medium",
        "dragon-skin-20",
        "dragon-skin-30",
        "ecoflex-0030",
        "ecoflex-0050",
    ]
    assert "ODbL" in payload["attribution"]


def test_a_test_in_kpa_is_one_line_exit_2_and_force_reads_it(tmp_path, capsys):
    csv = tmp_path / "kpa.csv"
    rows = "\n".join(f"{0.1 * i:.2f};{400.0 * 0.1 * i:.2f}" for i in range(1, 12))  # E = 400
    csv.write_text("Engineering Strain;Engineering Stress (MPa)\n" + rows + "\n")
    out = tmp_path / "o"
    assert main(["materials", "fit", str(csv), "--out", str(out)]) == 2
    line = one_error_line(capsys)
    assert "looks like kPa" in line and "400 MPa" in line and "--force" in line
    assert not out.exists()
    assert main(["materials", "fit", str(csv), "--force", "--out", str(out)]) == 0
    assert (out / "fit.json").exists()


# --- ``softbend materials fit`` on oversized or absurd tensile files: one line, exit 2 ---


HEADER = "Engineering Strain;Engineering Stress (MPa)"


def test_fit_names_file_line_and_column_of_an_absurd_stress(tmp_path, capsys):
    rows = [f"{0.1 * (i + 1):.2f};{0.05 * (i + 1):.3f}" for i in range(8)]
    rows[4] = "0.50;7e4"  # kPa where MPa was meant, perhaps
    path = tmp_path / "kpa.csv"
    path.write_text("\n".join([HEADER, *rows]) + "\n", encoding="utf-8")
    assert main(["materials", "fit", str(path), "--out", str(tmp_path / "o")]) == 2
    line = one_error_line(capsys)
    assert f"'{path}', line 6, column 'Engineering Stress (MPa)'" in line
    assert "70000 is not a plausible stress (allowed -1000 to 1000 MPa)" in line
    assert not (tmp_path / "o" / "fit.json").exists()


def test_fit_refuses_more_rows_than_the_limit(tmp_path, capsys, monkeypatch):
    monkeypatch.setenv("SOFTBEND_MAX_CSV_ROWS", "20")
    rows = [f"{0.1 * (i + 1):.2f};{0.05 * (i + 1):.3f}" for i in range(21)]
    path = tmp_path / "long.csv"
    path.write_text("\n".join([HEADER, *rows]) + "\n", encoding="utf-8")
    assert main(["materials", "fit", str(path), "--out", str(tmp_path / "o")]) == 2
    line = one_error_line(capsys)
    assert str(path) in line and "21 rows" in line and "SOFTBEND_MAX_CSV_ROWS" in line
