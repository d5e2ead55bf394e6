"""Choosing the base for transfer: ``transfer loco --base a,b`` and ``train --measurements``.

Two quick bases (plr and xgb, trained on ``examples/pneunet`` with two folds and the quick
grid) are scored on the example's measurements: the pair named is the minimum of the table,
a single ``--base`` writes what it wrote before, and ``train --measurements`` selects the
family of the lowest transfer RMSE and records both criteria.
"""

from __future__ import annotations

import json
import shutil
from pathlib import Path

import pandas as pd
import pytest

from softbend.cli import main
from softbend.cli.transfer_loco import CHOICE_FILES, LOCO_FILES

from .conftest import one_error_line

EXAMPLE = Path(__file__).resolve().parents[2] / "examples" / "pneunet"
SIMULATIONS = EXAMPLE / "simulations.csv"
MEASUREMENTS = EXAMPLE / "measurements.csv"
ACTUATOR = EXAMPLE / "actuator.json"

#: Quick strategies that apply to every family (no network training).
STRATEGIES = "fem-only,base-mean-residual,scale-offset,pressure-scale"
QUICK = ("--grid", "quick", "--folds", "2", "--epochs", "30", "--workers", "1",
         "--device", "cpu", "--seed", "0", "--no-onnx")  # fmt: skip


def _run(*args: object) -> int:
    return main([str(arg) for arg in args])


@pytest.fixture(scope="module")
def bases(tmp_path_factory) -> dict[str, Path]:
    """plr and xgb trained once on the PneuNet table, each a saved model."""
    folder = tmp_path_factory.mktemp("bases")
    found = {}
    for family in ("plr", "xgb"):
        out = folder / family
        code = _run("train", SIMULATIONS, "--actuator", ACTUATOR, "--models", family, *QUICK,
                    "-o", out)  # fmt: skip
        assert code == 0, family
        found[family] = out / "models" / f"{family}.json"
    return found


def _loco(out: Path, base: str, *more: str) -> int:
    return _run("transfer", "loco", MEASUREMENTS, "--base", base, "-o", out,
                "--strategies", STRATEGIES, "--no-learning-curve", *more)  # fmt: skip


def test_every_base_x_strategy_is_scored_and_the_best_pair_is_the_table_s_minimum(
    bases, tmp_path, capsys
):
    out = tmp_path / "choice"
    assert _loco(out, f"{bases['plr']},{bases['xgb']}", "--json") == 0
    payload = json.loads(capsys.readouterr().out)
    entries = {p.name for p in out.iterdir() if not p.name.startswith(".")}
    assert entries == {*CHOICE_FILES, "plr", "xgb"}
    for label in ("plr", "xgb"):  # each base's own results, as a single run writes them
        assert {p.name for p in (out / label).iterdir()} >= set(LOCO_FILES) - {"learning_curve.png"}
    table = pd.read_csv(out / "summary.csv")
    assert len(table) == 2 * 4 and set(table["base"]) == {"plr", "xgb"}
    assert set(table["strategy"]) == set(STRATEGIES.split(","))
    lowest = table.loc[table["rmse_deg"].idxmin()]
    record = json.loads((out / "loco.json").read_text(encoding="utf-8"))
    best = record["best"]
    assert (best["base"], best["strategy"]) == (lowest["base"], lowest["strategy"])
    assert best["rmse_deg"] == pytest.approx(float(lowest["rmse_deg"]))
    assert best["base_file"] == str(bases[best["base"]])
    assert table.loc[table["best"], ["base", "strategy"]].values.tolist() == [
        [best["base"], best["strategy"]]
    ]
    assert sorted(table["rank"]) == list(range(1, 9))  # every pair a candidate, ranked
    assert payload["best"] == best
    assert record["settings"]["measurement_files"][0]["path"] == str(MEASUREMENTS)
    # each base's record is its own run's, with the measurement files
    for label in ("plr", "xgb"):
        own = json.loads((out / label / "loco.json").read_text(encoding="utf-8"))
        assert record["bases"][label]["result"]["summary"] == own["summary"]
        assert own["settings"]["measurement_files"][0]["path"] == str(MEASUREMENTS)


def test_the_text_output_names_the_best_pair_and_a_rerun_replaces_the_folder(
    bases, tmp_path, capsys
):
    out = tmp_path / "choice"
    assert _loco(out, f"{bases['xgb']},{bases['plr']}") == 0
    text = capsys.readouterr().out
    best = json.loads((out / "loco.json").read_text(encoding="utf-8"))["best"]
    assert f"best pair by mean leave-one-actuator-out RMSE: base {best['base']}" in text
    assert best["strategy"] in text
    assert _run("transfer", "loco", MEASUREMENTS, "--base", f"{bases['xgb']},{bases['plr']}",
                "-o", out, "--strategies", "fem-only", "--no-learning-curve") == 0  # fmt: skip
    capsys.readouterr()
    assert set(pd.read_csv(out / "summary.csv")["strategy"]) == {"fem-only"}


def test_a_single_base_writes_what_it_wrote_before(bases, tmp_path, capsys):
    single, both = tmp_path / "single", tmp_path / "both"
    assert _loco(single, str(bases["plr"]), "--json") == 0
    payload = json.loads(capsys.readouterr().out)
    assert {p.name for p in single.iterdir() if not p.name.startswith(".")} == set(LOCO_FILES) - {
        "learning_curve.png"
    }
    record = json.loads((single / "loco.json").read_text(encoding="utf-8"))
    assert "best" not in record and "bases" not in record  # a LocoResult's record, as before
    assert {"summary", "per_actuator", "settings"} <= set(payload)
    assert _loco(both, f"{bases['plr']},{bases['xgb']}") == 0
    capsys.readouterr()
    pd.testing.assert_frame_equal(  # the same seeded run, in the base's own folder
        pd.read_csv(single / "summary.csv").drop(columns="fit_s"),
        pd.read_csv(both / "plr" / "summary.csv").drop(columns="fit_s"),
    )


def test_a_base_that_does_not_exist_is_one_error(bases, tmp_path, capsys):
    out = tmp_path / "o"
    assert _loco(out, f"{bases['plr']},{tmp_path / 'missing.json'}") == 2
    line = one_error_line(capsys)
    assert "missing.json" in line
    assert not out.exists()


def test_a_base_of_another_actuator_is_one_error(bases, tmp_path, capsys):
    from softbend.transfer.base import shipped_base_path

    out = tmp_path / "o"
    assert _loco(out, f"{bases['plr']},{shipped_base_path()}") == 2
    line = one_error_line(capsys)
    assert "--base" in line and "every base must model the measurements' actuator" in line
    assert "models pneunet_synthetic" in line and "models sfrba" in line
    # bases that agree with each other but not with the measurements' columns
    a, b = tmp_path / "a.json", tmp_path / "b.json"
    shutil.copy(shipped_base_path(), a)
    shutil.copy(shipped_base_path(), b)
    assert _loco(out, f"{a},{b}") == 2
    line = one_error_line(capsys)
    assert f"--base: {a} (a model of sfrba): " in line and "lacks the column(s)" in line
    assert not out.exists()


def test_a_base_named_twice_or_an_empty_name_is_one_error(bases, tmp_path, capsys):
    out = tmp_path / "o"
    assert _loco(out, f"{bases['plr']},{bases['plr']}") == 2
    assert "twice" in one_error_line(capsys)
    assert _loco(out, f"{bases['plr']},") == 2
    assert "empty name" in one_error_line(capsys)


def test_a_strategy_that_applies_to_one_base_only_is_left_out_for_the_other(
    bases, tmp_path, capsys
):
    out = tmp_path / "o"
    assert _run("transfer", "loco", MEASUREMENTS, "--base", f"{bases['plr']},{bases['xgb']}",
                "-o", out, "--strategies", "refined", "--no-learning-curve") == 2  # fmt: skip
    assert "refined" in one_error_line(capsys)  # applies to neither: refused before any fit


def test_train_with_measurements_selects_by_transfer_and_records_both(tmp_path, capsys):
    out = tmp_path / "t"
    assert _run("train", SIMULATIONS, "--actuator", ACTUATOR, "--models", "plr,xgb", *QUICK,
                "--measurements", MEASUREMENTS, "-o", out, "--json") == 0  # fmt: skip
    summary = json.loads(capsys.readouterr().out)
    selection = summary["selection"]
    scores = {name: m["transfer_rmse_deg"] for name, m in summary["models"].items()}
    assert summary["best"] == min(scores, key=scores.__getitem__)
    assert summary["selected_by"] == "transfer" == selection["criterion"]
    assert selection["by_transfer"] == summary["best"]
    cv = {name: m["rmse_deg"] for name, m in summary["models"].items()}
    assert selection["by_cv"] == summary["best_by_cv"] == min(cv, key=cv.__getitem__)
    for name in ("plr", "xgb"):
        family = selection["families"][name]
        assert family["cv_rmse_deg"] == pytest.approx(cv[name])
        assert family["transfer_rmse_deg"] > 0 and family["transfer_strategy"]
    assert set(selection["strategies_left_out"]["plr"]) >= {"experimental", "refined"}
    table = pd.read_csv(out / "summary.csv")
    assert table.set_index("model")["transfer_rmse_deg"].to_dict() == pytest.approx(scores)
    assert table.loc[table["selected_by_transfer"], "model"].tolist() == [summary["best"]]
    pairs = pd.read_csv(out / "transfer_selection.csv")
    assert set(pairs["base"]) == {"plr", "xgb"}
    assert float(pairs["rmse_deg"].min()) == pytest.approx(min(scores.values()))


def test_train_without_measurements_keeps_the_cross_validated_choice(bases):
    folder = bases["plr"].parents[1]
    assert not (folder / "transfer_selection.csv").exists()
    table = pd.read_csv(folder / "summary.csv")
    assert "transfer_rmse_deg" not in table.columns


def test_train_refuses_measurements_it_cannot_read_before_any_fit(tmp_path, capsys):
    out = tmp_path / "t"
    argv = ("train", SIMULATIONS, "--actuator", ACTUATOR, "--models", "plr", *QUICK, "-o", out)
    assert _run(*argv, "--measurements", tmp_path / "none.csv") == 2
    assert "none.csv" in one_error_line(capsys)
    other = tmp_path / "other.csv"
    other.write_text("l,r,t,b,phi,lc,pressure_mpa,angle_deg\n100,6,2,2,5,8,0.1,20\n")
    assert _run(*argv, "--measurements", other) == 2
    line = one_error_line(capsys)
    assert "measurements" in line and "lacks the column(s)" in line
    assert not out.exists()
