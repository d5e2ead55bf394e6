"""Optional heavy dependencies, and one clear error when one is missing.

``pip install softbend`` gives the kinematics, the materials, the analytical
model, campaigns on local processes, the analysis, paper A's identification and
saved polynomial surrogates. The extras add the rest:

=========  ============================================  ===============================
extra      packages                                      needed by
=========  ============================================  ===============================
``fem``    NGSolve (with netgen)                         :mod:`softbend.fem`
``ml``     PyTorch, XGBoost, ONNX, ONNX Runtime,         the MLP and XGBoost surrogates,
           onnxmltools                                   the search, ONNX export
``dask``   Dask distributed                              campaigns on a Dask cluster
``rig``    pymodbus                                      the Modbus rig (``softbend control run``)
``all``    all of the above
=========  ============================================  ===============================

A surrogate family that needs an extra names it in its storage
(:class:`softbend.surrogates.families.Storage`, ``extra``), so that loading its
saved model without the extra is the same one-line error.
"""

from __future__ import annotations

import importlib
from types import ModuleType

from softbend.errors import MissingExtraError

__all__ = ["EXTRAS", "require"]

#: The distribution that provides each optional top-level module, and its extra.
EXTRAS: dict[str, tuple[str, str]] = {
    "ngsolve": ("NGSolve", "fem"),
    "netgen": ("NGSolve", "fem"),
    "torch": ("PyTorch", "ml"),
    "xgboost": ("XGBoost", "ml"),
    "onnx": ("ONNX", "ml"),
    "onnxruntime": ("ONNX Runtime", "ml"),
    "onnxmltools": ("onnxmltools", "ml"),
    "distributed": ("Dask distributed", "dask"),
    "pymodbus": ("pymodbus", "rig"),
}


def require(module: str, purpose: str) -> ModuleType:
    """Import an optional dependency, or raise one line naming the extra to install.

    Parameters
    ----------
    module : str
        Top-level module name, a key of :data:`EXTRAS`.
    purpose : str
        What needs it, for the message (e.g. ``"the FEM (softbend.fem)"``).

    Raises
    ------
    MissingExtraError
        If the module cannot be imported.
    ValueError
        For a module that no extra provides (naming the known ones).
    """
    if module not in EXTRAS:
        raise ValueError(
            f"Unknown optional module {module!r} (in require); known: {', '.join(EXTRAS)}."
        )
    package, extra = EXTRAS[module]
    try:
        return importlib.import_module(module)
    except ImportError as exc:
        raise MissingExtraError(
            f"{purpose} needs {package}, which is not installed: "
            f"pip install 'softbend[{extra}]' (or 'softbend[all]')."
        ) from exc
