"""``softbend transfer refine/loco --set`` and ``softbend lab measure``: values held, no leftovers.

Every ``--set`` value is held to its declared range before any work, a refit
that is not finite is refused, options that contradict each other are refused
naming both, messages name the options typed, and a failed or interrupted lab
run leaves no temporary file: always one ``softbend: error:`` line, exit 2 (130
when interrupted), never a traceback.
"""

from __future__ import annotations

import os
import subprocess
import sys
import textwrap
import time

import pytest

from softbend.cli import main
from softbend.transfer.lab import VirtualLab

from .conftest import one_error_line

LAB = ["lab", "measure", "--plant", "analytical"]
ONE = ["--design", "100,6,2,2,5,8", "--pmax", "0.03", "--json"]


def _listing(folder):
    return sorted(p.name for p in folder.iterdir())


@pytest.fixture(scope="module")
def lab_csv(tmp_path_factory):
    out = tmp_path_factory.mktemp("lab") / "lab.csv"
    assert main([*LAB, "--pmax", "0.12", "--out", str(out), "--json"]) == 0
    return out


def _refine(base, lab_csv, out, strategy, *settings):
    argv = ["transfer", "refine", str(base), str(lab_csv), "--out", str(out)]
    argv += ["--strategy", strategy]
    for item in settings:
        argv += ["--set", item]
    return main(argv)


# ------------------------------------------------------------------ refine --set
@pytest.mark.parametrize(
    ("strategy", "setting", "expected"),
    [
        (
            "experimental",
            "hidden_sizes=0,0",  # was a ZeroDivisionError
            "--set: hidden_sizes: must be 2 integers separated by commas, each in [1, 1024] "
            "units per layer; got '0,0' (2 values)",
        ),
        (
            "experimental",
            "hidden_sizes=100000,100000",  # was tens of GB of weights
            "--set: hidden_sizes: must be 2 integers separated by commas, each in [1, 1024] "
            "units per layer; got '100000,100000' (2 values)",
        ),
        (
            "experimental",
            "hidden_sizes=-3,4",  # was "expected non-negative integer"
            "got '-3,4' (2 values)",
        ),
        (
            "residual-gp",
            "n_restarts=1000000000",  # hung
            "--set: n_restarts: must be in [0, 100] restarts; got '1000000000'",
        ),
        (
            "refined",
            "learning_rate=1e6",  # was a NaN model with exit 0
            "--set: learning_rate: must be in (0, 1] standardized units; got '1e6'",
        ),
        ("refined-ensemble", "n_members=100000", "must be in [2, 100] networks"),
        (
            "refined",
            "epochs=0",
            "--set: epochs: must be in [1, inf) Adam steps; got '0'",
        ),
    ],
)
def test_refine_refuses_a_value_out_of_range_at_once(
    lab_csv, tmp_path, capsys, small_base_file, strategy, setting, expected
):
    out = tmp_path / "model.json"
    start = time.perf_counter()
    assert _refine(small_base_file, lab_csv, out, strategy, setting) == 2
    assert time.perf_counter() - start < 5.0  # before any work
    line = one_error_line(capsys)
    assert expected in line and "Traceback" not in line
    assert _listing(tmp_path) == []


def test_refine_refuses_a_negative_seed_and_zero_epochs(lab_csv, tmp_path, capsys, small_base_file):
    argv = ["transfer", "refine", str(small_base_file), str(lab_csv)]
    argv += ["--out", str(tmp_path / "m.json"), "--strategy", "experimental"]
    assert main([*argv, "--seed", "-1"]) == 2
    assert "'--seed'" in one_error_line(capsys)
    assert main([*argv, "--epochs", "0"]) == 2
    assert "'--epochs'" in one_error_line(capsys)
    assert _listing(tmp_path) == []


def test_refine_a_diverged_refit_is_one_line_and_no_model(
    lab_csv, tmp_path, monkeypatch, capsys, small_base_file
):
    import softbend.transfer.strategies.networks as strategies

    train = strategies.fine_tune_many

    def diverged(*args, **kwargs):
        models = train(*args, **kwargs)
        for model in models:
            model.coefs_[-1] = model.coefs_[-1] * 1e12
        return models

    monkeypatch.setattr(strategies, "fine_tune_many", diverged)
    out = tmp_path / "model.json"
    assert _refine(small_base_file, lab_csv, out, "refined", "epochs=3") == 2
    err = capsys.readouterr().err.strip().splitlines()
    assert all(not line.startswith("softbend:") for line in err[:-1])  # progress lines
    line = err[-1]
    assert line.startswith(
        "softbend: error: The 'refined' strategy's training diverged at learning_rate 0.0006: "
        "it predicts "
    )
    assert "nan" not in line.lower() and _listing(tmp_path) == []


def test_refine_a_non_finite_prediction_is_one_line_and_no_model(
    lab_csv, tmp_path, monkeypatch, capsys, small_base_file
):
    import numpy as np

    import softbend.transfer.refine as refine

    fit = refine.fit_strategy

    def blank_at_one_reading(*args, **kwargs):
        model = fit(*args, **kwargs)
        answer = model.predict

        def predict(X):
            out = np.array(answer(X), dtype=float)
            out[4] = np.nan
            return out

        model.predict = predict
        return model

    monkeypatch.setattr(refine, "fit_strategy", blank_at_one_reading)
    out = tmp_path / "model.json"
    assert _refine(small_base_file, lab_csv, out, "scale-offset") == 2
    line = one_error_line(capsys)
    assert "The 'scale-offset' refit predicts no finite angle at 1 of the" in line
    assert "(first: reading 4, " in line and _listing(tmp_path) == []


# -------------------------------------------------------------------- loco --set
def test_loco_refuses_a_value_out_of_range_before_any_work(
    lab_csv, tmp_path, capsys, small_base_file
):
    out = tmp_path / "loco"
    argv = ["transfer", "loco", str(lab_csv), "--base", str(small_base_file), "--out", str(out)]
    argv += ["--strategies", "refined,residual-gp", "--no-learning-curve", "--json"]
    start = time.perf_counter()
    assert main([*argv, "--set", "refined.learning_rate=1e6"]) == 2
    assert "--set: learning_rate: must be in (0, 1]" in one_error_line(capsys)
    assert main([*argv, "--set", "n_restarts=-1"]) == 2
    assert "--set: n_restarts: must be in [0, 100] restarts" in one_error_line(capsys)
    assert time.perf_counter() - start < 5.0
    assert _listing(tmp_path) == []


# --------------------------------------------------------------------- lab measure
@pytest.mark.parametrize(
    "option", [["--elastomer", "dragon-skin-20"], ["--elastomer-max-stretch", "2"]]
)
def test_lab_measure_refuses_material_with_an_option_it_replaces(
    fit_file, tmp_path, capsys, option
):
    out = tmp_path / "lab.csv"
    assert main([*LAB, "--material", str(fit_file), *option, "--out", str(out), "--json"]) == 2
    assert one_error_line(capsys) == (
        f"softbend: error: The '--material' gives the lab's silicone whole, so the "
        f"'{option[0]}' would not be used; give one of '--material' and '{option[0]}'."
    )
    assert _listing(tmp_path) == []


def test_lab_measure_takes_material_alone(fit_file, tmp_path, capsys):
    out = tmp_path / "lab.csv"
    assert main([*LAB, *ONE, "--material", f"{fit_file}#yeoh", "--out", str(out)]) == 0
    assert "lab.material" in capsys.readouterr().out
    assert _listing(tmp_path) == ["lab.csv", "lab.png"]


def test_the_library_refuses_material_with_another_elastomer_too():
    with pytest.raises(ValueError, match=r"^material: .*so elastomer \('dragon-skin-20'\)"):
        VirtualLab(plant="analytical", material="dragon-skin-30", elastomer="dragon-skin-20")


@pytest.mark.parametrize(
    ("argv", "expected"),
    [
        (["--pmax", "5"], "--pmax: must be a number in (0, 1]; got 5.0"),
        (["--pstep", "0"], "--pstep: must be a number in (0, 0.1]; got 0.0"),
        (["--pmax", "0.255"], "--pmax: must be a whole number of steps of 0.01 MPa"),
        (["--camera-noise", "nan"], "--camera-noise: must be a number in [0, 90]; got NaN"),
        (["--hysteresis", "0.3"], "--hysteresis: must be a number in [0, 0.25); got 0.3"),
        (["--fabrication-error", "-1"], "--fabrication-error: must be a number in [0, 1)"),
        (["--max-angle", "400"], "--max-angle: must be a number in (0, 300]; got 400.0"),
        (["--elastomer-max-stretch", "1"], "--elastomer-max-stretch: must be a number in (1, 50)"),
        (["--seed", "-1"], "--seed: must be an integer in [0, inf); got -1"),
        (["--cycles", "0"], "--cycles: must be an integer in [1, inf); got 0"),
        (["--plant", "magic"], "--plant: unknown lab model 'magic'; known: fem, analytical"),
        (["--elastomer", "rubber"], "--elastomer: must be one of 'dragon-skin-10-medium'"),
        (["--design", "1,2,3"], "--design: '1,2,3' is not a design: A design needs 6"),
        (
            ["--design", "100,6,2,2,5,8", "--design", "100,6,2,2,5,8"],
            "--design: must be distinct designs; got 100,6,2,2,5,8 more than once",
        ),
    ],
)
def test_lab_measure_names_the_options_typed(tmp_path, capsys, argv, expected):
    out = tmp_path / "lab.csv"
    assert main([*LAB, *argv, "--out", str(out), "--json"]) == 2
    line = one_error_line(capsys)
    assert expected in (line.lower() if "unknown" in expected else line)
    assert "VirtualLab" not in line
    assert not any(f"'{field}'" in line for field in VirtualLab.__dataclass_fields__)
    assert _listing(tmp_path) == []


def _old_outputs(tmp_path):
    out = tmp_path / "lab.csv"
    out.write_text("old csv\n")
    (tmp_path / "lab.png").write_bytes(b"\x89PNG old")
    return out


@pytest.mark.parametrize("fault", [KeyboardInterrupt, RuntimeError, MemoryError])
def test_lab_measure_failing_or_interrupted_leaves_no_temporary_file(
    tmp_path, monkeypatch, capsys, fault
):
    import softbend.reports.transfer_figures as figures

    def broken(measurements, path):
        path.write_bytes(b"half a figure")  # the temporary exists when the fault comes
        raise fault("stop")

    monkeypatch.setattr(figures, "lab_measurements", broken)
    out = _old_outputs(tmp_path)
    argv = [*LAB, *ONE, "--out", str(out)]
    if fault is KeyboardInterrupt:
        assert main(argv) == 130
        assert capsys.readouterr().err.strip().splitlines() == [
            f"softbend: interrupted; {out} and {tmp_path / 'lab.png'} are as they were"
        ]  # one line, as every interrupted command's
    else:
        with pytest.raises(fault):
            main(argv)
    assert _listing(tmp_path) == ["lab.csv", "lab.png"]  # no .lab.csv.*.tmp.csv
    assert out.read_text() == "old csv\n"


def test_lab_measure_stopped_by_sigterm_leaves_no_temporary_file(tmp_path):
    """``kill`` while the figure is written: the temporary CSV is removed, the old files kept."""
    out = _old_outputs(tmp_path)
    script = textwrap.dedent(
        f"""
        import os, signal, sys, time
        import softbend.reports.transfer_figures as figures

        def killed(measurements, path):
            os.kill(os.getpid(), signal.SIGTERM)
            time.sleep(30)

        figures.lab_measurements = killed
        from softbend.cli import main
        sys.exit(main({[*LAB, *ONE, "--out", str(out)]!r}))
        """
    )
    done = subprocess.run(
        [sys.executable, "-c", script],
        capture_output=True,
        text=True,
        timeout=60,
        env={**os.environ, "COLUMNS": "200"},
    )
    assert done.returncode == 130, done.stderr
    assert done.stderr.strip().splitlines()[-1].startswith("softbend: interrupted; ")
    assert "Traceback" not in done.stderr
    assert _listing(tmp_path) == ["lab.csv", "lab.png"]
    assert out.read_text() == "old csv\n"
