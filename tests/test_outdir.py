"""The one rule for output folders: replaced only when empty or wholly the same command's own.

Property: whatever a user keeps in or beside an output folder (nested files, links, files
named like results, folders named like staging folders), a run either refuses before it
replaces anything or replaces only what an earlier run of the same command listed; no
user file is ever removed or changed.
"""

from __future__ import annotations

import json
import os
from pathlib import Path

import pytest
from hypothesis import given
from hypothesis import strategies as st

from softbend._outdir import (
    MANIFEST,
    OutputFolderError,
    check_replaceable,
    foreign_entries,
    read_manifest,
    replaceable_target,
    running,
    staged_dir,
    stale_staging,
    write_manifest,
)
from softbend.errors import InputError

from .folders import dead_pid, tree
from .properties import property_settings


def _earlier(out: Path, command: str, names: tuple[str, ...] = ("summary.json", "fig/a.png")):
    """An earlier result of ``command`` in ``out``: its files and its manifest."""
    with staged_dir(out, command) as stage:
        for name in names:
            (stage / name).parent.mkdir(parents=True, exist_ok=True)
            (stage / name).write_text(f"{command} {name}\n")


# ----------------------------------------------------------------------------- the rule


def test_a_new_or_empty_folder_is_written_with_its_manifest(tmp_path):
    out = tmp_path / "new"
    _earlier(out, "train")
    manifest = read_manifest(out)
    assert manifest is not None and manifest.complete and manifest.command == "train"
    assert manifest.entries == {"fig": "folder", "fig/a.png": "file", "summary.json": "file"}
    empty = tmp_path / "empty"
    empty.mkdir()
    _earlier(empty, "train")
    assert (empty / "summary.json").exists()


def test_an_earlier_result_of_the_same_command_is_replaced_whole(tmp_path):
    out = tmp_path / "out"
    _earlier(out, "train", ("old.csv", "summary.json"))
    _earlier(out, "train", ("summary.json",))
    assert sorted(p.name for p in out.iterdir()) == [MANIFEST, "summary.json"]


def test_a_users_file_beside_an_earlier_result_is_refused_and_kept(tmp_path):
    out = tmp_path / "out"
    _earlier(out, "fem run", ("sweep.json", "vtk/shape_p0.vtu"))
    (out / "thesis.txt").write_text("three years\n")
    (out / "vtk" / "mine.vtu").write_text("<VTK/>\n")
    before = tree(tmp_path)
    assert foreign_entries(out, "fem run") == ["thesis.txt", "vtk/mine.vtu"]
    with pytest.raises(InputError, match=r"holds other files \(thesis.txt, vtk/mine.vtu\)"):
        check_replaceable(out, "fem run")
    with pytest.raises(OutputFolderError, match="nothing was replaced"), staged_dir(out, "fem run"):
        pass
    after = tree(tmp_path)
    for key, value in before.items():  # every file kept as it was (a staging folder is added)
        assert after[key] == value


def test_another_commands_results_are_not_replaced(tmp_path):
    out = tmp_path / "out"
    _earlier(out, "train")
    assert foreign_entries(out, "design find") == ["fig", "summary.json"]
    assert foreign_entries(out, "train") == []


def test_a_folder_without_a_manifest_is_foreign_whatever_its_names(tmp_path):
    out = tmp_path / "out"
    out.mkdir()
    for name in ("cv_results.csv", "search.json", "sweep.json", "summary.csv"):
        (out / name).write_text("mine\n")
    assert foreign_entries(out, "train") == [
        "cv_results.csv",
        "search.json",
        "summary.csv",
        "sweep.json",
    ]


def test_a_forged_or_broken_manifest_proves_nothing(tmp_path):
    out = tmp_path / "out"
    out.mkdir()
    (out / "data.csv").write_text("mine\n")
    (out / MANIFEST).write_text("{not json")
    assert foreign_entries(out, "train") == [MANIFEST, "data.csv"]
    (out / MANIFEST).write_text(json.dumps({"command": "train", "entries": {"data.csv": "file"}}))
    assert "data.csv" in foreign_entries(out, "train")  # no format: not softbend's


def test_an_unfinished_manifest_is_not_an_earlier_result(tmp_path):
    out = tmp_path / "out"
    out.mkdir()
    (out / "half.json").write_text("{")
    write_manifest(out, "train", complete=False)
    assert foreign_entries(out, "train") == ["half.json"]


def test_the_current_folder_and_those_above_it_are_refused(tmp_path, monkeypatch):
    (tmp_path / "work").mkdir()
    monkeypatch.chdir(tmp_path / "work")
    for given_path in (".", "..", os.getcwd(), "/"):
        with pytest.raises(InputError, match="replaced as a whole, so name a new folder"):
            replaceable_target(given_path)
    assert replaceable_target("results") == tmp_path / "work" / "results"


def test_a_symlinked_out_is_resolved_and_stays_a_link(tmp_path):
    real = tmp_path / "disk" / "results"
    real.parent.mkdir()
    link = tmp_path / "out"
    link.symlink_to(real, target_is_directory=True)
    _earlier(link, "train")  # the link points to a folder not there yet
    _earlier(link, "train", ("second.json",))
    assert link.is_symlink() and os.readlink(link) == str(real)
    assert sorted(p.name for p in real.iterdir()) == [MANIFEST, "second.json"]
    assert sorted(p.name for p in tmp_path.iterdir()) == ["disk", "out"]
    assert sorted(p.name for p in real.parent.iterdir()) == ["results"]


def test_the_running_command_names_the_results(tmp_path):
    with running("curling simulate"), staged_dir(tmp_path / "sim") as stage:
        (stage / "positive-01.csv").write_text("x\n")
    assert read_manifest(tmp_path / "sim").command == "curling simulate"


# ----------------------------------------------------------------------------- staging folders


def test_only_staging_folders_that_prove_they_are_softbends_are_removed(tmp_path):
    dead = dead_pid()
    out = tmp_path / "models"
    killed = tmp_path / f".models.{dead}-abc123.new"  # a run killed before its swap
    killed.mkdir()
    (killed / "half.json").write_text("{")
    manifest = {"format": "softbend-output-manifest", "version": 1, "command": "train",
                "pid": dead, "complete": False, "entries": {}}  # fmt: skip
    (killed / MANIFEST).write_text(json.dumps(manifest))
    named_alike = tmp_path / f".models.{dead}-mine.new"  # the user's, with the same shape
    named_alike.mkdir()
    (named_alike / "notes.txt").write_text("mine\n")
    live = tmp_path / f".models.{os.getpid()}-live.new"  # a run of a live process
    live.mkdir()
    write_manifest(live, "train", complete=False)
    other_pid = tmp_path / f".models.{dead}-other.new"  # a manifest naming another PID
    other_pid.mkdir()
    (other_pid / MANIFEST).write_text(json.dumps({**manifest, "pid": dead + 1}))
    assert stale_staging(out) == [killed]
    with staged_dir(out, "train") as staging:
        (staging / "model.json").write_text("{}")
        assert staging.name.startswith(f".models.{os.getpid()}-")
    assert not killed.exists()
    assert (named_alike / "notes.txt").read_text() == "mine\n"
    assert live.exists() and other_pid.exists()
    assert (out / "model.json").exists()


def test_a_failed_block_leaves_the_folder_and_no_staging(tmp_path):
    out = tmp_path / "out"
    _earlier(out, "train")
    before = tree(tmp_path)
    with pytest.raises(RuntimeError), staged_dir(out, "train") as stage:
        (stage / "partial.json").write_text("{")
        raise RuntimeError("stopped")
    assert tree(tmp_path) == before


# ----------------------------------------------------------------------------- property

_NAMES = st.sampled_from(
    ["notes.txt", "summary.json", "summary.csv", "cv_results.csv", "search.json", "sweep.json",
     "index.html", "vtk", "models", "positive-01.csv", "ticks.csv", MANIFEST, ".hidden"]
)  # fmt: skip
_PATHS = st.lists(_NAMES, min_size=1, max_size=3).map(lambda parts: "/".join(parts))


@st.composite
def _layouts(draw: st.DrawFn) -> dict[str, object]:
    """An output folder and its neighbourhood as a user may leave them."""
    return {
        "earlier": draw(st.sampled_from([None, "train", "fem run"])),
        "files": draw(st.lists(_PATHS, max_size=4, unique=True)),
        "links": draw(st.lists(_NAMES, max_size=2, unique=True)),
        "out_is_link": draw(st.booleans()),
        "staging_alike": draw(st.booleans()),
    }


def _lay_out(root: Path, layout: dict[str, object]) -> Path:
    outside = root / "elsewhere"
    outside.mkdir()
    (outside / "precious.txt").write_text("keep\n")
    out = root / "out"
    if layout["out_is_link"]:
        (root / "real").mkdir()
        out.symlink_to(root / "real", target_is_directory=True)
    if layout["earlier"]:
        _earlier(out, str(layout["earlier"]), ("summary.json", "vtk/shape.vtu"))
    target = Path(os.path.realpath(out))
    for relative in layout["files"]:  # type: ignore[attr-defined]
        path = target / relative
        if any(p.is_file() or p.is_symlink() for p in [path, *path.parents] if p != target):
            continue  # a file where a folder would be: leave it
        path.parent.mkdir(parents=True, exist_ok=True)
        if not path.exists():
            path.write_text(f"the user's {relative}\n")
    for name in layout["links"]:  # type: ignore[attr-defined]
        link = target / f"link-{name}"
        if not link.exists():
            target.mkdir(parents=True, exist_ok=True)
            link.symlink_to(outside / "precious.txt")
    if layout["staging_alike"]:
        alike = root / f".{target.name}.{dead_pid()}-x.new"
        alike.mkdir()
        (alike / "mine.txt").write_text("mine\n")
    return out


@property_settings(60)
@given(layout=_layouts(), command=st.sampled_from(["train", "fem run"]))
def test_no_user_file_is_ever_removed(tmp_path_factory, layout, command):
    root = tmp_path_factory.mktemp("layout")
    out = _lay_out(root, layout)
    before = tree(root)
    own: set[str] = set()
    target = Path(os.path.realpath(out))
    manifest = read_manifest(target)
    if manifest is not None and manifest.command == command:  # an earlier result: replaceable
        top = target.relative_to(root).as_posix()
        own = {f"{top}/{name}" for name in [*manifest.entries, MANIFEST]}
    try:
        check_replaceable(out, command)
    except InputError:
        assert tree(root) == before  # refused before any work: nothing touched
        refused = True
    else:
        refused = False
    try:
        with staged_dir(out, command) as stage:
            (stage / "result.json").write_text("{}\n")
    except OutputFolderError:
        assert refused
    after = tree(root)
    for key, value in before.items():
        if key in own:
            continue  # the command's own earlier results may be replaced
        assert after.get(key) == value, key
    assert (root / "elsewhere" / "precious.txt").read_text() == "keep\n"
    if not refused:
        assert (out / "result.json").exists()
        assert out.is_symlink() == layout["out_is_link"]
