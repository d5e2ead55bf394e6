"""``softbend curling identify`` on oversized or absurd experiment files: one line, exit 2."""

from softbend.cli import main

from .conftest import one_error_line

HEADER = "time_s,pressure_kpa,x_mm,y_mm\n"


def test_identify_refuses_a_file_over_the_size_limit_before_reading(tmp_path, capsys, monkeypatch):
    monkeypatch.setenv("SOFTBEND_MAX_FILE_MIB", "1")
    path = tmp_path / "huge.csv"
    path.write_text(HEADER + "".join(f"{0.02 * k:.2f},10,0.5,0.1\n" for k in range(90_000)))
    out = tmp_path / "out"
    assert main(["curling", "identify", str(path), "--out", str(out)]) == 2
    line = one_error_line(capsys)
    assert str(path) in line and "SOFTBEND_MAX_FILE_MIB" in line and "limit of 1 MiB" in line
    assert "reading" not in line and not (out / "metrics.csv").exists()


def test_identify_refuses_too_many_rows(tmp_path, capsys, monkeypatch):
    monkeypatch.setenv("SOFTBEND_MAX_CSV_ROWS", "100")
    path = tmp_path / "long.csv"
    path.write_text(HEADER + "".join(f"{0.02 * k:.2f},10,0.5,0.1\n" for k in range(101)))
    assert main(["curling", "identify", str(path), "--out", str(tmp_path / "o")]) == 2
    line = one_error_line(capsys)
    assert str(path) in line and "101 rows" in line and "SOFTBEND_MAX_CSV_ROWS" in line


def test_identify_names_file_line_and_column_of_an_absurd_pressure(tmp_path, capsys):
    path = tmp_path / "kpa.csv"
    path.write_text(HEADER + "0,0,0,0\n0.02,10,0.5,0.1\n0.04,3e6,1.0,0.3\n")
    assert main(["curling", "identify", str(path), "--out", str(tmp_path / "o")]) == 2
    line = one_error_line(capsys)
    assert f"{path}:4:2: pressure_kpa: " in line
    assert "3e+06 is not a plausible gauge pressure (allowed -101.3 to 2000 kPa)" in line


def test_simulate_refuses_experiments_its_reader_would_refuse(tmp_path, capsys):
    out = tmp_path / "sim"
    assert main(["curling", "simulate", "--out", str(out), "--samples", "1000000000"]) == 2
    line = one_error_line(capsys)
    assert "--samples: the sample count is 1,000,000,000 rows" in line
    assert "SOFTBEND_MAX_CSV_ROWS" in line
    assert main(["curling", "simulate", "--out", str(out), "--dt", "1e300"]) == 2
    line = one_error_line(capsys)
    assert line.startswith("--dt: must make") or "--dt: must make" in line
    assert "plausible time of 1e+07 s" in line and "1e+300" in line
    assert not out.exists()
