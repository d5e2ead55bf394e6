"""The tutorials in docs/ (and Getting started) run as written: every bash block, in order, in a
fresh folder.

Set-up lines (``make …``, ``source .venv/bin/activate``, ``export PATH=…``) are left out: the
test runs with this environment's softbend first on PATH. The folder holds links to the
repository's ``src`` and ``examples`` so that the tutorials' paths to the shipped data work as
they do from the repository's folder.
"""

from __future__ import annotations

import os
import re
import shutil
import subprocess
import sys
from pathlib import Path

import pytest

ROOT = Path(__file__).resolve().parents[1]
#: The pages a newcomer follows step by step: the tutorials and Getting started.
TUTORIALS = [*sorted((ROOT / "docs").glob("tutorial-*.md")), ROOT / "docs" / "getting-started.md"]
_SETUP = re.compile(r"^\s*(make |source \.venv/bin/activate|export PATH=)")


def _script(page: Path) -> str:
    blocks = re.findall(r"```bash\n(.*?)```", page.read_text(encoding="utf-8"), flags=re.S)
    lines = [line for block in blocks for line in block.splitlines() if not _SETUP.match(line)]
    return "set -euo pipefail\n" + "\n".join(lines) + "\n"


def unanswered(text: str) -> list[int]:
    """The first lines of the ```bash blocks with a ``softbend`` command that no "You should
    see" line follows before the next ```bash block: the reader has nothing to compare with."""
    missing: list[int] = []
    waiting: int | None = None  # the first line of a softbend block not yet answered
    fence: str | None = None  # the fence of the block the line is in, None outside
    start, has_command = 0, False
    for number, line in enumerate(text.splitlines(), start=1):
        if line.startswith("```"):
            if fence is None:
                fence = line.strip()
                if fence == "```bash":
                    if waiting is not None:
                        missing.append(waiting)
                        waiting = None
                    start, has_command = number, False
            else:
                if fence == "```bash" and has_command:
                    waiting = start
                fence = None
            continue
        if fence == "```bash" and line.strip().startswith("softbend "):
            has_command = True
        if fence is None and line.startswith("You should see"):
            waiting = None
    return [*missing, *([] if waiting is None else [waiting])]


def test_a_command_block_without_its_expected_output_is_caught():
    page = (
        "```bash\nsoftbend --help\n```\n\nYou should see (abridged):\n\n```text\nUsage\n```\n"
        "```bash\ncat > a.csv <<'EOF'\nx\nEOF\n```\n"
        "```bash\nsoftbend predict m.json \\\n    --pressures 0.1\n```\nThe angle.\n"
        "```bash\nsoftbend materials list\n```\n"
    )
    assert unanswered(page) == [15, 20]


@pytest.mark.parametrize("page", TUTORIALS, ids=lambda p: p.stem)
def test_every_command_block_shows_what_to_expect(page):
    lines = unanswered(page.read_text(encoding="utf-8"))
    assert not lines, f"{page.name}: add a 'You should see' after the blocks of lines {lines}"


def test_there_is_a_tutorial_for_one_s_own_measurements():
    assert ROOT / "docs" / "tutorial-own-measurements.md" in TUTORIALS


@pytest.mark.parametrize("page", TUTORIALS, ids=lambda p: p.stem)
def test_a_tutorial_runs_as_written(page, tmp_path):
    bash = shutil.which("bash")
    if bash is None:
        pytest.skip("bash is needed to run the tutorials")
    (tmp_path / "src").symlink_to(ROOT / "src", target_is_directory=True)
    (tmp_path / "examples").symlink_to(ROOT / "examples", target_is_directory=True)
    env = {**os.environ, "PATH": f"{Path(sys.executable).parent}{os.pathsep}{os.environ['PATH']}"}
    done = subprocess.run(
        [bash, "-c", _script(page)],
        cwd=tmp_path,
        env=env,
        capture_output=True,
        text=True,
        timeout=900,
        check=False,
    )
    assert done.returncode == 0, f"{page.name}:\n{done.stderr[-3000:]}"
