"""Compare two ``summary.json`` files of ``softbend reproduce`` key by key.

A refactoring that must not change paper B's figures is checked by running ``make run``
before and after and comparing the two summaries. What is timed differs on every run and
is left out: the run's dates and wall time (the volatile entries of ``provenance``) and
every value whose key names a duration or a speed (``seconds``, ``*_s``, ``*_ms``,
``*_us``, ``*_per_s``, ``realtime_factor``, ``... (s)``); every other value must be
identical::

    python benchmarks/summary_diff.py before/summary.json results/reproduce/summary.json

Prints each differing key path with both values and exits 1 when any differs.
"""

from __future__ import annotations

import argparse
import json
import re
import sys
from pathlib import Path
from typing import Any

#: Top-level keys that describe the run itself rather than its figures.
RUN_KEYS = ("seconds",)
#: A key whose value is a duration or a speed: measured anew on every run.
TIMED = re.compile(r"(seconds|_s|_ms|_us|_per_s|realtime_factor|\((s|ms|µs)\))$")
#: Entries of ``provenance`` that change with every run.
VOLATILE = ("started (UTC)", "finished (UTC)", "wall time")


def _walk(a: Any, b: Any, path: str, out: list[str]) -> None:
    if isinstance(a, dict) and isinstance(b, dict):
        for key in sorted(set(a) | set(b), key=str):
            here = f"{path}.{key}" if path else str(key)
            if TIMED.search(str(key)):
                continue
            if key not in a or key not in b:
                out.append(f"{here}: only in {'after' if key in b else 'before'}")
            else:
                _walk(a[key], b[key], here, out)
    elif isinstance(a, list) and isinstance(b, list) and len(a) == len(b):
        for i, (x, y) in enumerate(zip(a, b, strict=True)):
            _walk(x, y, f"{path}[{i}]", out)
    elif a != b:
        out.append(f"{path}: {a!r} -> {b!r}")


def differences(before: dict[str, Any], after: dict[str, Any]) -> list[str]:
    """Key paths whose values differ, leaving off the run's own dates and wall time."""

    def figures(summary: dict[str, Any]) -> dict[str, Any]:
        kept = {k: v for k, v in summary.items() if k not in RUN_KEYS}
        if isinstance(kept.get("provenance"), dict):
            kept["provenance"] = {k: v for k, v in kept["provenance"].items() if k not in VOLATILE}
        return kept

    out: list[str] = []
    _walk(figures(before), figures(after), "", out)
    return out


def _summary(path: Path) -> dict:
    """A ``summary.json``, given as the file or as the report folder that holds it."""
    file = path / "summary.json" if path.is_dir() else path
    if not file.is_file():
        print(f"summary_diff: no summary.json at {path}", file=sys.stderr)
        sys.exit(2)
    return json.loads(file.read_text(encoding="utf-8"))


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("before", type=Path, help="summary.json, or the report folder holding it")
    parser.add_argument("after", type=Path, help="summary.json, or the report folder holding it")
    args = parser.parse_args()
    found = differences(_summary(args.before), _summary(args.after))
    print("\n".join(found) if found else "identical (dates, durations and speeds left off)")
    sys.exit(1 if found else 0)


if __name__ == "__main__":
    main()
