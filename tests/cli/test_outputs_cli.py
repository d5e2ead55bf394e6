"""Outputs of every command: checked before any work, OS errors as one line naming the option."""

from __future__ import annotations

import errno

import pytest

from softbend.cli import main

from .conftest import one_error_line


@pytest.fixture
def afile(tmp_path):
    """An existing file where a command expects its output folder."""
    path = tmp_path / "afile"
    path.write_text("keep me\n")
    return path


def _commands(tmp_path, out):
    db = tmp_path / "c.duckdb"
    db.touch()
    data = tmp_path / "data"
    data.mkdir(exist_ok=True)
    return {
        "materials fit": ["materials", "fit", "--out", str(out)],
        "analyze": ["analyze", str(db), "--out", str(out)],
        "curling identify": ["curling", "identify", str(data), "--out", str(out)],
        "curling simulate": ["curling", "simulate", "--out", str(out), "--samples", "16"],
        "fem run": ["fem", "run", "--out", str(out), "--pmax", "0.01"],
        "train": ["train", str(db), "--out", str(out), "--models", "plr"],
        "campaign dataset": ["campaign", "dataset", str(db), "--out", str(out), "--command", "x"],
    }


COMMANDS = [
    "materials fit",
    "analyze",
    "curling identify",
    "curling simulate",
    "fem run",
    "train",
    "campaign dataset",
]


@pytest.mark.parametrize("command", COMMANDS)
def test_an_out_folder_that_is_a_file_is_one_line_before_any_work(tmp_path, afile, capsys, command):
    argv = _commands(tmp_path, afile)[command]
    assert main(argv) == 2
    line = one_error_line(capsys)
    assert f"The '--out' must name a folder; {afile} is a file." in line
    assert afile.read_text() == "keep me\n"


def test_an_out_folder_under_a_file_is_one_line(tmp_path, afile, capsys):
    assert main(["materials", "fit", "--out", str(afile / "sub")]) == 2
    assert f"The '--out' {afile / 'sub' / 'x'} cannot be created: {afile} is a file" in (
        one_error_line(capsys)
    )


def test_a_full_disk_during_a_write_is_one_line_naming_the_option(tmp_path, monkeypatch, capsys):
    import softbend.reports.material_figures as figures

    def full(*args, **kwargs):
        raise OSError(errno.ENOSPC, "No space left on device")

    monkeypatch.setattr(figures, "fit_figure", full)
    out = tmp_path / "o"
    assert main(["materials", "fit", "--models", "yeoh", "--out", str(out)]) == 2
    assert one_error_line(capsys) == (
        f"softbend: error: The '--out' {out} could not be written: No space left on device."
    )


def test_identify_never_writes_into_its_data_folder(tmp_path, capsys):
    data = tmp_path / "data"
    data.mkdir()
    (data / "summary.csv").write_text("an experiment\n")
    assert main(["curling", "identify", str(data), "--out", str(data)]) == 2
    assert f"The '--out' {data} is also an input; choose another folder." in one_error_line(capsys)
    assert main(["curling", "identify", str(data / "summary.csv"), "--out", str(data)]) == 2
    assert "would overwrite the input" in one_error_line(capsys)
    assert (data / "summary.csv").read_text() == "an experiment\n"
