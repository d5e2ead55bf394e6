"""``softbend lab`` and ``softbend transfer``: files written, bad input as one line."""

from __future__ import annotations

import errno
import json
import time

import pytest

from softbend._outdir import MANIFEST, write_manifest
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
        "patience": 1000,
        "min_delta": 1e-3,
        "validation_share": 0.2,
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
        "patience": 1000,
        "min_delta": 1e-3,
        "validation_share": 0.2,
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
        assert "bench.csv: angle_deg: the actuator '130,7,2.5,3,10,9' reaches only 0.8" in line
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


# --- ``softbend lab`` and ``softbend transfer`` on bad input and failing disks ---
#
# Whatever goes wrong, a command prints one line and leaves its previous outputs
# (or nothing): never a traceback, a half-written output or a model with
# non-finite numbers.


FULL = "No space left on device"


def _full(*args, **kwargs):
    raise OSError(errno.ENOSPC, FULL)


def _strict_json(text: str):
    """Parse ``text`` as strict JSON (no NaN or Infinity tokens)."""

    def refuse(token):
        raise AssertionError(f"not strict JSON: {token}")

    return json.loads(text, parse_constant=refuse)


def _listing(folder):
    return sorted(p.name for p in folder.iterdir())


@pytest.fixture(scope="module")
def lab_csv_fault(tmp_path_factory):
    out = tmp_path_factory.mktemp("lab") / "lab.csv"
    argv = ["lab", "measure", "--plant", "analytical", "--pmax", "0.12", "--out", str(out)]
    assert main([*argv, "--json"]) == 0
    return out


def _with_angle(lab_csv_fault, tmp_path, value: str, name: str = "bad.csv"):
    """The lab CSV with the angle of its fifth reading replaced by ``value``; and that line."""
    lines = lab_csv_fault.read_text().splitlines()
    header = next(i for i, line in enumerate(lines) if not line.startswith("#"))
    column = lines[header].split(",").index("angle_deg")
    cells = lines[header + 5].split(",")
    cells[column] = value
    lines[header + 5] = ",".join(cells)
    path = tmp_path / name
    path.write_text("\n".join(lines) + "\n")
    return path, header + 6


# ------------------------------------------------------------------ lab measure
def test_lab_measure_refuses_a_billion_cycles_at_once(tmp_path, capsys):
    out = tmp_path / "lab.csv"
    start = time.perf_counter()
    argv = ["lab", "measure", "--plant", "analytical", "--cycles", "1000000000"]
    assert main([*argv, "--out", str(out)]) == 2
    assert time.perf_counter() - start < 5.0
    line = one_error_line(capsys)
    assert line.startswith("softbend: error: --cycles: ") and "1,000,000,000 cycles" in line
    assert "limit of 1,000" in line
    assert "SOFTBEND_MAX_CYCLES" in line
    assert _listing(tmp_path) == []


def test_lab_measure_refuses_an_out_its_figure_would_replace(tmp_path, capsys):
    assert main(["lab", "measure", "--plant", "analytical", "--out", str(tmp_path / "x.png")]) == 2
    line = one_error_line(capsys)
    assert "'--out' must name the CSV file" in line and "x.png" in line
    assert _listing(tmp_path) == []


def test_lab_measure_a_max_angle_below_the_first_step_is_one_line(tmp_path, capsys):
    out = tmp_path / "lab.csv"
    argv = ["lab", "measure", "--plant", "analytical", "--max-angle", "0.01", "--out", str(out)]
    assert main(argv) == 2
    line = one_error_line(capsys)
    assert "softbend: error: --max-angle: (0.01°) stops actuator" in line
    assert "raise it, or lower the pressure step" in line
    assert "max_angle_deg" not in line and "VirtualLab" not in line
    assert _listing(tmp_path) == []


def _old_lab_outputs(tmp_path):
    out = tmp_path / "lab.csv"
    out.write_text("old csv\n")
    figure = tmp_path / "lab.png"
    figure.write_bytes(b"\x89PNG old")
    return out, figure


def test_lab_measure_failing_on_the_figure_keeps_the_previous_csv(tmp_path, monkeypatch, capsys):
    import softbend.reports.transfer_figures as figures

    out, figure = _old_lab_outputs(tmp_path)
    monkeypatch.setattr(figures, "lab_measurements", _full)
    argv = ["lab", "measure", "--plant", "analytical", "--pmax", "0.05", "--out", str(out)]
    assert main([*argv, "--json"]) == 2  # --json: no progress lines
    assert one_error_line(capsys) == (
        f"softbend: error: The '--out' {figure} could not be written: {FULL}."
    )
    assert out.read_text() == "old csv\n" and figure.read_bytes() == b"\x89PNG old"
    assert _listing(tmp_path) == ["lab.csv", "lab.png"]


def test_lab_measure_failing_on_the_csv_names_it_and_writes_nothing(tmp_path, monkeypatch, capsys):
    import softbend.cli.transfer_lab as command

    out, figure = _old_lab_outputs(tmp_path)

    def full_open(path, *args, **kwargs):
        raise OSError(errno.ENOSPC, FULL, str(path))

    monkeypatch.setattr(command, "open", full_open, raising=False)
    argv = ["lab", "measure", "--plant", "analytical", "--pmax", "0.05", "--out", str(out)]
    assert main([*argv, "--json"]) == 2  # --json: no progress lines
    assert one_error_line(capsys) == (
        f"softbend: error: The '--out' {out} could not be written: {FULL}."
    )
    assert out.read_text() == "old csv\n" and figure.read_bytes() == b"\x89PNG old"
    assert _listing(tmp_path) == ["lab.csv", "lab.png"]


def test_lab_measure_replaces_both_outputs_when_it_succeeds(tmp_path, capsys):
    out, figure = _old_lab_outputs(tmp_path)
    out.chmod(0o640)
    argv = ["lab", "measure", "--plant", "analytical", "--pmax", "0.05", "--out", str(out)]
    assert main([*argv, "--json"]) == 0
    summary = _strict_json(capsys.readouterr().out)
    assert summary["out"] == str(out) and summary["figure"] == str(figure)
    assert out.read_text().startswith("# softbend measurements CSV v1\n# synthetic: true\n")
    assert figure.read_bytes()[:4] == b"\x89PNG" and figure.stat().st_size > 1000
    assert out.stat().st_mode & 0o777 == 0o640  # the replaced file's permissions
    assert _listing(tmp_path) == ["lab.csv", "lab.png"]


# ---------------------------------------------------------------- transfer loco
def _loco(lab_csv_fault, out, base, *extra):
    argv = ["transfer", "loco", str(lab_csv_fault), "--base", str(base), "--out", str(out)]
    argv += ["--strategies", "fem-only,scale-offset", "--no-learning-curve", "--json"]
    return main([*argv, *extra])  # --json: no progress lines


def test_loco_failing_on_a_figure_keeps_the_previous_results(
    lab_csv_fault, tmp_path, monkeypatch, capsys, small_base_file
):
    import softbend.reports.transfer_figures as figures

    out = tmp_path / "loco"
    out.mkdir()
    (out / "loco.json").write_text('{"old": true}\n')
    write_manifest(out, "transfer loco", complete=True)  # an earlier result of the command
    monkeypatch.setattr(figures, "actuator_panels", _full)
    assert _loco(lab_csv_fault, out, small_base_file) == 2
    assert one_error_line(capsys) == (
        f"softbend: error: The '--out' {out} could not be written: {FULL}."
    )
    assert _listing(out) == [MANIFEST, "loco.json"]
    assert (out / "loco.json").read_text() == '{"old": true}\n'
    assert _listing(tmp_path) == ["loco"]  # no staging folder left


def test_loco_an_os_error_inside_the_folder_names_the_final_file(
    lab_csv_fault, tmp_path, monkeypatch, capsys, small_base_file
):
    import softbend.reports.transfer_figures as figures

    def denied(result, path, **kwargs):
        raise PermissionError(errno.EACCES, "Permission denied", str(path))

    monkeypatch.setattr(figures, "loss_curves", denied)
    out = tmp_path / "loco"
    assert _loco(lab_csv_fault, out, small_base_file) == 2
    assert one_error_line(capsys) == (
        f"softbend: error: The '--out' {out} could not be written: Permission denied "
        f"({out / 'fig6_loss_curves.png'})."
    )
    assert _listing(tmp_path) == []


def test_loco_writes_its_folder_whole_with_strict_json(
    lab_csv_fault, tmp_path, capsys, small_base_file
):
    out = tmp_path / "loco"
    out.mkdir()
    (out / "learning_curve.png").write_bytes(b"an earlier run's figure")
    write_manifest(out, "transfer loco", complete=True)  # of an earlier run
    assert _loco(lab_csv_fault, out, small_base_file) == 0
    payload = _strict_json(capsys.readouterr().out)
    # The old folder is gone as a whole: no figure of an earlier run beside the new tables.
    assert "learning_curve.png" not in _listing(out)
    written = {str(out / name) for name in _listing(out) if name != MANIFEST}
    assert set(payload["files"].values()) == written
    saved = _strict_json((out / "loco.json").read_text())
    fem_only = next(r for r in saved["summary"] if r["strategy"] == "fem-only")
    assert fem_only["coverage"] is None  # NaN written as null
    assert _listing(tmp_path) == ["loco"]


def test_loco_never_replaces_a_folder_holding_other_files(
    lab_csv_fault, tmp_path, capsys, small_base_file
):
    out = tmp_path / "results"
    out.mkdir()
    (out / "notes.txt").write_text("mine\n")
    assert _loco(lab_csv_fault, out, small_base_file) == 2
    line = one_error_line(capsys)
    assert "'--out'" in line and "notes.txt" in line and "replaced as a whole" in line
    assert (out / "notes.txt").read_text() == "mine\n"
    inside = out / "lab.csv"
    inside.write_text(lab_csv_fault.read_text())
    (out / "notes.txt").unlink()
    assert _loco(inside, out, small_base_file) == 2
    assert f"holds the 'MEASUREMENTS' {inside}" in one_error_line(capsys)
    assert _listing(out) == ["lab.csv"]


def test_loco_refuses_a_file_over_the_row_limit_quickly(
    lab_csv_fault, tmp_path, monkeypatch, capsys, small_base_file
):
    monkeypatch.setenv("SOFTBEND_MAX_CSV_ROWS", "10")
    assert _loco(lab_csv_fault, tmp_path / "o", small_base_file) == 2
    line = one_error_line(capsys)
    assert (
        str(lab_csv_fault) in line
        and "limit of 10 rows" in line
        and "SOFTBEND_MAX_CSV_ROWS" in line
    )


# -------------------------------------------------------------- transfer refine
def test_refine_an_absurd_angle_is_one_line_and_no_model(
    lab_csv_fault, tmp_path, capsys, small_base_file
):
    bad, line_number = _with_angle(lab_csv_fault, tmp_path, "1e300")
    out = tmp_path / "model.json"
    argv = ["transfer", "refine", str(small_base_file), str(bad), "--out", str(out)]
    assert main([*argv, "--strategy", "scale-offset"]) == 2
    line = one_error_line(capsys)  # no overflow warnings before it
    assert f"{bad}:{line_number}:8: angle_deg: 1e+300" in line
    assert "-3600 to 3600" in line
    assert not out.exists()


def test_refine_a_bad_metadata_header_is_one_line(lab_csv_fault, tmp_path, capsys, small_base_file):
    text = lab_csv_fault.read_text().replace("# synthetic: true", "# synthetic: maybe")
    bad = tmp_path / "meta.csv"
    bad.write_text(text)
    argv = ["transfer", "refine", str(small_base_file), str(bad), "--out", str(tmp_path / "m.json")]
    assert main([*argv, "--strategy", "scale-offset"]) == 2
    assert f"{bad}:2: synthetic: must be 'true' or 'false'" in one_error_line(capsys)


def test_refine_on_a_full_disk_names_the_option_and_keeps_the_old_model(
    lab_csv_fault, tmp_path, monkeypatch, capsys, small_base_file
):
    import softbend._io as io

    out = tmp_path / "model.json"
    out.write_text('{"format": "softbend-surrogate", "old": true}\n')

    def full(*args, **kwargs):
        raise OSError(errno.ENOSPC, FULL)

    monkeypatch.setattr(io.os, "replace", full)
    argv = ["transfer", "refine", str(small_base_file), str(lab_csv_fault), "--out", str(out)]
    assert main([*argv, "--strategy", "scale-offset"]) == 2
    lines = capsys.readouterr().err.strip().splitlines()
    # The lab file's few actuators earn a warning about the calibration first.
    assert all(line.startswith("softbend: warning: ") for line in lines[:-1])
    assert lines[-1] == f"softbend: error: The '--out' {out} could not be written: {FULL}."
    assert out.read_text() == '{"format": "softbend-surrogate", "old": true}\n' and _listing(
        tmp_path
    ) == ["model.json"]


@pytest.mark.parametrize("strategy", ["scale-offset", "residual-gp"])
def test_refine_writes_strict_json(lab_csv_fault, tmp_path, capsys, small_base_file, strategy):
    out = tmp_path / "model.json"
    argv = ["transfer", "refine", str(small_base_file), str(lab_csv_fault), "--out", str(out)]
    assert main([*argv, "--strategy", strategy]) == 0
    saved = _strict_json(out.read_text())
    assert saved["metadata"]["strategy"] == strategy


def test_refine_a_non_finite_figure_is_one_line_and_no_model(
    lab_csv_fault, tmp_path, monkeypatch, capsys, small_base_file
):
    import softbend.transfer.refine as refine

    fit = refine.fit_strategy

    def with_nan_loss(*args, **kwargs):
        model = fit(*args, **kwargs)
        model.loss_curve_ = [float("nan")]
        return model

    monkeypatch.setattr(refine, "fit_strategy", with_nan_loss)
    out = tmp_path / "model.json"
    argv = ["transfer", "refine", str(small_base_file), str(lab_csv_fault), "--out", str(out)]
    assert main([*argv, "--strategy", "scale-offset"]) == 2
    lines = capsys.readouterr().err.strip().splitlines()
    assert lines[-1] == (
        "softbend: error: The 'scale-offset' refit's final training MSE (deg²) is nan, not a "
        "finite number; it is not saved. Check the strategy's parameters (a smaller "
        "learning_rate) and the measurements"
    )
    assert not out.exists() and _listing(tmp_path) == []


# ---------------------------------------------------------------- transfer base
def test_base_on_a_full_disk_names_the_option(tmp_path, monkeypatch, capsys):
    import softbend.surrogates.persistence as persistence

    monkeypatch.setattr(persistence, "save_surrogate", _full)
    out = tmp_path / "base.json"
    assert main(["transfer", "base", "--out", str(out), "--epochs", "1"]) == 2
    err = capsys.readouterr().err.strip().splitlines()  # progress lines, then the error
    assert [line for line in err if line.startswith("softbend:")] == [
        f"softbend: error: The '--out' {out} could not be written: {FULL}."
    ]
    assert err[-1].startswith("softbend: error:") and not out.exists()
