"""``softbend.fem`` is light: its pure-Python parts work without NGSolve.

Each case runs in a fresh interpreter; ``sys.modules[name] = None`` makes an
import of NGSolve (and netgen) fail there as on a machine without ``softbend[fem]``.
"""

from __future__ import annotations

import subprocess
import sys
import textwrap

BLOCK_NGSOLVE = "import sys\nsys.modules['ngsolve'] = None\nsys.modules['netgen'] = None\n"


def _run(code: str, *, block_ngsolve: bool = False) -> subprocess.CompletedProcess[str]:
    code = textwrap.dedent(code)
    return subprocess.run(
        [sys.executable, "-c", BLOCK_NGSOLVE + code if block_ngsolve else code],
        capture_output=True,
        text=True,
        timeout=300,
        check=False,
    )


def test_the_pure_python_parts_import_and_work_without_ngsolve():
    done = _run(
        """
        import softbend.fem
        from softbend.design import sfrba_design
        from softbend.fem import (
            GRAVITY_DIRECTIONS, OUTPUT_MODES, ActuatorGeometry, FEMOptions, FEMStats, fem_stats,
        )

        options = FEMOptions(maxh_mm=4.0).replace(gravity="none")
        assert options.maxh_mm == 4.0 and "none" in GRAVITY_DIRECTIONS and OUTPUT_MODES
        info = ActuatorGeometry(sfrba_design(100, 6, 2, 2, 5, 8), options.base_cap_mm)
        assert info.length_mm == 111.0
        assert fem_stats({"stop_reason": "x"})["stop_reason"] == "x"
        assert "stop_reason" in FEMStats.__required_keys__
        heavy = [m for m in ("ngsolve", "netgen", "torch") if sys.modules.get(m) is not None]
        assert not heavy, heavy
        print("ok")
        """,
        block_ngsolve=True,
    )
    assert done.returncode == 0, done.stderr
    assert done.stdout.strip() == "ok"


def test_the_names_that_solve_say_which_extra_is_missing():
    done = _run(
        """
        import importlib
        from softbend.errors import MissingExtraError

        for name in ("simulate", "FEMModel", "use_compiled"):
            try:
                getattr(importlib.import_module("softbend.fem"), name)
            except MissingExtraError as exc:
                assert "softbend[fem]" in str(exc), exc
            else:
                raise AssertionError(name)
        for module in ("softbend.fem.sweep", "softbend.fem.actuator", "softbend.fem.export"):
            try:
                importlib.import_module(module)
            except MissingExtraError as exc:
                assert "softbend[fem]" in str(exc), exc
            else:
                raise AssertionError(module)
        print("ok")
        """,
        block_ngsolve=True,
    )
    assert done.returncode == 0, done.stderr
    assert done.stdout.strip() == "ok"


def test_pytorch_is_loaded_before_ngsolve_whichever_fem_module_comes_first():
    for module in ("softbend.fem.sweep", "softbend.fem.geometry"):
        done = _run(
            f"""
            import importlib.util
            import sys

            import {module} as first
            if hasattr(first, "mesh_actuator"):
                from softbend.fem._ngsolve import require_ngsolve
                require_ngsolve()  # what mesh_actuator does first
            order = list(sys.modules)
            assert "ngsolve" in order, order
            if importlib.util.find_spec("torch") is not None:
                assert order.index("torch") < order.index("ngsolve")
            print("ok")
            """
        )
        assert done.returncode == 0, (module, done.stderr)


def test_the_exports_are_the_public_names():
    import softbend.fem as fem

    assert sorted(fem.__all__) == sorted(fem._EXPORTS)
    assert sorted(dir(fem)) == sorted(fem.__all__)
    for name in fem.__all__:
        assert getattr(fem, name) is not None
