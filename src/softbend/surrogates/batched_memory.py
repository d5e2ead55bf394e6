"""Memory of a batched MLP training pass: estimate, what is free, and how many models fit.

:func:`softbend.surrogates.batched.train_mlp_grid` trains its models in passes;
:func:`models_per_pass` checks that the pass it is asked for fits in the memory
allowed and otherwise says how many models would.
"""

from __future__ import annotations

import math
import os
from typing import TYPE_CHECKING

from softbend._torch import require_torch
from softbend.errors import InputError

if TYPE_CHECKING:
    import torch
else:
    torch = require_torch("the MLP surrogate (softbend.surrogates)")

__all__ = ["available_bytes", "estimate_pass_bytes", "models_per_pass"]


def estimate_pass_bytes(
    n_models: int,
    n_features: int,
    h1_max: int,
    h2_max: int,
    batch_size: int,
    n_rows_max: int,
    itemsize: int = 4,
) -> int:
    """Rough peak memory of one training pass of :func:`train_mlp_grid`, bytes.

    Counts parameters with their gradients, Adam moments and update temporaries,
    the activations and backward temporaries of one (M, B, ·) mini-batch, the
    gathered float64 inputs and the per-epoch (M, n_rows_max) row-index table,
    plus 25 % for allocator slack.

    Parameters
    ----------
    n_models : int
        Models trained at once (M).
    n_features : int
        Inputs per sample (d).
    h1_max, h2_max : int
        Padded hidden layer sizes.
    batch_size : int
        Rows per mini-batch (B).
    n_rows_max : int
        Largest training set of the models, rows.
    itemsize : int
        Bytes per training float (4 for float32, 8 for float64).

    Returns
    -------
    int
        Estimated bytes.
    """
    n_params = n_features * h1_max + h1_max + h1_max * h2_max + 2 * h2_max + 1
    params = 8 * n_models * n_params * itemsize
    rows = n_models * batch_size
    activations = rows * (4 * (h1_max + h2_max) + n_features + 4) * itemsize
    gathered = rows * (2 * n_features + 2) * 8
    n_cols = math.ceil(n_rows_max / batch_size) * batch_size
    index = n_models * n_cols * (2 * 8 + itemsize)
    return int(1.25 * (params + activations + gathered + index))


def available_bytes(device: str) -> int:
    """Memory free on ``device`` now, bytes (CUDA: free device memory; CPU: MemAvailable)."""
    if device == "cuda":
        return int(torch.cuda.mem_get_info()[0])
    try:
        with open("/proc/meminfo", encoding="ascii") as handle:
            for line in handle:
                if line.startswith("MemAvailable:"):
                    return int(line.split()[1]) * 1024
    except OSError:
        pass
    return int(os.sysconf("SC_PAGE_SIZE") * os.sysconf("SC_AVPHYS_PAGES"))


def models_per_pass(
    n_models: int,
    n_features: int,
    h1_max: int,
    h2_max: int,
    batch_size: int,
    n_rows_max: int,
    *,
    device: str,
    dtype: torch.dtype,
    max_models_per_pass: int | None,
    max_memory_mb: float | None,
) -> int:
    """Models one pass trains at once, checked against the memory allowed.

    Parameters
    ----------
    n_models : int
        Models to train in all.
    n_features, h1_max, h2_max, batch_size, n_rows_max : int
        As for :func:`estimate_pass_bytes`.
    device : str
        "cpu" or "cuda".
    dtype : torch.dtype
        Training precision.
    max_models_per_pass : int or None
        Upper bound asked for (None: all models at once).
    max_memory_mb : float or None
        Memory a pass may use, MB; None: 80 % of :func:`available_bytes`.

    Returns
    -------
    int
        ``min(max_models_per_pass, n_models)`` (``n_models`` if None).

    Raises
    ------
    softbend.errors.InputError
        Key ``max_models_per_pass``: that many models would not fit; the message
        names the largest number that would (or that even one does not fit).
    """
    per_pass = n_models if max_models_per_pass is None else min(max_models_per_pass, n_models)
    itemsize = torch.empty((), dtype=dtype).element_size()
    budget = 0.8 * available_bytes(device) if max_memory_mb is None else max_memory_mb * 1024.0**2

    def need(count: int) -> int:
        return estimate_pass_bytes(
            count, n_features, h1_max, h2_max, batch_size, n_rows_max, itemsize
        )

    if need(per_pass) > budget:
        fitting = [k for k in range(per_pass, 0, -1) if need(k) <= budget][:1]
        hint = (
            f"set it to {fitting[0]} or fewer"
            if fitting
            else "even one model does not fit: lower 'batch_size'"
        )
        raise InputError(
            f"must leave a pass within the memory allowed: training {per_pass} MLPs at once "
            f"needs about {need(per_pass) / 1024**2:.3g} MB on {device}, more than the "
            f"{budget / 1024**2:.3g} MB allowed; {hint} (train fewer configurations at a time)",
            key="max_models_per_pass",
        )
    return per_pass
