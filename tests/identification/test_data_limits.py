"""The experiment CSV reader refuses oversized files and absurd values, naming where."""

import pytest

from softbend.errors import DatasetError, LimitError
from softbend.identification.data import load_experiments

HEADER = "time_s,pressure_kpa,x_mm,y_mm\n"
GOOD_ROWS = ["0,0,0,0", "0.02,10,0.5,0.1", "0.04,20,1.0,0.3", "0.06,30,1.2,0.4"]


def _write(path, rows, *, comments=""):
    path.write_text(comments + HEADER + "\n".join(rows) + "\n", encoding="utf-8")
    return path


def test_a_file_over_the_size_limit_is_refused_before_it_is_read(tmp_path, monkeypatch):
    from softbend.identification.data import experiment_files

    monkeypatch.setenv("SOFTBEND_MAX_FILE_MIB", "1")
    rows = [f"{0.02 * k:.2f},{k % 50},0.5,0.1" for k in range(80_000)]  # about 1.5 MiB
    path = _write(tmp_path / "big.csv", rows)
    with pytest.raises(LimitError) as info:
        load_experiments(path)
    message = str(info.value)
    assert str(path) in message and "SOFTBEND_MAX_FILE_MIB" in message and "MiB" in message
    with pytest.raises(LimitError, match="SOFTBEND_MAX_FILE_MIB"):
        experiment_files(tmp_path)  # a folder: each file is checked


def test_more_rows_than_the_limit_are_refused_before_any_row_is_parsed(tmp_path, monkeypatch):
    monkeypatch.setenv("SOFTBEND_MAX_CSV_ROWS", "5")
    rows = [*GOOD_ROWS, "0.08,not a number,1,1", "0.10,40,1.4,0.5"]  # 6 rows, one broken
    path = _write(tmp_path / "rows.csv", rows, comments="# rest_length_mm: 15.25\n")
    with pytest.raises(LimitError) as info:
        load_experiments(path)
    message = str(info.value)
    assert str(path) in message and "6 rows" in message and "5 rows" in message
    assert "SOFTBEND_MAX_CSV_ROWS" in message
    monkeypatch.setenv("SOFTBEND_MAX_CSV_ROWS", "6")
    with pytest.raises(
        DatasetError, match='pressure_kpa: must be a finite number; got "not a number"'
    ):
        load_experiments(path)


@pytest.mark.parametrize(
    ("row", "column", "needle"),
    [
        ("1e300,40,1.4,0.5", "time_s", "plausible time (allowed 0 to 1e+07 s)"),
        ("0.08,1e9,1.4,0.5", "pressure_kpa", "plausible gauge pressure (allowed -101.3 to 2000"),
        ("0.08,-500,1.4,0.5", "pressure_kpa", "-500 is not a plausible gauge pressure"),
        ("0.08,40,2e4,0.5", "x_mm", "plausible position (allowed -10000 to 10000 mm)"),
        ("0.08,40,1.4,-1e12", "y_mm", "plausible position"),
    ],
)
def test_an_absurd_value_names_file_line_and_column(tmp_path, row, column, needle):
    path = _write(tmp_path / "absurd.csv", [*GOOD_ROWS, row], comments="# comment\n")
    with pytest.raises(DatasetError) as info:
        load_experiments(path)
    message = str(info.value)
    position = HEADER.strip().split(",").index(column) + 1
    assert message.startswith(f"{path}:7:{position}: {column}: ")
    assert (info.value.file, info.value.line, info.value.key) == (str(path), 7, column)
    assert needle in message and "\n" not in message


def test_the_first_absurd_value_in_the_file_is_the_one_named(tmp_path):
    rows = [*GOOD_ROWS, "0.08,40,1.4,-1e12", "1e300,1e9,1.4,0.5"]
    with pytest.raises(DatasetError, match=r"two.csv:6:4: y_mm: "):
        load_experiments(_write(tmp_path / "two.csv", rows))
    rows = [*GOOD_ROWS[:2], "0.04,5000,1,0.3", "1e300,30,1.2,0.4"]
    with pytest.raises(DatasetError, match=r"three.csv:4:2: pressure_kpa: "):
        load_experiments(_write(tmp_path / "three.csv", rows))


@pytest.mark.parametrize(
    ("value", "needle"),
    [
        ("1e300", ":1: rest_length_mm: 1e+300 is not a plausible length"),
        ("nan", ":1: rest_length_mm: must be a positive number (mm); got 'nan'"),
        ("-3", ":1: rest_length_mm: must be a positive number (mm); got '-3'"),
        ("inf", ":1: rest_length_mm: must be a positive number"),
    ],
)
def test_an_absurd_rest_length_comment_names_the_file_and_line(tmp_path, value, needle):
    path = _write(tmp_path / "rest.csv", GOOD_ROWS, comments=f"# rest_length_mm: {value}\n")
    with pytest.raises(DatasetError) as info:
        load_experiments(path)
    assert str(path) in str(info.value) and needle in str(info.value)


def test_a_deeply_nested_metadata_comment_is_a_limit_not_a_recursion_error(tmp_path):
    nested = "[" * 100_000 + "]" * 100_000
    path = _write(tmp_path / "deep.csv", GOOD_ROWS, comments=f"# metadata: {nested}\n")
    with pytest.raises(LimitError) as info:
        load_experiments(path)
    message = str(info.value)
    assert f"{path}:1: metadata: the value is" in message and "SOFTBEND_MAX_NESTING" in message


def test_a_field_too_long_for_the_csv_module_is_one_dataset_error(tmp_path):
    rows = [*GOOD_ROWS, "0.08,40,1.4," + "1" * 200_000]
    path = _write(tmp_path / "field.csv", rows)
    with pytest.raises(DatasetError, match=rf"{path.name}:6: not a CSV row"):
        load_experiments(path)


def test_plausible_files_still_load_to_the_same_numbers(tmp_path):
    rows = [*GOOD_ROWS, "0.08,-101.3,1.4,0.5", "0.10,2000,1.6,0.6"]
    (experiment,) = load_experiments(_write(tmp_path / "ok.csv", rows))
    assert experiment.pressure_kpa.tolist() == [0.0, 10.0, 20.0, 30.0, -101.3, 2000.0]
    assert experiment.time_s[-1] == 0.10
