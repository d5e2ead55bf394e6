"""Measurement files at the edges: size limits, implausible numbers, the metadata header."""

from __future__ import annotations

import pandas as pd
import pytest

from softbend.errors import DatasetError, LimitError
from softbend.transfer import measurements as measurements_module
from softbend.transfer.lab import LAB_MODELS
from softbend.transfer.measurements import (
    METADATA_KEYS,
    Measurements,
    format_measurements,
    load_measurements,
    save_measurements,
)

HEADER = "l,r,t,b,phi,lc,pressure_mpa,angle_deg"
ROW = "100,6,2,2,5,8,0.1,20"


def _write(path, text):
    path.write_text(text, encoding="utf-8")
    return path


def _one_line(error: pytest.ExceptionInfo) -> str:
    message = str(error.value)
    assert "\n" not in message
    return message


# ---------------------------------------------------------------------- limits
def test_a_file_over_the_row_limit_is_refused_before_its_rows_are_parsed(tmp_path, monkeypatch):
    monkeypatch.setenv("SOFTBEND_MAX_CSV_ROWS", "5")
    rows = "".join(f"100,6,2,2,5,8,{0.01 * k:.2f},{k}\n" for k in range(6))
    path = _write(tmp_path / "big.csv", f"# rig: bench\n{HEADER}\n\n# a comment\n{rows}")

    def no_parsing(*args, **kwargs):
        raise AssertionError("the rows were parsed")

    with monkeypatch.context() as patched:
        patched.setattr(measurements_module, "_normalize", no_parsing)
        with pytest.raises(LimitError) as error:
            load_measurements(path)
    message = _one_line(error)
    assert str(path) in message and "6 rows" in message and "limit of 5 rows" in message
    assert "SOFTBEND_MAX_CSV_ROWS" in message
    # At the limit (comments, blank lines and the header do not count) the file is read.
    _write(path, f"# rig: bench\n{HEADER}\n\n# a comment\n{rows.split(chr(10), 1)[1]}")
    assert len(load_measurements(path)) == 5


def test_a_file_over_the_size_limit_is_refused_before_it_is_read(tmp_path, monkeypatch):
    monkeypatch.setenv("SOFTBEND_MAX_FILE_MIB", "1")
    path = _write(tmp_path / "huge.csv", f"{HEADER}\n{ROW}\n" + "# padding\n" * 120_000)
    with pytest.raises(LimitError) as error:
        load_measurements(path)
    message = _one_line(error)
    assert str(path) in message and "MiB" in message and "SOFTBEND_MAX_FILE_MIB" in message


def test_a_cell_too_long_for_csv_is_one_error_naming_the_line(tmp_path):
    path = _write(tmp_path / "long.csv", f"{HEADER},actuator_id\n{ROW},A\n{ROW},{'x' * 200_000}\n")
    with pytest.raises(DatasetError) as error:
        load_measurements(path)
    message = _one_line(error)
    assert message.startswith(f"{path}:3:") and "not a CSV row" in message


# ---------------------------------------------------------------- plausibility
IMPLAUSIBLE = [
    ("angle", f"{ROW}\n100,6,2,2,5,8,0.2,1e300\n", "3", "angle_deg", "-3600 to 3600"),
    ("angle-low", "100,6,2,2,5,8,0.2,-4000\n", "2", "angle_deg", "-3600 to 3600"),
    ("pressure", "100,6,2,2,5,8,5,20\n", "2", "pressure_mpa", "It looks like kPa"),
    ("pressure-huge", "100,6,2,2,5,8,1e300,20\n", "2", "pressure_mpa", "0.1013 to 2"),
    ("l", "20000,6,2,2,5,8,0.1,20\n", "2", "l", "0 to 10000"),
    ("r", "100,1e300,2,2,5,8,0.1,20\n", "2", "r", "0 to 10000"),
    ("t", "100,6,-1e300,2,5,8,0.1,20\n", "2", "t", "0 to 10000"),
    ("b", "100,6,2,1e300,5,8,0.1,20\n", "2", "b", "0 to 10000"),
    ("phi", "100,6,2,2,95,8,0.1,20\n", "2", "phi", "fiber winding angle"),
    ("phi-negative", "100,6,2,2,-1e300,8,0.1,20\n", "2", "phi", "0 to 90"),
    ("lc", "100,6,2,2,5,1e300,0.1,20\n", "2", "lc", "0 to 10000"),
]


@pytest.mark.parametrize(
    ("rows", "line", "column", "allowed"),
    [case[1:] for case in IMPLAUSIBLE],
    ids=[case[0] for case in IMPLAUSIBLE],
)
def test_an_implausible_number_names_file_line_column_and_range(
    tmp_path, rows, line, column, allowed
):
    path = _write(tmp_path / "absurd.csv", f"{HEADER}\n{rows}")
    with pytest.raises(DatasetError) as error:
        load_measurements(path)
    message = _one_line(error)
    assert message.startswith(f"{path}:{line}:") and f": {column}: " in message
    assert (error.value.file, error.value.line, error.value.key) == (str(path), int(line), column)
    assert "plausible" in message and allowed in message


def test_an_implausible_number_in_a_frame_names_its_row():
    frame = pd.DataFrame(
        {
            "l": [100.0] * 3,
            "r": [6.0] * 3,
            "t": [2.0] * 3,
            "b": [2.0] * 3,
            "phi": [5.0] * 3,
            "lc": [8.0] * 3,
            "pressure_mpa": [0.0, 0.1, 0.2],
            "angle_deg": [0.0, 20.0, 1e300],
        },
        index=[7, 8, 9],
    )
    with pytest.raises(DatasetError, match=r"^lab: angle_deg: row 9: 1e\+300 .*3600"):
        Measurements.from_frame(frame, source="lab")
    frame["angle_deg"] = [0.0, 20.0, 30.0]
    frame["pressure_mpa"] = [0.0, 10.0, 20.0]
    with pytest.raises(DatasetError, match=r"^pressure_mpa: row 8: .*looks like kPa"):
        Measurements.from_frame(frame)


# -------------------------------------------------------------------- metadata
BAD_HEADERS = [
    ("unknown", "# temperature: 21 C\n", "line 2", ["temperature: is not a header key", "rig"]),
    (
        "synthetic",
        "# synthetic: maybe\n",
        "line 2",
        ["synthetic: must be 'true' or 'false'; got 'maybe'"],
    ),
    ("synthetic-case", "# synthetic: True\n", "line 2", ["synthetic: must be", "'True'"]),
    ("seed", "# lab.seed: -1\n", "line 2", ["lab.seed: must be an integer >= 0; got '-1'"]),
    ("cycles", "# lab.cycles: two\n", "line 2", ["lab.cycles: must be an integer >= 1"]),
    (
        "noise",
        "# lab.camera_noise_deg: nan\n",
        "line 2",
        ["lab.camera_noise_deg: must be a finite"],
    ),
    ("plant", "# lab.plant: abaqus\n", "line 2", ["lab.plant: must be 'fem' or 'analytical'"]),
    ("unloading", "# lab.unloading: yes\n", "line 2", ["lab.unloading: must be 'True' or 'False'"]),
    ("date", "# date: 12/03/2024\n", "line 2", ["date: must be an ISO 8601", "'12/03/2024'"]),
    ("lab-unknown", "# lab.colour: red\n", "line 2", ["lab.colour: is not a header key"]),
]


@pytest.mark.parametrize(
    ("header", "line", "expected"),
    [case[1:] for case in BAD_HEADERS],
    ids=[case[0] for case in BAD_HEADERS],
)
def test_a_bad_metadata_header_is_one_error_naming_file_and_line(tmp_path, header, line, expected):
    path = _write(tmp_path / "meta.csv", f"# rig: bench 2\n{header}{HEADER}\n{ROW}\n")
    with pytest.raises(DatasetError) as error:
        load_measurements(path)
    message = _one_line(error)
    assert message.startswith(f"{path}:{line.split()[1]}: ")
    for part in expected:
        assert part in message


def test_good_metadata_headers_are_read_and_plain_comments_stay_comments(tmp_path):
    path = _write(
        tmp_path / "meta.csv",
        "# softbend measurements CSV v1\n# synthetic: false\n# date: 2024-05-17T14:30\n"
        "# note: bench 2, url: http://x/y\n# a remark without a colon\n"
        f"{HEADER}\n# after the header: anything\n{ROW}\n",
    )
    m = load_measurements(path)
    assert m.metadata == {
        "synthetic": "false",
        "date": "2024-05-17T14:30",
        "note": "bench 2, url: http://x/y",
    }


def test_in_memory_metadata_is_held_to_what_a_file_can_read_back(tmp_path):
    frame = load_measurements(_write(tmp_path / "m.csv", f"{HEADER}\n{ROW}\n")).frame
    with pytest.raises(ValueError, match=r"unknown metadata key 'colour'"):
        Measurements.from_frame(frame, metadata={"colour": "red"})
    with pytest.raises(ValueError, match=r"'synthetic' must be 'true' or 'false'"):
        Measurements.from_frame(frame, metadata={"synthetic": "yes"})


def test_every_virtual_lab_key_is_a_known_metadata_key(quick_lab, quick_measurements, tmp_path):
    assert set(quick_lab.metadata()) <= set(METADATA_KEYS)
    assert all(METADATA_KEYS["lab.plant"][1](plant) for plant in LAB_MODELS)
    path = save_measurements(quick_measurements, tmp_path / "lab.csv")
    assert path.read_text(encoding="utf-8") == format_measurements(quick_measurements)
    assert load_measurements(path) == quick_measurements
