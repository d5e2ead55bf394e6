"""NGSolve for the FEM: imported after PyTorch, or one line naming ``softbend[fem]``.

Every module of :mod:`softbend.fem` that builds or solves a mesh calls
:func:`require_ngsolve` when it is imported, so NGSolve is never loaded before
PyTorch (see :mod:`softbend._torch`) and a missing NGSolve is one
:class:`~softbend.errors.MissingExtraError`. The pure-Python modules
(:mod:`~softbend.fem.options`, :mod:`~softbend.fem.stats`, the dimensions of
:mod:`~softbend.fem.geometry`) do not, so they work without NGSolve.
"""

from __future__ import annotations

from types import ModuleType

from softbend._extras import require

__all__ = ["require_ngsolve"]


def require_ngsolve() -> ModuleType:
    """The ``ngsolve`` module, imported after PyTorch (when PyTorch is installed).

    Raises
    ------
    MissingExtraError
        If NGSolve is not installed (the message names ``softbend[fem]``).
    """
    import softbend._torch  # noqa: F401  (PyTorch before NGSolve: see softbend._torch)

    return require("ngsolve", "The FEM (softbend.fem)")
