import json

import numpy as np
import pytest

from softbend.cli import main

from .conftest import one_error_line


def _run(args, capsys):
    code = main(args)
    captured = capsys.readouterr()
    return code, captured.out, captured.err


def test_train_writes_models_tables_figures_and_predicts(small_campaign, tmp_path, capsys):
    args = ["train", str(small_campaign), "--out", str(tmp_path), "--models", "plr,mlp"]
    code, out, _ = _run([*args, "--epochs", "20", "--folds", "4", "--json"], capsys)
    assert code == 0
    summary = json.loads(out)
    assert set(summary["models"]) == {"plr", "mlp"}
    for name in ("plr", "mlp"):
        m = summary["models"][name]
        assert 0.0 < m["r2"] <= 1.0 and m["onnx_max_abs_diff_deg"] < 1e-3
        assert (tmp_path / "models" / f"{name}.json").is_file()
        assert (tmp_path / "models" / f"{name}.onnx").is_file()
    for name in ("cv_results.csv", "summary.csv", "fig5_parity_errors.png", "mlp_loss.png"):
        assert (tmp_path / name).is_file(), name
    assert summary["settings"]["folds"] == 4

    from softbend.surrogates.persistence import load_surrogate

    model = load_surrogate(tmp_path / "models" / "plr.json").model
    code, out, _ = _run(
        [
            "predict",
            str(tmp_path / "models" / "plr.json"),
            "--design",
            "100,6,2,2,5,8",
            "--pressures",
            "0,0.05,0.1",
            "--json",
        ],
        capsys,
    )
    assert code == 0
    angles = json.loads(out)["angle_deg"]
    X = np.array([[100, 6, 2, 2, 5, 8, p] for p in (0, 0.05, 0.1)], dtype=float)
    np.testing.assert_array_equal(angles, model.predict(X))
    assert angles[0] < angles[1] < angles[2]


@pytest.mark.parametrize(
    ("extra", "needle"),
    [
        (
            ["--models", "plr,svm"],
            "--models: Unknown surrogate family 'svm'; known: plr, xgb, mlp, table.",
        ),
        (["--models", " , "], "--models: must be at least one surrogate family name"),
        (["--grid", "huge"], "--grid: must be one of"),
        (["--select-by", "mae"], "--select-by: must be one of 'rmse', 'mape', 'r2'"),
        (["--device", "tpu"], "--device: must be one of"),
        (["--folds", "1"], "folds"),
        (
            ["--workers", "0"],
            "--workers: must be an integer in [1, inf); got 0",
        ),
        (["--workers", "-1"], "--workers: must be an integer in [1, inf)"),
        (["--halving-rungs", "0"], "--halving-rungs: must be an integer"),
        (["--plr-patience", "0"], "--plr-patience: must be an integer"),
        (["--halving-rungs", "3"], "needs 'halving'"),
        (["--halving", "3", "--halving-rungs", "40"], "--halving-rungs: rungs: must be at most"),
    ],
)
def test_train_bad_input_is_one_line_exit_2(small_campaign, tmp_path, capsys, extra, needle):
    code, _, err = _run(["train", str(small_campaign), "--out", str(tmp_path), *extra], capsys)
    assert code == 2
    lines = err.strip().splitlines()
    assert len(lines) == 1 and needle in lines[0]


def test_train_missing_database(tmp_path, capsys):
    code, _, err = _run(["train", str(tmp_path / "nope.duckdb"), "--out", str(tmp_path)], capsys)
    assert code == 2 and "does not exist" in err


@pytest.mark.parametrize(
    ("design", "pressure", "needle"),
    [
        ("100,6,2,2,5", "0.1", "6 values"),
        ("100,6,2,2,5,x", "0.1", "--design: lc_mm must be a number"),
        ("100,6,-2,2,5,8", "0.1", "t_mm"),
        ("l_mm=100,r_mm=6", "0.1", "lacks t_mm, b_mm, phi_deg, lc_mm"),
        ("n_chambers=10", "0.1", "not a design parameter"),
        ("100,6,2,2,5,8", "0.1,abc", "--pressures: must be comma-separated numbers"),
        ("100,6,2,2,5,8", "-0.1", "--pressures: must be finite and >= 0"),
    ],
)
def test_predict_bad_input(small_base_file, capsys, design, pressure, needle):
    model = str(small_base_file)
    code, _, err = _run(["predict", model, "--design", design, "--pressures", pressure], capsys)
    assert code == 2
    assert needle in err and len(err.strip().splitlines()) == 1


def test_predict_not_a_model(tmp_path, capsys):
    fake = tmp_path / "m.json"
    fake.write_text('{"hello": 1}')
    code, _, err = _run(
        ["predict", str(fake), "--design", "100,6,2,2,5,8", "--pressures", "0.1"], capsys
    )
    assert code == 2 and len(err.strip().splitlines()) == 1


def test_predict_warns_outside_the_training_ranges_and_strict_refuses(tmp_path, capsys):
    import numpy as np

    from softbend.surrogates.features import training_ranges
    from softbend.surrogates.persistence import save_surrogate
    from softbend.surrogates.polynomial import PolynomialRegressor
    from softbend.surrogates.support import support_from_rows

    rng = np.random.default_rng(0)
    low = np.array([100.0, 6.0, 2.0, 2.0, 5.0, 8.0, 0.0])
    high = np.array([160.0, 10.0, 4.0, 4.0, 15.0, 12.0, 0.3])
    X = low + (high - low) * rng.random((200, 7))
    X[:, 6] = np.tile(np.linspace(0.0, 0.3, 5), 40)  # 40 designs, each swept to 0.3 MPa
    X[:, :6] = np.repeat(X[::5, :6], 5, axis=0)
    model = PolynomialRegressor(degree=2).fit(X, 300 * X[:, 6])
    metadata = {
        "training_ranges": training_ranges(X),
        "support": support_from_rows(X, 300 * X[:, 6]).to_dict(),
    }
    path = save_surrogate(model, tmp_path / "m.json", metadata=metadata)
    args = ["predict", str(path), "--design", "130,8,3,3,10,10"]
    assert main([*args, "--pressures", "0.1"]) == 0
    assert "warning" not in capsys.readouterr().err
    # an older file without support: a note that only the ranges were checked
    old = save_surrogate(
        model, tmp_path / "old.json", metadata={"training_ranges": training_ranges(X)}
    )
    assert main(["predict", str(old), "--design", "130,8,3,3,10,10", "--pressures", "0.1"]) == 0
    assert "records no training support" in capsys.readouterr().err
    assert main([*args, "--pressures", "0.5", "--json"]) == 0
    captured = capsys.readouterr()
    assert "softbend: warning:" in captured.err and "pressure_mpa 0.5 outside" in captured.err
    assert main([*args, "--pressures", "0.5", "--strict"]) == 2
    assert "pressure_mpa" in capsys.readouterr().err
    # an absurd pressure whose prediction overflows is one error line, never a null angle
    assert main([*args, "--pressures", "1e308", "--json"]) == 2
    assert "pressure_mpa" in capsys.readouterr().err


@pytest.mark.parametrize("fault", [KeyboardInterrupt, OSError(28, "No space left on device")])
def test_an_interrupted_train_leaves_the_previous_output_folder_whole(
    small_campaign, tmp_path, capsys, monkeypatch, fault
):
    out = tmp_path / "surrogates"
    args = ["train", str(small_campaign), "--out", str(out), "--models", "plr", "--no-onnx"]
    assert main([*args, "--json"]) == 0
    capsys.readouterr()
    before = {p.relative_to(out): p.read_bytes() for p in out.rglob("*") if p.is_file()}

    import softbend.surrogates.workflow as workflow

    real = workflow.train_surrogates

    def half_done(db, stage, **kwargs):  # new models written, then the run dies
        real(db, stage, **kwargs)
        raise fault

    monkeypatch.setattr(workflow, "train_surrogates", half_done)
    if fault is KeyboardInterrupt:  # Ctrl-C: the CLI says "aborted", exit 130
        assert main([*args, "--folds", "3"]) == 130
    else:
        assert main([*args, "--folds", "3"]) == 2
        assert "--out" in capsys.readouterr().err
    after = {p.relative_to(out): p.read_bytes() for p in out.rglob("*") if p.is_file()}
    assert after == before
    # No staging folder left; the interrupted search's checkpoint stays for a resume.
    left = sorted(p.name for p in tmp_path.iterdir())
    assert left == [".surrogates.train-checkpoint.jsonl", "surrogates"]


def test_train_killed_at_random_moments_leaves_the_old_folder_or_the_new_one(
    small_campaign, tmp_path
):
    import json
    import os
    import signal
    import subprocess
    import sys
    import time

    import pandas as pd

    out = tmp_path / "surrogates"
    cli = [sys.executable, "-c", "import sys; from softbend.cli import main; sys.exit(main())"]
    args = [*cli, "train", str(small_campaign), "--out", str(out), "--models", "plr"]
    args += ["--no-onnx", "--folds"]

    def consistent() -> int:
        """The folds of one whole run: the model, the summary and the CV table agree."""
        meta = json.loads((out / "models" / "plr.json").read_text())["metadata"]
        summary = pd.read_csv(out / "summary.csv").set_index("model")
        assert summary.loc["plr", "rmse_deg"] == pytest.approx(meta["cv"]["rmse_deg"])
        return int(meta["search"]["folds"])

    first = subprocess.run([*args, "3"], capture_output=True, check=False)
    assert first.returncode == 0, first.stderr.decode()[-500:]
    assert consistent() == 3
    rng = np.random.default_rng(7)
    for k, delay in enumerate(rng.uniform(0.5, 6.0, size=4)):
        folds = str(4 + k % 2)  # each run differs from the one before
        child = subprocess.Popen(
            [*args, folds],
            start_new_session=True,
            stdout=subprocess.DEVNULL,
            stderr=subprocess.DEVNULL,
        )
        time.sleep(float(delay))
        if child.poll() is None:
            os.killpg(child.pid, signal.SIGKILL)
        child.wait()
        assert consistent() in (3, 4, 5), f"a mix after a kill at {delay:.2f} s"


def _scores(out):
    """The cross-validated results of a train output, without the timings."""
    import pandas as pd

    cv = pd.read_csv(out / "cv_results.csv").drop(columns=["fit_s_per_config"])
    summary = pd.read_csv(out / "summary.csv")
    summary = summary[["model", "params", "r2", "rmse_deg", "mape_pct", "max_abs_error_deg"]]
    models = {
        p.name: json.loads(p.read_text())["metadata"]["cv"] for p in (out / "models").glob("*.json")
    }
    return cv, summary, models


def test_a_killed_train_resumes_from_its_finished_folds(small_campaign, tmp_path, capsys):
    import os
    import signal
    import subprocess
    import sys
    import time

    import pandas as pd

    from softbend.surrogates.checkpoint import checkpoint_path

    out = tmp_path / "surrogates"
    checkpoint = checkpoint_path(out)
    options = ["--models", "xgb", "--folds", "3", "--workers", "1", "--no-onnx"]
    cli = [sys.executable, "-c", "import sys; from softbend.cli import main; sys.exit(main())"]
    child = subprocess.Popen(
        [*cli, "train", str(small_campaign), "--out", str(out), *options],
        start_new_session=True,
        stdout=subprocess.DEVNULL,
        stderr=subprocess.DEVNULL,
    )
    try:
        # Killed once the checkpoint holds 4 of the 4 x 3 configuration-folds.
        deadline = time.monotonic() + 120
        while time.monotonic() < deadline and child.poll() is None:
            if checkpoint.is_file() and checkpoint.read_bytes().count(b"\n") >= 1 + 4:
                break
            time.sleep(0.01)
        os.killpg(child.pid, signal.SIGKILL)
    finally:
        child.wait()
    assert child.returncode == -signal.SIGKILL, "the search ended before it was killed"
    assert not out.exists()
    saved = checkpoint.read_bytes().count(b"\n") - 1
    assert saved >= 4

    args = ["train", str(small_campaign), "--out", str(out), *options]
    code, _, err = _run(args, capsys)
    assert code == 0, err
    resumed = [line for line in err.splitlines() if line.startswith("resuming from")]
    assert len(resumed) == 1 and str(checkpoint) in resumed[0]
    assert int(resumed[0].split(": ")[1].split()[0]) >= saved - 1  # a line cut by the kill
    assert not checkpoint.exists()  # removed once the new folder is in place

    reference = tmp_path / "reference"
    code, out_json, _ = _run(
        ["train", str(small_campaign), "--out", str(reference), *options, "--json"], capsys
    )
    assert code == 0 and json.loads(out_json)["resumed_config_folds"] == 0
    for got, expected in zip(_scores(out), _scores(reference), strict=True):
        if isinstance(got, pd.DataFrame):
            pd.testing.assert_frame_equal(got, expected)
        else:
            assert got == expected
    # Beside them only the (empty) staging folder of the killed run (see staged_dir).
    left = sorted(p.name for p in tmp_path.iterdir() if not p.name.endswith(".new"))
    assert left == ["reference", "surrogates"]


def test_train_with_other_settings_discards_the_checkpoint_with_a_warning(
    small_campaign, tmp_path, capsys, monkeypatch
):
    import softbend.surrogates.search as search_module
    from softbend.surrogates.checkpoint import checkpoint_path

    out = tmp_path / "surrogates"
    args = ["train", str(small_campaign), "--out", str(out), "--models", "xgb", "--no-onnx"]
    real = search_module._make
    fits = 0

    def dies_after_four_fits(model, params, **kwargs):
        nonlocal fits
        fits += 1
        if fits > 4:
            raise KeyboardInterrupt  # Ctrl-C in the fifth fit
        return real(model, params, **kwargs)

    monkeypatch.setattr(search_module, "_make", dies_after_four_fits)
    assert main([*args, "--folds", "3"]) == 130
    capsys.readouterr()
    assert checkpoint_path(out).is_file() and not out.exists()
    monkeypatch.setattr(search_module, "_make", real)

    code, out_json, err = _run([*args, "--folds", "4", "--json"], capsys)
    assert code == 0
    warnings = [line for line in err.splitlines() if line.startswith("softbend: warning:")]
    assert len(warnings) == 2 and "80 designs: fewer than 100" in warnings[0]  # the advice
    warnings = warnings[1:]
    assert "discarded" in warnings[0] and "other settings (folds, splits)" in warnings[0]
    assert json.loads(out_json)["resumed_config_folds"] == 0
    assert not checkpoint_path(out).exists()


def test_a_second_train_into_the_same_folder_is_refused_while_one_runs(
    small_campaign, tmp_path, capsys
):
    from softbend.surrogates.checkpoint import SearchCheckpoint, checkpoint_path

    out = tmp_path / "surrogates"
    with SearchCheckpoint(checkpoint_path(out)) as running:
        running.start({"another": "search"})
        code, _, err = _run(
            ["train", str(small_campaign), "--out", str(out), "--models", "plr"], capsys
        )
    assert code == 2
    # the small-table advice may precede it; the refusal is one error line
    lines = [line for line in err.strip().splitlines() if not line.startswith("softbend: warning")]
    assert len(lines) == 1 and "Another search is writing the checkpoint" in lines[0]
    assert not out.exists()


def test_train_does_not_swap_away_a_folder_of_other_files_or_its_input(
    small_campaign, tmp_path, capsys
):
    import shutil

    mine = tmp_path / "mine"
    mine.mkdir()
    (mine / "notes.txt").write_text("keep me")
    args = ["train", str(small_campaign), "--models", "plr", "--no-onnx"]
    assert main([*args, "--out", str(mine)]) == 2
    line = one_error_line(capsys)
    assert "'--out'" in line and "notes.txt" in line and "replaced as a whole" in line
    assert (mine / "notes.txt").read_text() == "keep me"
    # the database inside its own --out folder would be deleted by the swap: refused
    inside = tmp_path / "inside"
    inside.mkdir()
    db = shutil.copy(small_campaign, inside / "c.duckdb")
    assert main(["train", str(db), "--models", "plr", "--no-onnx", "--out", str(inside)]) == 2
    assert "holds the 'DB'" in one_error_line(capsys)
    assert (inside / "c.duckdb").is_file()
    # an earlier result of softbend train is replaced as before
    out = tmp_path / "out"
    assert main([*args, "--out", str(out), "--json"]) == 0
    capsys.readouterr()
    assert main([*args, "--out", str(out), "--json"]) == 0


def test_train_chooses_by_rmse_names_the_mape_floor_and_advises_small_tables(
    small_campaign, tmp_path, capsys
):
    args = ["train", str(small_campaign), "--out", str(tmp_path / "a"), "--models", "plr,xgb"]
    args += ["--folds", "3", "--no-onnx", "--workers", "1"]
    code, out, err = _run(args, capsys)
    assert code == 0
    # paper B's actuator: paper B's MAPE, over all but the 0 MPa readings
    assert "MAPE % (|θ| ≥ 1°)" in out
    assert "best by held-out RMSE:" in out
    lines = [line for line in err.splitlines() if line.startswith("softbend: warning:")]
    assert len(lines) == 1 and lines[0].startswith("softbend: warning: 80 designs: fewer than 100")
    code, out, _ = _run(
        [*args[:3], str(tmp_path / "b"), *args[4:], "--select-by", "r2", "--json"], capsys
    )
    summary = json.loads(out)
    scores = {name: m["r2"] for name, m in summary["models"].items()}
    assert summary["selected_by"] == "r2" and summary["best"] == max(scores, key=scores.get)
    assert summary["best_by_mape"] in scores and summary["settings"]["grid"] == "small"
    for m in summary["models"].values():
        assert m["mape_floor_deg"] == summary["mape_floor_deg"] == 1.0
        assert 0 < m["n_mape_used"] < m["n"]


def test_an_undefined_mape_is_a_dash_in_the_table(capsys):
    from softbend.cli.train import print_summary

    row = {"r2": 0.9, "rmse_deg": 1.5, "max_abs_error_deg": 3.0, "paper_b": {}}
    row |= {"inference_single_us": 10.0, "inference_batch_ms": 1.0, "params": "degree=2"}
    summary = {
        "actuator": {"name": "tiny", "parameters": [{"name": "w"}], "pressure_unit": "kPa"},
        "models": {"plr": {**row, "mape_pct": None}, "xgb": {**row, "mape_pct": 4.25}},
        "mape_floor_deg": 12.5,
        "best": "plr",
        "selected_by": "rmse",
    }
    print_summary(summary)
    out = capsys.readouterr().out
    assert "MAPE % (|θ| ≥ 12.5°)" in out and "4.250" in out and "best by held-out RMSE: plr" in out
    plr_row = next(line for line in out.splitlines() if "degree=2" in line and "plr" in line)
    assert "—" in plr_row and "nan" not in out.lower()


def test_predict_takes_pressures_with_units_in_the_models_unit(small_base_file, capsys):
    """50 kPa and 7.2519 psi are 0.05 MPa, paper B's unit: the same angle as 0.05."""
    args = ["predict", str(small_base_file), "--design", "100,6,2,2,5,8", "--json"]
    assert main([*args, "--pressures", "0.05,50kPa,7.2519psi"]) == 0
    payload = json.loads(capsys.readouterr().out)
    assert payload["pressure_mpa"] == pytest.approx([0.05, 0.05, 0.05], rel=1e-5)
    angles = payload["angle_deg"]
    assert angles == pytest.approx([angles[0]] * 3, rel=1e-4)
    assert main([*args, "--pressures", "0.05,5furlongs"]) == 2
    assert "--pressures: must be comma-separated numbers, each optionally with a unit" in (
        one_error_line(capsys)
    )
