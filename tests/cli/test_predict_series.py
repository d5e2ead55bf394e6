"""softbend predict MODEL --input CSV: an identified model run free on a new input series."""

from __future__ import annotations

import csv
import json

import numpy as np
import pytest

from softbend.cli import main

from .conftest import one_error_line

GAIN, POLE, DT = 0.5, 0.8, 0.02  # x(t) = 0.8·x(t−1) + 0.1·p(t−1), sampled every 20 ms


def _series(n: int, seed: int) -> tuple[np.ndarray, np.ndarray]:
    u = np.repeat(np.random.default_rng(seed).uniform(0.0, 20.0, n // 10), 10)
    y = np.zeros(n)
    for t in range(1, n):
        y[t] = POLE * y[t - 1] + GAIN * (1 - POLE) * u[t - 1]
    return u, y


def _write(path, u, y=None, time=True):
    header = (["time_s"] if time else []) + ["p_kpa"] + (["x_mm"] if y is not None else [])
    rows = [",".join(header)]
    for t in range(len(u)):
        cells = ([repr(t * DT)] if time else []) + [repr(float(u[t]))]
        cells += [repr(float(y[t]))] if y is not None else []
        rows.append(",".join(cells))
    path.write_text("\n".join(rows) + "\n", encoding="utf-8")
    return path


@pytest.fixture(scope="module")
def model(tmp_path_factory):
    """``softbend identify`` on three short experiments of a first-order system.

    Linear and polynomial candidates only: the kernel search is not what is tested here.
    """
    from softbend.identification import selection

    folder = tmp_path_factory.mktemp("identify")
    lines = ["experiment,time_s,p_kpa,x_mm"]
    for e in range(3):
        u, y = _series(100, seed=e)
        lines += [f"run{e},{t * DT!r},{float(u[t])!r},{float(y[t])!r}" for t in range(100)]
    data = folder / "data.csv"
    data.write_text("\n".join(lines) + "\n", encoding="utf-8")
    out = folder / "model"
    args = ["identify", str(data), "--inputs", "p_kpa", "--outputs", "x_mm", "--time", "time_s",
            "--experiment", "experiment", "--folds", "2", "--out", str(out), "--json"]  # fmt: skip
    few = [c for c in selection.default_candidates(0, n_kernel=0) if c.family != "gg-svr"]
    with pytest.MonkeyPatch.context() as patch:
        patch.setattr(selection, "default_candidates", lambda seed=0, n_kernel=6, delays=True: few)
        assert main(args) == 0
    return out / "model.json"


def test_identify_records_the_step_reading_in_the_model(model):
    metadata = json.loads(model.read_text())["metadata"]
    assert metadata["time"] == "time_s" and metadata["sample_period"] == pytest.approx(DT)
    (reading,) = metadata["dynamics"]
    assert reading["gain"] == pytest.approx(GAIN, rel=1e-3) and reading["gain_unit"] == "mm/kPa"
    assert reading["delay_s"] == pytest.approx(DT)
    assert reading["time_constant_s"] == pytest.approx(-DT / np.log(POLE), rel=1e-2)


def test_predict_runs_free_from_the_measured_outputs(model, tmp_path, capsys):
    u, y = _series(200, seed=9)
    series = _write(tmp_path / "new.csv", u, y)
    out = tmp_path / "run.csv"
    assert main(["predict", str(model), "--input", str(series), "--out", str(out)]) == 0
    printed = capsys.readouterr().out
    assert "200 rows" in printed and "free-run NRMSE" in printed and "x_mm" in printed
    with open(out, encoding="utf-8") as handle:
        rows = list(csv.DictReader(handle))
    assert list(rows[0]) == ["time_s", "p_kpa", "x_mm_simulated", "x_mm_measured"]
    simulated = np.array([float(r["x_mm_simulated"]) for r in rows])
    assert len(rows) == 200 and np.max(np.abs(simulated - y)) < 1e-3 * np.ptp(y)


def test_predict_json_from_rest(model, tmp_path, capsys):
    u, _ = _series(120, seed=10)
    series = _write(tmp_path / "inputs.csv", u, time=False)
    assert main(["predict", str(model), "--input", str(series), "--json"]) == 0
    payload = json.loads(capsys.readouterr().out)
    assert payload["start"] == "rest" and payload["rows"] == 120
    assert payload["duration_s"] == pytest.approx(119 * DT)
    figures = payload["outputs"]["x_mm"]
    assert figures["nrmse"] is None
    simulated = np.array(payload["simulated"]["x_mm"])
    # at rest: the first input's steady state until the first step reaches the output
    assert simulated[0] == pytest.approx(GAIN * u[0], rel=1e-3)
    assert figures["final"] == pytest.approx(simulated[-1])
    assert figures["min"] == pytest.approx(simulated.min())


@pytest.mark.parametrize(
    ("extra", "option"),
    [
        (["--design", "1,2"], "--design"),
        (["--pressures", "0.1"], "--pressures"),
        (["--strict"], "--strict"),
        ([], "--input"),
    ],
)
def test_surrogate_options_with_an_identified_model_are_refused(model, tmp_path, capsys, extra,
                                                                option):  # fmt: skip
    series = _write(tmp_path / "in.csv", *_series(50, seed=1)[:1])
    given = ["--input", str(series)] if option != "--input" else []
    assert main(["predict", str(model), *given, *extra]) == 2
    assert option in one_error_line(capsys)


def test_input_with_a_surrogate_is_refused(tmp_path, capsys):
    from softbend.surrogates.persistence import save_surrogate
    from softbend.surrogates.polynomial import PolynomialRegressor

    X = np.random.default_rng(0).random((40, 7))
    surrogate = save_surrogate(PolynomialRegressor(degree=1).fit(X, X[:, 6]), tmp_path / "m.json")
    series = _write(tmp_path / "in.csv", np.zeros(10))
    assert main(["predict", str(surrogate), "--input", str(series)]) == 2
    assert "--input" in one_error_line(capsys)
    assert main(["predict", str(surrogate), "--pressures", "0.1"]) == 2
    assert "--design" in one_error_line(capsys)


def test_a_bad_series_is_one_line(model, tmp_path, capsys):
    lacking = tmp_path / "lacking.csv"
    lacking.write_text("time_s,x_mm\n0,1\n0.02,2\n0.04,3\n", encoding="utf-8")
    assert main(["predict", str(model), "--input", str(lacking)]) == 2
    assert "p_kpa" in one_error_line(capsys)
    short = _write(tmp_path / "short.csv", np.zeros(1))
    assert main(["predict", str(model), "--input", str(short)]) == 2
    assert "rows" in one_error_line(capsys)
    series = _write(tmp_path / "ok.csv", np.zeros(10))
    assert main(["predict", str(model), "--input", str(series), "--out", str(model)]) == 2
    assert "--out" in one_error_line(capsys)
