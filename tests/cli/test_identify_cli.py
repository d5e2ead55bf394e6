"""softbend identify: any time series to a model chosen by its held-out free run."""

from __future__ import annotations

import csv
import json
import re

import numpy as np
import pytest

from softbend.cli import main
from softbend.identification.arm import arm_experiments
from softbend.identification.data import save_experiments
from softbend.identification.multi import load_multi_narx
from softbend.identification.synthetic import synthetic_dataset
from softbend.identification.timeseries import Series, TimeSeriesSet
from softbend.identification.timeseries_io import save_timeseries

from .conftest import one_error_line

ARGS = ["--inputs", "p1_kpa,p2_kpa,p3_kpa", "--outputs", "x_mm,y_mm",
        "--experiment", "experiment", "--time", "time_s"]  # fmt: skip


@pytest.fixture(scope="module")
def recording(tmp_path_factory):
    data = arm_experiments(n_train=4, n_validate=2, duration_s=15.0, seed=2)
    return save_timeseries(data, tmp_path_factory.mktemp("arm") / "arm.csv"), data


def test_identify_writes_the_selection_the_model_and_the_held_out_runs(recording, tmp_path, capsys):
    path, data = recording
    validation = [n for n in data.names if n.startswith("val")]
    out = tmp_path / "model"
    args = ["identify", str(path), *ARGS, "--validate-on", ",".join(validation), "--folds", "2",
            "--out", str(out), "--json"]  # fmt: skip
    assert main(args) == 0
    payload = json.loads(capsys.readouterr().out)
    assert payload["validation"] == validation and len(payload["train"]) == 4
    families = {row["family"] for row in payload["table"]}
    assert families == {"arx", "poly2", "gg-svr", "poly2-sim", "nn-sim"}
    assert payload["best"] in {row["candidate"] for row in payload["table"]}
    with open(out / "holdout_freerun.csv", encoding="utf-8") as handle:
        rows = list(csv.DictReader(handle))
    ends = ("measured", "simulated", "low", "high")
    columns = [f"{name}_{end}" for name in ("x_mm", "y_mm") for end in ends]
    assert list(rows[0]) == ["experiment", "time_s", *columns]
    assert {r["experiment"] for r in rows} == set(validation)
    # the 90 % band: the free run plus the CV residuals' 5 % and 95 % quantiles, no width
    # over the initial conditions, its coverage the measured samples inside it
    band, lag = payload["band"], load_multi_narx(out / "model.json")[0].max_lag
    assert band["level"] == 0.9 and band["coverage_on"] == "validation experiments"
    given = np.array([r["experiment"] != rows[max(i - lag, 0)]["experiment"] or i < lag
                      for i, r in enumerate(rows)])  # fmt: skip
    assert band["coverage_samples"] == len(rows) - given.sum() == len(rows) - lag * len(validation)
    for j, name in enumerate(("x_mm", "y_mm")):
        low, high, simulated, measured = (
            np.array([float(r[f"{name}_{end}"]) for r in rows])
            for end in ("low", "high", "simulated", "measured")
        )
        np.testing.assert_allclose(low[~given] - simulated[~given], band["low"][j], atol=1e-9)
        np.testing.assert_allclose(high[~given] - simulated[~given], band["high"][j], atol=1e-9)
        np.testing.assert_array_equal(high[given], low[given])
        inside = (measured >= low) & (measured <= high)
        assert inside[~given].mean() == pytest.approx(band["coverage"][j])
    assert payload["peak_memory_mib"] > 0 and payload["total_seconds"] >= payload["seconds"]
    model, metadata = load_multi_narx(out / "model.json")
    assert metadata["inputs"] == ["p1_kpa", "p2_kpa", "p3_kpa"] and model.n_outputs_ == 2
    # the chosen model read physically: one step reading per (input, output) pair
    pairs = {(r["input"], r["output"]) for r in payload["dynamics"]}
    assert pairs == {(p, o) for p in ("p1_kpa", "p2_kpa", "p3_kpa") for o in ("x_mm", "y_mm")}
    assert {r["gain_unit"] for r in payload["dynamics"]} == {"mm/kPa"}
    assert metadata["dynamics"] == payload["dynamics"] and metadata["time_unit_s"] == 1.0
    assert metadata["band"] == payload["band"]
    assert metadata["sample_period"] == pytest.approx(np.median(np.diff(data.experiments[0].time)))
    for name in ("selection.csv", "selection.png", "freerun.png"):
        assert (out / name).is_file()


def test_without_validation_the_band_is_checked_fold_by_fold_and_drawn(
    recording, tmp_path, capsys, monkeypatch
):
    from softbend.identification import selection as selection_module
    from softbend.reports import identify_figures

    every = selection_module.default_candidates
    monkeypatch.setattr(  # the linear ARX models only: the band, not the search, is tested here
        selection_module,
        "default_candidates",
        lambda seed=0, **kw: [c for c in every(seed) if c.family == "arx"],
    )
    drawn = {}
    overlays = identify_figures.freerun_overlays

    def spy(data, outputs, path, **kwargs):
        drawn.update(kwargs, outputs=outputs)
        return overlays(data, outputs, path, **kwargs)

    monkeypatch.setattr(identify_figures, "freerun_overlays", spy)
    path, data = recording
    out = tmp_path / "model"
    assert main(["identify", str(path), *ARGS, "--folds", "3", "--out", str(out)]) == 0
    text = capsys.readouterr().out
    said = re.search(r"90 % free-run band covers (\d+) % of held-out samples "
                     r"\(cross-validation folds; x_mm (\d+) %, y_mm (\d+) %", text)  # fmt: skip
    assert said is not None, text
    record = json.loads((out / "selection.json").read_text())
    band = record["band"]
    assert band["coverage_on"] == "cross-validation folds"
    assert int(said[1]) == round(100 * band["coverage_mean"])
    assert record["peak_memory_mib"] > 0 and record["seconds"] > 0
    said = r"[\d,]+ rows identified in \d+ s \(selection \d+ s, CPU \d+ s\), peak memory"
    assert re.search(said, text), text
    # every held-out run is drawn with its band, the level in the legend
    assert set(drawn["bands"]) == set(drawn["outputs"]) == set(data.names)
    assert drawn["band_label"].startswith("90 % band")
    for low, high in drawn["bands"].values():
        width = (high - low)[-1]
        np.testing.assert_allclose(width, np.subtract(band["high"], band["low"]), rtol=1e-12)


@pytest.mark.parametrize(
    ("extra", "edit", "needle"),
    [
        (["--outputs", "x_mm,z_mm"], None, "z_mm"),
        ([], lambda text: text.replace("val02-ramps", "train01-steps"), "contiguous"),
        (["--validate-on", "val09"], None, "val09"),
        (["--folds", "1"], None, "--folds"),
        ([], lambda text: text.replace(",0.25,", ",nan,", 1), "line"),
    ],
)
def test_bad_input_is_one_line_exit_2(recording, tmp_path, capsys, extra, edit, needle):
    path, _ = recording
    if edit is not None:
        broken = tmp_path / "broken.csv"
        broken.write_text(edit(path.read_text()))
        path = broken
    args = ["identify", str(path), *ARGS, *extra, "--out", str(tmp_path / "x")]
    assert main(args) == 2
    err = capsys.readouterr().err.strip().splitlines()
    assert len(err) == 1 and needle in err[0], err


def test_an_experiment_column_of_one_experiment_names_the_option(recording, tmp_path, capsys):
    _, data = recording
    one = tmp_path / "one.csv"
    save_timeseries(data.subset(data.names[:1]), one)
    assert main(["identify", str(one), *ARGS, "--out", str(tmp_path / "x")]) == 2
    line = one_error_line(capsys)
    assert "--experiment: the column 'experiment' names one experiment" in line, line
    assert "nothing to hold out" in line and "--validate-on" not in line, line


def _arx_only(monkeypatch):
    """The linear ARX candidates only: the split, not the search, is tested here."""
    from softbend.identification import selection as selection_module

    every = selection_module.default_candidates
    monkeypatch.setattr(
        selection_module,
        "default_candidates",
        lambda seed=0, **kw: [c for c in every(seed) if c.family == "arx"],
    )


def test_one_recording_is_split_into_segments_and_says_which_samples_went_where(
    tmp_path, capsys, monkeypatch
):
    _arx_only(monkeypatch)
    rng = np.random.default_rng(3)
    u = rng.normal(size=200)
    y = np.convolve(u, [0.0, 0.5, 0.25], mode="full")[:200]
    path = tmp_path / "rec.csv"
    rows = np.column_stack([0.02 * np.arange(200), u, y]).tolist()
    path.write_text("t,u,y\n" + "".join(",".join(map(repr, row)) + "\n" for row in rows))
    out = tmp_path / "out"
    args = ["identify", str(path), "--inputs", "u", "--outputs", "y", "--time", "t"]
    assert main([*args, "--out", str(out)]) == 0
    err = capsys.readouterr().err
    said = ("One recording ('rec', 200 samples, no experiment column): split into 5 contiguous "
            "segments; selection on samples 0–159 (4 segments, one cross-validation fold each), "
            "validation on samples 160–199 (the last segment).")  # fmt: skip
    assert said in err, err
    record = json.loads((out / "selection.json").read_text())
    assert record["validation"] == ["rec[160:200]"] and len(record["train"]) == 4
    segments = record["split"]["segments"]
    assert [(s["first_sample"], s["last_sample"], s["role"]) for s in segments] == [
        (0, 39, "selection"), (40, 79, "selection"), (80, 119, "selection"),
        (120, 159, "selection"), (160, 199, "validation"),
    ]  # fmt: skip


@pytest.mark.parametrize(
    ("samples", "extra", "said"),
    [
        (60, [], "--experiment: not given, and the data is one recording 'rec'"),
        (200, ["--validate-on", "rec"], "--validate-on: names experiments, but the data is one "
                                        "recording ('rec', no --experiment column)"),
    ],
    ids=["too-short", "validate-on"],
)  # fmt: skip
def test_one_recording_that_cannot_be_split_names_the_option(
    tmp_path, capsys, no_fit, samples, extra, said
):
    path = tmp_path / "rec.csv"
    path.write_text("u,y\n" + "".join(f"{i % 7},{i % 5}\n" for i in range(samples)))
    out = tmp_path / "out"
    args = ["identify", str(path), "--inputs", "u", "--outputs", "y", *extra]
    assert main([*args, "--out", str(out)]) == 2
    line = one_error_line(capsys)
    assert said in line, line
    assert not out.exists()


def test_an_experiment_shorter_than_the_lags_is_one_line(recording, tmp_path, capsys):
    from softbend.identification.timeseries import Series, TimeSeriesSet

    _, data = recording
    first = data.experiments[0]
    stub = Series("stub", first.time[:3], first.inputs[:3], first.outputs[:3])
    short = TimeSeriesSet(data.input_names, data.output_names, (*data.experiments, stub), "time_s")
    path = save_timeseries(short, tmp_path / "short.csv")
    assert main(["identify", str(path), *ARGS, "--out", str(tmp_path / "x")]) == 2
    err = capsys.readouterr().err.strip().splitlines()
    assert len(err) == 1 and "stub" in err[0], err


# --- ``softbend identify`` and ``softbend curling identify`` refuse bad input before any work ---
#
# Every numeric option is held to its declared range (softbend.identification.ranges),
# and data whose figures could not be finite (a constant output, values whose squares
# overflow) are refused up front: one ``softbend: error:`` line, exit 2, no fit, no
# output folder.


ARGS_BIG = ["--inputs", "u", "--outputs", "y,z", "--experiment", "experiment", "--time", "t"]


@pytest.fixture
def no_fit(monkeypatch):
    """Any model fit fails the test: the refusal must come before the first one."""
    from softbend.identification.multi import MultiNARX
    from softbend.identification.narx import NARXRegressor

    def fit(self, *args, **kwargs):
        raise AssertionError("a model was fitted before the input was checked")

    monkeypatch.setattr(MultiNARX, "fit", fit)
    monkeypatch.setattr(NARXRegressor, "fit", fit)


def _recording(path, z_of=None):
    """Four experiments a, b, c, d of 40 samples: input u, outputs y and z."""
    rng = np.random.default_rng(0)
    experiments = []
    for k, name in enumerate("abcd"):
        u = rng.normal(size=40)
        y = np.cumsum(u) * 0.1
        z = z_of(k, y) if z_of is not None else y**2
        experiments.append(Series(name, np.arange(40.0), u, np.column_stack([y, z])))
    return save_timeseries(TimeSeriesSet(("u",), ("y", "z"), tuple(experiments), "t"), path)


# ------------------------------------------------------------------ softbend identify
@pytest.mark.parametrize(
    ("option", "value", "said"),
    [
        ("--seed", "-1", r"--seed: must be an integer in [0, 4294967295]; got -1"),
        ("--folds", "1", r"--folds: must be an integer in [2, 1000]; got 1"),
        ("--folds", "99999999999999999999", "; got 99999999999999999999"),
        ("--max-memory-mb", "nan", r"--max-memory-mb: must be a number in (0, 1e+09]"),
        ("--max-memory-mb", "-1", r"--max-memory-mb: must be a number in (0, 1e+09]"),
    ],
)
def test_identify_options_out_of_range(tmp_path, capsys, no_fit, option, value, said):
    out = tmp_path / "out"
    missing = tmp_path / "nowhere.csv"  # the option is refused before the data are looked at
    assert main(["identify", str(missing), *ARGS_BIG, option, value, "--out", str(out)]) == 2
    line = one_error_line(capsys)
    assert said in line, line
    assert "expected non-negative integer" not in line and not out.exists()


@pytest.mark.parametrize(
    ("held", "said"),
    [
        ("a,a", "--validate-on: must name each experiment once; got 'a' more than once"),
        ("a,zz", "--validate-on: must name experiments of the data (a, b, c, d); got 'zz'"),
        ("a,b,c", "--validate-on: must leave at least 2 of the 4 experiments to train on"),
    ],
)
def test_identify_validate_on_is_checked_before_any_fit(tmp_path, capsys, no_fit, held, said):
    path = _recording(tmp_path / "rec.csv")
    out = tmp_path / "out"
    assert main(["identify", str(path), *ARGS_BIG, "--validate-on", held, "--out", str(out)]) == 2
    assert said in one_error_line(capsys)
    assert not out.exists()


@pytest.mark.parametrize(
    ("z_of", "extra", "said"),
    [
        (
            lambda k, y: np.full_like(y, 2.5),
            [],
            "The output column 'z' is constant over the training experiments (every sample 2.5)",
        ),
        (lambda k, y: 1e301 * y, [], "The output column 'z' of experiment 'a'"),
        # constant where it is trained on: its validation experiment varying does not help
        (
            lambda k, y: np.full_like(y, 2.5) if k < 3 else y,
            ["--validate-on", "d"],
            "'z' is constant over the training experiments",
        ),
        (
            lambda k, y: np.full_like(y, 2.5) + 1e-12 * (y > 0),
            [],
            "The output column 'z' is near-constant over the training experiments",
        ),
    ],
    ids=["constant", "1e301", "constant-in-training", "near-constant"],
)
def test_identify_refuses_an_output_whose_figures_could_not_be_finite(
    tmp_path, capsys, no_fit, z_of, extra, said
):
    path = _recording(tmp_path / "rec.csv", z_of)
    out = tmp_path / "out"
    assert main(["identify", str(path), *ARGS_BIG, *extra, "--out", str(out)]) == 2
    line = one_error_line(capsys)
    assert said in line and "nan" not in line.lower(), line
    assert not out.exists()


def test_one_recording_with_a_constant_input_is_one_line(tmp_path, capsys, no_fit):
    path = tmp_path / "rec.csv"
    path.write_text("u,p_kpa,y\n" + "".join(f"{i % 7},101.325,{i % 5}\n" for i in range(200)))
    out = tmp_path / "out"
    args = ["identify", str(path), "--inputs", "u,p_kpa", "--outputs", "y", "--out", str(out)]
    assert main(args) == 2
    assert "The input column 'p_kpa' is constant" in one_error_line(capsys)
    assert not out.exists()


def test_identify_refuses_a_constant_input_naming_the_column(tmp_path, capsys, no_fit):
    rng = np.random.default_rng(0)
    experiments = []
    for name in "abcd":
        u = rng.normal(size=40)
        y = np.cumsum(u) * 0.1
        still = np.full(40, 101.325)
        experiments.append(Series(name, np.arange(40.0), np.column_stack([u, still]), y))
    path = tmp_path / "rec.csv"
    save_timeseries(TimeSeriesSet(("u", "p_kpa"), ("y",), tuple(experiments), "t"), path)
    out = tmp_path / "out"
    args = ["identify", str(path), "--inputs", "u,p_kpa", "--outputs", "y"]
    assert main([*args, "--experiment", "experiment", "--out", str(out)]) == 2
    line = one_error_line(capsys)
    assert "The input column 'p_kpa' is constant over the training experiments" in line, line
    assert "leave it out of the inputs" in line and not out.exists()


# ---------------------------------------------------------- softbend curling identify
@pytest.mark.parametrize(
    ("option", "value", "said"),
    [
        (
            "--input-lags",
            "1000000000",
            "--input-lags: must be an integer in [1, 50]; got 1000000000",
        ),
        (
            "--output-lags",
            "99999999999999999999",
            "--output-lags: must be an integer in [1, 50]; got 99999999999999999999",
        ),
        ("--output-lags", "0", "--output-lags: must be an integer in [1, 50]; got 0"),
        ("--C", "1e300", "--C: must be a number in (0, 10000]; got 1e+300"),
        ("--C", "0", "--C: must be a number in (0, 10000]; got 0.0"),
        ("--epsilon", "nan", "--epsilon: must be a number in [0, 10]; got nan"),
        ("--epsilon", "-0.1", "--epsilon: must be a number in [0, 10]; got -0.1"),
        ("--max-memory-mb", "inf", "--max-memory-mb: must be a number in (0, 1e+09]"),
    ],
)
def test_curling_identify_options_out_of_range(tmp_path, capsys, no_fit, option, value, said):
    out = tmp_path / "out"
    missing = tmp_path / "nowhere"  # the option is refused before the data are looked at
    assert main(["curling", "identify", str(missing), option, value, "--out", str(out)]) == 2
    line = one_error_line(capsys)
    assert said in line, line
    assert "Maximum allowed size" not in line and not out.exists()


def test_curling_identify_refuses_lags_the_shortest_experiment_cannot_hold(
    tmp_path, capsys, no_fit
):
    data = synthetic_dataset(n_experiments=2, n_samples=16, seed=1)
    folder = tmp_path / "exp"
    save_experiments([e for group in data.values() for e in group], folder)
    out = tmp_path / "out"
    assert main(["curling", "identify", str(folder), "--output-lags", "20", "-o", str(out)]) == 2
    line = one_error_line(capsys)
    assert "--output-lags: must be an integer in [1, 12] for these experiments" in line
    assert "16 sample(s)" in line and "; got 20" in line and not out.exists()


def test_curling_identify_refuses_an_experiment_with_a_constant_output(tmp_path, capsys, no_fit):
    from softbend.identification.data import Experiment

    data = synthetic_dataset(n_experiments=2, n_samples=64, seed=1)
    experiments = [e for group in data.values() for e in group]
    first = experiments[0]
    n = first.n_samples
    still = Experiment("still", first.time_s, np.full(n, 5.0), np.zeros(n), np.zeros(n))
    folder = tmp_path / "exp"
    save_experiments([*experiments, still], folder)
    out = tmp_path / "out"
    assert main(["curling", "identify", str(folder), "-o", str(out)]) == 2
    line = one_error_line(capsys)
    assert "Experiment 'still' has a constant rho (every sample 0)" in line
    assert not out.exists()


def test_identify_search_delays_adds_the_delay_searched_candidate(recording, tmp_path, monkeypatch):
    """By default the selection gets the polynomial whose input delays are searched, after the
    one without; --no-search-delays leaves it out."""
    from softbend.identification import selection as module

    seen = []

    class SeenError(Exception):
        pass

    def select(data, **kwargs):
        seen.append([c.name for c in kwargs["candidates"]])
        raise SeenError  # the candidates are all this test needs

    monkeypatch.setattr(module, "select_model", select)
    path, _ = recording
    for flag in (["--no-search-delays"], []):
        with pytest.raises(SeenError):
            main([*["identify", str(path)], *ARGS, "--out", str(tmp_path / "o"), *flag])
    plain, delayed = seen
    assert "poly2-sim-2-3-filter-delay" not in plain
    assert delayed == [*plain[: plain.index("poly2-sim-2-3-filter") + 1],
                       "poly2-sim-2-3-filter-delay",
                       *plain[plain.index("poly2-sim-2-3-filter") + 1 :]]  # fmt: skip
