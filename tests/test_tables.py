"""The one table reader: a format is a declaration; every error names file, line, column, key."""

from __future__ import annotations

import numpy as np
import pandas as pd
import pytest

from softbend.errors import DatasetError, LimitError
from softbend.tables import Column, HeaderKey, TableFormat, check_columns, read_table

FORMAT = TableFormat(
    name="test CSV",
    columns=(
        Column("time_s", "s", quantity="time_s"),
        Column("pressure_kpa", "kPa", quantity="pressure_kpa", low=0.0),
        Column("run", kind="text", required=False),
        Column("cycle", kind="integer", required=False, low=1),
        Column("mode", kind="choice", required=False, choices=("up", "down")),
    ),
    header=(
        HeaderKey("rig", required=True),
        HeaderKey("synthetic", "true or false", lambda v: v in ("true", "false")),
        HeaderKey(
            "length_mm", "a number", lambda v: v.replace(".", "").isdigit(), quantity="length_mm"
        ),
    ),
    other_keys="error",
)


def _write(tmp_path, text, name="t.csv"):
    path = tmp_path / name
    path.write_text(text, encoding="utf-8")
    return path


def _error(path, fmt=FORMAT) -> DatasetError:
    with pytest.raises(DatasetError) as info:
        read_table(path, fmt)
    assert "\n" not in str(info.value)
    return info.value


def test_a_good_file_reads_into_typed_columns_and_its_header(tmp_path):
    path = _write(
        tmp_path,
        "# rig: bench 2\n# synthetic: true\n\n# a remark\n"
        "time_s,pressure_kpa,run,cycle,mode\n0,0,a,1,up\n# between rows\n0.5,12.5,a,2.0,down\n",
    )
    table = read_table(path, FORMAT)
    assert table.header == {"rig": "bench 2", "synthetic": "true"}
    assert table.header_lines == {"rig": 1, "synthetic": 2}
    assert table.lines.tolist() == [6, 8] and table.header_line == 5
    assert table.positions == {"time_s": 1, "pressure_kpa": 2, "run": 3, "cycle": 4, "mode": 5}
    assert table.frame["pressure_kpa"].dtype == np.float64
    assert table.frame["cycle"].tolist() == [1, 2] and table.frame["cycle"].dtype == np.int64
    assert table.frame["run"].tolist() == ["a", "a"]
    error = table.error("does not increase", row=1, column="time_s")
    assert str(error) == f"{path}:8:1: time_s: does not increase"


@pytest.mark.parametrize(
    ("text", "where", "key", "detail"),
    [
        ("time_s,pressure_kpa\n0,0\n", (None, None), "rig", "lacks the header line"),
        ("# rig: a\n# rig: b\ntime_s,pressure_kpa\n0,0\n", (2, None), "rig", "is set twice"),
        ("# rig: a\n# colour: red\ntime_s,pressure_kpa\n0,0\n", (2, None), "colour", "is not a"),
        ("# rig: a\n# synthetic: yes\ntime_s,pressure_kpa\n0,0\n", (2, None), "synthetic",
         "must be true or false; got 'yes'"),
        ("# rig: a\n# length_mm: 20000\ntime_s,pressure_kpa\n0,0\n", (2, None), "length_mm",
         "not a plausible length"),
        ("# rig: a\ntime_s,pressure\n0,0\n", (2, 2), "pressure",
         "lacks the column(s) pressure_kpa and has column(s) pressure"),
        ("# rig: a\ntime_s,pressure_kpa,time_s\n0,0,0\n", (2, 3), "time_s", "appears twice"),
        ("# rig: a\ntime_s,pressure_kpa\n0,0\n1,2,3\n", (4, None), None, "has 3 cells"),
        ("# rig: a\ntime_s,pressure_kpa\n", (2, None), None, "0 data row(s)"),
        ("# rig: a\ntime_s,pressure_kpa\n0,x\n", (3, 2), "pressure_kpa",
         'must be a finite number >= 0 kPa; got "x"'),
        ("# rig: a\ntime_s,pressure_kpa\n0,\n", (3, 2), "pressure_kpa", "got an empty cell"),
        ("# rig: a\ntime_s,pressure_kpa\nnan,0\n", (3, 1), "time_s", 'got "nan"'),
        ("# rig: a\ntime_s,pressure_kpa\n0,-1\n", (3, 2), "pressure_kpa", ">= 0 kPa"),
        ("# rig: a\ntime_s,pressure_kpa,cycle\n0,1,1.5\n", (3, 3), "cycle", "integer >= 1"),
        ("# rig: a\ntime_s,pressure_kpa,mode\n0,1,sideways\n", (3, 3), "mode",
         "must be one of 'up', 'down'; got \"sideways\""),
        ("# rig: a\ntime_s,pressure_kpa,run\n0,1,\n", (3, 3), "run", "must be non-empty text"),
        ("# rig: a\ntime_s,pressure_kpa\n0,1\n1e300,1\n", (4, 1), "time_s", "plausible time"),
        ("# rig: a\ntime_s,pressure_kpa\n0,5000\n", (3, 2), "pressure_kpa", "plausible gauge"),
    ],
)  # fmt: skip
def test_every_error_carries_file_line_column_and_key(tmp_path, text, where, key, detail):
    path = _write(tmp_path, text)
    error = _error(path)
    assert (error.file, error.line, error.column, error.key) == (str(path), *where, key)
    assert detail in error.detail
    assert str(error).startswith(str(path))


def test_the_first_bad_cell_in_file_order_is_the_one_reported(tmp_path):
    path = _write(tmp_path, "# rig: a\ntime_s,pressure_kpa\n0,1\n1,x\ny,2\n")
    assert (_error(path).line, _error(path).key) == (4, "pressure_kpa")
    path = _write(tmp_path, "# rig: a\ntime_s,pressure_kpa\n0,1\n1,1e9\n-5,2\n", "p.csv")
    assert (_error(path).line, _error(path).key) == (4, "pressure_kpa")


def test_missing_files_folders_and_other_keys_and_columns(tmp_path):
    assert "no such file" in _error(tmp_path / "none.csv").detail
    assert "is a folder" in _error(tmp_path).detail
    loose = TableFormat("loose CSV", (Column("x"),), other_keys="keep", other_columns="ignore")
    path = _write(tmp_path, "# rig: a\n# a remark: kept out\nx,y\n1,z\n")
    table = read_table(path, loose)
    assert table.header == {"rig": "a"} and list(table.frame.columns) == ["x"]
    assert table.columns == ("x", "y")
    kept = TableFormat("kept CSV", (), other_columns="keep")
    frame = read_table(_write(tmp_path, "n,w,s\n1,2.5,a\n2,,b\n", "k.csv"), kept).frame
    assert frame["n"].dtype == np.int64 and np.isnan(frame["w"].iloc[1])
    assert frame["s"].tolist() == ["a", "b"]


def test_the_row_limit_is_checked_before_the_rows_are_read(tmp_path, monkeypatch):
    monkeypatch.setenv("SOFTBEND_MAX_CSV_ROWS", "2")
    path = _write(tmp_path, "# rig: a\ntime_s,pressure_kpa\n0,1\n1,1\n2,x\n")
    with pytest.raises(LimitError, match="3 rows"):
        read_table(path, FORMAT)
    small = TableFormat("small", FORMAT.columns, max_rows=10)
    assert (
        len(
            read_table(
                _write(tmp_path, "time_s,pressure_kpa\n0,1\n1,1\n2,3\n", "s.csv"), small
            ).frame
        )
        == 3
    )


def test_a_frame_from_elsewhere_gets_the_same_column_checks():
    good = pd.DataFrame({"time_s": [0.0, 1.0], "pressure_kpa": [0.0, 3.0]})
    check_columns(good, FORMAT, file="t.parquet")
    with pytest.raises(DatasetError) as info:
        check_columns(good.drop(columns="pressure_kpa"), FORMAT, file="t.parquet")
    assert (info.value.file, info.value.key) == ("t.parquet", "pressure_kpa")
    with pytest.raises(DatasetError, match=r"^t\.parquet: pressure_kpa: row 1: must be .*>= 0"):
        check_columns(good.assign(pressure_kpa=[0.0, -1.0]), FORMAT, file="t.parquet")
    with pytest.raises(DatasetError, match=r"^t\.parquet: time_s: row 1: 1e\+300 is not"):
        check_columns(good.assign(time_s=[0.0, 1e300]), FORMAT, file="t.parquet")
    with pytest.raises(
        DatasetError,
        match=r"^t\.parquet: time_s: must be a finite number in every row; got \w+ values$",
    ):
        check_columns(good.assign(time_s=["a", "b"]), FORMAT, file="t.parquet")


def test_a_large_file_reports_its_read_before_its_first_byte_is_read(tmp_path, monkeypatch):
    import softbend._io
    import softbend._progress
    from softbend._progress import listening

    path = _write(tmp_path, "# rig: r\ntime_s,pressure_kpa\n" + "0.1,1\n" * 200, "big.csv")
    heard: list[object] = []
    read_bytes = softbend._io.read_input_bytes

    def reading(*args, **kwargs):
        heard.append("the file is read")
        return read_bytes(*args, **kwargs)

    monkeypatch.setattr(softbend._io, "read_input_bytes", reading)
    with listening(lambda *call: heard.append(call)):
        read_table(path, FORMAT)  # below the size that reports: silent
        assert heard == ["the file is read"]
        heard.clear()
        monkeypatch.setattr(softbend._progress, "READ_REPORT_BYTES", 0)
        read_table(path, FORMAT)
    phase = "reading big.csv, %"
    assert heard[:2] == [(phase, 0, 100), "the file is read"]
    reads = [c for c in heard if isinstance(c, tuple) and c[0] == phase]
    assert [d for _, d, _ in reads] == sorted(d for _, d, _ in reads) and reads[-1][1] == 100
    assert heard[-1] == ("checking big.csv's columns", 2, 2)


def test_an_increasing_column_is_checked_within_each_experiment(tmp_path):
    fmt = TableFormat(
        "time CSV", (Column("t_s", increasing=True), Column("run", kind="text")), group="run"
    )
    path = tmp_path / "t.csv"
    path.write_text("t_s,run\n0,a\n0,b\n1,a\n1,b\n1,a\n", encoding="utf-8")
    with pytest.raises(DatasetError) as caught:
        read_table(path, fmt)
    assert str(caught.value) == (
        f"{path}:6:1: t_s: 1.0 does not increase after 1.0 (line 4) in experiment 'a'; "
        "it must increase strictly"
    )
    path.write_text("t_s,run\n0,a\n1,a\n0,b\n2,a\n", encoding="utf-8")
    contiguous = TableFormat(fmt.name, fmt.columns, group="run", contiguous_groups=True)
    with pytest.raises(DatasetError, match=r":5:2: run: experiment 'a' appears again after 'b'"):
        read_table(path, contiguous)
    assert read_table(path, fmt).frame["t_s"].tolist() == [0, 1, 0, 2]


def test_a_column_s_unit_defaults_to_the_unit_its_name_ends_with():
    assert Column("p1_KPA").unit == "kPa" and Column("t_ms").unit == "ms"
    assert Column("rho").unit == "" and Column("p_kpa", "MPa").unit == "MPa"
