import os

import numpy as np
import pytest

from softbend.errors import DatasetError, LimitError
from softbend.identification.data import (
    REQUIRED_COLUMNS,
    Experiment,
    load_experiments,
    save_experiments,
)
from softbend.kinematics import tip_position


def _experiment(name="exp-a", n=8, rho_peak=0.3, length_mm=16.0, **kwargs):
    time = 0.02 * np.arange(n)
    rho = np.linspace(0.0, rho_peak, n)
    x, y = tip_position(rho, np.full(n, length_mm))
    pressure = np.linspace(0.0, 80.0 if rho_peak >= 0 else -60.0, n)
    return Experiment(name, time, pressure, x, y, **kwargs)


def _write(path, text):
    path.write_text(text, encoding="utf-8")
    return path


GOOD = "time_s,pressure_kpa,x_mm,y_mm\n0,0,0,0\n0.02,10,0.5,0.1\n0.04,20,1.0,0.3\n"


# ---------------------------------------------------------------- Experiment
def test_bending_and_length_come_from_the_tip_by_constant_curvature():
    rho = np.array([0.0, 0.1, 0.25, 0.45, -0.3])
    length = np.array([15.25, 16.0, 17.0, 18.25, 9.25])
    x, y = tip_position(rho, length)
    exp = Experiment("k", np.arange(5.0), np.array([0, 10, 40, 100, -80.0]), x, y)
    np.testing.assert_allclose(exp.rho, rho, atol=1e-12)
    np.testing.assert_allclose(exp.length_mm, length, rtol=1e-12)
    assert exp.n_samples == 5
    assert exp.dt_s == 1.0


def test_sign_follows_the_pressure_of_largest_magnitude():
    assert _experiment(rho_peak=0.3).sign == "positive"
    assert _experiment(rho_peak=-0.2).sign == "negative"
    mixed = Experiment("m", [0, 1, 2.0], [5.0, -40.0, 30.0], [0, 0, 0.0], [0, 0, 0.0])
    assert mixed.sign == "negative"


def test_dt_is_the_median_step():
    exp = Experiment("d", [0, 0.02, 0.04, 0.07, 0.09], [0.0] * 5, [0.0] * 5, [0.0] * 5)
    assert exp.dt_s == pytest.approx(0.02)


def test_arrays_are_read_only_copies_and_frame_has_every_column():
    x = np.zeros(4)
    exp = Experiment("f", np.arange(4.0), np.zeros(4), x, np.zeros(4))
    x[0] = 99.0
    assert exp.x_mm[0] == 0.0
    with pytest.raises(ValueError):
        exp.x_mm[0] = 1.0
    frame = exp.to_frame()
    assert list(frame.columns) == [
        "experiment",
        "time_s",
        "pressure_kpa",
        "x_mm",
        "y_mm",
        "rho",
        "length_mm",
    ]
    assert (frame["experiment"] == "f").all()
    np.testing.assert_array_equal(frame["length_mm"], 15.25)


@pytest.mark.parametrize(
    ("kwargs", "pattern"),
    [
        ({"x_mm": np.zeros(3)}, "equal lengths.*x_mm: 3"),
        ({"n": 2}, "at least 3 samples"),
        ({"y_mm": np.array([0, 0, np.nan, 0, 0])}, "'y_mm'.*finite.*nan at sample 2"),
        ({"pressure_kpa": np.array([0, 1, 2, np.inf, 4])}, "'pressure_kpa'.*inf at sample 3"),
        (
            {"time_s": np.array([0, 1, 1, 2, 3.0])},
            r"time_s: 1.0 does not increase after 1.0 \(sample 1\).*'bad'.*increase strictly",
        ),
        ({"time_s": np.zeros((5, 1))}, "'time_s'.*1-D"),
    ],
)
def test_experiment_rejects_bad_columns(kwargs, pattern):
    n = kwargs.pop("n", 5)
    columns = {c: np.arange(float(n)) * (c == "time_s") for c in REQUIRED_COLUMNS}
    columns.update(kwargs)
    with pytest.raises(DatasetError, match=pattern):
        Experiment("bad", **columns)


def test_experiment_rejects_empty_name_and_bad_rest_length():
    with pytest.raises(ValueError, match="'name' of Experiment"):
        Experiment(" ", [0, 1, 2.0], [0.0] * 3, [0.0] * 3, [0.0] * 3)
    with pytest.raises(ValueError, match=r"rest_length_mm: must be a number in \(0, inf\)"):
        Experiment("r", [0, 1, 2.0], [0.0] * 3, [0.0] * 3, [0.0] * 3, rest_length_mm=-1)


# ------------------------------------------------------------------ round trip
def test_csv_round_trip_is_exact(tmp_path):
    rng = np.random.default_rng(5)
    originals = [
        _experiment("pos", n=40, metadata={"operator": "lab 2", "run": 3}),
        _experiment(
            "neg",
            n=30,
            rho_peak=-0.25,
            length_mm=11.0,
            synthetic=True,
            metadata={"label": "SYNTHETIC DATA test", "seed": 7, "gains": [1.5, 2.0]},
        ),
        Experiment(
            "noisy",
            np.cumsum(rng.uniform(0.01, 0.03, 50)),
            rng.normal(0, 50, 50),
            rng.normal(0, 3, 50),
            rng.normal(0, 3, 50) - 1e-17,
            rest_length_mm=20.5,
        ),
    ]
    paths = save_experiments(originals, tmp_path / "out")
    assert [p.name for p in paths] == ["pos.csv", "neg.csv", "noisy.csv"]
    loaded = load_experiments(tmp_path / "out")
    by_name = {e.name: e for e in loaded}
    assert [e.name for e in loaded] == ["neg", "noisy", "pos"]  # sorted file order
    for original in originals:
        again = by_name[original.name]
        assert again == original
        for column in REQUIRED_COLUMNS:
            assert np.array_equal(getattr(again, column), getattr(original, column))
        assert again.rest_length_mm == original.rest_length_mm
        assert again.synthetic == original.synthetic
        assert again.metadata == original.metadata
    # Nothing but the CSV files is left behind (the temporary files were moved into place).
    assert sorted(os.listdir(tmp_path / "out")) == ["neg.csv", "noisy.csv", "pos.csv"]


def test_synthetic_files_say_so_in_the_header(tmp_path):
    (path,) = save_experiments(
        _experiment("s", synthetic=True, metadata={"label": "SYNTHETIC DATA x"}), tmp_path
    )
    header = [line for line in path.read_text().splitlines() if line.startswith("#")]
    assert "# synthetic: true" in header
    assert any("SYNTHETIC DATA" in line for line in header)
    (real,) = save_experiments(_experiment("r"), tmp_path)
    assert "# synthetic: false" in real.read_text()
    assert "SYNTHETIC" not in real.read_text()


def test_unsafe_names_are_kept_in_an_experiment_column(tmp_path):
    original = _experiment("run 1/a")
    (path,) = save_experiments([original], tmp_path)
    assert path.name == "run_1_a.csv"
    (loaded,) = load_experiments(path)
    assert loaded == original


def test_saving_two_names_to_one_file_is_refused(tmp_path):
    with pytest.raises(ValueError, match="distinct file names"):
        save_experiments([_experiment("a b"), _experiment("a_b")], tmp_path)


def test_saving_over_a_file_is_refused(tmp_path):
    target = _write(tmp_path / "x.csv", GOOD)
    with pytest.raises(ValueError, match="must be a folder"):
        save_experiments([_experiment()], target)


# ---------------------------------------------------------------------- loading
def test_file_stem_names_a_single_experiment_and_extra_columns_are_ignored(tmp_path):
    text = "# a comment\ntime_s,temperature_c,pressure_kpa,x_mm,y_mm\n"
    text += "0,21,0,0,0\n0.02,21,10,0.5,0.1\n# mid comment\n\n0.04,22,20,1.0,0.3\n"
    (exp,) = load_experiments(_write(tmp_path / "trial7.csv", text))
    assert exp.name == "trial7"
    assert not exp.synthetic
    assert exp.rest_length_mm == 15.25
    np.testing.assert_array_equal(exp.pressure_kpa, [0, 10, 20])
    np.testing.assert_array_equal(exp.y_mm, [0, 0.1, 0.3])


def test_experiment_column_splits_one_file(tmp_path):
    text = "experiment,time_s,pressure_kpa,x_mm,y_mm\n"
    for name in ("b", "a"):
        for k in range(4):
            text += f"{name},{0.02 * k},{5 * k},{0.1 * k},0\n"
    experiments = load_experiments(_write(tmp_path / "many.csv", text), rest_length_mm=14.0)
    assert [e.name for e in experiments] == ["b", "a"]
    assert all(e.n_samples == 4 and e.rest_length_mm == 14.0 for e in experiments)


def _error(path) -> str:
    with pytest.raises(DatasetError) as info:
        load_experiments(path)
    message = str(info.value)
    assert "\n" not in message
    return message


def test_missing_path(tmp_path):
    message = _error(tmp_path / "nope.csv")
    assert "not found" in message and "nope.csv" in message


def test_folder_without_csv(tmp_path):
    _write(tmp_path / "notes.txt", "nothing")
    assert "no CSV files" in _error(tmp_path)


def test_empty_file(tmp_path):
    assert "has no column header" in _error(_write(tmp_path / "e.csv", ""))
    message = _error(_write(tmp_path / "c.csv", "# only comments\n\n"))
    assert "has no column header" in message and "time_s, pressure_kpa, x_mm, y_mm" in message


def test_header_without_rows(tmp_path):
    assert "followed by 0 data row(s)" in _error(
        _write(tmp_path / "h.csv", "time_s,pressure_kpa,x_mm,y_mm\n")
    )


def test_missing_columns_are_named_with_the_required_list(tmp_path):
    message = _error(_write(tmp_path / "m.csv", "time_s,pressure,x_mm\n0,0,0\n"))
    assert "m.csv:1: pressure_kpa: lacks the column(s) pressure_kpa, y_mm" in message
    assert "has the columns time_s, pressure_kpa, x_mm, y_mm" in message


def test_non_numeric_value_names_column_and_row(tmp_path):
    text = "# header comment\n" + GOOD.replace("0.02,10,0.5", "0.02,ten,0.5")
    message = _error(_write(tmp_path / "n.csv", text))
    assert 'n.csv:4:2: pressure_kpa: must be a finite number; got "ten"' in message


@pytest.mark.parametrize("cell", ["", "nan", "NaN"])
def test_missing_value_names_column_and_row(tmp_path, cell):
    text = GOOD.replace("0.04,20,1.0,0.3", f"0.04,20,{cell},0.3")
    message = _error(_write(tmp_path / "v.csv", text))
    assert "v.csv:4:3: x_mm: must be a finite number; got " in message


def test_infinite_value_is_refused(tmp_path):
    message = _error(_write(tmp_path / "i.csv", GOOD.replace("0.1\n", "inf\n")))
    assert 'i.csv:3:4: y_mm: must be a finite number; got "inf"' in message


def test_ragged_row(tmp_path):
    message = _error(_write(tmp_path / "r.csv", GOOD + "0.06,1,2\n"))
    assert "r.csv:5: has 3 cells" in message


def test_non_increasing_time_names_experiment_and_row(tmp_path):
    text = "experiment,time_s,pressure_kpa,x_mm,y_mm\n"
    text += "a,0,0,0,0\nb,0,0,0,0\na,0.02,1,0,0\nb,0.02,1,0,0\na,0.02,2,0,0\n"
    message = _error(_write(tmp_path / "t.csv", text))
    assert "t.csv:6:2: time_s: 0.02 does not increase after 0.02 (line 4)" in message
    assert "experiment 'a'" in message
    assert "increase strictly" in message


def test_too_few_samples_in_an_experiment(tmp_path):
    message = _error(
        _write(tmp_path / "s.csv", "time_s,pressure_kpa,x_mm,y_mm\n0,0,0,0\n1,0,0,0\n")
    )
    assert "2 sample(s)" in message and "at least 3" in message


def test_duplicate_names_across_files(tmp_path):
    text = "experiment,time_s,pressure_kpa,x_mm,y_mm\n" + "".join(
        f"same,{k},0,0,0\n" for k in range(3)
    )
    _write(tmp_path / "a.csv", text)
    _write(tmp_path / "b.csv", text)
    message = _error(tmp_path)
    assert "'same'" in message and "unique" in message


def test_bad_header_comment(tmp_path):
    message = _error(_write(tmp_path / "h.csv", "# rest_length_mm: long\n" + GOOD))
    assert "h.csv:1: rest_length_mm: must be a positive number (mm); got 'long'" in message


def test_unreachable_tip_is_a_dataset_error(tmp_path):
    # On the rest axis above the base: no arc of positive length ends there.
    message = _error(_write(tmp_path / "u.csv", GOOD.replace("0,0,0,0\n", "0,0,0,20\n")))
    assert "u.csv:2:3: x_mm: the tip" in message and "y_mm=20.0" in message


def test_bad_rest_length_argument(tmp_path):
    with pytest.raises(ValueError, match=r"rest_length_mm: must be a number in \(0, inf\)"):
        load_experiments(_write(tmp_path / "g.csv", GOOD), rest_length_mm=0.0)


def test_saved_experiment_files_get_the_mode_of_a_plain_write(tmp_path):
    import os

    from softbend.identification.data import load_experiments, save_experiments

    source = tmp_path / "a"
    source.mkdir()
    (source / "e1.csv").write_text(
        "time_s,pressure_kpa,x_mm,y_mm\n0,0,0.5,15.2\n0.02,1,1.0,15.1\n0.04,2,1.5,15.0\n"
    )
    old = os.umask(0o022)
    try:
        paths = save_experiments(load_experiments(source, rest_length_mm=15.25), tmp_path / "out")
    finally:
        os.umask(old)
    assert all(oct(p.stat().st_mode & 0o777) == oct(0o644) for p in paths)


# --- The experiment CSV reader refuses oversized files and absurd values, naming where ---


HEADER = "time_s,pressure_kpa,x_mm,y_mm\n"
GOOD_ROWS = ["0,0,0,0", "0.02,10,0.5,0.1", "0.04,20,1.0,0.3", "0.06,30,1.2,0.4"]


def _write_big(path, rows, *, comments=""):
    path.write_text(comments + HEADER + "\n".join(rows) + "\n", encoding="utf-8")
    return path


def test_a_file_over_the_size_limit_is_refused_before_it_is_read(tmp_path, monkeypatch):
    from softbend.identification.data import experiment_files

    monkeypatch.setenv("SOFTBEND_MAX_FILE_MIB", "1")
    rows = [f"{0.02 * k:.2f},{k % 50},0.5,0.1" for k in range(80_000)]  # about 1.5 MiB
    path = _write_big(tmp_path / "big.csv", rows)
    with pytest.raises(LimitError) as info:
        load_experiments(path)
    message = str(info.value)
    assert str(path) in message and "SOFTBEND_MAX_FILE_MIB" in message and "MiB" in message
    with pytest.raises(LimitError, match="SOFTBEND_MAX_FILE_MIB"):
        experiment_files(tmp_path)  # a folder: each file is checked


def test_more_rows_than_the_limit_are_refused_before_any_row_is_parsed(tmp_path, monkeypatch):
    monkeypatch.setenv("SOFTBEND_MAX_CSV_ROWS", "5")
    rows = [*GOOD_ROWS, "0.08,not a number,1,1", "0.10,40,1.4,0.5"]  # 6 rows, one broken
    path = _write_big(tmp_path / "rows.csv", rows, comments="# rest_length_mm: 15.25\n")
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
    path = _write_big(tmp_path / "absurd.csv", [*GOOD_ROWS, row], comments="# comment\n")
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
        load_experiments(_write_big(tmp_path / "two.csv", rows))
    rows = [*GOOD_ROWS[:2], "0.04,5000,1,0.3", "1e300,30,1.2,0.4"]
    with pytest.raises(DatasetError, match=r"three.csv:4:2: pressure_kpa: "):
        load_experiments(_write_big(tmp_path / "three.csv", rows))


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
    path = _write_big(tmp_path / "rest.csv", GOOD_ROWS, comments=f"# rest_length_mm: {value}\n")
    with pytest.raises(DatasetError) as info:
        load_experiments(path)
    assert str(path) in str(info.value) and needle in str(info.value)


def test_a_deeply_nested_metadata_comment_is_a_limit_not_a_recursion_error(tmp_path):
    nested = "[" * 100_000 + "]" * 100_000
    path = _write_big(tmp_path / "deep.csv", GOOD_ROWS, comments=f"# metadata: {nested}\n")
    with pytest.raises(LimitError) as info:
        load_experiments(path)
    message = str(info.value)
    assert f"{path}:1: metadata: the value is" in message and "SOFTBEND_MAX_NESTING" in message


def test_a_field_too_long_for_the_csv_module_is_one_dataset_error(tmp_path):
    rows = [*GOOD_ROWS, "0.08,40,1.4," + "1" * 200_000]
    path = _write_big(tmp_path / "field.csv", rows)
    with pytest.raises(DatasetError, match=rf"{path.name}:6: not a CSV row"):
        load_experiments(path)


def test_plausible_files_still_load_to_the_same_numbers(tmp_path):
    rows = [*GOOD_ROWS, "0.08,-101.3,1.4,0.5", "0.10,2000,1.6,0.6"]
    (experiment,) = load_experiments(_write_big(tmp_path / "ok.csv", rows))
    assert experiment.pressure_kpa.tolist() == [0.0, 10.0, 20.0, 30.0, -101.3, 2000.0]
    assert experiment.time_s[-1] == 0.10
