"""``softbend lab`` and ``softbend transfer``: files written, bad input as one line."""

from __future__ import annotations

import json

import pytest

from softbend.cli import main

from .conftest import one_error_line

GOOD_HEADER = "l,r,t,b,phi,lc,pressure_mpa,angle_deg\n"


@pytest.fixture(scope="module")
def lab_csv(tmp_path_factory):
    out = tmp_path_factory.mktemp("lab") / "lab.csv"
    code = main(
        ["lab", "measure", "--plant", "analytical", "--pmax", "0.12", "--out", str(out), "--json"]
    )
    assert code == 0
    return out


def test_lab_measure_writes_a_synthetic_csv_and_its_figure(lab_csv):
    text = lab_csv.read_text()
    assert "# synthetic: true" in text and "# lab.fabrication_error_mm: 0.2" in text
    assert lab_csv.with_suffix(".png").is_file()


def test_lab_measure_json_summary(tmp_path, capsys):
    out = tmp_path / "lab.csv"
    assert (
        main(
            [
                "lab",
                "measure",
                "--plant",
                "analytical",
                "--pmax",
                "0.05",
                "--out",
                str(out),
                "--json",
            ]
        )
        == 0
    )
    summary = json.loads(capsys.readouterr().out)
    assert summary["synthetic"] is True and len(summary["actuators"]) == 7
    assert summary["n_measurements"] == sum(a["points"] for a in summary["actuators"])


def test_loco_then_refine_then_predict(lab_csv, tmp_path, capsys, small_base_file):
    out = tmp_path / "loco"
    code = main(
        [
            "transfer",
            "loco",
            str(lab_csv),
            "--base",
            str(small_base_file),
            "--out",
            str(out),
            "--strategies",
            "fem-only,scale-offset",
            "--json",
        ]
    )
    assert code == 0
    payload = json.loads(capsys.readouterr().out)
    assert {r["strategy"] for r in payload["summary"]} == {"fem-only", "scale-offset"}
    assert payload["synthetic"] is True
    for name in (
        "summary.csv",
        "loco.json",
        "fig7_actuators.png",
        "fig6_loss_curves.png",
        "learning_curve.png",
    ):
        assert (out / name).is_file(), name
    model = tmp_path / "refined.json"
    assert (
        main(
            [
                "transfer",
                "refine",
                str(small_base_file),
                str(lab_csv),
                "--out",
                str(model),
                "--epochs",
                "20",
            ]
        )
        == 0
    )
    # Off a terminal, the refit's epochs and the calibration's refits are plain lines.
    err = capsys.readouterr().err
    assert "training 1 network (epochs): 20/20" in err
    assert "training 7 networks (epochs): 20/20" in err  # one refit per actuator left out
    assert (
        main(["predict", str(model), "--design", "100,6,2,2,5,8", "--pressures", "0.05", "--json"])
        == 0
    )
    angle = json.loads(capsys.readouterr().out)["angle_deg"][0]
    assert 0.0 < angle < 180.0


@pytest.mark.parametrize(
    ("body", "needle"),
    [
        ("", "has no column header"),
        ("l,r,t,b,phi,lc,pressure_mpa\n100,6,2,2,5,8,0.1\n", "angle_deg"),
        (GOOD_HEADER + "100,6,2,2,5,8,0.1,nan\n", "angle_deg"),
        (GOOD_HEADER + "100,6,2,2,5,8,-0.1,20\n", "pressure_mpa"),
        (GOOD_HEADER + "100,6,2,2,5,8,abc,20\n", "pressure_mpa"),
        (GOOD_HEADER + "100,-6,2,2,5,8,0.1,20\n", "bad.csv:2:2: r: "),
        (GOOD_HEADER + "100,6,2,2,5,8,0.1\n", "bad.csv:2: "),
        ("l,r,t,b,phi,lc,pressure_mpa,angle_deg,colour\n100,6,2,2,5,8,0.1,20,red\n", "colour"),
        (GOOD_HEADER.strip() + ",direction\n100,6,2,2,5,8,0.1,20,sideways\n", "direction"),
    ],
)
def test_bad_measurement_files_are_one_line_exit_2(tmp_path, capsys, body, needle, small_base_file):
    path = tmp_path / "bad.csv"
    path.write_text(body)
    code = main(
        [
            "transfer",
            "loco",
            str(path),
            "--base",
            str(small_base_file),
            "--out",
            str(tmp_path / "o"),
        ]
    )
    assert code == 2
    line = one_error_line(capsys)
    assert "bad.csv" in line and needle in line


def test_unknown_strategy_and_bad_out_are_refused_before_work(
    lab_csv, tmp_path, capsys, small_base_file
):
    code = main(
        [
            "transfer",
            "loco",
            str(lab_csv),
            "--base",
            str(small_base_file),
            "--out",
            str(tmp_path / "o"),
            "--strategies",
            "magic",
        ]
    )
    line = one_error_line(capsys)
    assert code == 2 and "--strategies: unknown transfer strategy 'magic'" in line.lower()
    assert "known: fem-only, base-mean-residual, analytical" in line
    a_file = tmp_path / "file.txt"
    a_file.write_text("x")
    code = main(
        ["transfer", "loco", str(lab_csv), "--base", str(small_base_file), "--out", str(a_file)]
    )
    assert code == 2 and "--out" in one_error_line(capsys)
    code = main(["lab", "measure", "--plant", "abaqus", "--out", str(tmp_path / "x.csv")])
    assert code == 2 and "--plant: unknown lab model 'abaqus'" in one_error_line(capsys).lower()
    code = main(
        [
            "transfer",
            "refine",
            str(small_base_file),
            str(lab_csv),
            "--out",
            str(tmp_path / "m.json"),
            "--strategy",
            "analytical",
        ]
    )
    line = one_error_line(capsys)
    assert code == 2 and "'analytical' learns nothing" in line and "refined, " in line
    code = main(
        [
            "transfer",
            "refine",
            str(small_base_file),
            str(lab_csv),
            "--out",
            str(tmp_path / "m.json"),
            "--strategy",
            "residual-gp",
            "--epochs",
            "5",
        ]
    )
    line = one_error_line(capsys)
    assert code == 2 and line.startswith("softbend: error: --set: epochs: is not a parameter")
    assert "known: n_restarts" in line


def test_transfer_base_and_refine_bad_input_is_one_line(tmp_path, capsys, small_base_file, lab_csv):
    code = main(["transfer", "base", "--out", str(tmp_path / "b.json"), "--epochs", "0"])
    assert code == 2 and "epochs" in one_error_line(capsys)
    code = main(
        [
            "transfer",
            "refine",
            str(small_base_file),
            str(tmp_path / "missing.csv"),
            "--out",
            str(tmp_path / "r.json"),
        ]
    )
    assert code == 2 and "missing.csv" in one_error_line(capsys)
    code = main(
        [
            "transfer",
            "refine",
            str(tmp_path / "nobase.json"),
            str(lab_csv),
            "--out",
            str(tmp_path / "r.json"),
        ]
    )
    assert code == 2 and "nobase.json" in one_error_line(capsys)
    # Readings at 0 MPa only: no pressure scale can be fitted.
    lines = lab_csv.read_text().splitlines()
    header = next(i for i, line in enumerate(lines) if not line.startswith("#"))
    column = lines[header].split(",").index("pressure_mpa")
    unpressurized = tmp_path / "zero.csv"
    unpressurized.write_text(
        "\n".join(
            lines[: header + 1]
            + [r for r in lines[header + 1 :] if float(r.split(",")[column]) == 0.0]
        )
        + "\n"
    )
    code = main(
        [
            "transfer",
            "refine",
            str(small_base_file),
            str(unpressurized),
            "--out",
            str(tmp_path / "r.json"),
            "--strategy",
            "pressure-scale",
        ]
    )
    assert code == 2 and "pressure above 0 MPa" in one_error_line(capsys)


@pytest.mark.parametrize(
    ("strategy", "options", "interval"),
    [
        ("experimental", ["--epochs", "20"], True),  # every refined model: calibrated
        ("scale-offset", [], True),
        ("pressure-scale", [], True),
        ("residual-gp", [], True),
        ("refined-ensemble", ["--epochs", "20"], True),
        ("scaled-refined", ["--epochs", "20"], True),
    ],
)
def test_every_refine_strategy_saves_a_model_that_predicts(
    strategy, options, interval, lab_csv, tmp_path, capsys, small_base_file
):
    model = tmp_path / f"{strategy}.json"
    argv = ["transfer", "refine", str(small_base_file), str(lab_csv), "--out", str(model)]
    assert main([*argv, "--strategy", strategy, *options]) == 0
    capsys.readouterr()
    saved = json.loads(model.read_text())
    assert saved["metadata"]["strategy"] == strategy
    assert saved["metadata"]["training_rmse_deg"] >= 0.0
    argv = ["predict", str(model), "--design", "100,6,2,2,5,8", "--pressures", "0,0.05", "--json"]
    assert main(argv) == 0
    result = json.loads(capsys.readouterr().out)
    assert ("interval_low_deg" in result) is interval
    if interval:
        low, high, angle = (
            result[k] for k in ("interval_low_deg", "interval_high_deg", "angle_deg")
        )
        # The low end may sit on the angle where the floor (0°) lifts it.
        assert all(lo <= a < hi for lo, a, hi in zip(low, angle, high, strict=True))
        assert result["interval_level"] == 0.9
        # The table shows the interval too.
        assert (
            main(["predict", str(model), "--design", "100,6,2,2,5,8", "--pressures", "0.05"]) == 0
        )
        assert "90% interval" in capsys.readouterr().out


def test_refine_parameters_by_set_are_recorded_and_match_the_epochs_option(
    lab_csv, tmp_path, capsys, small_base_file
):
    argv = ["transfer", "refine", str(small_base_file), str(lab_csv)]
    by_option, by_set = tmp_path / "a.json", tmp_path / "b.json"
    assert main([*argv, "--out", str(by_option), "--epochs", "20"]) == 0
    assert (
        main([*argv, "--out", str(by_set), "--set", "epochs=20", "--set", "learning_rate=6e-4"])
        == 0
    )
    capsys.readouterr()
    a, b = (json.loads(p.read_text()) for p in (by_option, by_set))
    assert a["metadata"]["parameters"] == {
        "epochs": 20,
        "learning_rate": 6e-4,
        "device": "auto",
        "seed": 0,
    }
    assert b["metadata"]["parameters"] == a["metadata"]["parameters"]
    assert a["state"] == b["state"]
    bad = [*argv, "--out", str(tmp_path / "c.json")]
    assert main([*bad, "--epochs", "20", "--set", "epochs=30"]) == 2
    assert "given twice" in one_error_line(capsys)
    assert main([*bad, "--set", "epochs=many"]) == 2
    line = one_error_line(capsys)
    assert line.startswith("softbend: error: --set: epochs: must be an integer; got 'many'")
    assert main([*bad, "--set", "epochs"]) == 2
    assert "NAME=VALUE" in one_error_line(capsys)
    assert not (tmp_path / "c.json").exists()


def test_loco_set_reaches_the_strategies_of_the_run(lab_csv, tmp_path, capsys, small_base_file):
    argv = ["transfer", "loco", str(lab_csv), "--base", str(small_base_file)]
    argv += ["--out", str(tmp_path / "o"), "--strategies", "fem-only,scale-offset"]
    assert main([*argv, "--set", "epochs=5"]) == 2
    line = one_error_line(capsys)
    assert line.startswith("softbend: error: --set: epochs: is not a parameter of any strategy")
    assert "(fem-only, scale-offset)" in line
    assert main([*argv, "--set", "refined.epoch=5"]) == 2
    line = one_error_line(capsys)
    assert line.startswith("softbend: error: --set: epoch: is not a parameter; known: epochs")
    assert not (tmp_path / "o").exists()


def test_strategies_lists_every_strategy_with_its_parameters(capsys):
    assert main(["transfer", "strategies", "--json"]) == 0
    rows = json.loads(capsys.readouterr().out)
    by_name = {r["name"]: r for r in rows}
    assert list(by_name)[:3] == ["fem-only", "base-mean-residual", "analytical"]
    assert by_name["refined"]["parameters"] == {
        "epochs": 1000,
        "learning_rate": 6e-4,
        "device": "auto",
    }
    assert by_name["experimental"]["parameters"]["hidden_sizes"] == [63, 65]
    assert not by_name["fem-only"]["learns"] and by_name["residual-gp"]["interval"]
    assert main(["transfer", "strategies"]) == 0
    assert "n_restarts=3" in capsys.readouterr().out
    assert main(["transfer", "loco", "--help"]) == 0
    assert "softbend transfer strategies" in " ".join(capsys.readouterr().out.split())


BENCH_CSV = (
    "# operator: AB\n"
    "l,r,t,b,phi,lc,pressure_mpa,angle_deg\n"
    "130,7,2.5,3,10,9,0.0,0.0\n"
    "130,7,2.5,3,10,9,0.05,20.0\n"
    "130,7,2.5,3,10,9,0.1,45.0\n"
)


def test_refine_and_loco_join_several_files_and_record_them(
    lab_csv, tmp_path, capsys, small_base_file
):
    bench = tmp_path / "bench.csv"
    bench.write_text(BENCH_CSV)
    model = tmp_path / "refined.json"
    args = [str(small_base_file), str(lab_csv), str(bench), "--out", str(model)]
    assert main(["transfer", "refine", *args, "--strategy", "scale-offset"]) == 0
    meta = json.loads(model.read_text())["metadata"]
    assert meta["measurements"] == [str(lab_csv), str(bench)]
    assert [(f["path"], f["synthetic"]) for f in meta["measurement_files"]] == [
        (str(lab_csv), True),
        (str(bench), False),
    ]
    assert all(len(f["sha256"]) == 64 for f in meta["measurement_files"])
    assert meta["synthetic_measurements"] == "mixed"
    assert "130,7,2.5,3,10,9" in meta["actuators"]
    capsys.readouterr()
    out = tmp_path / "loco"
    code = main(
        [
            "transfer",
            "loco",
            str(lab_csv),
            str(bench),
            "--base",
            str(small_base_file),
            "--out",
            str(out),
            "--strategies",
            "fem-only,scale-offset",
            "--no-learning-curve",
            "--json",
        ]
    )
    assert code == 0
    payload = json.loads(capsys.readouterr().out)
    assert "130,7,2.5,3,10,9" in payload["settings"]["actuators"]
    saved = json.loads((out / "loco.json").read_text())["settings"]["measurement_files"]
    assert [f["readings"] for f in saved][1] == 3


def test_refine_with_one_file_records_it_as_before(lab_csv, tmp_path, small_base_file):
    model = tmp_path / "one.json"
    args = [str(small_base_file), str(lab_csv), "--out", str(model), "--strategy", "scale-offset"]
    assert main(["transfer", "refine", *args]) == 0
    meta = json.loads(model.read_text())["metadata"]
    assert meta["measurements"] == str(lab_csv) and meta["synthetic_measurements"] == "true"
    assert len(meta["measurement_files"]) == 1


@pytest.mark.parametrize("force", [[], ["--force"]])
def test_kpa_in_the_mpa_column_is_one_line_exit_2(
    lab_csv, tmp_path, capsys, small_base_file, force
):
    bench = tmp_path / "bench.csv"
    bench.write_text(GOOD_HEADER + "130,7,2.5,3,10,9,0,0\n130,7,2.5,3,10,9,50,30\n")
    for command in (
        ["transfer", "refine", str(small_base_file), str(lab_csv), str(bench)],
        ["transfer", "loco", str(lab_csv), str(bench), "--base", str(small_base_file)],
    ):
        assert main([*command, "--out", str(tmp_path / "o"), *force]) == 2
        line = one_error_line(capsys)
        assert "bench.csv:3:7: pressure_mpa: " in line and "looks like kPa" in line


def test_radians_are_one_line_exit_2_and_force_reads_them_with_a_warning(
    lab_csv, tmp_path, capsys, small_base_file
):
    bench = tmp_path / "bench.csv"
    bench.write_text(GOOD_HEADER + "130,7,2.5,3,10,9,0,0\n130,7,2.5,3,10,9,0.1,0.8\n")
    for command in (
        ["transfer", "refine", str(small_base_file), str(lab_csv), str(bench)],
        ["transfer", "loco", str(lab_csv), str(bench), "--base", str(small_base_file)],
    ):
        assert main([*command, "--out", str(tmp_path / "o")]) == 2
        line = one_error_line(capsys)
        assert "bench.csv:3:8: angle_deg: " in line
        assert "look like radians" in line and "--force" in line
    model = tmp_path / "forced.json"
    args = [str(small_base_file), str(lab_csv), str(bench), "--out", str(model)]
    assert main(["transfer", "refine", *args, "--strategy", "scale-offset", "--force"]) == 0
    err = capsys.readouterr().err.splitlines()
    assert any(line.startswith("softbend: warning:") and "radians" in line for line in err)
    assert model.is_file()


def test_one_actuator_id_with_two_designs_in_two_files_names_both(
    tmp_path, capsys, small_base_file
):
    a, b = tmp_path / "a.csv", tmp_path / "b.csv"
    a.write_text(GOOD_HEADER.strip() + ",actuator_id\n100,6,2,2,5,8,0.05,30,P1\n")
    b.write_text(GOOD_HEADER.strip() + ",actuator_id\n130,7,2.5,3,10,9,0.05,20,P1\n")
    code = main(
        ["transfer", "refine", str(small_base_file), str(a), str(b), "--out", str(tmp_path / "m")]
    )
    assert code == 2
    line = one_error_line(capsys)
    assert "a.csv" in line and "b.csv" in line and "'P1'" in line
