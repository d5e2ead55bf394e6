"""Benchmark: the README's two commands on this machine, against their budgets.

1. ``run``: the main job, ``softbend reproduce`` on its built-in defaults (what
   ``make run`` runs after its setup), in a fresh process into a temporary
   folder; prints the wall time against the 10-minute budget and each section's
   own seconds from the run's ``summary.json``.
2. ``tests``: the test command CI runs (``make test-full``: every test but the
   slow tier, with ``--durations``), in a fresh process; prints the wall time
   against the 20-minute budget (for ``.ci/run`` as a whole, which adds lint,
   type check and the documentation build, about 2.5 minutes here), the number
   of tests over 20 s (the budget for a test outside the slow tier) and the
   slowest five.

Each is minutes long (about 6 and 15 on two cores), so each runs alone on
request; the setup (``make setup``) is not timed. Run::

    .venv/bin/python benchmarks/bench_readme_commands.py run [--out results/reproduce]
    .venv/bin/python benchmarks/bench_readme_commands.py tests
"""

from __future__ import annotations

import argparse
import json
import re
import subprocess
import sys
import tempfile
import time
from pathlib import Path

from _record import record

ROOT = Path(__file__).resolve().parents[1]

#: Budgets of the two commands on two cores (issue "Fast by default"), seconds.
RUN_BUDGET_S = 600.0
TESTS_BUDGET_S = 1200.0
#: The longest a test outside the slow tier may take, seconds.
TEST_BUDGET_S = 20.0

#: The command line, as the ``softbend`` script runs it.
_CLI = "import sys; from softbend.cli import run; sys.argv[0] = 'softbend'; run()"

#: A line of pytest's --durations table: "12.34s call     tests/x.py::test_y".
_DURATION = re.compile(r"^\s*([0-9.]+)s\s+(call|setup|teardown)\s+(\S+)")


def bench_run(keep: Path | None = None) -> None:
    """Time ``softbend reproduce`` on its defaults and record the figures.

    The report is written into ``keep`` when given (to compare or publish its
    figures), else into a temporary folder.
    """
    with tempfile.TemporaryDirectory(prefix="softbend-bench-run-") as folder:
        out = keep if keep is not None else Path(folder) / "reproduce"
        start = time.perf_counter()
        subprocess.run(
            [sys.executable, "-c", _CLI, "reproduce", "--out", str(out)],
            check=True,
            cwd=ROOT,
        )
        wall = time.perf_counter() - start
        summary = json.loads((out / "summary.json").read_text())
    sections = {
        name: float(value["seconds"])
        for name, value in summary.items()
        if isinstance(value, dict) and isinstance(value.get("seconds"), int | float)
    }
    print(f"softbend reproduce: {wall:.0f} s ({wall / RUN_BUDGET_S:.0%} of the 10-min budget)")
    for name, seconds in sorted(sections.items(), key=lambda item: -item[1]):
        print(f"  {name:<22} {seconds:7.1f} s")
    figures: dict[str, float] = {"wall time": round(wall, 1)}
    figures |= {f"section {name}": round(s, 1) for name, s in sections.items()}
    record(
        "readme-run",
        figures,
        units=dict.fromkeys(figures, "s"),
        notes="softbend reproduce on its defaults in a fresh process (make run less its setup); "
        "budget 600 s on two cores.",
    )


def durations(text: str) -> list[tuple[float, str, str]]:
    """The (seconds, phase, test) rows of pytest's --durations table in ``text``."""
    rows = []
    for line in text.splitlines():
        match = _DURATION.match(line)
        if match:
            rows.append((float(match.group(1)), match.group(2), match.group(3)))
    return rows


def bench_tests() -> None:
    """Time the CI test command and record the figures."""
    start = time.perf_counter()
    done = subprocess.run(
        [sys.executable, "-m", "pytest", "-q", "-m", "not slow", "--durations=40"],
        cwd=ROOT,
        capture_output=True,
        text=True,
        check=False,
    )
    wall = time.perf_counter() - start
    tail = done.stdout.strip().splitlines()[-1] if done.stdout.strip() else ""
    rows = durations(done.stdout)
    over = [row for row in rows if row[0] > TEST_BUDGET_S]
    print(f"pytest -m 'not slow': {wall:.0f} s ({wall / TESTS_BUDGET_S:.0%} of 20 min); {tail}")
    print(f"tests over {TEST_BUDGET_S:.0f} s: {len(over)}")
    for seconds, phase, test in rows[:5]:
        print(f"  {seconds:6.1f} s {phase:<8} {test}")
    if done.returncode != 0:
        print(done.stdout[-3000:], file=sys.stderr)
        raise SystemExit(f"the tests failed (exit {done.returncode}); nothing recorded")
    figures: dict[str, float | str] = {
        "wall time": round(wall, 1),
        f"tests over {TEST_BUDGET_S:.0f} s": len(over),
        "slowest test": rows[0][2] if rows else "",
        "slowest test: seconds": round(rows[0][0], 1) if rows else 0.0,
    }
    record(
        "readme-tests",
        figures,
        units={"wall time": "s", "slowest test: seconds": "s"},
        notes=f"pytest -m 'not slow' (make test-full) in a fresh process: {tail}; "
        "budget 1 200 s for .ci/run as a whole on two cores.",
    )


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    parser.add_argument("command", choices=("run", "tests"), help="Which README command.")
    parser.add_argument(
        "--out", type=Path, help="run: keep the report in this folder (default: a temporary one)."
    )
    args = parser.parse_args()
    if args.command == "run":
        bench_run(args.out)
    else:
        bench_tests()


if __name__ == "__main__":
    main()
