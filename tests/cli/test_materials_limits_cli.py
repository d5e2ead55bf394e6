"""``softbend materials fit`` on oversized or absurd tensile files: one line, exit 2."""

from softbend.cli import main

from .conftest import one_error_line

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
