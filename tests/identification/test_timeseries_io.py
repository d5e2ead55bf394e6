import numpy as np
import pytest

from softbend.errors import DatasetError
from softbend.identification.timeseries import Series, TimeSeriesSet
from softbend.identification.timeseries_io import (
    check_experiments_for_lags,
    check_holdout,
    check_signals,
    load_timeseries,
    save_timeseries,
)


def _series(name, n=200, seed=0, source=""):
    rng = np.random.default_rng(seed)
    time = np.cumsum(rng.uniform(0.001, 0.02, n))
    inputs = rng.normal(size=(n, 2)) * 10 ** rng.uniform(-8, 8, size=(n, 2))
    outputs = rng.normal(size=(n, 3))
    outputs[0, 0] = -0.0  # the sign of zero survives too
    return Series(name, time, inputs, outputs, source=source)


def _set(*names, n=200):
    experiments = tuple(_series(name, n, seed) for seed, name in enumerate(names))
    return TimeSeriesSet(("p1_kpa", "p2_kpa"), ("x_mm", "y_mm", "theta"), experiments, "t_s")


def _write(path, text):
    path.write_text(text, encoding="utf-8")
    return path


def _same_bits(a, b):
    return a.tobytes() == b.tobytes() and a.shape == b.shape


# ------------------------------------------------------------ TimeSeriesSet
def test_series_rejects_bad_shapes_nonfinite_and_non_increasing_time():
    with pytest.raises(ValueError, match="one row of inputs and outputs"):
        Series("a", [0.0, 1.0], [[1.0], [2.0], [3.0]], [1.0, 2.0])
    with pytest.raises(ValueError, match="inputs of experiment 'a' must be finite"):
        Series("a", [0.0, 1.0], [np.nan, 1.0], [1.0, 2.0])
    with pytest.raises(ValueError, match="must increase strictly"):
        Series("a", [0.0, 0.0], [1.0, 2.0], [1.0, 2.0])
    series = Series("a", [0.0, 1.0], [1.0, 2.0], [3.0, 4.0])
    assert series.inputs.shape == (2, 1) and series.n_samples == 2
    assert not series.time.flags.writeable


def test_set_subset_keeps_the_order_given_and_names_unknown_experiments():
    data = _set("a", "b", "c", n=20)
    assert data.subset(["c", "a"]).names == ("c", "a")
    assert data.subset(["c", "a"]).experiments[0] is data.experiments[2]
    with pytest.raises(ValueError, match=r"'zz'.*the experiments are a, b, c"):
        data.subset(["a", "zz"])


def test_set_stacked_concatenates_rows_with_their_experiment():
    data = _set("a", "b", n=20)
    U, Y, groups = data.stacked()
    assert U.shape == (40, 2) and Y.shape == (40, 3)
    np.testing.assert_array_equal(U[20:], data.experiments[1].inputs)
    np.testing.assert_array_equal(Y[:20], data.experiments[0].outputs)
    assert list(groups[:20]) == ["a"] * 20 and list(groups[20:]) == ["b"] * 20


def test_set_rejects_duplicate_names_and_wrong_widths():
    e = _series("a", 10)
    with pytest.raises(ValueError, match="unique names"):
        TimeSeriesSet(("u1", "u2"), ("y1", "y2", "y3"), (e, e))
    with pytest.raises(ValueError, match="must have 1 inputs and 3 outputs"):
        TimeSeriesSet(("u1",), ("y1", "y2", "y3"), (e,))


# --------------------------------------------------------------- round trip
def test_save_then_load_round_trips_bit_for_bit(tmp_path):
    data = _set("run-1", "run 2", "#3, odd", n=300)
    path = save_timeseries(data, tmp_path / "sub" / "set.csv")
    text = path.read_text(encoding="utf-8").splitlines()
    assert text[:4] == [
        "# softbend time series v1",
        "# time: t_s",
        "# inputs: p1_kpa,p2_kpa",
        "# outputs: x_mm,y_mm,theta",
    ]
    assert text[4] == "experiment,t_s,p1_kpa,p2_kpa,x_mm,y_mm,theta"
    back = load_timeseries(
        path, data.input_names, data.output_names, experiment="experiment", time="t_s"
    )
    assert back.names == data.names
    assert (back.input_names, back.output_names, back.time_name) == (
        data.input_names,
        data.output_names,
        "t_s",
    )
    for a, b in zip(data.experiments, back.experiments, strict=True):
        assert _same_bits(a.time, b.time)
        assert _same_bits(a.inputs, b.inputs)
        assert _same_bits(a.outputs, b.outputs)
        assert b.source == str(path)
    assert np.signbit(back.experiments[0].outputs[0, 0])


def test_save_without_time_column_round_trips_with_the_sample_column(tmp_path):
    _write(tmp_path / "raw.csv", "u,y\n1,2\n3,4\n5,6\n")
    data = load_timeseries(tmp_path / "raw.csv", ["u"], ["y"])
    assert data.time_name == "sample"
    np.testing.assert_array_equal(data.experiments[0].time, [0.0, 1.0, 2.0])
    path = save_timeseries(data, tmp_path / "out.csv")
    back = load_timeseries(path, ["u"], ["y"], experiment="experiment", time="sample")
    assert back.names == ("raw",)
    assert _same_bits(back.experiments[0].time, data.experiments[0].time)


def test_save_replaces_a_file_atomically_and_leaves_no_temporary(tmp_path):
    target = _write(tmp_path / "set.csv", "old\n")
    save_timeseries(_set("a", n=10), target)
    assert target.read_text(encoding="utf-8").startswith("# softbend time series v1")
    assert sorted(p.name for p in tmp_path.iterdir()) == ["set.csv"]


@pytest.mark.parametrize(
    ("inputs", "outputs", "time_name", "name", "match"),
    [
        (("u",), ("u",), "t", "a", "distinct names"),
        (("experiment",), ("y",), "t", "a", "distinct names"),
        (("u",), ("y",), "t", " a", "experiment name"),
        (("u",), ("y",), "t", "a\nb", "experiment name"),
        (("u ",), ("y",), "t", "a", "column name"),
    ],
)
def test_save_refuses_names_that_would_not_read_back(
    tmp_path, inputs, outputs, time_name, name, match
):
    data = TimeSeriesSet(inputs, outputs, (Series(name, [0.0], [1.0], [2.0]),), time_name)
    with pytest.raises(ValueError, match=match):
        save_timeseries(data, tmp_path / "x.csv")
    assert not (tmp_path / "x.csv").exists()


def test_save_refuses_a_folder_and_a_non_set(tmp_path):
    with pytest.raises(ValueError, match="must be a file"):
        save_timeseries(_set("a", n=5), tmp_path)
    with pytest.raises(ValueError, match="must be a TimeSeriesSet"):
        save_timeseries([1, 2], tmp_path / "x.csv")


# ------------------------------------------------------------------ reading
def test_a_folder_gives_one_experiment_per_file_in_sorted_order(tmp_path):
    _write(tmp_path / "b.csv", "# rig: 2\nt,u1,u2,y,extra\n0,1,2,3,x\n0.5,4,5,6,y\n")
    _write(tmp_path / "a.csv", "extra,y,u2,u1,t\nq,30,20,10,1\nr,60,50,40,2\ns,90,80,70,3\n")
    _write(tmp_path / "notes.txt", "not read\n")
    data = load_timeseries(tmp_path, ["u1", "u2"], "y", time="t")
    assert data.names == ("a", "b")
    assert data.time_name == "t"
    a, b = data.experiments
    np.testing.assert_array_equal(a.time, [1.0, 2.0, 3.0])
    np.testing.assert_array_equal(a.inputs, [[10, 20], [40, 50], [70, 80]])
    np.testing.assert_array_equal(a.outputs[:, 0], [30, 60, 90])
    np.testing.assert_array_equal(b.inputs, [[1, 2], [4, 5]])
    assert a.source == str(tmp_path / "a.csv") and b.source == str(tmp_path / "b.csv")


def test_an_experiment_column_splits_a_file_into_contiguous_runs(tmp_path):
    text = "run,t,u,y\n" + "".join(
        f"{run},{t},{10 * k + t},{-t}\n"
        for k, run in enumerate(["s1", "s2", "s0"])
        for t in range(4)
    )
    path = _write(tmp_path / "log.csv", text)
    data = load_timeseries(path, ["u"], ["y"], experiment="run", time="t")
    assert data.names == ("s1", "s2", "s0")  # file order, not sorted
    for k, e in enumerate(data.experiments):
        np.testing.assert_array_equal(e.time, [0, 1, 2, 3])  # time restarts per experiment
        np.testing.assert_array_equal(e.inputs[:, 0], 10 * k + np.arange(4))
    without_time = load_timeseries(path, ["u"], ["y"], experiment="run")
    np.testing.assert_array_equal(without_time.experiments[2].time, [0, 1, 2, 3])


def test_comment_and_blank_lines_are_skipped_but_counted(tmp_path):
    path = _write(tmp_path / "c.csv", "# a: 1\n\n# b: 2\nt,u,y\n0,1,2\n# note\n1,1,2\n2,x,2\n")
    with pytest.raises(DatasetError, match=r'c\.csv:8:2: u: must be a finite number; got "x"'):
        load_timeseries(path, ["u"], ["y"], time="t")


# ------------------------------------------------------------------- errors
GOOD = "t,u,y\n0,1,2\n1,3,4\n2,5,6\n"


def test_missing_column_lists_the_files_columns(tmp_path):
    path = _write(tmp_path / "m.csv", "# c\nt,u,y\n0,1,2\n")
    with pytest.raises(
        DatasetError, match=r"m\.csv:2: v: lacks the column\(s\) v; .*the file has t, u, y"
    ):
        load_timeseries(path, ["u", "v"], ["y"], time="t")
    with pytest.raises(DatasetError, match=r"lacks the column.*time_s"):
        load_timeseries(path, ["u"], ["y"], time="time_s")


def test_a_later_file_missing_a_column_of_the_first_names_both(tmp_path):
    _write(tmp_path / "a.csv", GOOD)
    _write(tmp_path / "b.csv", "t,u,z\n0,1,2\n")
    with pytest.raises(
        DatasetError, match=r"b\.csv:1: y: lacks the column\(s\) y.*first file .*a\.csv"
    ):
        load_timeseries(tmp_path, ["u"], ["y"], time="t")


@pytest.mark.parametrize(
    ("row", "reason"),
    [
        ("1,abc,4", 'must be a finite number; got "abc"'),
        ("1,nan,4", 'must be a finite number; got "nan"'),
        ("1,-inf,4", 'must be a finite number; got "-inf"'),
        ("1,,4", "must be a finite number; got an empty cell"),
    ],
)
def test_bad_values_name_file_line_and_column(tmp_path, row, reason):
    path = _write(tmp_path / "v.csv", f"# x\nt,u,y\n0,1,2\n{row}\n")
    with pytest.raises(DatasetError, match=rf"v\.csv:4:2: u: {reason}"):
        load_timeseries(path, ["u"], ["y"], time="t")


def test_the_first_bad_line_is_reported_whatever_its_column(tmp_path):
    path = _write(tmp_path / "v.csv", "t,u,y\n0,1,2\n1,2,bad\n2,bad,4\n")
    with pytest.raises(DatasetError, match=r":3:3: y: "):
        load_timeseries(path, ["u"], ["y"], time="t")
    path = _write(tmp_path / "w.csv", "t,u,y\n0,1,2\n1,2,nan\n2,oops,4\n")
    with pytest.raises(DatasetError, match=r":3:3: y: "):
        load_timeseries(path, ["u"], ["y"], time="t")


def test_time_not_increasing_names_line_and_column(tmp_path):
    path = _write(tmp_path / "t.csv", "e,t,u,y\nA,0,1,2\nA,1,1,2\nB,0,1,2\nB,0.5,1,2\nB,0.5,1,2\n")
    with pytest.raises(DatasetError, match=r"t\.csv:6:2: t: 0\.5 does not increase.*'B'"):
        load_timeseries(path, ["u"], ["y"], experiment="e", time="t")


def test_an_experiment_that_reappears_is_refused(tmp_path):
    path = _write(tmp_path / "r.csv", "e,u,y\nA,1,2\nA,1,2\nB,1,2\nA,1,2\n")
    with pytest.raises(
        DatasetError, match=r"r\.csv:5:1: e: experiment 'A' appears again after 'B'"
    ):
        load_timeseries(path, ["u"], ["y"], experiment="e")


def test_an_empty_experiment_name_is_refused(tmp_path):
    path = _write(tmp_path / "n.csv", "e,u,y\nA,1,2\n,1,2\n")
    with pytest.raises(
        DatasetError, match=r"n\.csv:3:1: e: must be non-empty text; got an empty cell"
    ):
        load_timeseries(path, ["u"], ["y"], experiment="e")


@pytest.mark.parametrize(
    ("text", "match"),
    [
        ("", "has no column header"),
        ("# only a comment\n\n", "has no column header"),
        ("t,u,y\n", "followed by 0 data row"),
    ],
)
def test_an_empty_file_is_refused(tmp_path, text, match):
    path = _write(tmp_path / "e.csv", text)
    with pytest.raises(DatasetError, match=rf"e\.csv.*{match}"):
        load_timeseries(path, ["u"], ["y"], time="t")


def test_a_folder_without_csv_and_a_missing_path_are_refused(tmp_path):
    _write(tmp_path / "readme.txt", "x")
    with pytest.raises(DatasetError, match="no CSV files"):
        load_timeseries(tmp_path, ["u"], ["y"])
    with pytest.raises(DatasetError, match="not found"):
        load_timeseries(tmp_path / "nope.csv", ["u"], ["y"])


def test_a_ragged_line_and_a_repeated_column_are_refused(tmp_path):
    path = _write(tmp_path / "g.csv", "t,u,y\n0,1,2\n1,2\n")
    with pytest.raises(
        DatasetError, match=r"g\.csv:3: has 2 cells, but the header \(line 1\) has 3 columns"
    ):
        load_timeseries(path, ["u"], ["y"], time="t")
    path = _write(tmp_path / "d.csv", "t,u,u,y\n0,1,1,2\n")
    with pytest.raises(DatasetError, match=r"d\.csv:1:3: u: appears twice in the column header"):
        load_timeseries(path, ["u"], ["y"], time="t")


def test_the_same_experiment_name_in_two_files_is_refused(tmp_path):
    _write(tmp_path / "a.csv", "e,u,y\nX,1,2\n")
    _write(tmp_path / "b.csv", "e,u,y\nX,1,2\n")
    with pytest.raises(
        DatasetError, match=r"b\.csv: experiment 'X' was already read from .*a\.csv"
    ):
        load_timeseries(tmp_path, ["u"], ["y"], experiment="e")


@pytest.mark.parametrize(
    ("kwargs", "match"),
    [
        ({"inputs": [], "outputs": ["y"]}, "^inputs: must be one or more"),
        ({"inputs": ["u"], "outputs": []}, "^outputs: must be one or more"),
        ({"inputs": ["u", "u"], "outputs": ["y"]}, "^inputs: must name distinct"),
        ({"inputs": ["u"], "outputs": ["y", "u"]}, "^outputs: .*already in 'inputs'"),
        ({"inputs": ["u"], "outputs": ["y"], "time": "u"}, "^time: .*already in 'inputs'"),
        ({"inputs": ["u"], "outputs": ["y"], "experiment": ""}, "^experiment: must be"),
    ],
)
def test_bad_column_arguments_are_refused_before_reading(tmp_path, kwargs, match):
    path = _write(tmp_path / "ok.csv", GOOD)
    with pytest.raises(ValueError, match=match):
        load_timeseries(path, **kwargs)


def test_a_single_name_is_one_column(tmp_path):
    path = _write(tmp_path / "ok.csv", GOOD)
    data = load_timeseries(path, "u", "y", time="t")
    assert data.input_names == ("u",) and data.output_names == ("y",)


# ------------------------------------------------------------------- checks
def test_check_experiments_for_lags_names_the_short_experiment_and_its_file(tmp_path):
    data = TimeSeriesSet(
        ("u",),
        ("y",),
        (
            Series("long", np.arange(10.0), np.zeros(10), np.zeros(10), source="a.csv"),
            Series("short", np.arange(3.0), np.zeros(3), np.zeros(3), source="b.csv"),
        ),
    )
    check_experiments_for_lags(data, 2)  # 3 samples: one regressor row
    with pytest.raises(DatasetError, match=r"'short' \(b\.csv\) has 3 sample\(s\).*at least 4"):
        check_experiments_for_lags(data, 3)
    with pytest.raises(ValueError, match=r"^max_lag: must be an integer"):
        check_experiments_for_lags(data, -1)


def test_check_holdout():
    data = _set("a", "b", "c", n=5)
    check_holdout(data, None)
    check_holdout(data, ["b"])
    check_holdout(data, "c")
    with pytest.raises(ValueError, match=r"'zz'.*\(a, b, c\)|\(a, b, c\).*'zz'"):
        check_holdout(data, ["a", "zz"])
    with pytest.raises(ValueError, match="at least 2 of the 3 experiments to train on"):
        check_holdout(data, ["a", "b", "c"])
    with pytest.raises(ValueError, match="at least one experiment, or be None"):
        check_holdout(data, [])
    with pytest.raises(ValueError, match="nothing to hold out"):
        check_holdout(data.subset(["a"]), None)
    with pytest.raises(ValueError, match="at least 2 of the 1 experiments to train"):
        check_holdout(data.subset(["a"]), ["a"])


def test_check_holdout_refuses_a_repeated_name_and_a_single_training_experiment():
    data = _set("a", "b", "c", n=5)
    with pytest.raises(ValueError, match=r"^validate_on: must name each experiment once; "
                       r"got 'a' more than once$"):  # fmt: skip
        check_holdout(data, ["a", "a"])
    # selecting holds one training experiment out at a time: one left is too few
    with pytest.raises(ValueError, match=r"^validate_on: must leave at least 2 .*leaves 'c'"):
        check_holdout(data, ["a", "b"])


def _one_output(*columns, inputs=None):
    """A set of one output column per experiment (``columns``), inputs random by default."""
    experiments = []
    for k, column in enumerate(columns):
        values = np.asarray(column, dtype=float)
        u = np.arange(values.size, dtype=float) if inputs is None else inputs
        experiments.append(Series(f"e{k}", np.arange(values.size), u, values, source=f"f{k}.csv"))
    return TimeSeriesSet(("u",), ("y",), tuple(experiments))


def test_check_signals_refuses_a_constant_output_naming_the_column():
    check_signals(_one_output([1, 2, 3], [1, 1, 1]))  # constant in one experiment only: fine
    with pytest.raises(DatasetError, match=r"output column 'y' is constant .*every sample 3\.0"):
        check_signals(_one_output([3, 3, 3], [3, 3, 3]))
    # constant over the training experiments: the validation one does not count
    with pytest.raises(DatasetError, match="'y' is constant over the training experiments"):
        check_signals(_one_output([3, 3, 3], [3, 3, 3], [1, 2, 3]), ["e2"])
    with pytest.raises(DatasetError, match=r"'y' varies by only 1e-200"):
        check_signals(_one_output([0, 1e-200, 0], [0, 0, 0]))


def test_check_signals_refuses_a_constant_input_naming_the_column():
    check_signals(_one_output([1, 2, 3], [3, 2, 1]))  # a varying input: fine
    with pytest.raises(DatasetError, match=r"input column 'u' is constant .*every sample 5\.0.*"
                       r"gain or time constant"):  # fmt: skip
        check_signals(_one_output([1, 2, 3], [3, 2, 1], inputs=np.array([5.0, 5.0, 5.0])))


@pytest.mark.parametrize("kind", ["input", "output"])
@pytest.mark.parametrize(
    ("relative", "refused"), [(5e-10, True), (9e-10, True), (1.1e-9, False), (1e-6, False)]
)
def test_check_signals_near_constant_is_a_range_within_1e_9_of_the_magnitude(
    kind, relative, refused
):
    """101.325 up to rounding is refused; a range just above 1e-9 of it is a signal."""
    wobble = 101.325 * (1 + relative * np.array([0.0, 1.0, 0.5, 0.0, 1.0]))
    varying = np.array([0.0, 1.0, 2.0, 1.0, 0.0])
    if kind == "input":
        data = _one_output(varying, varying, inputs=wobble)
    else:
        data = _one_output(wobble, wobble, inputs=varying)
    if refused:
        with pytest.raises(DatasetError, match=rf"The {kind} column '[uy]' is near-constant "
                           r"over the training experiments: it varies by only .* around "
                           r"101\.325.*leave it out"):  # fmt: skip
            check_signals(data)
    else:
        check_signals(data)


def test_check_signals_refuses_values_whose_squares_overflow():
    with pytest.raises(DatasetError, match=r"output column 'y' of experiment 'e1' \(f1\.csv\) "
                       r"holds 1e\+301 at sample 2.*within ±1e\+50"):  # fmt: skip
        check_signals(_one_output([1, 2, 3], [1, 2, 1e301]))
    with pytest.raises(DatasetError, match=r"input column 'u' of experiment 'e0'.*-1e\+200"):
        check_signals(_one_output([1, 2, 3], [1, 2, 3], inputs=np.array([0.0, -1e200, 1.0])))
    check_signals(_one_output([1, 2, 1e50], [-1e50, 0, 1]))  # the bound itself is accepted
