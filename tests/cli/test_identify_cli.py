"""softbend identify: any time series to a model chosen by its held-out free run."""

from __future__ import annotations

import csv
import json

import pytest

from softbend.cli import main
from softbend.identification.arm import arm_experiments
from softbend.identification.multi import load_multi_narx
from softbend.identification.timeseries_io import save_timeseries

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
    assert families == {"arx", "poly2", "gg-svr"}
    assert payload["best"] in {row["candidate"] for row in payload["table"]}
    with open(out / "holdout_freerun.csv", encoding="utf-8") as handle:
        rows = list(csv.DictReader(handle))
    assert list(rows[0]) == ["experiment", "time_s", "x_mm_measured", "x_mm_simulated",
                             "y_mm_measured", "y_mm_simulated"]  # fmt: skip
    assert {r["experiment"] for r in rows} == set(validation)
    model, metadata = load_multi_narx(out / "model.json")
    assert metadata["inputs"] == ["p1_kpa", "p2_kpa", "p3_kpa"] and model.n_outputs_ == 2
    for name in ("selection.csv", "selection.png", "freerun.png"):
        assert (out / name).is_file()


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


def test_one_experiment_only_has_nothing_to_hold_out(recording, tmp_path, capsys):
    _, data = recording
    one = tmp_path / "one.csv"
    save_timeseries(data.subset(data.names[:1]), one)
    assert main(["identify", str(one), *ARGS, "--out", str(tmp_path / "x")]) == 2
    err = capsys.readouterr().err.strip().splitlines()
    assert len(err) == 1 and "hold" in err[0]


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
