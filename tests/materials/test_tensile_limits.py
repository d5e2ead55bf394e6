"""Tensile data files: size and row limits before parsing, absurd values named by line."""

import pytest

from softbend.errors import DatasetError, LimitError
from softbend.materials import load_shipped, load_tensile_csv, shipped_tensile_tests

HEADER = "Time (s);Engineering Strain;Engineering Stress (MPa)"


def _rows(n):
    return [f"{0.1 * i:.1f};{0.05 * (i + 1):.4f};{0.02 * (i + 1):.4f}" for i in range(n)]


def _write(path, rows, metadata=("PARAMETER;INFO;URL", "Material;Test", "")):
    path.write_text("\n".join([*metadata, HEADER, *rows]) + "\n", encoding="utf-8")
    return path


def test_a_file_over_the_size_limit_is_refused_before_it_is_read(tmp_path, monkeypatch):
    monkeypatch.setenv("SOFTBEND_MAX_FILE_MIB", "1")
    path = _write(tmp_path / "big.csv", _rows(60_000))  # about 1.6 MiB
    with pytest.raises(LimitError) as info:
        load_tensile_csv(path)
    assert str(path) in str(info.value) and "SOFTBEND_MAX_FILE_MIB" in str(info.value)


def test_more_rows_than_the_limit_are_refused_before_any_row_is_parsed(tmp_path, monkeypatch):
    monkeypatch.setenv("SOFTBEND_MAX_CSV_ROWS", "10")
    rows = _rows(11)
    rows[2] = "0.2;oops;0.1"
    path = _write(tmp_path / "rows.csv", rows)
    with pytest.raises(LimitError) as info:
        load_tensile_csv(path)
    message = str(info.value)
    assert str(path) in message and "11 rows" in message and "SOFTBEND_MAX_CSV_ROWS" in message


@pytest.mark.parametrize(
    ("cell", "value", "column", "needle"),
    [
        (1, "1e5", "Engineering Strain", "100000 is not a plausible strain (allowed -1 to 100)"),
        (2, "2.5e6", "Engineering Stress (MPa)", "not a plausible stress (allowed -1000 to 1000"),
        (2, "-5000", "Engineering Stress (MPa)", "-5000 is not a plausible stress"),
    ],
)
def test_an_absurd_value_names_file_line_and_column(tmp_path, cell, value, column, needle):
    rows = _rows(8)
    cells = rows[5].split(";")
    cells[cell] = value
    rows[5] = ";".join(cells)
    path = _write(tmp_path / "absurd.csv", rows)
    with pytest.raises(DatasetError) as info:
        load_tensile_csv(path)
    message = str(info.value)
    assert message.startswith(f"'{path}', line 10, column '{column}': ")  # 3 metadata, header
    assert needle in message


def test_the_first_absurd_value_in_file_order_is_named(tmp_path):
    rows = _rows(8)
    rows[3] = "0.3;0.2;5000"
    rows[6] = "0.6;500;0.1"
    with pytest.raises(DatasetError, match=r"line 8, column 'Engineering Stress \(MPa\)'"):
        load_tensile_csv(_write(tmp_path / "two.csv", rows))


@pytest.mark.parametrize("name", shipped_tensile_tests())
def test_the_shipped_tests_are_plausible(name):
    assert load_shipped(name).n_points > 300
