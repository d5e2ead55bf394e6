"""The README's tour runs: every ``softbend …`` command of its bash blocks, in order, in a quick
variant, in a fresh folder; and its first line makes ``softbend`` a command of a new shell.

The README's tour is already in quick settings (a coarse FEM mesh, the analytical lab, no MLP);
the test's variant appends options to a command (a later option wins in the command line) so
that the tour runs in about a minute: a coarser mesh still, fewer designs and folds, an
analytical check instead of the FEM's. :data:`QUICK` holds them by command. A command of the
README that :data:`QUICK` does not know fails the test, so each new command gets a decision.
``make run`` and ``make test-full``, the README's two commands, are what CI and the pipeline tests
run; they are not run again here.
"""

from __future__ import annotations

import os
import shlex
import shutil
import subprocess
import sys
from pathlib import Path

import pytest

from .doc_commands import softbend_commands

ROOT = Path(__file__).resolve().parents[1]

#: Options appended to each README command (by its command path) in the quick variant.
QUICK: dict[str, tuple[str, ...]] = {
    "materials fit": (),
    "fem run": ("--maxh", "12", "--pmax", "0.04", "--pstep", "0.02", "--shapes", "2"),
    "campaign run": ("--space", "corners", "--pmax", "0.1", "--pstep", "0.01"),
    "analyze": (),
    "train": ("--folds", "2", "--no-onnx"),
    "predict": (),
    "design find": ("--verify", "1", "--backend", "analytical"),
    "lab measure": ("--plant", "analytical"),
    "transfer loco": ("--strategies", "scale-offset,pressure-scale", "--no-learning-curve"),
    "transfer refine": ("--epochs", "20"),
    "control simulate": ("--duration", "4"),
    "curling simulate": ("--experiments", "3", "--samples", "160"),
    "curling identify": (),
}


def _commands() -> list[list[str]]:
    """The README's ``softbend`` commands as words, continuation lines joined."""
    return [shlex.split(command) for _, command in softbend_commands(ROOT / "README.md")]


def _path(words: list[str]) -> str:
    """``fem run`` of ``softbend fem run --design …``."""
    head = [w for w in words[1:3] if not w.startswith("-")]
    two = " ".join(head[:2])
    return two if two in QUICK else head[0]


COMMANDS = _commands()


def test_the_tour_shows_the_lab_s_path():
    paths = [_path(c) for c in COMMANDS]
    assert len(paths) >= 12
    for stage in ("materials fit", "fem run", "campaign run", "train", "design find"):
        assert stage in paths
    assert {"transfer refine", "control simulate", "curling identify"} <= set(paths)


def test_every_readme_command_has_a_quick_variant():
    unknown = sorted({_path(c) for c in COMMANDS} - set(QUICK))
    assert not unknown, f"add the README's {unknown} to QUICK (with the options that make it quick)"


def _tour() -> list[str]:
    """The lines of the tour's bash block (the first after its heading)."""
    text = (ROOT / "README.md").read_text(encoding="utf-8")
    after = text[text.index("## A five-minute tour") :]
    return after.split("```bash\n", 1)[1].split("```", 1)[0].splitlines()


def test_the_tour_opens_with_the_line_that_puts_softbend_on_path():
    lines = [line for line in _tour() if line.strip() and not line.startswith("#")]
    assert lines[0].split("#")[0].strip() == "source .venv/bin/activate"
    assert all(line.lstrip().startswith(("softbend ", "-")) for line in lines[1:]), lines


def test_the_first_line_makes_softbend_a_command_of_a_new_shell(tmp_path):
    """In a shell whose PATH has no softbend, the tour's first line finds .venv's."""
    bash = shutil.which("bash")
    venv = Path(sys.prefix)
    if bash is None or not (venv / "bin" / "activate").is_file():
        pytest.skip("needs bash and a virtual environment with bin/activate")
    (tmp_path / ".venv").symlink_to(venv, target_is_directory=True)
    plain = os.pathsep.join(
        p for p in os.environ["PATH"].split(os.pathsep) if not (Path(p) / "softbend").exists()
    )
    env = {**os.environ, "PATH": plain or "/usr/bin:/bin"}
    env.pop("VIRTUAL_ENV", None)
    missing = subprocess.run(
        [bash, "-c", "command -v softbend"], cwd=tmp_path, env=env, capture_output=True, text=True
    )
    assert missing.returncode != 0  # as a new user's shell after make run
    first = _tour()[0].split("#")[0].strip()
    found = subprocess.run(
        [bash, "-c", f"{first} && command -v softbend"],
        cwd=tmp_path,
        env=env,
        capture_output=True,
        text=True,
        timeout=120,
    )
    assert found.returncode == 0, found.stderr
    assert Path(found.stdout.strip()).samefile(venv / "bin" / "softbend")


def _tree(root: Path) -> dict[str, tuple[int, int]]:
    """Every file and folder under ``root`` (links not followed): size and modification time."""
    found = {}
    for path in root.rglob("*"):
        if path.is_symlink():
            continue
        info = path.stat()
        found[path.relative_to(root).as_posix()] = (info.st_size, info.st_mtime_ns)
    return found


def _outputs(words: list[str]) -> set[str]:
    """The first path component of every output a command names: --out, -o, a campaign's DB."""
    named = {words[i + 1] for i, w in enumerate(words[:-1]) if w in ("--out", "-o")}
    if _path(words) == "campaign run":
        named.add(words[3])
    return {Path(n).parts[0] for n in named}


def _outside(changed: set[str], outputs: set[str]) -> list[str]:
    """The changed paths outside a command's outputs.

    Beside an output file, its companions count as the output: a DuckDB write-ahead
    log (``table1.duckdb.wal``) and the figure of a measurement file (``lab.png``
    beside ``lab.csv``).
    """

    def own(top: str, output: str) -> bool:
        stem = Path(output).stem
        return top in (output, f"{output}.wal") or (stem != output and top == f"{stem}.png")

    return sorted(p for p in changed if not any(own(Path(p).parts[0], o) for o in outputs))


def test_the_tour_runs_in_its_quick_variant(tmp_path):
    """Each command succeeds and writes nothing outside its own outputs."""
    (tmp_path / "src").symlink_to(ROOT / "src", target_is_directory=True)
    bin_dir = Path(sys.executable).parent
    env = {**os.environ, "PATH": f"{bin_dir}{os.pathsep}{os.environ['PATH']}"}
    softbend = str(bin_dir / "softbend") if (bin_dir / "softbend").exists() else "softbend"
    for words in COMMANDS:
        argv = [softbend, *words[1:], *QUICK[_path(words)]]
        before = _tree(tmp_path)
        done = subprocess.run(
            argv, cwd=tmp_path, env=env, capture_output=True, text=True, timeout=600, check=False
        )
        shown = " ".join(words)
        assert done.returncode == 0, f"{shown}\n{done.stderr[-3000:]}"
        after = _tree(tmp_path)
        changed = {p for p, v in after.items() if before.get(p) != v} | (set(before) - set(after))
        assert not _outside(changed, _outputs(words)), f"{shown} wrote outside its outputs"
    # The tour's files are where the README says they are.
    for name in ("mat/fit.json", "corners.duckdb", "surrogates/models/xgb.json", "refined.json"):
        assert (tmp_path / name).exists(), name
    assert (tmp_path / "ctl").is_dir() and (tmp_path / "ident").is_dir()
