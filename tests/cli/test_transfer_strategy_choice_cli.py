"""``softbend transfer loco|refine``: the strategies that fit the base, and fits that fail alone."""

from __future__ import annotations

import csv
import json

import numpy as np
import pytest

from softbend.cli import main
from softbend.surrogates.persistence import load_surrogate

from ..stand_ins import actuator_law, actuator_plr_base, actuator_table
from .conftest import one_error_line

BUILT = {  # id: (n_chambers, wall_mm, height_mm, layer)
    "P1": (8, 1.5, 10.0, "paper"),
    "P2": (12, 2.5, 14.0, "fabric"),
    "P3": (10, 2.0, 12.0, "paper"),
}
HEADER = "actuator,n_chambers,wall_mm,height_mm,layer,p_kpa,angle_deg"
#: What 'all' leaves out for a polynomial base of another actuator than paper B's.
NOT_FOR_PLR = {"analytical", "refined", "refined-ensemble", "scaled-refined"}


def _reading(name: str, p: float) -> str:
    n, wall, height, layer = BUILT[name]
    angle = 0.7 * actuator_law(n, wall, height, layer, p)
    return f"{name},{n},{wall},{height},{layer},{p},{angle:.3f}"


@pytest.fixture(scope="module")
def plr_lab(tmp_path_factory):
    """A polynomial base of a kPa actuator (seconds), its readings, and readings of two
    actuators of which one was measured at 0 kPa only."""
    folder = tmp_path_factory.mktemp("plr")
    sims = folder / "sims.csv"
    actuator_table(designs=30).to_csv(sims, index=False)
    base = actuator_plr_base(sims, folder / "m")
    pressures = (0.0, 10.0, 20.0, 30.0, 40.0, 50.0)
    readings = folder / "readings.csv"
    readings.write_text(
        "\n".join([HEADER] + [_reading(name, p) for name in BUILT for p in pressures]) + "\n"
    )
    zero = folder / "zero.csv"  # P1 over its pressures, P3 at rest only
    zero.write_text(
        "\n".join([HEADER] + [_reading("P1", p) for p in pressures] + [_reading("P3", 0.0)] * 2)
        + "\n"
    )
    return base, readings, zero


def _warnings(err: str) -> list[str]:
    return [line for line in err.splitlines() if line.startswith("softbend: warning: ")]


def test_loco_all_runs_what_applies_to_a_polynomial_base_and_says_what_it_left_out(
    plr_lab, tmp_path, capsys
):
    base, readings, _ = plr_lab
    argv = ["transfer", "loco", str(readings), "--base", str(base), "--out", str(tmp_path / "o")]
    code = main([*argv, "--set", "epochs=5", "--no-learning-curve", "--json"])
    captured = capsys.readouterr()
    assert code == 0, captured.err
    record = json.loads(captured.out)
    assert set(record["settings"]["left_out"]) == NOT_FOR_PLR
    assert "plr surrogate, not an mlp" in record["settings"]["left_out"]["refined"]
    assert [r["strategy"] for r in record["summary"]] == [
        "fem-only",
        "base-mean-residual",
        "experimental",
        "scale-offset",
        "pressure-scale",
        "residual-gp",
    ]
    (line,) = [w for w in _warnings(captured.err) if "left out" in w]
    assert "refined, refined-ensemble, scaled-refined (trains the base's network further" in line
    assert "the base is a plr surrogate, not an mlp" in line and "analytical (" in line


def test_a_strategy_that_cannot_take_the_base_is_refused_before_any_work(plr_lab, tmp_path, capsys):
    base, _, _ = plr_lab
    unread = tmp_path / "unread.csv"  # never read: the refusal comes first
    unread.write_text("not,a,measurements,file\n")
    out = tmp_path / "o"
    code = main(
        [
            *("transfer", "loco", str(unread), "--base", str(base), "--out", str(out)),
            *("--strategies", "scale-offset,refined"),
        ]
    )
    assert code == 2
    assert one_error_line(capsys) == (
        "softbend: error: --strategies: 'refined' trains the base's network further, and the "
        "base is a plr surrogate, not an mlp; the strategies that apply to this plr base: "
        "fem-only, base-mean-residual, experimental, scale-offset, pressure-scale, residual-gp"
    )
    assert not out.exists()
    model = tmp_path / "m.json"
    code = main(
        [
            *("transfer", "refine", str(base), str(unread), "--out", str(model)),
            *("--strategy", "scaled-refined"),
        ]
    )
    assert code == 2
    line = one_error_line(capsys)
    assert line.startswith("softbend: error: --strategy: 'scaled-refined' trains the base's")
    assert line.endswith(
        "apply to this plr base: experimental, scale-offset, pressure-scale, residual-gp"
    )
    assert not model.exists()


def test_refine_without_a_strategy_fits_one_that_takes_the_base_and_says_so(
    plr_lab, tmp_path, capsys
):
    base, readings, _ = plr_lab
    model = tmp_path / "m.json"
    code = main(["transfer", "refine", str(base), str(readings), "--out", str(model)])
    captured = capsys.readouterr()
    assert code == 0, captured.err
    saved = load_surrogate(model)
    assert saved.metadata["strategy"] == "scale-offset"
    assert set(saved.metadata["strategy_left_out"]) == {"refined"}
    (line,) = [w for w in _warnings(captured.err) if "--strategy" in w]
    assert "'refined' trains the base's network further" in line
    assert "fitted 'scale-offset' instead" in line


def test_a_fit_that_fails_on_one_held_out_actuator_is_reported_and_the_rest_written(
    plr_lab, tmp_path, capsys
):
    base, _, zero = plr_lab
    out = tmp_path / "o"
    code = main(
        [
            *("transfer", "loco", str(zero), "--base", str(base), "--out", str(out), "--json"),
            *("--strategies", "fem-only,scale-offset,pressure-scale", "--no-learning-curve"),
        ]
    )
    captured = capsys.readouterr()
    assert code == 0, captured.err
    record = json.loads(captured.out)
    rows = {(r["strategy"], r["actuator_id"]): r for r in record["per_actuator"]}
    failed = {key for key, r in rows.items() if r["status"] == "failed"}
    # held out P1, the others are P3's two readings at rest: no scale is fitted on them
    assert failed == {("scale-offset", "P1"), ("pressure-scale", "P1")}
    for key in failed:
        assert rows[key]["rmse_deg"] is None
    assert all(np.isfinite(r["rmse_deg"]) for key, r in rows.items() if key not in failed)
    # the model's own unit and column, never a class or method
    reason = rows[("pressure-scale", "P1")]["error"]
    assert "above 0 kPa (column 'p_kpa')" in reason and "MPa" not in reason
    assert ".fit" not in reason and "Regressor" not in reason
    summary = {r["strategy"]: r for r in record["summary"]}
    assert summary["pressure-scale"]["n_failed"] == 1 and summary["fem-only"]["n_failed"] == 0
    assert np.isfinite(summary["pressure-scale"]["rmse_deg"])  # on P3
    assert [(f["strategy"], f["actuator_id"]) for f in record["settings"]["failed"]] == [
        ("scale-offset", "P1"),
        ("pressure-scale", "P1"),
    ]
    with open(out / "per_actuator.csv", newline="") as table:
        written = {(r["strategy"], r["actuator_id"]): r for r in csv.DictReader(table)}
    assert written[("pressure-scale", "P1")]["status"] == "failed"
    assert "0 kPa" in written[("pressure-scale", "P1")]["error"]
    assert (out / "fig7_actuators.png").is_file()
    (line,) = _warnings(captured.err)
    assert "2 fit(s) failed" in line
    assert "scale-offset on held-out P1, pressure-scale on held-out P1" in line


def test_a_learning_curve_fit_that_fails_is_reported_in_its_table(plr_lab, tmp_path, capsys):
    base, readings, _ = plr_lab
    three = tmp_path / "three.csv"  # P1 and P2 over their pressures, P3 at rest only
    lines = [line for line in readings.read_text().splitlines() if not line.startswith("P3,")]
    three.write_text("\n".join([*lines, _reading("P3", 0.0), _reading("P3", 0.0)]) + "\n")
    out = tmp_path / "o"
    code = main(
        [
            *("transfer", "loco", str(three), "--base", str(base), "--out", str(out)),
            *("--strategies", "scale-offset"),
        ]
    )
    captured = capsys.readouterr()
    assert code == 0, captured.err
    with open(out / "learning_curve.csv", newline="") as table:
        rows = list(csv.DictReader(table))
    failed = [r for r in rows if r["error"]]
    assert failed and all(r["rmse_deg"] == "" and r["n_actuators"] == "1" for r in failed)
    assert "must hold at least 3 readings" in failed[0]["error"]
    assert all(r["rmse_deg"] for r in rows if not r["error"])
    (line,) = _warnings(captured.err)
    assert f"{len(failed)} fit(s) of the learning curve or the calibration failed" in line


def test_a_batched_network_fit_that_fails_on_one_held_out_actuator_leaves_the_others(
    tmp_path, capsys, small_base_file
):
    readings = tmp_path / "zero.csv"
    lines = ["actuator_id,l,r,t,b,phi,lc,pressure_mpa,angle_deg"]
    lines += [f"A,100,6,2,2,5,8,{p:.2f},{600 * p:.2f}" for p in (0.0, 0.02, 0.04, 0.06, 0.08)]
    lines += ["Z,120,6,2,2,5,8,0.0,0.1", "Z,120,6,2,2,5,8,0.0,-0.1"]  # at rest only
    readings.write_text("\n".join(lines) + "\n")
    out = tmp_path / "o"
    code = main(
        [
            *("transfer", "loco", str(readings), "--base", str(small_base_file), "--out", str(out)),
            *("--strategies", "refined,scaled-refined", "--set", "epochs=5", "--json"),
        ]
    )
    captured = capsys.readouterr()
    assert code == 0, captured.err
    record = json.loads(captured.out)
    status = {(r["strategy"], r["actuator_id"]): r["status"] for r in record["per_actuator"]}
    assert status == {
        ("refined", "A"): "ok",
        ("refined", "Z"): "ok",
        ("scaled-refined", "A"): "failed",  # its pressure scale, fitted on Z at rest
        ("scaled-refined", "Z"): "ok",
    }
    (failure,) = record["settings"]["failed"]
    assert "must include a pressure above 0 MPa (column 'pressure_mpa')" in failure["error"]
    assert "scaled-refined on held-out A" in _warnings(captured.err)[0]
