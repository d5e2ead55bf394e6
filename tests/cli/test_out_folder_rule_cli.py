"""Every command that writes a folder keeps the user's files: one rule, checked before any work.

A folder given as ``--out`` is replaced only when it is empty or holds nothing but an
earlier result of the same command (its manifest lists every entry). Anything else (a
thesis beside the models, a file under ``vtk/``, a ``summary.csv`` of the user's, an input
read from inside ``--out``) is one line and exit 2, and a snapshot of the whole folder tree
before and after shows nothing removed or changed. The property test draws such folders
for every command that writes one.
"""

from __future__ import annotations

import os
from pathlib import Path

import pytest
from hypothesis import given
from hypothesis import strategies as st

from softbend._outdir import MANIFEST, read_manifest
from softbend.cli import main

from ..folders import tree
from ..properties import property_settings
from .conftest import one_error_line

ROOT = Path(__file__).resolve().parents[2]
MEASUREMENTS = ROOT / "src" / "softbend" / "data" / "transfer" / "virtual_lab.csv"
PNEUNET = ROOT / "examples" / "pneunet"


@pytest.fixture
def inputs(tmp_path, small_campaign, small_base_file) -> dict[str, Path]:
    """Inputs the commands read; none is read before the output folder is checked."""
    recordings = tmp_path / "recordings"
    recordings.mkdir()
    (recordings / "run.csv").write_text("time_s,p_kpa,angle_deg\n0,0,0\n0.1,1,1\n")
    return {
        "db": small_campaign,
        "base": small_base_file,
        "recordings": recordings,
        "recording": recordings / "run.csv",
    }


def _argv(command: str, out: Path, given: dict[str, Path]) -> list[str]:
    o = str(out)
    return {
        "train": ["train", str(given["db"]), "--out", o, "--models", "plr"],
        "design find": ["design", "find", "--angle", "30", "--at", "0.08", "--out", o],
        "fem run": ["fem", "run", "--pmax", "0.01", "--out", o],
        "transfer loco": ["transfer", "loco", str(MEASUREMENTS), "--base", str(given["base"]),
                          "--out", o],
        "identify": ["identify", str(given["recording"]), "--inputs", "p_kpa", "--outputs",
                     "angle_deg", "--time", "time_s", "--out", o],
        "control simulate": ["control", "simulate", "--out", o],
        "control run": ["control", "run", "--out", o],
        "analyze": ["analyze", str(given["db"]), "--out", o],
        "curling simulate": ["curling", "simulate", "--out", o, "--samples", "16"],
        "curling identify": ["curling", "identify", str(given["recordings"]), "--out", o],
        "reproduce": ["reproduce", "--out", o],
        "campaign dataset": ["campaign", "dataset", str(given["db"]), "--out", o, "--command",
                             "softbend campaign run"],
    }[command]  # fmt: skip


COMMANDS = [
    "train", "design find", "fem run", "transfer loco", "identify", "control simulate",
    "control run", "analyze", "curling simulate", "curling identify", "reproduce",
    "campaign dataset",
]  # fmt: skip

_NAMES = st.sampled_from(
    ["thesis.txt", "summary.csv", "summary.json", "cv_results.csv", "search.json", "sweep.json",
     "vtk", "models", "index.html", "selection.json", "run.json", ".hidden"]
)  # fmt: skip


@st.composite
def _foreign(draw: st.DrawFn) -> dict[str, object]:
    """What a user keeps in an output folder: at least one file, maybe nested or linked."""
    return {
        "files": draw(
            st.lists(
                st.lists(_NAMES, min_size=1, max_size=3), min_size=1, max_size=3, unique_by=tuple
            )
        ),
        "earlier_manifest": draw(st.booleans()),
        "link_inside": draw(st.booleans()),
        "out_is_link": draw(st.booleans()),
        "staging_alike": draw(st.booleans()),
    }


def _lay_out(root: Path, command: str, foreign: dict[str, object]) -> Path:
    """``root/out`` holding the user's files (and maybe an earlier run's manifest)."""
    from softbend._outdir import write_manifest

    out = root / "out"
    target = out
    if foreign["out_is_link"]:
        target = root / "real"
        out.symlink_to(target, target_is_directory=True)
    target.mkdir(exist_ok=True)
    (root / "keep.txt").write_text("outside\n")
    for parts in foreign["files"]:  # type: ignore[attr-defined]
        path = target.joinpath(*parts)
        if any(p.is_file() for p in [path, *path.parents] if p != target):
            continue
        path.parent.mkdir(parents=True, exist_ok=True)
        if not path.exists():
            path.write_text("the user's\n")
    if foreign["link_inside"]:
        (target / "mine-link").symlink_to(root / "keep.txt")
    if foreign["earlier_manifest"]:
        # an earlier run of the command that listed only part of what is there now
        write_manifest(target, command, complete=True)
        listed = read_manifest(target)
        assert listed is not None
        (target / "added-after.txt").write_text("written after the run\n")
    if foreign["staging_alike"]:
        (root / ".out.1-x.new").mkdir()
        (root / ".out.1-x.new" / "mine.txt").write_text("mine\n")
    return out


@pytest.mark.parametrize("command", COMMANDS)
def test_a_folder_with_the_users_files_is_refused_and_kept(tmp_path_factory, inputs, command):
    @property_settings(4)
    @given(foreign=_foreign())
    def check(foreign):
        root = tmp_path_factory.mktemp("user")
        out = _lay_out(root, command, foreign)
        before = tree(root)
        code = main(_argv(command, out, inputs))
        after = tree(root)
        assert code == 2, command
        assert after == before, command

    check()


@pytest.mark.parametrize("command", COMMANDS)
def test_the_refusal_is_one_line_naming_out_and_the_files(tmp_path, inputs, capsys, command):
    out = tmp_path / "out"
    (out / "vtk").mkdir(parents=True)
    (out / "vtk" / "mine.vtu").write_text("<VTKFile/>\n")
    (out / "thesis.txt").write_text("three years\n")
    assert main(_argv(command, out, inputs)) == 2
    line = one_error_line(capsys)
    assert f"The '--out' {out} is replaced as a whole by the results of '{command}'" in line
    assert "holds other files (thesis.txt, vtk)" in line


def test_a_thesis_beside_an_earlier_training_is_kept(tmp_path, small_campaign, capsys):
    out = tmp_path / "models"
    out.mkdir()
    (out / "cv_results.csv").write_text("an earlier result's marker\n")
    (out / "thesis.txt").write_text("three years\n")
    assert main(["train", str(small_campaign), "--out", str(out), "--models", "plr"]) == 2
    assert "thesis.txt" in one_error_line(capsys)
    assert (out / "thesis.txt").read_text() == "three years\n"


def test_an_input_read_from_inside_out_is_refused_before_any_work(tmp_path, capsys):
    out = tmp_path / "o"
    out.mkdir()
    actuator = out / "actuator.json"
    actuator.write_bytes((PNEUNET / "actuator.json").read_bytes())
    argv = ["train", str(PNEUNET / "simulations.csv"), "--actuator", str(actuator),
            "--out", str(out), "--models", "plr"]  # fmt: skip
    assert main(argv) == 2
    line = one_error_line(capsys)
    assert f"holds the '--actuator' {actuator}" in line
    assert sorted(p.name for p in out.iterdir()) == ["actuator.json"]
    assert not list(tmp_path.glob(".o.*"))  # no staging, no checkpoint: no work began


def test_a_users_file_under_vtk_survives_fem_run(tmp_path, capsys):
    out = tmp_path / "fem"
    (out / "vtk").mkdir(parents=True)
    (out / "sweep.json").write_text("{}\n")  # named like a result, but no run wrote it
    (out / "vtk" / "mine.vtu").write_text("<VTKFile/>\n")
    assert main(["fem", "run", "--pmax", "0.01", "--out", str(out)]) == 2
    assert "vtk" in one_error_line(capsys)
    assert (out / "vtk" / "mine.vtu").read_text() == "<VTKFile/>\n"


def test_a_users_summary_survives_transfer_loco(tmp_path, small_base_file, capsys):
    out = tmp_path / "loco"
    out.mkdir()
    (out / "summary.csv").write_text("my own summary\n")
    argv = ["transfer", "loco", str(MEASUREMENTS), "--base", str(small_base_file),
            "--out", str(out)]  # fmt: skip
    assert main(argv) == 2
    assert "summary.csv" in one_error_line(capsys)
    assert (out / "summary.csv").read_text() == "my own summary\n"


def test_a_symlinked_out_is_written_through_and_stays_a_link(tmp_path, capsys):
    real = tmp_path / "disk" / "sim"
    link = tmp_path / "sim"
    real.parent.mkdir()
    link.symlink_to(real, target_is_directory=True)
    argv = ["curling", "simulate", "--out", str(link), "--samples", "16", "--experiments", "1"]
    assert main(argv) == 0
    assert main([*argv, "--seed", "3"]) == 0  # its own earlier result: replaced
    assert link.is_symlink() and os.readlink(link) == str(real)
    assert sorted(p.name for p in real.iterdir()) == [
        MANIFEST,
        "negative-01.csv",
        "positive-01.csv",
    ]
    assert sorted(p.name for p in tmp_path.iterdir()) == ["disk", "sim"]  # no hidden leftovers
    assert sorted(p.name for p in real.parent.iterdir()) == ["sim"]


@pytest.mark.parametrize("given", [".", ".."])
def test_out_as_the_current_folder_or_above_is_one_line(tmp_path, monkeypatch, capsys, given):
    work = tmp_path / "work"
    work.mkdir()
    (work / "notes.txt").write_text("mine\n")
    monkeypatch.chdir(work)
    before = tree(tmp_path)
    assert main(["curling", "simulate", "--out", given, "--samples", "16"]) == 2
    line = one_error_line(capsys)
    assert f"The '--out' {given} is " in line and "name a new folder" in line
    assert tree(tmp_path) == before


def test_a_saved_model_never_replaces_a_users_json(tmp_path, small_base_file, capsys):
    notes = tmp_path / "notes.json"
    notes.write_text('{"my": "notes"}\n')
    argv = ["transfer", "refine", str(small_base_file), str(MEASUREMENTS), "--out", str(notes)]
    assert main(argv) == 2
    assert "--out" in one_error_line(capsys)
    assert notes.read_text() == '{"my": "notes"}\n'
