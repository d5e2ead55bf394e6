import json

import pytest

from softbend.cli import main
from softbend.identification.persistence import load_narx

from .conftest import one_error_line


@pytest.fixture(scope="module")
def simulated(tmp_path_factory):
    out = tmp_path_factory.mktemp("sim")
    code = main(
        [
            "curling",
            "simulate",
            "--out",
            str(out),
            "--experiments",
            "2",
            "--samples",
            "160",
            "--seed",
            "5",
            "--json",
        ]
    )
    assert code == 0
    return out


def test_simulate_writes_labelled_csv_files(simulated):
    files = sorted(simulated.glob("*.csv"))
    assert len(files) == 4
    header = files[0].read_text().splitlines()[:3]
    assert any("SYNTHETIC DATA" in line for line in header)


def test_identify_prints_metrics_and_writes_models_and_figures(simulated, tmp_path, capsys):
    capsys.readouterr()
    code = main(["curling", "identify", str(simulated), "--out", str(tmp_path), "--json"])
    assert code == 0
    payload = json.loads(capsys.readouterr().out)
    assert len(payload["metrics"]) == 2 * 2 * 2 * 2  # signs x outputs x held-out x modes
    assert {row["mode"] for row in payload["metrics"]} == {"one-step", "free-run"}
    for name in (
        "fig5_tip_positions",
        "fig6_bending_grade",
        "fig7_arc_length",
        "fig9_identified_rho",
        "fig10_identified_length",
    ):
        assert (tmp_path / f"{name}.png").stat().st_size > 10_000
    model, metadata = load_narx(tmp_path / "models" / "negative_length_mm.json")
    assert metadata["output_unit"] == "mm" and metadata["synthetic_data"] is True
    assert model.max_lag_ == 2


def _write(path, text):
    path.write_text(text)
    return path


@pytest.mark.parametrize(
    ("content", "expected"),
    [
        ("time_s,pressure_kpa,x_mm\n0,1,0\n0.1,2,0\n0.2,3,0\n", "y_mm"),
        ("time_s,pressure_kpa,x_mm,y_mm\n0,1,0,0\n0.1,nan,0,0\n0.2,3,0,0\n", "pressure_kpa"),
        ("time_s,pressure_kpa,x_mm,y_mm\n0,1,0,0\n0.1,2,0,0\n0.1,3,0,0\n", "time"),
    ],
    ids=["missing-column", "nan", "non-increasing-time"],
)
def test_bad_csv_gives_one_line_and_exit_2(tmp_path, capsys, content, expected):
    path = _write(tmp_path / "bad.csv", content)
    assert main(["curling", "identify", str(path), "--out", str(tmp_path / "o")]) == 2
    assert expected in one_error_line(capsys)


def test_missing_data_path_and_bad_options_exit_2(tmp_path, capsys):
    assert main(["curling", "identify", str(tmp_path / "nope.csv"), "--out", str(tmp_path)]) == 2
    one_error_line(capsys)
    assert (
        main(["curling", "identify", str(tmp_path), "--out", str(tmp_path), "--kernel", "x"]) == 2
    )
    assert "--kernel: must be one of 'moments', 'cv'" in one_error_line(capsys)
    assert main(["curling", "simulate", "--out", str(tmp_path), "--samples", "abc"]) == 2
    one_error_line(capsys)


# --- ``softbend curling identify`` on oversized or absurd experiment files: one line, exit 2 ---


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
