"""softbend without its optional extras: what still works, and the one-line errors.

Each case runs in a fresh interpreter in which the extras' packages cannot be
imported (a meta-path hook refuses them), as on an installation without
``softbend[fem]``, ``softbend[ml]`` or ``softbend[dask]``.
"""

from __future__ import annotations

import subprocess
import sys
import textwrap

import pytest

from softbend._extras import EXTRAS, require
from softbend.errors import MissingExtraError

BLOCK = textwrap.dedent(
    f"""
    import sys

    class _NotInstalled:
        blocked = {sorted(EXTRAS)!r}

        def find_spec(self, name, path=None, target=None):
            if name.split(".")[0] in self.blocked:
                raise ModuleNotFoundError(f"No module named {{name!r}}", name=name)
            return None

    sys.meta_path.insert(0, _NotInstalled())
    """
)


XGB = (
    "from softbend.surrogates.search import _make; "
    "_make('xgb', {}, seed=0, n_jobs=1, device='cpu', epochs=1)"
)


def _run(code: str) -> subprocess.CompletedProcess[str]:
    return subprocess.run(
        [sys.executable, "-c", BLOCK + textwrap.dedent(code)],
        capture_output=True,
        text=True,
        timeout=300,
        check=False,
    )


def test_the_core_works_without_extras(tmp_path):
    model = tmp_path / "plr.json"
    done = _run(
        f"""
        import numpy as np
        from softbend.kinematics import bending_from_tip, tip_position
        from softbend.identification import NARXRegressor, synthetic_dataset
        from softbend.analytical import AnalyticalModel
        from softbend.design import sfrba_design
        from softbend.models import default_pressures_mpa
        from softbend.surrogates.polynomial import PolynomialRegressor
        from softbend.surrogates.persistence import load_surrogate, save_surrogate

        experiment = synthetic_dataset(seed=0)["positive"][0]
        narx = NARXRegressor().fit(experiment.pressure_kpa, experiment.rho)
        assert np.isfinite(narx.simulate(experiment.pressure_kpa, experiment.rho)).all()
        design = sfrba_design(100, 6, 2, 2, 5, 8)
        sweep = AnalyticalModel().sweep(design, default_pressures_mpa(0.1))
        X = np.random.default_rng(0).random((50, 7)) + 1.0
        plr = PolynomialRegressor(degree=2).fit(X, X.sum(axis=1))
        save_surrogate(plr, {str(model)!r})
        assert np.allclose(load_surrogate({str(model)!r}).model.predict(X), plr.predict(X))
        loaded = [m for m in ("torch", "ngsolve", "xgboost", "distributed") if m in sys.modules]
        assert not loaded, loaded
        print("ok", sweep.angle_deg[-1])
        """
    )
    assert done.returncode == 0, done.stderr
    assert done.stdout.startswith("ok")


@pytest.mark.parametrize(
    ("code", "extra"),
    [
        ("from softbend.fem import FEMModel", "softbend[fem]"),
        # A saved MLP predicts on NumPy alone; training it needs PyTorch.
        (
            "from softbend.surrogates import NormalizedMLPRegressor; "
            "NormalizedMLPRegressor(epochs=1).fit([[1.0] * 7, [2.0] * 7], [0.0, 1.0])",
            "softbend[ml]",
        ),
        (XGB, "softbend[ml]"),
    ],
)
def test_a_missing_extra_is_one_error_naming_it(code, extra):
    done = _run(
        f"""
        from softbend.errors import MissingExtraError
        try:
            {code}
        except MissingExtraError as exc:
            print(exc)
        """
    )
    assert done.returncode == 0, done.stderr
    assert extra in done.stdout and "pip install" in done.stdout


def test_the_cli_exits_2_naming_the_extra():
    done = _run(
        """
        from softbend.cli import main
        sys.exit(main(["fem", "run", "--design", "100,6,2,2,5,8", "--pmax", "0.01"]))
        """
    )
    assert done.returncode == 2, done.stderr
    lines = done.stderr.strip().splitlines()
    assert len(lines) == 1 and "softbend[fem]" in lines[0], done.stderr


def test_require_names_the_package_and_the_extra(monkeypatch):
    import importlib

    def refuse(name):
        raise ImportError(name)

    monkeypatch.setattr(importlib, "import_module", refuse)
    with pytest.raises(MissingExtraError, match=r"Dask distributed.*softbend\[dask\]"):
        require("distributed", "A campaign on a Dask cluster")


def test_require_refuses_a_module_no_extra_provides():
    with pytest.raises(ValueError, match=r"Unknown optional module 'sklearn'.*known: ngsolve"):
        require("sklearn", "Anything")


def test_a_saved_xgboost_surrogate_without_the_extra_is_one_error_naming_it(tmp_path):
    import numpy as np

    xgb = pytest.importorskip("xgboost")
    from softbend.surrogates.persistence import save_surrogate

    X = np.random.default_rng(0).uniform(
        [100, 6, 2, 2, 5, 8, 0], [160, 10, 4, 4, 15, 12, 0.3], (60, 7)
    )
    model = xgb.XGBRegressor(n_estimators=3, max_depth=2, n_jobs=1).fit(X, 300 * X[:, 6])
    path = save_surrogate(model, tmp_path / "xgb.json")
    done = _run(
        f"""
        from softbend.errors import MissingExtraError
        from softbend.surrogates.persistence import load_surrogate
        try:
            load_surrogate({str(path)!r})
        except MissingExtraError as exc:
            print(exc)
        """
    )
    assert done.returncode == 0, done.stderr
    assert "XGBoost" in done.stdout and "softbend[ml]" in done.stdout
