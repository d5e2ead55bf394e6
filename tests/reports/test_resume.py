"""Finished sections of an interrupted report are taken over, in order, and only when valid."""

from __future__ import annotations

from pathlib import Path

import pytest

from softbend.reports.html import Report
from softbend.reports.resume import CHECKPOINTS, Sections, keep, section_key


def _section(stage: Path, report: Report, name: str, calls: list[str], text: str = "x"):
    """A section that writes one file, adds one report section and returns its path."""

    def compute():
        calls.append(name)
        path = stage / name / "table.csv"
        path.parent.mkdir(parents=True, exist_ok=True)
        path.write_text(f"{name},{text}\n")
        report.section(name.title()).text(f"{name} says {text}")
        return {"file": str(path), "value": len(calls)}

    return compute


def _first_run(tmp_path: Path, names=("a", "b", "c"), stop_at: str | None = "c"):
    """Run the sections into ``stage`` until ``stop_at`` raises, then keep what finished."""
    stage, kept = tmp_path / "stage1", tmp_path / "kept"
    stage.mkdir()
    report, calls = Report("r"), []
    sections = Sections(stage, None, report)
    figures = {}
    with pytest.raises(KeyboardInterrupt):
        for name in names:
            if name == stop_at:
                raise KeyboardInterrupt
            figures[name] = sections.run(name, {"seed": 0}, _section(stage, report, name, calls))
    return keep(stage, kept), kept, figures, report


def test_a_stopped_run_s_finished_sections_are_taken_over_and_the_rest_computed(tmp_path):
    taken, kept, first, first_report = _first_run(tmp_path)
    assert taken == ["a", "b"]
    stage = tmp_path / "stage2"
    stage.mkdir()
    report, calls = Report("r"), []
    sections = Sections(stage, kept, report)
    figures = {
        name: sections.run(name, {"seed": 0}, _section(stage, report, name, calls))
        for name in ("a", "b", "c")
    }
    assert calls == ["c"] and sections.resumed == ["a", "b"]
    # the files moved into the new folder, their paths named there
    assert figures["a"]["file"] == str(stage / "a" / "table.csv")
    assert (stage / "a" / "table.csv").read_text() == "a,x\n"
    assert not (kept / "a" / "table.csv").exists()
    assert figures["a"]["value"] == first["a"]["value"]
    # the report's sections come back as they were, in order
    assert [s.title for s in report.sections] == ["A", "B", "C"]
    assert report.sections[0].parts == first_report.sections[0].parts
    assert sorted(p.name for p in (stage / CHECKPOINTS).iterdir()) == ["a.json", "b.json", "c.json"]


def test_other_settings_compute_every_section_again(tmp_path):
    _, kept, _, _ = _first_run(tmp_path)
    stage = tmp_path / "stage2"
    stage.mkdir()
    report, calls = Report("r"), []
    sections = Sections(stage, kept, report)
    for name in ("a", "b"):
        sections.run(name, {"seed": 1}, _section(stage, report, name, calls, "y"))
    assert calls == ["a", "b"] and sections.resumed == []
    assert (stage / "a" / "table.csv").read_text() == "a,y\n"


def test_a_missing_file_stops_the_take_over_there(tmp_path):
    _, kept, _, _ = _first_run(tmp_path)
    (kept / "a" / "table.csv").unlink()
    stage = tmp_path / "stage2"
    stage.mkdir()
    report, calls = Report("r"), []
    sections = Sections(stage, kept, report)
    for name in ("a", "b"):
        sections.run(name, {"seed": 0}, _section(stage, report, name, calls))
    # b was finished and intact, but may read what a wrote: computed again too
    assert calls == ["a", "b"] and sections.resumed == []


def test_keep_replaces_a_section_kept_before(tmp_path):
    _, kept, _, _ = _first_run(tmp_path)
    stage = tmp_path / "stage2"
    stage.mkdir()
    report, calls = Report("r"), []
    sections = Sections(stage, None, report)
    sections.run("a", {"seed": 5}, _section(stage, report, "a", calls, "new"))
    assert keep(stage, kept) == ["a"]
    assert (kept / "a" / "table.csv").read_text() == "a,new\n"
    assert (kept / "b" / "table.csv").is_file()


def test_files_left_to_the_caller_are_not_a_section_s(tmp_path):
    stage = tmp_path / "stage"
    (stage / "db").mkdir(parents=True)
    report = Report("r")

    def compute():
        (stage / "db" / "campaign.duckdb").write_text("rows")
        (stage / "out.txt").write_text("out")
        return {}

    Sections(stage, None, report, skip=(Path("db/campaign.duckdb"),)).run("s", {}, compute)
    kept = tmp_path / "kept"
    keep(stage, kept)
    assert (kept / "out.txt").is_file() and not (kept / "db" / "campaign.duckdb").exists()
    assert (stage / "db" / "campaign.duckdb").is_file()


def test_the_key_follows_name_and_settings():
    assert section_key("a", {"seed": 0}) == section_key("a", {"seed": 0})
    assert section_key("a", {"seed": 0}) != section_key("a", {"seed": 1})
    assert section_key("a", {"seed": 0}) != section_key("b", {"seed": 0})
