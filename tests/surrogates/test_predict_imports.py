"""``softbend predict`` of a saved MLP imports NumPy, not PyTorch nor scikit-learn.

Each check runs in a fresh interpreter, so what the test session imported does
not count.
"""

from __future__ import annotations

import json
import subprocess
import sys
from importlib.resources import files

SHIPPED_MLP = str(files("softbend") / "data" / "transfer" / "table1_fem_mlp.json")

#: Packages that a saved MLP's prediction does not use (training ones, tables).
UNUSED_BY_MLP = ("torch", "sklearn", "scipy", "pandas", "xgboost", "duckdb", "matplotlib")


def _predict_in_fresh_process(model: str, *extra: str) -> tuple[int, list[str], str]:
    """Exit code, the heavy packages imported, and stdout of a fresh ``softbend predict``."""
    code = (
        "import json, sys\n"
        "from softbend.cli import main\n"
        f"code = main(['predict', {model!r}, '--design', '100,6,2,2,5,8', "
        f"'--pressures', '0.05', *{list(extra)!r}])\n"
        "heavy = sorted({m.split('.')[0] for m in sys.modules} & set("
        + repr(UNUSED_BY_MLP)
        + "))\n"
        "print('HEAVY=' + json.dumps(heavy), file=sys.stderr)\n"
        "sys.exit(code)\n"
    )
    done = subprocess.run([sys.executable, "-c", code], capture_output=True, text=True, check=False)
    line = next(x for x in done.stderr.splitlines() if x.startswith("HEAVY="))
    return done.returncode, json.loads(line.removeprefix("HEAVY=")), done.stdout


def test_predicting_with_the_shipped_mlp_imports_no_torch_nor_sklearn():
    code, heavy, out = _predict_in_fresh_process(SHIPPED_MLP, "--json")
    assert code == 0
    assert heavy == []
    assert json.loads(out)["kind"] == "mlp"


def test_predicting_with_a_saved_polynomial_imports_no_torch(tmp_path):
    import numpy as np

    from softbend.surrogates.persistence import save_surrogate
    from softbend.surrogates.polynomial import PolynomialRegressor

    from .conftest import smooth_angle, table1_inputs

    X = table1_inputs(200, seed=3)
    path = save_surrogate(
        PolynomialRegressor(degree=2).fit(X, smooth_angle(X)), tmp_path / "p.json"
    )
    code, heavy, out = _predict_in_fresh_process(str(path), "--json")
    assert code == 0
    # the estimator class is scikit-learn's; training's packages stay out
    assert not set(heavy) & {"torch", "xgboost", "duckdb", "matplotlib"}
    result = json.loads(out)
    assert result["kind"] == "plr" and np.isfinite(result["angle_deg"]).all()
