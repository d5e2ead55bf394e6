"""Write docs/performance.md from the benchmarks' JSON files (run by `make docs`).

Every ``benchmarks/bench_*.py`` records its headline figures in
``benchmarks/results/<name>.json`` (``benchmarks/_record.py``). This script renders
one section per file, sorted by name: a table of the figures with their units,
the command that measured them, the date, the commit and the machine. Benchmark
scripts with no file yet are listed at the end with the command to run.

Usage: python docs/gen_performance.py [--check] [--results DIR] [--benchmarks DIR] [--out FILE]

``--check`` writes nothing and exits 1 if the page differs from what it would write.
A results file that is not a benchmark record (not JSON, a key missing or of the
wrong type) is one line naming the file and what is wrong, exit code 2, and the
page is left as it was.
"""

from __future__ import annotations

import argparse
import ast
import json
import re
import sys
from collections.abc import Iterable, Mapping, Sequence
from pathlib import Path
from typing import Any

ROOT = Path(__file__).resolve().parents[1]
RESULTS = ROOT / "benchmarks" / "results"
BENCHMARKS = ROOT / "benchmarks"
PAGE = ROOT / "docs" / "performance.md"

#: The keys every record must have (``benchmarks/_record.py``, schema 1).
REQUIRED = ("benchmark", "command", "date", "figures", "machine", "notes", "software")

INTRO = """\
# Performance

What softbend's benchmarks measured, figure by figure, with the machine, the date and
the command of each. This page is generated: `make docs` runs `docs/gen_performance.py`,
which reads the JSON files the benchmarks write to `benchmarks/results/` (one per
benchmark, written by `benchmarks/_record.py`); do not edit it by hand.

To refresh a benchmark's figures, run its command (shown under its table) from the
repository root, then `make docs`. Timings depend on the machine and on what else it
runs: compare them within one section, or rerun the other benchmark on the same machine.
"""


class RecordError(ValueError):
    """A file of the results folder is not a benchmark record."""


#: The type each key of :data:`REQUIRED` must have, as JSON names it.
_TYPES: dict[str, tuple[type, ...]] = {
    "benchmark": (str,),
    "command": (str,),
    "date": (str,),
    "figures": (list,),
    "machine": (dict,),
    "notes": (str,),
    "software": (dict,),
}

#: The schema of ``benchmarks/_record.py`` this page reads.
SCHEMA = 1


def json_kind(value: Any) -> str:
    """What a parsed JSON value is, as JSON names it (``"an object"``, ``"null"``…).

    >>> json_kind({}), json_kind([1]), json_kind("x"), json_kind(2.5), json_kind(None)
    ('an object', 'a list', 'a string', 'a number', 'null')
    """
    if value is None:
        return "null"
    if isinstance(value, bool):
        return "true or false"
    if isinstance(value, int | float):
        return "a number"
    if isinstance(value, str):
        return "a string"
    return "a list" if isinstance(value, list) else "an object"


def read_json(path: Path, error: type[Exception]) -> Any:
    """The parsed JSON of ``path``; ``error`` naming the file for one that cannot be.

    Unreadable, not UTF-8, not JSON (with the line and column) or nested too
    deeply to parse: one line each.
    """
    try:
        text = path.read_text(encoding="utf-8")
    except UnicodeDecodeError as exc:
        raise error(f"{path}: not UTF-8 text (undecodable byte at offset {exc.start}).") from None
    except OSError as exc:
        raise error(f"{path}: cannot be read ({exc.strerror or type(exc).__name__}).") from None
    try:
        return json.loads(text)
    except json.JSONDecodeError as exc:
        raise error(f"{path}: not valid JSON (line {exc.lineno}, column {exc.colno}).") from None
    except RecursionError:
        raise error(f"{path}: JSON nested too deeply to read.") from None


def check_record(data: Any, path: Path) -> dict[str, Any]:
    """``data`` if it is a benchmark record of :data:`SCHEMA`, else :class:`RecordError`.

    Every key of :data:`REQUIRED` with its type (:data:`_TYPES`); ``figures`` a
    list of objects, each with a text ``name``, a text ``unit`` (or none) and a
    ``value`` that is a number, a text, true/false or null.
    """
    missing = [k for k in REQUIRED if not isinstance(data, dict) or k not in data]
    if missing:
        raise RecordError(
            f"The file {path} must be a benchmark record with keys {list(REQUIRED)}. "
            f"Got one without {missing} instead."
        )
    for key, types in _TYPES.items():
        if not isinstance(data[key], types):
            wanted = json_kind(types[0]())
            raise RecordError(
                f"The file {path} must be a benchmark record whose '{key}' is {wanted}. "
                f"Got {json_kind(data[key])} instead."
            )
    schema = data.get("schema", SCHEMA)
    if schema != SCHEMA or isinstance(schema, bool):
        raise RecordError(
            f"The file {path} must be a benchmark record of schema {SCHEMA}. "
            f"Got schema {schema!r} instead."
        )
    for i, figure in enumerate(data["figures"]):
        where = f"The file {path} must be a benchmark record whose figure {i + 1}"
        if not isinstance(figure, dict) or not isinstance(figure.get("name"), str):
            raise RecordError(
                f"{where} is an object with a text 'name'. Got {json_kind(figure)}"
                f"{'' if not isinstance(figure, dict) else ' without one'} instead."
            )
        if not isinstance(figure.get("unit", ""), str | None):
            raise RecordError(
                f"{where} ({figure['name']!r}) has a text 'unit'. "
                f"Got {json_kind(figure['unit'])} instead."
            )
        if not isinstance(figure.get("value"), int | float | str | None):
            raise RecordError(
                f"{where} ({figure['name']!r}) has a 'value' that is a number, a text, "
                f"true/false or null. Got {json_kind(figure['value'])} instead."
            )
    return data


def load_records(folder: Path) -> list[dict[str, Any]]:
    """The records of ``folder/*.json``, sorted by benchmark name.

    Raises
    ------
    RecordError
        If ``folder`` is not a folder, or a file is not JSON or not a benchmark
        record (:func:`check_record`), naming the file and what is wrong.
    """
    if not folder.is_dir():
        raise RecordError(f"The results folder {folder} does not exist or is not a folder.")
    records = [check_record(read_json(p, RecordError), p) for p in sorted(folder.glob("*.json"))]
    return sorted(records, key=lambda r: str(r["benchmark"]))


def script_of(command: str) -> str | None:
    """The ``bench_*.py`` file a recorded command ran, if it names one."""
    match = re.search(r"(?:^|[\s/])(bench_[A-Za-z0-9_]+\.py)\b", command)
    return match.group(1) if match else None


def _docstring(script: Path) -> str:
    try:
        return ast.get_docstring(ast.parse(script.read_text(encoding="utf-8"))) or ""
    except (OSError, SyntaxError):
        return ""


def summary_of(script: Path) -> str:
    """The first line of a benchmark script's docstring (without a ``Benchmark:`` prefix)."""
    first = _docstring(script).strip().split("\n", 1)[0].strip()
    first = re.sub(r"^Benchmark:\s*", "", first)
    first = re.sub(r":[a-z]+:`~?([^`]+)`", r"`\1`", first).replace("``", "`")  # reST roles
    return first[:1].upper() + first[1:]


def default_command(script: Path) -> str:
    """How to run a script: the first command its docstring shows, else ``python <script>``."""
    name = re.escape(script.name)
    for line in _docstring(script).splitlines():
        match = re.search(rf"benchmarks/{name}([^#\n]*)", line)
        if match:
            args = match.group(1).replace("\\", " ").strip()
            if args.startswith(("[", "&")) or " & " in args:
                args = ""  # a synopsis or two shards side by side: the plain run
            return " ".join(["python", f"benchmarks/{script.name}", *args.split()])
    return f"python benchmarks/{script.name}"


def format_value(value: Any, unit: str = "") -> str:
    """A figure as the page shows it: the number and its unit, or the text alone.

    >>> format_value(0.213, "s"), format_value(12000, "designs"), format_value(3.5, "°")
    ('0.213 s', '12,000 designs', '3.5°')
    >>> format_value(None, "µs"), format_value(True), format_value("n/a", "µs")
    ('n/a', 'yes', 'n/a')
    """
    if value is None:
        return "n/a"
    if isinstance(value, bool):
        text = "yes" if value else "no"
    elif isinstance(value, int):
        text = f"{value:,}"
    elif isinstance(value, float):
        text = repr(value) if len(repr(value)) <= 10 else f"{value:.4g}"
    else:
        return str(value)  # a text (a design, "5 of 5") carries no unit
    if not unit:
        return text
    return f"{text}{unit}" if unit == "°" else f"{text} {unit}"


def _cell(text: str) -> str:
    return text.replace("|", "\\|").replace("\n", " ")


def _machine(machine: Mapping[str, Any]) -> str:
    parts = [str(machine.get("cpu") or "unknown CPU")]
    if machine.get("logical_cores"):
        parts.append(f"{machine['logical_cores']} logical cores")
    if machine.get("memory_gib"):
        parts.append(f"{machine['memory_gib']} GiB memory")
    parts.append(f"GPU {machine['gpu']}" if machine.get("gpu") else "no GPU used")
    if machine.get("load_average_1min") is not None:
        parts.append(f"load average {machine['load_average_1min']} before it started")
    if machine.get("platform"):
        parts.append(str(machine["platform"]))
    return ", ".join(parts)


def _software(software: Mapping[str, Any]) -> str:
    commit = str(software.get("git_commit") or "unknown")
    text = "commit unknown" if commit == "unknown" else f"commit `{commit[:10]}`"
    if software.get("git_dirty"):
        text += " (with uncommitted changes)"
    versions = ", ".join(
        f"{label} {software[key]}"
        for key, label in (("python", "Python"), ("numpy", "NumPy"), ("softbend", "softbend"))
        if software.get(key)
    )
    return f"{text}; {versions}" if versions else text


def _date(date: str) -> str:
    return date.replace("T", " ").replace("+00:00", " UTC")


def section(record: Mapping[str, Any], summary: str = "") -> str:
    """The Markdown section of one record: heading, figure table, notes, how measured."""
    script = script_of(str(record["command"]))
    lines = [f"## {record['benchmark']}", ""]
    if script:
        lines += [f"`benchmarks/{script}`: {summary}" if summary else f"`benchmarks/{script}`", ""]
    lines += ["| Figure | Value |", "|---|---|"]
    for figure in record["figures"]:
        value = format_value(figure.get("value"), str(figure.get("unit") or ""))
        lines.append(f"| {_cell(str(figure['name']))} | {_cell(value)} |")
    lines.append("")
    if record.get("notes"):
        lines += [f"{record['notes']}", ""]
    lines += [
        f"- Command: `{record['command']}`",
        f"- Measured: {_date(str(record['date']))}, {_software(record['software'])}",
        f"- Machine: {_machine(record['machine'])}",
        "",
    ]
    return "\n".join(lines)


def render(records: Sequence[Mapping[str, Any]], scripts: Iterable[Path]) -> str:
    """The whole page: the introduction, one section per record, then what is not measured.

    Parameters
    ----------
    records : sequence of mapping
        The benchmark records (:func:`load_records`), shown in name order.
    scripts : iterable of Path
        The benchmark scripts; those that no record's command ran are listed as
        not measured yet, with :func:`default_command`.
    """
    scripts = sorted(scripts, key=lambda p: p.name)
    by_name = {p.name: p for p in scripts}
    parts = [INTRO]
    for record in sorted(records, key=lambda r: str(r["benchmark"])):
        script = by_name.get(script_of(str(record["command"])) or "")
        parts.append(section(record, summary_of(script) if script else ""))
    measured = {script_of(str(r["command"])) for r in records}
    missing = [p for p in scripts if p.name not in measured]
    if missing:
        rows = ["## Not measured yet", ""]
        rows += [
            "These benchmarks have no figures on this page yet (long FEM campaigns, "
            "GPU runs, or not run since they started recording): run the command, "
            "then `make docs`.",
            "",
            "| Benchmark | What it measures | Command |",
            "|---|---|---|",
        ]
        rows += [
            f"| `benchmarks/{p.name}` | {_cell(summary_of(p))} | `{_cell(default_command(p))}` |"
            for p in missing
        ]
        parts.append("\n".join([*rows, ""]))
    return "\n".join(parts)


def main(argv: Sequence[str] | None = None) -> int:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--check", action="store_true", help="exit 1 if the page is stale")
    parser.add_argument("--results", type=Path, default=RESULTS, help="folder of the JSON files")
    parser.add_argument("--benchmarks", type=Path, default=BENCHMARKS, help="bench_*.py folder")
    parser.add_argument("--out", type=Path, default=PAGE, help="the page to write")
    args = parser.parse_args(argv)
    try:
        records = load_records(args.results)
        if not args.benchmarks.is_dir():
            raise RecordError(
                f"The benchmarks folder {args.benchmarks} does not exist or is not a folder."
            )
    except RecordError as exc:
        print(exc, file=sys.stderr)
        return 2
    text = render(records, args.benchmarks.glob("bench_*.py"))
    if args.check:
        current = args.out.read_text(encoding="utf-8") if args.out.is_file() else None
        if current != text:
            print(
                f"{args.out} is out of date: run `make docs` (python docs/gen_performance.py).",
                file=sys.stderr,
            )
            return 1
        return 0
    from softbend._io import write_text_atomic

    try:
        write_text_atomic(args.out, text)  # the page whole or as it was, never half of it
    except OSError as exc:
        print(f"{args.out}: cannot be written ({exc.strerror or exc}).", file=sys.stderr)
        return 1
    print(f"wrote {args.out} from {len(records)} benchmark records")
    return 0


if __name__ == "__main__":
    sys.exit(main())
