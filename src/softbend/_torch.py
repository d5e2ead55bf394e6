"""PyTorch, imported in one place and before NGSolve.

NGSolve's bundled OpenBLAS exports the BLAS symbols that PyTorch's CPU kernels
otherwise bind to: with NGSolve imported first, a batched matrix product in
PyTorch (the surrogates' MLP training) crashes the interpreter with a
segmentation fault. Loaded in this order, both work in one process, so
:mod:`softbend.fem` imports this module before NGSolve, and every module of
softbend that needs PyTorch takes it from here.
"""

from __future__ import annotations

import torch

__all__ = ["torch"]
