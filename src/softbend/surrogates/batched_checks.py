"""Argument checks of :func:`softbend.surrogates.batched.train_mlp_grid`.

Each raises an :class:`~softbend.errors.InputError` (a ``ValueError``) keyed by the
argument, saying what it must be and what came in.
"""

from __future__ import annotations

from collections.abc import Sequence
from typing import TYPE_CHECKING

import numpy as np
from numpy.typing import ArrayLike

from softbend._torch import require_torch
from softbend._validation import must_be
from softbend.errors import InputError
from softbend.surrogates.mlp_core import check_hidden_pair

if TYPE_CHECKING:
    import torch
else:
    torch = require_torch("the MLP surrogate (softbend.surrogates)")

__all__ = ["check_data", "check_dtype", "check_hidden_sizes", "check_splits"]

_DTYPES = {"float32": torch.float32, "float64": torch.float64}


def check_dtype(dtype: object) -> torch.dtype:
    if dtype in (torch.float32, torch.float64):
        return dtype  # type: ignore[return-value]
    if isinstance(dtype, str) and dtype in _DTYPES:
        return _DTYPES[dtype]
    raise InputError(f"must be one of torch.float32, torch.float64; got {dtype!r}", key="dtype")


def check_data(X: ArrayLike, y: ArrayLike) -> tuple[np.ndarray, np.ndarray]:
    X = np.array(X, dtype=np.float64, copy=True)
    y = np.array(y, dtype=np.float64, copy=True)
    if X.ndim != 2 or X.shape[0] == 0 or X.shape[1] == 0:
        raise InputError(
            f"must be a non-empty 2-D array (n_samples, n_features); got shape {X.shape}",
            key="X",
        )
    if y.shape != (X.shape[0],):
        raise InputError(
            f"must have shape ({X.shape[0]},) to match X; got shape {y.shape}", key="y"
        )
    for name, array in (("X", X), ("y", y)):
        bad = ~np.isfinite(array)
        if bad.any():
            first = int(np.flatnonzero(bad.ravel())[0])
            raise InputError(
                f"must be finite (no NaN or inf); got {array.ravel()[first]!r} at flat "
                f"position {first}",
                key=name,
            )
    return X, y


def check_splits(splits: object, n_samples: int) -> list[tuple[np.ndarray, np.ndarray]]:
    requirement = (
        f"must be a non-empty list of (train_idx, val_idx) pairs of integer index arrays in "
        f"[0, {n_samples}), train_idx non-empty"
    )

    def error(got: str) -> InputError:
        return InputError(f"{requirement}; got {got}", key="splits")

    try:
        pairs = list(splits)  # type: ignore[call-overload]
    except TypeError:
        raise error(type(splits).__name__) from None
    if not pairs:
        raise error("an empty list")
    checked = []
    for k, pair in enumerate(pairs):
        try:
            train, val = pair
        except (TypeError, ValueError):
            raise error(f"split {k} {pair!r}") from None
        arrays = []
        for part, idx in (("train", train), ("val", val)):
            arr = np.asarray(idx)
            if arr.size == 0:
                arr = arr.astype(np.int64)
            if arr.ndim != 1 or arr.dtype.kind not in "iu":
                raise error(
                    f"{part} indices of split {k} of dtype {arr.dtype} and shape {arr.shape}"
                )
            if arr.size and (arr.min() < 0 or arr.max() >= n_samples):
                raise error(f"{part} indices of split {k} spanning [{arr.min()}, {arr.max()}]")
            arrays.append(arr.astype(np.int64))
        if arrays[0].size == 0:
            raise error(f"split {k} with no training row")
        checked.append((arrays[0], arrays[1]))
    return checked


def check_hidden_sizes(hidden_sizes: Sequence[tuple[int, int]]) -> list[tuple[int, int]]:
    """The configurations (h1, h2) as a non-empty list of pairs of positive ints."""
    try:
        configs = [check_hidden_pair(h) for h in hidden_sizes]
    except TypeError:
        configs = []
    if not configs:
        raise InputError(
            must_be("a non-empty list of (h1, h2) pairs of positive integers", hidden_sizes),
            key="hidden_sizes",
        )
    return configs
