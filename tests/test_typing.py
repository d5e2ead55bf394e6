"""softbend is a typed package: py.typed ships, mypy's scope is stated, the public API checks.

``make typecheck`` runs mypy on the whole package (CI runs it after the tests);
these tests keep its configuration honest and show what a user's type checker sees.
"""

from __future__ import annotations

import importlib.util
import subprocess
import sys
import tomllib
from pathlib import Path

import pytest

import softbend

PACKAGE = Path(softbend.__file__).parent
ROOT = PACKAGE.parent.parent
PYPROJECT = tomllib.loads((ROOT / "pyproject.toml").read_text(encoding="utf-8"))
MYPY = PYPROJECT["tool"]["mypy"]
#: Modules whose type errors mypy is told to ignore, still to be fixed.
IGNORED = {
    module
    for override in MYPY.get("overrides", [])
    if override.get("ignore_errors")
    for module in override["module"]
}
#: What must stay clean: the typed seams between the stages.
MUST_CHECK = (
    "softbend._io",
    "softbend.registry",
    "softbend.models",
    "softbend.kinematics",
    "softbend.analytical",
    "softbend.datasets",
    "softbend.fem",
    "softbend.identification",
    "softbend.analysis",
)


def test_the_package_ships_its_py_typed_marker():
    assert (PACKAGE / "py.typed").is_file()
    assert "py.typed" in PYPROJECT["tool"]["setuptools"]["package-data"]["softbend"]
    assert any(
        dev.startswith("mypy") for dev in PYPROJECT["project"]["optional-dependencies"]["dev"]
    )


def test_the_mypy_scope_is_the_whole_package():
    assert MYPY["packages"] == ["softbend"] and MYPY["ignore_missing_imports"] is True
    assert "typecheck:" in (ROOT / "Makefile").read_text(encoding="utf-8")
    assert "make typecheck" in (ROOT / ".ci" / "run").read_text(encoding="utf-8")


def test_the_ignored_modules_exist_and_leave_the_public_seams_checked():
    missing = sorted(m for m in IGNORED if importlib.util.find_spec(m) is None)
    assert not missing, f"drop these from [tool.mypy] overrides: {missing}"
    for module in IGNORED:
        assert not any(module == m or module.startswith(m + ".") for m in MUST_CHECK), module


def test_no_module_is_excused_from_mypy():
    assert not IGNORED, f"fix these instead of ignoring them: {sorted(IGNORED)}"


USER_CODE = """
from softbend.analytical import AnalyticalModel
from softbend.fem import FEMModel, FEMOptions, fem_stats
from softbend.identification import GeneralizedGaussianSVR
from softbend.models import BendingModel, SweepResult

models: list[BendingModel] = [AnalyticalModel(), FEMModel(FEMOptions(maxh_mm=6.0))]


def reason(result: SweepResult) -> str:
    return fem_stats(result)["stop_reason"]


def steps(result: SweepResult) -> int:
    return len(fem_stats(result)["steps_mpa"])


def fast(model: GeneralizedGaussianSVR) -> float:
    return model.predictor()([0.0, 0.0, 0.0, 0.0])
"""

MISSPELT = """
from softbend.fem import fem_stats
from softbend.models import SweepResult


def reason(result: SweepResult) -> str:
    return fem_stats(result)["stop_reasn"]
"""


def _mypy(code: str, tmp_path: Path) -> subprocess.CompletedProcess[str]:
    script = tmp_path / "user.py"
    script.write_text(code, encoding="utf-8")
    return subprocess.run(
        [
            sys.executable,
            "-m",
            "mypy",
            "--ignore-missing-imports",
            "--no-error-summary",
            "--cache-dir",
            str(tmp_path.parent / "mypy-cache"),
            str(script),
        ],
        capture_output=True,
        text=True,
        timeout=600,
        check=False,
        cwd=tmp_path,
        env={"MYPYPATH": str(PACKAGE.parent), "PATH": ""},
    )


def test_user_code_type_checks_against_the_public_api(tmp_path):
    pytest.importorskip("mypy")
    done = _mypy(USER_CODE, tmp_path)
    assert done.returncode == 0, done.stdout + done.stderr
    done = _mypy(MISSPELT, tmp_path)
    assert done.returncode == 1
    assert 'TypedDict "FEMStats" has no key "stop_reasn"' in done.stdout
