"""The tutorial on an identified model (docs/tutorial-identified-model.md) runs as written and
prints the figures it shows: the model's reading, its free run on a new input, and the rows
that name the identified plant and the rig set from it."""

from __future__ import annotations

import os
import re
import shutil
import subprocess
import sys
from pathlib import Path

import pytest

from .doc_commands import softbend_commands
from .test_tutorials import ROOT, TUTORIALS, _script, unanswered

PAGE = ROOT / "docs" / "tutorial-identified-model.md"


def _shown(text: str) -> str:
    """The ```text blocks of the page (what the reader should see), joined."""
    return "\n".join(re.findall(r"```text\n(.*?)```", text, flags=re.S))


def _cells(line: str) -> list[str]:
    """The words of a table line, whatever its box drawing."""
    return [w for w in re.split(r"[\s│┃]+", line) if w]


#: Lines the page shows that the run must print (the figures a reader compares with).
FIGURES = [
    "pressure_mpa → angle_deg   1310 deg/MPa   0.0544 s     0 s",
    "angle_deg  6.962    73.5   71.67           0.0004",
    "plant                identified model ident/model.json (poly2-sim na=2 nb=3 (filter=True, "
    "seed=0), input tau = 3.67 samples), sample period 0.01 s",
    "rig from             ident/model.json: angle_time_constant_s 0.0544 s, valve_delay_s 0 s",
]


def test_the_page_is_a_tutorial_with_its_expected_outputs():
    text = PAGE.read_text(encoding="utf-8")
    assert PAGE in TUTORIALS  # tests/test_tutorials.py runs it as written, too
    assert not unanswered(text)
    shown = _shown(text)
    for figure in FIGURES:
        assert figure in shown, figure
    commands = [c for _, c in softbend_commands(PAGE)]
    assert any(c.startswith("softbend identify") for c in commands)
    assert any(c.startswith("softbend predict ident/model.json") for c in commands)
    assert any("--plant ident/model.json" in c for c in commands)
    assert any("--rig-from ident/model.json" in c for c in commands)


@pytest.mark.slow
def test_the_page_prints_the_figures_it_shows(tmp_path):
    bash = shutil.which("bash")
    if bash is None:
        pytest.skip("bash is needed to run the tutorial")
    (tmp_path / "src").symlink_to(ROOT / "src", target_is_directory=True)
    (tmp_path / "examples").symlink_to(ROOT / "examples", target_is_directory=True)
    env = {
        **os.environ,
        "PATH": f"{Path(sys.executable).parent}{os.pathsep}{os.environ['PATH']}",
        "COLUMNS": "200",
    }
    done = subprocess.run(
        [bash, "-c", _script(PAGE)], cwd=tmp_path, env=env, capture_output=True, text=True,
        timeout=900, check=False,
    )  # fmt: skip
    assert done.returncode == 0, done.stderr[-3000:]
    printed = [_cells(line) for line in done.stdout.splitlines()]
    for figure in FIGURES:
        assert _cells(figure) in printed, figure
