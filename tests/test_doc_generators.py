"""The documentation generators refuse a malformed input in one line and leave the page alone.

``docs/gen_validation.py`` reads a run's ``summary.json`` and ``docs/gen_performance.py``
the benchmark records of ``benchmarks/results``: a file that is not JSON, or not what
they read (a key missing, a value of the wrong type), is one line on stderr naming the
file and what is wrong, exit code 2, and the page is not written. ``docs/gen_cli_reference.py``
reads no file (the commands' own --help).
"""

from __future__ import annotations

import copy
import importlib.util
import json
import sys
from pathlib import Path

import pytest

ROOT = Path(__file__).resolve().parents[1]


def _load(name: str):
    spec = importlib.util.spec_from_file_location(name, ROOT / "docs" / f"{name}.py")
    module = importlib.util.module_from_spec(spec)
    sys.modules[name] = module
    spec.loader.exec_module(module)
    return module


gen_validation = _load("gen_validation")
gen_performance = _load("gen_performance")

#: A summary with every section the validation page reads (a reduced run's figures).
SUMMARY = {
    "seed": 0,
    "paper_a": {
        "free_run_nrmse_worst": {"positive/rho": 0.0957, "negative/L": 0.08},
        "selection": {
            "positive": {
                "best": "svr-5",
                "cv_freerun_nrmse": 0.0212,
                "best_arx_cv_freerun_nrmse": 0.0599,
                "paper_a_cv_freerun_nrmse": 0.0459,
            }
        },
    },
    "paper_b": {"r2": 0.84181, "f_value": 68146.3, "mape_pct": 133.55},
    "paper_b_fem_data": {
        "r2": 0.83593,
        "f_value": None,
        "mape_pct": 48.93,
        "surrogates_random": {"mlp": {"r2": 0.99994, "mape_pct": 1.31}},
    },
    "transfer": {"best": "refined", "summary": {"refined": {"rmse_deg": 7.6, "mape_pct": 7.05}}},
    "control": {"rig": [{"controller": "bang-bang", "reference": "square:90:4", "mape_pct": 7.17}]},
    "design": {
        "specifications": [
            {"name": "short-finger", "target": "90° at 0.08 MPa", "best": {"angle_deg": 88.3}},
            {"name": "none-found", "target": "300° at 0.01 MPa", "best": None},
        ]
    },
    "reduced_settings": ["fewer MLP epochs on the FEM data"],
    "provenance": {"command": "softbend reproduce --out results/reproduce", "seed": 0},
    "seconds": 406.0,
}

PAGE = "# an earlier page\n"


def _validation(tmp_path: Path, payload: object | str) -> tuple[Path, Path]:
    source, page = tmp_path / "summary.json", tmp_path / "validation.md"
    source.write_text(payload if isinstance(payload, str) else json.dumps(payload))
    page.write_text(PAGE)
    return source, page


def _one_line(capsys) -> str:
    captured = capsys.readouterr()
    lines = captured.err.strip().splitlines()
    assert len(lines) == 1, lines
    assert "Traceback" not in captured.err and captured.out == ""
    return lines[0]


# -- docs/gen_validation.py --------------------------------------------------------------


def test_a_whole_summary_makes_the_page(tmp_path, capsys):
    source, page = _validation(tmp_path, SUMMARY)
    assert gen_validation.main([str(source), "--out", str(page)]) == 0
    text = page.read_text()
    assert text.startswith("# Validation: softbend beside the papers")
    assert "**Reduced settings**: fewer MLP epochs on the FEM data." in text
    assert "| command | softbend reproduce --out results/reproduce |" in text
    assert "| 7.60° | 7.935° (Sec. 4.3, Fig. 7) |" in text
    assert f"wrote {page} from {source}" in capsys.readouterr().out
    assert sorted(p.name for p in tmp_path.iterdir()) == ["summary.json", "validation.md"]


def _without(*path: str) -> dict:
    data = json.loads(json.dumps(SUMMARY))
    *parents, last = path
    node = data
    for key in parents:
        node = node[key]
    del node[last]
    return data


def _with(value: object, *path: str) -> dict:
    data = json.loads(json.dumps(SUMMARY))
    *parents, last = path
    node = data
    for key in parents:
        node = node[int(key)] if isinstance(node, list) else node[key]
    node[last] = value
    return data


@pytest.mark.parametrize(
    ("payload", "said"),
    [
        (
            "{}",
            "it must have the keys paper_a, paper_b, paper_b_fem_data, transfer, control, "
            "design, provenance, reduced_settings",
        ),
        ('{"paper_a": ', "not valid JSON (line 1, column 13)"),
        ("", "not valid JSON (line 1, column 1)"),
        ("[1, 2]", "it must be a JSON object. Got a list instead."),
        (_without("transfer"), "Got one without transfer."),
        (_with([], "control"), "'control' must be an object. Got a list instead."),
        (_with({}, "provenance"), "'provenance' must describe the run. Got an empty object"),
        (_with("x", "reduced_settings"), "'reduced_settings' must be a list. Got a string"),
        (
            _with(["a", 3], "reduced_settings"),
            "'reduced_settings.1' must be a string. Got a number",
        ),
        (
            _with({"a": "x"}, "paper_a", "free_run_nrmse_worst"),
            "'paper_a.free_run_nrmse_worst.a' must be a number. Got a string instead.",
        ),
        (_with([1], "paper_b", "r2"), "'paper_b.r2' must be a number or a string or null."),
        (_with(["refined"], "transfer", "best"), "'transfer.best' must be a string or null."),
        (_with({"a": 1}, "control", "rig"), "'control.rig' must be a list or null. Got an object"),
        (_with([7], "control", "rig"), "'control.rig.0' must be an object. Got a number instead."),
        (
            _with("x", "design", "specifications", "0", "best"),
            "'design.specifications.0.best' must be an object or null. Got a string instead.",
        ),
    ],
    ids=[
        "empty object",
        "cut short",
        "empty file",
        "a list",
        "no transfer",
        "control a list",
        "empty provenance",
        "reduced a text",
        "reduced a number",
        "worst a text",
        "r2 a list",
        "best a list",
        "rig an object",
        "rig of numbers",
        "best design a text",
    ],
)
def test_a_malformed_summary_is_one_line_and_leaves_the_page(tmp_path, capsys, payload, said):
    source, page = _validation(tmp_path, payload)
    assert gen_validation.main([str(source), "--out", str(page)]) == 2
    line = _one_line(capsys)
    assert line.startswith(str(source)) and said in line
    assert page.read_text() == PAGE
    assert sorted(p.name for p in tmp_path.iterdir()) == ["summary.json", "validation.md"]


def test_a_missing_or_undecodable_summary_is_one_line(tmp_path, capsys):
    page = tmp_path / "validation.md"
    page.write_text(PAGE)
    missing = tmp_path / "nope.json"
    assert gen_validation.main([str(missing), "--out", str(page)]) == 2
    assert (
        _one_line(capsys) == f"{missing} is missing: `make run` writes the summary.json of a run."
    )
    assert gen_validation.main([str(tmp_path), "--out", str(page)]) == 2
    assert _one_line(capsys).startswith(f"{tmp_path} is a folder: ")
    latin = tmp_path / "latin.json"
    latin.write_bytes(b'{"x": "\xe9"}')
    assert gen_validation.main([str(latin), "--out", str(page)]) == 2
    assert _one_line(capsys) == f"{latin}: not UTF-8 text (undecodable byte at offset 7)."
    deep = tmp_path / "deep.json"
    deep.write_text("[" * 100_000 + "]" * 100_000)
    assert gen_validation.main([str(deep), "--out", str(page)]) == 2
    assert _one_line(capsys) == f"{deep}: JSON nested too deeply to read."
    assert page.read_text() == PAGE


# -- docs/gen_performance.py -------------------------------------------------------------

RECORD = {
    "benchmark": "demo",
    "command": "python benchmarks/bench_demo.py",
    "date": "2026-11-26T13:02:27+00:00",
    "figures": [{"name": "best", "unit": "s", "value": 0.25}, {"name": "n", "value": 3}],
    "machine": {"cpu": "CPU", "logical_cores": 2},
    "notes": "",
    "schema": 1,
    "software": {"git_commit": "unknown"},
}


def _performance(tmp_path: Path, text: str) -> tuple[list[str], Path]:
    results, benchmarks = tmp_path / "results", tmp_path / "benchmarks"
    results.mkdir()
    benchmarks.mkdir()
    (benchmarks / "bench_demo.py").write_text('"""Benchmark: demo."""\n')
    (results / "good.json").write_text(json.dumps(RECORD))
    (results / "bad.json").write_text(text)
    page = tmp_path / "performance.md"
    page.write_text(PAGE)
    argv = ["--results", str(results), "--benchmarks", str(benchmarks), "--out", str(page)]
    return argv, page


def _record_with(key: str, value: object) -> str:
    return json.dumps({**RECORD, key: value})


@pytest.mark.parametrize(
    ("text", "said"),
    [
        ('{"benchmark": ', "bad.json: not valid JSON (line 1, column 15)."),
        ("[]", "must be a benchmark record with keys"),
        (_record_with("figures", "fast"), "whose 'figures' is a list. Got a string instead."),
        (
            _record_with("figures", [1]),
            "whose figure 1 is an object with a text 'name'. Got a number",
        ),
        (
            _record_with("figures", [{"value": 1}]),
            "figure 1 is an object with a text 'name'. Got an",
        ),
        (
            _record_with("figures", [{"name": "x", "value": [1]}]),
            "figure 1 ('x') has a 'value' that is a number, a text, true/false or null. Got a list",
        ),
        (
            _record_with("figures", [{"name": "x", "unit": 3, "value": 1}]),
            "figure 1 ('x') has a text 'unit'. Got a number instead.",
        ),
        (_record_with("machine", "CPU"), "whose 'machine' is an object. Got a string instead."),
        (_record_with("software", None), "whose 'software' is an object. Got null instead."),
        (_record_with("benchmark", 7), "whose 'benchmark' is a string. Got a number instead."),
        (
            _record_with("schema", 2),
            "must be a benchmark record of schema 1. Got schema 2 instead.",
        ),
    ],
    ids=[
        "cut short",
        "a list",
        "figures a text",
        "a figure a number",
        "a figure without name",
        "a value a list",
        "a unit a number",
        "machine a text",
        "software null",
        "benchmark a number",
        "another schema",
    ],
)
def test_a_malformed_record_is_one_line_and_leaves_the_page(tmp_path, capsys, text, said):
    argv, page = _performance(tmp_path, text)
    assert gen_performance.main(argv) == 2
    line = _one_line(capsys)
    assert "bad.json" in line and said in line
    assert page.read_text() == PAGE
    assert gen_performance.main([*argv, "--check"]) == 2  # checked before comparing, too
    _one_line(capsys)


def test_a_missing_results_folder_is_refused_not_an_empty_page(tmp_path, capsys):
    argv, page = _performance(tmp_path, json.dumps({**RECORD, "benchmark": "other"}))
    assert gen_performance.main(argv) == 0
    capsys.readouterr()
    written = page.read_text()
    assert "## demo" in written and "## other" in written
    missing = ["--results", str(tmp_path / "nothing"), *argv[2:]]
    assert gen_performance.main(missing) == 2
    assert "results folder" in _one_line(capsys) and page.read_text() == written
    no_scripts = [*argv[:2], "--benchmarks", str(tmp_path / "nothing"), *argv[4:]]
    assert gen_performance.main(no_scripts) == 2
    assert "benchmarks folder" in _one_line(capsys) and page.read_text() == written


def test_the_cli_reference_generator_reads_no_input():
    text = (ROOT / "docs" / "gen_cli_reference.py").read_text()
    assert "open(" not in text and "read_text" not in text and "sys.argv" not in text


# make docs after a fresh make run leaves docs/validation.md as it was: two runs of the same
# code differ in their dates and wall time only, which the page leaves off.

#: A run's summary as ``softbend reproduce`` writes it (the figures the page reads).
RUN = {
    "paper_a": {},
    "paper_b": {"r2": 0.84181, "f_value": 68146.3, "mape_pct": 133.55},
    "paper_b_fem_data": {"r2": 0.83593, "f_value": 37817.9, "mape_pct": 48.93},
    "transfer": {"best": "refined", "summary": {"refined": {"rmse_deg": 7.6, "mape_pct": 7.05}}},
    "control": {"rig": [{"controller": "bang-bang", "reference": "square:90:4", "mape_pct": 7.17}]},
    "design": {"specifications": []},
    "reduced_settings": [],
    "provenance": {
        "command": "softbend reproduce --out results/reproduce",
        "softbend": "0.1.0",
        "seed": 0,
        "started (UTC)": "2026-11-26 13:25:58",
        "finished (UTC)": "2026-11-26 13:32:44",
        "wall time": "406 s",
    },
    "seconds": 406.0,
}


def _rerun(**changes: object) -> dict:
    """The same run again: other dates and wall time, and ``changes`` to its figures."""
    again = copy.deepcopy(RUN)
    again["provenance"].update(
        {"started (UTC)": "2026-11-28 02:00:01", "finished (UTC)": "2026-11-28 02:07:30"}
    )
    again["provenance"]["wall time"] = "449 s"
    again["seconds"] = 449.3
    for section, figures in changes.items():
        again[section] = {**again[section], **figures}
    return again


def test_a_rerun_makes_the_same_page():
    page = gen_validation.page_text(gen_validation.check_summary(copy.deepcopy(RUN)))
    assert gen_validation.page_text(_rerun()) == page
    assert "2026-11-26" not in page and "406 s" not in page
    assert "| seed | 0 |" in page and "| 0.84181 |" in page  # the setting and the figures stay
    assert page.rstrip().endswith(gen_validation.NOTE)


def test_a_changed_figure_changes_the_page():
    page = gen_validation.page_text(RUN)
    assert gen_validation.page_text(_rerun(paper_b={"r2": 0.84182})) != page


def test_the_tracked_page_has_no_run_s_dates():
    tracked = (ROOT / "docs" / "validation.md").read_text(encoding="utf-8")
    for key in gen_validation.VOLATILE:
        assert f"| {key} |" not in tracked, key
    assert tracked.rstrip().endswith(gen_validation.NOTE)
