"""PyTorch, imported in one place and before NGSolve.

NGSolve's bundled OpenBLAS exports the BLAS symbols that PyTorch's CPU kernels
otherwise bind to: with NGSolve imported first, a batched matrix product in
PyTorch (the surrogates' MLP training) crashes the interpreter with a
segmentation fault. Loaded in this order, both work in one process, so
:mod:`softbend.fem` imports this module before NGSolve (without PyTorch
installed there is nothing to order), and every module of softbend that needs
PyTorch calls :func:`require_torch`.
"""

from __future__ import annotations

from types import ModuleType

from softbend._extras import require

__all__ = ["require_torch", "torch_loaded"]

_torch: ModuleType | None
try:
    import torch as _torch
except ImportError:  # the 'ml' extra is not installed: nothing to load first
    _torch = None


def torch_loaded() -> bool:
    """Whether PyTorch is installed (and therefore already imported)."""
    return _torch is not None


def require_torch(purpose: str = "the MLP surrogate") -> ModuleType:
    """PyTorch, or one line naming the ``ml`` extra when it is not installed."""
    if _torch is not None:
        return _torch
    return require("torch", purpose)
