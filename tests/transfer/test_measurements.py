import numpy as np
import pandas as pd
import pytest

from softbend.design import FEATURES, sfrba_design
from softbend.errors import DatasetError
from softbend.transfer.measurements import (
    DIRECTIONS,
    MEASUREMENT_COLUMNS,
    OPTIONAL_COLUMNS,
    Measurements,
    load_measurements,
    save_measurements,
)

HEADER = "l,r,t,b,phi,lc,pressure_mpa,angle_deg"
DESIGN_A = "100,6,2,2,5,8"
DESIGN_B = "120,8,3,3,10,10"


def _write(path, text):
    path.write_text(text, encoding="utf-8")
    return path


def _frame(**overrides):
    data = {
        "l": [100.0, 100.0, 120.0, 120.0, 100.0],
        "r": [6.0, 6.0, 8.0, 8.0, 6.0],
        "t": [2.0, 2.0, 3.0, 3.0, 2.0],
        "b": [2.0, 2.0, 3.0, 3.0, 2.0],
        "phi": [5.0, 5.0, 10.0, 10.0, 5.0],
        "lc": [8.0, 8.0, 10.0, 10.0, 8.0],
        "pressure_mpa": [0.0, 0.05, 0.0, 0.1, 0.1],
        "angle_deg": [0.0, 31.5, -0.25, 80.125, 95.0],
        "actuator_id": ["A2", "A2", "B1", "B1", "A2"],
        "cycle": [1, 1, 1, 1, 2],
        "direction": ["loading", "loading", "loading", "unloading", "unloading"],
    }
    data.update(overrides)
    return pd.DataFrame({k: v for k, v in data.items() if v is not None})


# ------------------------------------------------------------------ round trip
def test_save_then_load_gives_equal_measurements(tmp_path):
    frame = _frame(
        angle_deg=[0.1 + 0.2, 1 / 3, -1e-17, 1234.56789012345678, 2.0**-40],
        pressure_mpa=[0.0, 0.1 + 0.2, 1e-300, 0.1, 7 / 90],
        actuator_id=['A, "two"', 'A, "two"', "  B1  ", "B1", 'A, "two"'],
    )
    metadata = {"rig": "bench 2", "operator": "AB", "note": "url: http://x/y#z"}
    m = Measurements.from_frame(frame, metadata=metadata, source="memory")
    target = save_measurements(m, tmp_path / "sub" / "m.csv")
    assert target == tmp_path / "sub" / "m.csv"
    loaded = load_measurements(target)
    assert loaded.frame.equals(m.frame)
    assert loaded.metadata == metadata
    assert loaded == m
    assert loaded.source == str(target)
    assert loaded.actuator_ids == ('A, "two"', "B1")
    # A second round trip writes the same bytes.
    again = save_measurements(loaded, tmp_path / "again.csv")
    assert again.read_bytes() == target.read_bytes()
    text = target.read_text(encoding="utf-8").splitlines()
    assert text[1:4] == ["# rig: bench 2", "# operator: AB", "# note: url: http://x/y#z"]
    assert text[4] == ",".join(MEASUREMENT_COLUMNS + OPTIONAL_COLUMNS)
    assert not list(tmp_path.glob("**/*.tmp"))


def test_frame_has_every_column_with_canonical_dtypes():
    frame = _frame(cycle=[1.0, 1.0, 1.0, 1.0, 2.0], l=[100, 100, 120, 120, 100])
    m = Measurements.from_frame(frame[list(reversed(frame.columns))])
    assert list(m.frame.columns) == list(MEASUREMENT_COLUMNS + OPTIONAL_COLUMNS)
    for column in MEASUREMENT_COLUMNS:
        assert m.frame[column].dtype == np.float64
    assert m.frame["cycle"].dtype == np.int64
    assert m.frame["actuator_id"].dtype == object
    assert m.frame["direction"].dtype == object
    assert isinstance(m.frame.index, pd.RangeIndex)
    assert len(m) == 5


def test_input_frame_is_copied_and_arrays_are_fresh():
    frame = _frame()
    m = Measurements.from_frame(frame)
    frame.loc[0, "angle_deg"] = 999.0
    assert m.frame.loc[0, "angle_deg"] == 0.0
    m.features[0, 0] = -1.0
    m.angle_deg[0] = -1.0
    assert m.frame.loc[0, "l"] == 100.0
    assert m.frame.loc[0, "angle_deg"] == 0.0


def test_source_is_not_compared_but_frame_and_metadata_are():
    a = Measurements.from_frame(_frame(), source="a")
    assert a == Measurements.from_frame(_frame(), source="b")
    assert a != Measurements.from_frame(_frame(), metadata={"rig": "v"})
    assert a != Measurements.from_frame(_frame(angle_deg=[0, 31.5, -0.25, 80.125, 95.5]))


# -------------------------------------------------------------------- defaults
def test_optional_columns_get_defaults(tmp_path):
    path = _write(
        tmp_path / "plain.csv",
        f"# rig: bench 1\n{HEADER}\n{DESIGN_A},0,0\n{DESIGN_A},0.05,31.5\n"
        f"{DESIGN_B},0.1,40\n100.5,6,2,2,5,8,0.1,1\n",
    )
    m = load_measurements(path)
    assert m.metadata == {"rig": "bench 1"}
    assert m.actuator_ids == ("100,6,2,2,5,8", "120,8,3,3,10,10", "100.5,6,2,2,5,8")
    assert m.frame["cycle"].tolist() == [1, 1, 1, 1]
    assert m.frame["direction"].tolist() == ["loading"] * 4
    assert m.design_of("100,6,2,2,5,8") == sfrba_design(100, 6, 2, 2, 5, 8)
    assert DIRECTIONS == ("loading", "unloading")


def test_column_order_is_free_and_cells_are_stripped(tmp_path):
    path = _write(
        tmp_path / "shuffled.csv",
        "\ufeffdirection , angle_deg,cycle,actuator_id,lc,phi,b,t,r,l,pressure_mpa\r\n"
        " unloading ,  12.5 , 3 ,  X 1 , 8, 5, 2, 2, 6, 100, 0.2 \r\n"
        "\r\n"
        "# a comment between rows\r\n"
        "loading,3,1,X 1,8,5,2,2,6,100,0.05\r\n",
    )
    m = load_measurements(path)
    assert m.actuator_ids == ("X 1",)
    assert m.frame["direction"].tolist() == ["unloading", "loading"]
    assert m.frame["cycle"].tolist() == [3, 1]
    np.testing.assert_array_equal(m.angle_deg, [12.5, 3.0])
    assert m.metadata == {}


# ---------------------------------------------------------------- accessors
def test_ids_designs_features_groups_and_subset():
    m = Measurements.from_frame(_frame())
    assert m.actuator_ids == ("A2", "B1")
    assert m.designs == (sfrba_design(100, 6, 2, 2, 5, 8), sfrba_design(120, 8, 3, 3, 10, 10))
    assert m.design_of("B1") == sfrba_design(120, 8, 3, 3, 10, 10)

    features = m.features
    assert features.shape == (5, 7) and features.dtype == np.float64
    assert FEATURES[-1] == "pressure_mpa"
    np.testing.assert_array_equal(features[:, -1], m.frame["pressure_mpa"])
    for row, design in zip(features, [m.design_of(g) for g in m.groups], strict=True):
        np.testing.assert_array_equal(row[:-1], design.as_array())
    np.testing.assert_array_equal(features[3], [120, 8, 3, 3, 10, 10, 0.1])
    np.testing.assert_array_equal(m.angle_deg, [0.0, 31.5, -0.25, 80.125, 95.0])
    assert m.groups.tolist() == ["A2", "A2", "B1", "B1", "A2"]

    a = m.subset(["A2"])
    assert a.actuator_ids == ("A2",)
    assert len(a) == 3 and list(a.frame.index) == [0, 1, 2]
    np.testing.assert_array_equal(a.angle_deg, [0.0, 31.5, 95.0])
    assert m.subset("B1").groups.tolist() == ["B1", "B1"]
    assert m.subset(["B1", "A2"]) == m  # original row order kept
    with pytest.raises(ValueError, match=r"'A2', 'B1'.*unknown 'C9'"):
        m.subset(["A2", "C9"])
    with pytest.raises(ValueError, match="at least one"):
        m.subset([])
    with pytest.raises(ValueError, match=r"one of 'A2', 'B1'. Got 'C9'"):
        m.design_of("C9")


def test_integer_actuator_ids_become_text_and_frame_errors_name_rows():
    m = Measurements.from_frame(_frame(actuator_id=[7, 7, 8, 8, 7]))
    assert m.actuator_ids == ("7", "8")
    frame = _frame(cycle=[1, 1, 0, 1, 1])
    with pytest.raises(DatasetError, match=r"^lab: cycle: row 2: must be an integer >= 1"):
        Measurements.from_frame(frame, source="lab")
    frame.index = [10, 11, 12, 13, 14]
    with pytest.raises(DatasetError, match=r"^cycle: row 12: must be"):
        Measurements.from_frame(frame)
    with pytest.raises(DatasetError, match=r"^direction: row 1: .*'loading', 'unloading'"):
        Measurements.from_frame(_frame(direction=["loading", None, "loading", "loading", "x"]))
    with pytest.raises(DatasetError, match=r"^l: row 3: must be a finite number; got inf"):
        Measurements.from_frame(_frame(l=[100, 100, 120, np.inf, 100]))
    with pytest.raises(DatasetError, match=r"^angle_deg: row 4: .*a missing value"):
        Measurements.from_frame(_frame(angle_deg=[0, 1, 2, 3, np.nan]))
    with pytest.raises(DatasetError, match=r"missing required column\(s\) 'angle_deg'"):
        Measurements.from_frame(_frame(angle_deg=None))
    with pytest.raises(DatasetError, match="must be a pandas DataFrame"):
        Measurements.from_frame({"l": [1.0]})
    with pytest.raises(ValueError, match="metadata"):
        Measurements.from_frame(_frame(), metadata={"a:b": "c"})


# ----------------------------------------------------------------- bad files
ROW_A = f"{DESIGN_A},0.1,20"

BAD_FILES = [
    ("empty", "", ["has no column header"]),
    ("comments-only", "# rig: x\n\n# nothing else\n", ["has no column header"]),
    (
        "missing",
        "l,r,t,b,phi,lc,pressure_mpa\n1,2,3,4,5,6,7\n",
        [":1: angle_deg: lacks the column(s) angle_deg"],
    ),
    (
        "unknown",
        f"# rig: v\n{HEADER},temp_c\n{ROW_A},21\n",
        [":2:9: temp_c: has column(s) temp_c", "direction"],
    ),
    (
        "case",
        "L,r,t,b,phi,lc,pressure_mpa,angle_deg\n",
        [":1:1: L: lacks the column(s) l and has column(s) L", "case-sensitive"],
    ),
    ("duplicate", f"{HEADER},phi\n{ROW_A},5\n", [":1:9: phi:", "appears twice"]),
    ("cells", f"{HEADER}\n{ROW_A}\n{ROW_A},9\n", [":3: has 9 cells", "8 columns"]),
    ("no-rows", f"# operator: b\n{HEADER}\n\n", [":2: ", "0 data row(s)"]),
    ("text", f"{HEADER}\n{ROW_A}\n{DESIGN_A},high,1\n", [":3:7: pressure_mpa:", '"high"']),
    ("empty-cell", f"{HEADER}\n{DESIGN_A},,1\n", [":2:7: pressure_mpa:", "empty cell"]),
    ("nan", f"{HEADER}\n{ROW_A}\n{DESIGN_A},0.2,nan\n", [":3:8: angle_deg:", '"nan"']),
    ("inf", f"{HEADER}\n{ROW_A}\ninf,6,2,2,5,8,0.2,1\n", [":3:1: l:", "finite"]),
    ("negative", f"{HEADER}\n{DESIGN_A},-0.01,1\n", [":2:7: pressure_mpa:", ">= 0"]),
    (
        "design",
        f"# rig: v\n\n{HEADER}\n{ROW_A}\n100,6,2,2,61,8,0.1,1\n",
        [":5:5: phi: phi_deg must be"],
    ),
    (
        "cycle-zero",
        f"{HEADER},cycle\n{ROW_A},1\n{ROW_A},0\n",
        [":3:9: cycle:", "integer >= 1"],
    ),
    ("cycle-float", f"{HEADER},cycle\n{ROW_A},1.5\n", [":2:9: cycle:", '"1.5"']),
    (
        "direction",
        f"{HEADER},direction\n{ROW_A},Loading\n",
        [":2:9: direction:", "'loading', 'unloading'", '"Loading"'],
    ),
    (
        "two-designs",
        f"{HEADER},actuator_id\n{ROW_A},A1\n{DESIGN_B},0.1,20,A2\n{DESIGN_B},0.2,30,A1\n",
        [":4:9: actuator_id:", "'A1'", "line 2"],
    ),
    (
        "default-id-collision",
        f"{HEADER}\n{ROW_A}\n100.0000001,6,2,2,5,8,0.1,20\n",
        [":3: actuator_id:", "add an actuator_id column"],
    ),
    ("empty-id", f"{HEADER},actuator_id\n{ROW_A},\n", [":2:9: actuator_id:"]),
    ("metadata-twice", f"# rig: a\n# rig: b\n{HEADER}\n{ROW_A}\n", [":2: rig: is set twice"]),
]


@pytest.mark.parametrize(
    ("text", "expected"),
    [case[1:] for case in BAD_FILES],
    ids=[case[0] for case in BAD_FILES],
)
def test_bad_files_raise_one_line_naming_file_line_and_column(tmp_path, text, expected):
    path = _write(tmp_path / "bad_input.csv", text)
    with pytest.raises(DatasetError) as info:
        load_measurements(path)
    message = str(info.value)
    assert "\n" not in message
    assert message.startswith(str(path))
    assert "np." not in message  # values shown as Python literals
    for part in expected:
        assert part in message


def test_missing_folder_and_non_utf8_files(tmp_path):
    with pytest.raises(DatasetError, match=r"nowhere\.csv: no such file"):
        load_measurements(tmp_path / "nowhere.csv")
    with pytest.raises(DatasetError, match="is a folder"):
        load_measurements(tmp_path)
    latin = tmp_path / "latin1.csv"
    latin.write_bytes(f"# operator: J\xfcrgen\n{HEADER}\n{ROW_A}\n".encode("latin-1"))
    with pytest.raises(DatasetError, match=r"latin1\.csv is not UTF-8 text"):
        load_measurements(latin)


def test_save_rejects_other_objects(tmp_path):
    with pytest.raises(ValueError, match="Measurements object"):
        save_measurements(_frame(), tmp_path / "x.csv")
