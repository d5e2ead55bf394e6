"""``softbend lab`` and ``softbend transfer`` on bad input and failing disks.

Whatever goes wrong, a command prints one line and leaves its previous outputs
(or nothing): never a traceback, a half-written output or a model with
non-finite numbers.
"""

from __future__ import annotations

import errno
import json
import time

import pytest

from softbend.cli import main

from .conftest import one_error_line

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
def lab_csv(tmp_path_factory):
    out = tmp_path_factory.mktemp("lab") / "lab.csv"
    argv = ["lab", "measure", "--plant", "analytical", "--pmax", "0.12", "--out", str(out)]
    assert main([*argv, "--json"]) == 0
    return out


def _with_angle(lab_csv, tmp_path, value: str, name: str = "bad.csv"):
    """The lab CSV with the angle of its fifth reading replaced by ``value``; and that line."""
    lines = lab_csv.read_text().splitlines()
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
def _loco(lab_csv, out, base, *extra):
    argv = ["transfer", "loco", str(lab_csv), "--base", str(base), "--out", str(out)]
    argv += ["--strategies", "fem-only,scale-offset", "--no-learning-curve", "--json"]
    return main([*argv, *extra])  # --json: no progress lines


def test_loco_failing_on_a_figure_keeps_the_previous_results(
    lab_csv, tmp_path, monkeypatch, capsys, small_base_file
):
    import softbend.reports.transfer_figures as figures

    out = tmp_path / "loco"
    out.mkdir()
    (out / "loco.json").write_text('{"old": true}\n')
    monkeypatch.setattr(figures, "actuator_panels", _full)
    assert _loco(lab_csv, out, small_base_file) == 2
    assert one_error_line(capsys) == (
        f"softbend: error: The '--out' {out} could not be written: {FULL}."
    )
    assert _listing(out) == ["loco.json"] and (out / "loco.json").read_text() == '{"old": true}\n'
    assert _listing(tmp_path) == ["loco"]  # no staging folder left


def test_loco_an_os_error_inside_the_folder_names_the_final_file(
    lab_csv, tmp_path, monkeypatch, capsys, small_base_file
):
    import softbend.reports.transfer_figures as figures

    def denied(result, path, **kwargs):
        raise PermissionError(errno.EACCES, "Permission denied", str(path))

    monkeypatch.setattr(figures, "loss_curves", denied)
    out = tmp_path / "loco"
    assert _loco(lab_csv, out, small_base_file) == 2
    assert one_error_line(capsys) == (
        f"softbend: error: The '--out' {out} could not be written: Permission denied "
        f"({out / 'fig6_loss_curves.png'})."
    )
    assert _listing(tmp_path) == []


def test_loco_writes_its_folder_whole_with_strict_json(lab_csv, tmp_path, capsys, small_base_file):
    out = tmp_path / "loco"
    out.mkdir()
    (out / "learning_curve.png").write_bytes(b"an earlier run's figure")
    assert _loco(lab_csv, out, small_base_file) == 0
    payload = _strict_json(capsys.readouterr().out)
    # The old folder is gone as a whole: no figure of an earlier run beside the new tables.
    assert "learning_curve.png" not in _listing(out)
    assert set(payload["files"].values()) == {str(out / name) for name in _listing(out)}
    saved = _strict_json((out / "loco.json").read_text())
    fem_only = next(r for r in saved["summary"] if r["strategy"] == "fem-only")
    assert fem_only["coverage"] is None  # NaN written as null
    assert _listing(tmp_path) == ["loco"]


def test_loco_never_replaces_a_folder_holding_other_files(
    lab_csv, tmp_path, capsys, small_base_file
):
    out = tmp_path / "results"
    out.mkdir()
    (out / "notes.txt").write_text("mine\n")
    assert _loco(lab_csv, out, small_base_file) == 2
    line = one_error_line(capsys)
    assert "'--out'" in line and "notes.txt" in line and "replaced as a whole" in line
    assert (out / "notes.txt").read_text() == "mine\n"
    inside = out / "lab.csv"
    inside.write_text(lab_csv.read_text())
    (out / "notes.txt").unlink()
    assert _loco(inside, out, small_base_file) == 2
    assert f"holds the input {inside}" in one_error_line(capsys)
    assert _listing(out) == ["lab.csv"]


def test_loco_refuses_a_file_over_the_row_limit_quickly(
    lab_csv, tmp_path, monkeypatch, capsys, small_base_file
):
    monkeypatch.setenv("SOFTBEND_MAX_CSV_ROWS", "10")
    assert _loco(lab_csv, tmp_path / "o", small_base_file) == 2
    line = one_error_line(capsys)
    assert str(lab_csv) in line and "limit of 10 rows" in line and "SOFTBEND_MAX_CSV_ROWS" in line


# -------------------------------------------------------------- transfer refine
def test_refine_an_absurd_angle_is_one_line_and_no_model(
    lab_csv, tmp_path, capsys, small_base_file
):
    bad, line_number = _with_angle(lab_csv, tmp_path, "1e300")
    out = tmp_path / "model.json"
    argv = ["transfer", "refine", str(small_base_file), str(bad), "--out", str(out)]
    assert main([*argv, "--strategy", "scale-offset"]) == 2
    line = one_error_line(capsys)  # no overflow warnings before it
    assert f"{bad}:{line_number}:8: angle_deg: 1e+300" in line
    assert "-3600 to 3600" in line
    assert not out.exists()


def test_refine_a_bad_metadata_header_is_one_line(lab_csv, tmp_path, capsys, small_base_file):
    text = lab_csv.read_text().replace("# synthetic: true", "# synthetic: maybe")
    bad = tmp_path / "meta.csv"
    bad.write_text(text)
    argv = ["transfer", "refine", str(small_base_file), str(bad), "--out", str(tmp_path / "m.json")]
    assert main([*argv, "--strategy", "scale-offset"]) == 2
    assert f"{bad}:2: synthetic: must be 'true' or 'false'" in one_error_line(capsys)


def test_refine_on_a_full_disk_names_the_option_and_keeps_the_old_model(
    lab_csv, tmp_path, monkeypatch, capsys, small_base_file
):
    import softbend._io as io

    out = tmp_path / "model.json"
    out.write_text('{"old": true}\n')

    def full(*args, **kwargs):
        raise OSError(errno.ENOSPC, FULL)

    monkeypatch.setattr(io.os, "replace", full)
    argv = ["transfer", "refine", str(small_base_file), str(lab_csv), "--out", str(out)]
    assert main([*argv, "--strategy", "scale-offset"]) == 2
    lines = capsys.readouterr().err.strip().splitlines()
    # The lab file's few actuators earn a warning about the calibration first.
    assert all(line.startswith("softbend: warning: ") for line in lines[:-1])
    assert lines[-1] == f"softbend: error: The '--out' {out} could not be written: {FULL}."
    assert out.read_text() == '{"old": true}\n' and _listing(tmp_path) == ["model.json"]


@pytest.mark.parametrize("strategy", ["scale-offset", "residual-gp"])
def test_refine_writes_strict_json(lab_csv, tmp_path, capsys, small_base_file, strategy):
    out = tmp_path / "model.json"
    argv = ["transfer", "refine", str(small_base_file), str(lab_csv), "--out", str(out)]
    assert main([*argv, "--strategy", strategy]) == 0
    saved = _strict_json(out.read_text())
    assert saved["metadata"]["strategy"] == strategy


def test_refine_a_non_finite_figure_is_one_line_and_no_model(
    lab_csv, tmp_path, monkeypatch, capsys, small_base_file
):
    import softbend.transfer.refine as refine

    fit = refine.fit_strategy

    def with_nan_loss(*args, **kwargs):
        model = fit(*args, **kwargs)
        model.loss_curve_ = [float("nan")]
        return model

    monkeypatch.setattr(refine, "fit_strategy", with_nan_loss)
    out = tmp_path / "model.json"
    argv = ["transfer", "refine", str(small_base_file), str(lab_csv), "--out", str(out)]
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
