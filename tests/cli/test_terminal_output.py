"""Output off a terminal (a pipe, a log): no word broken, undefined values as "—", Ctrl-C."""

from __future__ import annotations

import math
import re
import warnings

import numpy as np
import pytest
import typer
from rich.console import Console

from softbend.cli import _common, _console, app, interrupted_line, main

#: A message with long words, long enough to be wrapped at 80 columns.
WORDS = ["negative", "scale-offset", "calibration", "pressure-scaled"] * 12


@pytest.fixture
def piped(monkeypatch):
    """The CLI's consoles as off a terminal at rich's default 80 columns."""
    out = Console(width=80, soft_wrap=True, force_terminal=False)
    err = Console(width=80, soft_wrap=True, force_terminal=False, stderr=True)
    for module in (_console, _common):
        monkeypatch.setattr(module, "console", out)
        monkeypatch.setattr(module, "err_console", err)
    return out


def _words(text: str) -> set[str]:
    return set(re.findall(r"[\w-]+", text))


def test_piped_message_never_splits_a_word(piped, capsys):
    _common.warning_line(" ".join(WORDS))
    _console.console.print(" ".join(WORDS))
    captured = capsys.readouterr()
    for text in (captured.out, captured.err):
        assert len(text.strip().splitlines()) == 1  # one line, however long
        assert _words(text) >= set(WORDS)


def test_piped_table_never_splits_a_word(piped, capsys):
    long = " ".join(WORDS[:8])
    _common.print_table("t", ["name", "what it does", "more"], [["a", long, long], ["b", long, 1]])
    out = capsys.readouterr().out
    cells = set(re.findall(r"[A-Za-z-]+", out))
    assert set(WORDS) <= cells, cells - set(WORDS)
    # and it stays a table: every row is drawn between its borders
    assert all(line.startswith(("│", "┏", "┃", "┡", "└", " ")) for line in out.splitlines())


def test_listing_piped_through_the_cli_keeps_its_words(piped, capsys):
    from softbend.transfer.strategies import describe_strategies

    assert main(["transfer", "strategies"]) == 0
    out = capsys.readouterr().out
    summaries = [r["summary"] for r in describe_strategies()]
    found = _words(out)
    for summary in summaries:
        assert _words(summary) <= found, _words(summary) - found


@pytest.mark.parametrize("value", [math.nan, np.float64("nan"), np.float32("nan"), None, "", "nan"])
def test_undefined_value_prints_a_dash(capsys, value):
    _common.print_table("t", ["metric", "value"], [["nrmse", value], ["rmse", 1.5]])
    out = capsys.readouterr().out
    assert "nan" not in out.lower().replace("nrmse", "")
    row = next(line for line in out.splitlines() if "nrmse" in line)
    assert "—" in row
    assert "1.5" in out


def test_dash_with_its_reason_keeps_the_column_numeric(capsys):
    _common.print_table(
        "t", ["metric", "value"], [["a", _console.missing("no held-out run")], ["b", 2.25]]
    )
    out = capsys.readouterr().out
    assert "— (no held-out run)" in out
    row = next(line for line in out.splitlines() if " b " in line)
    assert row.rstrip(" │").endswith("2.25")  # right-aligned: a numeric column


def test_known_noisy_warning_is_silenced_others_are_shown(capsys):
    with _common.warnings_as_lines():
        warnings.warn("No artists with labels found to put in legend.", UserWarning, stacklevel=1)
        warnings.warn("something else", UserWarning, stacklevel=1)
    err = capsys.readouterr().err
    assert "No artists" not in err
    assert "softbend: warning: something else\n" in err  # no Python class in the line


def test_a_library_warning_names_its_package_not_its_class(capsys):
    from sklearn.exceptions import ConvergenceWarning

    with _common.warnings_as_lines():
        warnings.warn("did not converge", ConvergenceWarning, stacklevel=1)
    assert "softbend: warning: did not converge (from sklearn)" in capsys.readouterr().err


@pytest.fixture
def interrupting_command():
    """A command ``interrupt-me`` that stops as Ctrl-C stops a command."""

    def interrupt_me(out: str = typer.Option("x", "--out", "-o")) -> None:
        raise KeyboardInterrupt

    app.command("interrupt-me")(interrupt_me)
    yield
    app.registered_commands[:] = [c for c in app.registered_commands if c.name != "interrupt-me"]


def test_ctrl_c_exits_130_with_one_line(interrupting_command, capsys):
    assert main(["interrupt-me"]) == 130
    captured = capsys.readouterr()
    assert captured.err.strip().splitlines() == ["softbend: interrupted"]


def test_interrupted_train_names_its_checkpoint(tmp_path, monkeypatch):
    monkeypatch.chdir(tmp_path)
    args = ["train", "table.duckdb", "--out", "models"]
    assert interrupted_line(args) == "softbend: interrupted"  # nothing finished yet
    checkpoint = tmp_path / ".models.train-checkpoint.jsonl"
    checkpoint.write_text("{}\n")
    line = interrupted_line(args)
    assert line == (
        f"softbend: interrupted; finished work is kept in {checkpoint}; resume with: "
        "softbend train table.duckdb --out models"
    )
    assert interrupted_line(["train", "table.duckdb", "-o=models"]) == "softbend: interrupted"
    assert interrupted_line(["train", "table.duckdb", "-o", "models"]) == line.replace(
        "--out", "-o"
    )


def test_interrupted_campaign_names_its_database(tmp_path):
    db = tmp_path / "c.duckdb"
    args = ["campaign", "run", str(db), "--workers", "2"]
    assert interrupted_line(args) == "softbend: interrupted"
    db.write_bytes(b"")
    assert interrupted_line(args) == (
        f"softbend: interrupted; finished work is kept in {db}; resume with: "
        f"softbend campaign run {db} --workers 2"
    )
    spaced = tmp_path / "my runs" / "c.duckdb"
    spaced.parent.mkdir()
    spaced.write_bytes(b"")
    assert interrupted_line(["campaign", "run", str(spaced)]).endswith(
        f"resume with: softbend campaign run '{spaced}'"
    )  # quoted as a shell takes it
    assert interrupted_line(["fem", "run", str(db)]) == "softbend: interrupted"


def test_identify_prints_a_compact_summary(capsys, tmp_path):
    from types import SimpleNamespace

    import pandas as pd

    from softbend.cli.curling import BEST_ROWS, print_metrics

    rows = [
        {
            "sign": sign,
            "output": output,
            "experiment": f"e{k}",
            "mode": mode,
            "rmse": 1.0 + k,
            "nrmse": 0.01 * (k + 1) + (0.5 if mode == "one-step" else 0.0),
            "r2": 0.9,
            "fit_percent": 80.0,
        }
        for sign in ("positive", "negative")
        for output in ("x", "y")
        for mode in ("one-step", "free-run")
        for k in range(6)
    ]
    metrics = pd.DataFrame(rows)
    summary = pd.DataFrame(
        [
            {
                "sign": s,
                "output": o,
                "mode": m,
                "nrmse_mean": 0.1,
                "nrmse_max": math.nan,
                "r2_mean": 0.9,
            }
            for s in ("positive", "negative")
            for o in ("x", "y")
            for m in ("one-step", "free-run")
        ]
    )
    result = SimpleNamespace(metrics=metrics, summary=lambda: summary)
    print_metrics(result, tmp_path / "metrics.csv")
    out = capsys.readouterr().out
    best = [line for line in out.splitlines() if re.search(r"│ e\d", line)]
    assert len(best) == BEST_ROWS  # not the 48 rows
    assert all(" e0 " in line or " e1 " in line for line in best)  # the lowest NRMSE
    assert f"all {len(metrics)} held-out rows" in out and str(tmp_path / "metrics.csv") in out
    assert "nan" not in out


def test_fem_progress_counts_pressure_steps():
    from softbend.cli.fem import steps_reached
    from softbend.models import default_pressures_mpa

    grid = np.sort(np.asarray(default_pressures_mpa(0.2, 0.05)))  # 0, 0.05, ..., 0.2
    assert steps_reached(grid, 0.0) == 1
    assert steps_reached(grid, 0.049) == 1  # a sub-step short of the next pressure
    assert steps_reached(grid, 0.05) == 2
    assert steps_reached(grid, 0.15000000000000002) == 4  # rounding of 3 x 0.05
    assert steps_reached(grid, 0.2) == grid.size


@pytest.mark.parametrize(
    ("argv", "said"),
    [
        (["transfer", "refine", "nope.json", "lab.csv", "-o", "x.json"], "No saved surrogate"),
        (["transfer", "refine", "BASE", "nope.csv", "-o", "x.json"], "No measurements file"),
        (["transfer", "base", "-o", "x.json", "--epochs", "0"], "--epochs: must be an integer"),
    ],
)
def test_argument_errors_come_before_the_heavy_imports(tmp_path, argv, said):
    """An argument error costs no import of PyTorch, scikit-learn or SciPy (seconds)."""
    import subprocess
    import sys
    from importlib.resources import files

    base = str(files("softbend") / "data" / "transfer" / "table1_fem_mlp.json")
    argv = [base if a == "BASE" else a for a in argv]
    code = (
        "import sys\nfrom softbend.cli import main\nrc = main(sys.argv[1:])\n"
        "heavy = {m.split('.')[0] for m in sys.modules} & {'torch', 'sklearn', 'scipy'}\n"
        "print(rc, sorted(heavy))\n"
    )
    done = subprocess.run(
        [sys.executable, "-c", code, *argv], capture_output=True, text=True, cwd=tmp_path
    )
    assert done.stdout.strip() == "2 []", done.stderr
    assert said in done.stderr and len(done.stderr.strip().splitlines()) == 1
