"""The benchmarks' recorder (benchmarks/_record.py) and the Performance page generator.

The last test keeps docs/performance.md generated rather than typed: it must be
what ``docs/gen_performance.py`` writes from the committed ``benchmarks/results``.
"""

from __future__ import annotations

import importlib.util
import json
import os
import re
import sys
from datetime import UTC, datetime
from pathlib import Path

import numpy as np
import pytest

import softbend

ROOT = Path(__file__).resolve().parents[1]


def _load(name: str, path: Path):
    spec = importlib.util.spec_from_file_location(name, path)
    module = importlib.util.module_from_spec(spec)
    sys.modules[name] = module
    spec.loader.exec_module(module)
    return module


record_module = _load("_record", ROOT / "benchmarks" / "_record.py")
gen = _load("gen_performance", ROOT / "docs" / "gen_performance.py")

ARGV = [str(ROOT / "benchmarks" / "bench_demo.py"), "--runs", "3", "--label", "a b"]


def _record(tmp_path: Path, **kwargs) -> Path:
    figures = kwargs.pop("figures", {"best": 0.25, "median": np.float64(0.5), "n": np.int64(3)})
    units = kwargs.pop("units", {"best": "s", "median": "s"})
    return record_module.record(
        "demo", figures, units=units, out_dir=tmp_path, argv=ARGV, notes="two cores", **kwargs
    )


# -- the recorder ------------------------------------------------------------------------


def test_record_writes_every_field(tmp_path):
    path = _record(tmp_path)
    assert path == tmp_path / "demo.json"
    text = path.read_text(encoding="utf-8")
    data = json.loads(text)
    assert list(data) == sorted(data)  # deterministic key order
    assert text.startswith('{\n  "benchmark"')  # indent 2
    assert data["benchmark"] == "demo"
    assert data["schema"] == 1
    assert data["notes"] == "two cores"
    # the command as run from the repository root: relative, shell-quoted
    assert data["command"] == "python benchmarks/bench_demo.py --runs 3 --label 'a b'"
    assert data["figures"] == [
        {"name": "best", "unit": "s", "value": 0.25},
        {"name": "median", "unit": "s", "value": 0.5},
        {"name": "n", "unit": "", "value": 3},
    ]
    date = datetime.fromisoformat(data["date"])
    assert date.utcoffset().total_seconds() == 0
    assert abs((datetime.now(UTC) - date).total_seconds()) < 3600
    machine = data["machine"]
    assert machine["logical_cores"] == os.cpu_count()
    assert machine["memory_gib"] is None or machine["memory_gib"] > 0
    torch = sys.modules.get("torch")
    if torch is None or not torch.cuda.is_initialized():
        assert machine["gpu"] is None  # this process used no GPU
    assert set(machine) == {
        "cpu", "gpu", "logical_cores", "memory_gib", "load_average_1min", "platform"
    }  # fmt: skip
    assert machine["load_average_1min"] is None or machine["load_average_1min"] >= 0
    software = data["software"]
    assert software["numpy"] == np.__version__
    assert software["softbend"] == softbend.__version__
    assert software["python"] == ".".join(map(str, sys.version_info[:3]))
    commit = software["git_commit"]
    assert commit == "unknown" or re.fullmatch(r"[0-9a-f]{40}", commit)
    assert software["git_dirty"] in (True, False, None)


def test_record_keeps_the_figures_order_and_marks_non_finite_values(tmp_path):
    figures = {"z first": 1.0, "a second": float("nan"), "m third": None, "flag": True}
    data = json.loads(_record(tmp_path, figures=figures, units={}).read_text())
    assert [f["name"] for f in data["figures"]] == list(figures)
    values = {f["name"]: f["value"] for f in data["figures"]}
    assert values == {"z first": 1.0, "a second": "nan", "m third": None, "flag": True}


def test_record_replaces_the_file_atomically(tmp_path):
    _record(tmp_path, figures={"best": 1.0}, units={})
    _record(tmp_path, figures={"best": 2.0}, units={})
    assert [p.name for p in tmp_path.iterdir()] == ["demo.json"]  # no temporary file left
    assert json.loads((tmp_path / "demo.json").read_text())["figures"][0]["value"] == 2.0


def test_a_failed_write_leaves_the_old_file_and_no_temporary_file(tmp_path, monkeypatch):
    _record(tmp_path, figures={"best": 1.0}, units={})
    before = (tmp_path / "demo.json").read_text()

    def fail(src, dst):
        raise OSError("disk full")

    monkeypatch.setattr(os, "replace", fail)
    with pytest.raises(OSError, match="disk full"):
        _record(tmp_path, figures={"best": 2.0}, units={})
    assert [p.name for p in tmp_path.iterdir()] == ["demo.json"]
    assert (tmp_path / "demo.json").read_text() == before


@pytest.mark.parametrize("name", ["", "Demo", "a/b", "-x", "a b", None])
def test_record_refuses_a_bad_name(tmp_path, name):
    with pytest.raises(ValueError, match=r"The 'name' of record must be .* Got .* instead\."):
        record_module.record(name, {"x": 1}, out_dir=tmp_path, argv=ARGV)
    assert list(tmp_path.iterdir()) == []


def test_record_refuses_units_of_unknown_figures_and_odd_values(tmp_path):
    with pytest.raises(ValueError, match=r"The 'units' of record .* Got \['typo'\] instead\."):
        record_module.record("demo", {"x": 1}, units={"typo": "s"}, out_dir=tmp_path, argv=ARGV)
    with pytest.raises(TypeError, match="figure 'x' of record must be a number"):
        record_module.record("demo", {"x": [1, 2]}, out_dir=tmp_path, argv=ARGV)
    assert list(tmp_path.iterdir()) == []


def test_command_line_keeps_relative_and_outside_paths():
    assert record_module.command_line(["benchmarks/bench_x.py", "--db", "/tmp/x.duckdb"]) == (
        "python benchmarks/bench_x.py --db /tmp/x.duckdb"
    )
    inside = str(ROOT / "src" / "softbend" / "data" / "m.json")
    assert record_module.command_line([str(ROOT / "benchmarks" / "b.py"), inside]) == (
        "python benchmarks/b.py src/softbend/data/m.json"
    )


def test_variant_name_and_table_figures():
    assert record_module.variant_name("control", "lab", None) == "control-lab"
    assert record_module.variant_name("campaign", "LHS:200") == "campaign-lhs-200"
    figures, units = record_module.table_figures(
        {"gg": {"fit_s": 1.23456, "n": 3, "skip": 1}, "rbf": {"fit_s": None, "n": 4}},
        {"fit_s": ("fit", "s"), "n": ("runs", "")},
    )
    assert figures == {"gg: fit": 1.235, "gg: runs": 3, "rbf: fit": None, "rbf: runs": 4}
    assert units == {"gg: fit": "s", "rbf: fit": "s"}


# -- the generator -----------------------------------------------------------------------


def _benchmarks(tmp_path: Path) -> Path:
    folder = tmp_path / "benchmarks"
    folder.mkdir(parents=True)
    (folder / "bench_demo.py").write_text('"""Benchmark: demo timing of ``thing``."""\n')
    (folder / "bench_other.py").write_text(
        '"""Other work, with :func:`softbend.x`.\n\nRun::\n\n'
        "    .venv/bin/python benchmarks/bench_other.py --fast   # quick\n"
        '"""\n'
    )
    return folder


def test_the_page_renders_a_record_as_a_table_with_units(tmp_path):
    results = tmp_path / "results"
    _record(results)
    page = gen.render(gen.load_records(results), _benchmarks(tmp_path).glob("bench_*.py"))
    assert "## demo\n\n`benchmarks/bench_demo.py`: Demo timing of `thing`." in page
    assert "| best | 0.25 s |" in page
    assert "| median | 0.5 s |" in page
    assert "| n | 3 |" in page
    assert "- Command: `python benchmarks/bench_demo.py --runs 3 --label 'a b'`" in page
    assert "two cores" in page
    assert re.search(r"- Measured: \d{4}-\d\d-\d\d \d\d:\d\d:\d\d UTC, commit ", page)
    assert re.search(r"- Machine: .*\d+ logical cores.*no GPU used", page)
    assert "](" not in page  # no links: files are named as code


def test_a_benchmark_without_json_is_listed_as_not_measured(tmp_path):
    results = tmp_path / "results"
    _record(results)
    page = gen.render(gen.load_records(results), _benchmarks(tmp_path).glob("bench_*.py"))
    missing = page.split("## Not measured yet", 1)[1]
    assert (
        "| `benchmarks/bench_other.py` | Other work, with `softbend.x`. | "
        "`python benchmarks/bench_other.py --fast` |"
    ) in missing
    assert "bench_demo.py" not in missing
    # with nothing recorded, every script is listed and no section is written
    empty = gen.render([], _benchmarks(tmp_path / "again").glob("bench_*.py"))
    assert "## demo" not in empty
    assert "`benchmarks/bench_demo.py`" in empty.split("## Not measured yet", 1)[1]


def test_the_page_is_deterministic_and_sorted(tmp_path):
    results = tmp_path / "results"
    for name in ("zeta", "alpha"):
        record_module.record(name, {"x": 1}, out_dir=results, argv=ARGV)
    scripts = list(_benchmarks(tmp_path).glob("bench_*.py"))
    page = gen.render(gen.load_records(results), scripts)
    assert page.index("## alpha") < page.index("## zeta")
    assert page == gen.render(gen.load_records(results), reversed(scripts))


@pytest.mark.parametrize(
    ("value", "unit", "text"),
    [
        (0.213, "s", "0.213 s"),
        (12000, "designs", "12,000 designs"),
        (3.5, "°", "3.5°"),
        (None, "µs", "n/a"),
        (False, "", "no"),
        ("a|b", "", "a|b"),
        ("n/a", "µs", "n/a"),
        (1 / 3, "%", "0.3333 %"),
    ],
)
def test_format_value(value, unit, text):
    assert gen.format_value(value, unit) == text


def test_check_mode_tells_a_stale_page(tmp_path, capsys):
    results, out = tmp_path / "results", tmp_path / "performance.md"
    _record(results)
    benchmarks = _benchmarks(tmp_path)
    argv = ["--results", str(results), "--benchmarks", str(benchmarks), "--out", str(out)]
    assert gen.main([*argv, "--check"]) == 1  # no page yet
    assert gen.main(argv) == 0
    assert gen.main([*argv, "--check"]) == 0
    out.write_text(out.read_text() + "typed by hand\n")
    assert gen.main([*argv, "--check"]) == 1
    assert "is out of date: run `make docs`" in capsys.readouterr().err


def test_a_file_that_is_not_a_record_is_refused(tmp_path, capsys):
    results = tmp_path / "results"
    results.mkdir()
    (results / "broken.json").write_text('{"benchmark": "broken"}')
    assert gen.main(["--results", str(results), "--out", str(tmp_path / "p.md")]) == 2
    assert "must be a benchmark record" in capsys.readouterr().err
    assert not (tmp_path / "p.md").exists()


def test_the_committed_page_is_current():
    assert gen.main(["--check"]) == 0, (
        "docs/performance.md is out of date: run `make docs` (python docs/gen_performance.py)"
    )
