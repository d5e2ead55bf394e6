"""Argument checks of :func:`softbend.surrogates.batched.train_mlp_grid`.

Each raises ``ValueError`` in the package's format: the argument, what is
allowed, what came in.
"""

from __future__ import annotations

from collections.abc import Sequence
from typing import TYPE_CHECKING

import numpy as np
from numpy.typing import ArrayLike

from softbend._torch import require_torch
from softbend.surrogates.mlp_core import check_hidden_pair

if TYPE_CHECKING:
    import torch
else:
    torch = require_torch("the MLP surrogate (softbend.surrogates)")

__all__ = ["check_data", "check_dtype", "check_hidden_sizes", "check_splits"]

_OWNER = "train_mlp_grid"
_DTYPES = {"float32": torch.float32, "float64": torch.float64}


def check_dtype(dtype: object) -> torch.dtype:
    if dtype in (torch.float32, torch.float64):
        return dtype  # type: ignore[return-value]
    if isinstance(dtype, str) and dtype in _DTYPES:
        return _DTYPES[dtype]
    raise ValueError(
        f"The 'dtype' of {_OWNER} must be one of torch.float32, torch.float64. "
        f"Got {dtype!r} instead."
    )


def check_data(X: ArrayLike, y: ArrayLike) -> tuple[np.ndarray, np.ndarray]:
    X = np.array(X, dtype=np.float64, copy=True)
    y = np.array(y, dtype=np.float64, copy=True)
    if X.ndim != 2 or X.shape[0] == 0 or X.shape[1] == 0:
        raise ValueError(
            f"The 'X' of {_OWNER} must be a non-empty 2-D array (n_samples, n_features). "
            f"Got shape {X.shape} instead."
        )
    if y.shape != (X.shape[0],):
        raise ValueError(
            f"The 'y' of {_OWNER} must have shape ({X.shape[0]},) to match X. "
            f"Got shape {y.shape} instead."
        )
    for name, array in (("X", X), ("y", y)):
        bad = ~np.isfinite(array)
        if bad.any():
            first = int(np.flatnonzero(bad.ravel())[0])
            raise ValueError(
                f"The '{name}' of {_OWNER} must be finite (no NaN or inf). "
                f"Got {array.ravel()[first]!r} at flat position {first}."
            )
    return X, y


def check_splits(splits: object, n_samples: int) -> list[tuple[np.ndarray, np.ndarray]]:
    message = (
        f"The 'splits' of {_OWNER} must be a non-empty list of (train_idx, val_idx) pairs of "
        f"integer index arrays in [0, {n_samples}), train_idx non-empty."
    )
    try:
        pairs = list(splits)  # type: ignore[call-overload]
    except TypeError:
        raise ValueError(f"{message} Got {type(splits).__name__} instead.") from None
    if not pairs:
        raise ValueError(f"{message} Got an empty list instead.")
    checked = []
    for k, pair in enumerate(pairs):
        try:
            train, val = pair
        except (TypeError, ValueError):
            raise ValueError(f"{message} Split {k} is {pair!r}.") from None
        arrays = []
        for part, idx in (("train", train), ("val", val)):
            arr = np.asarray(idx)
            if arr.size == 0:
                arr = arr.astype(np.int64)
            if arr.ndim != 1 or arr.dtype.kind not in "iu":
                raise ValueError(
                    f"{message} The {part} indices of split {k} have dtype {arr.dtype} "
                    f"and shape {arr.shape}."
                )
            if arr.size and (arr.min() < 0 or arr.max() >= n_samples):
                raise ValueError(
                    f"{message} The {part} indices of split {k} span [{arr.min()}, {arr.max()}]."
                )
            arrays.append(arr.astype(np.int64))
        if arrays[0].size == 0:
            raise ValueError(f"{message} Split {k} has no training row.")
        checked.append((arrays[0], arrays[1]))
    return checked


def check_hidden_sizes(hidden_sizes: Sequence[tuple[int, int]]) -> list[tuple[int, int]]:
    """The configurations (h1, h2) as a non-empty list of pairs of positive ints."""
    try:
        configs = [check_hidden_pair(h, "hidden_sizes", _OWNER) for h in hidden_sizes]
    except TypeError:
        configs = []
    if not configs:
        raise ValueError(
            f"The 'hidden_sizes' of {_OWNER} must be a non-empty list of (h1, h2) pairs of "
            f"positive integers. Got {hidden_sizes!r} instead."
        )
    return configs
