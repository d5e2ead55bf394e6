"""Per-model row permutations drawn on the training device, from counter-based keys.

The host shuffle of :class:`~softbend.surrogates.batched_epochs.MiniBatches` draws
every model's permutation with NumPy and copies the (M, n_steps * B) row table to
the device once per epoch: on a GPU that host work and copy, not the arithmetic,
set the pace of the paper grid. :class:`DeviceShuffle` draws the same kind of
permutation where the table lives, without a host round trip:

* every column j < n_m of model m gets a key ``hash32(model_key_m, epoch, j) * 2**22 + j``
  (a 32-bit integer hash, made unique by the column index) and the padding columns
  j >= n_m get keys above all of them;
* one ``argsort`` along the columns is each model's permutation of its own rows,
  with the padding last.

A model's permutations depend on its own key and the epoch alone (not on which
models are trained beside it), and the integer arithmetic is exact on every
device, so CPU and GPU draw the same permutations. They are not NumPy's: a model
trained with ``shuffle="device"`` visits its rows in another order than with
``shuffle="host"``, and ends elsewhere within the spread of random restarts.

The hash is the "lowbias32" integer finalizer (C. Wellons, 2018: xorshift-multiply
rounds with constants found by search for low bias). Products are split into
16-bit halves so that no int64 product overflows.
"""

from __future__ import annotations

from typing import TYPE_CHECKING

import numpy as np

from softbend._torch import require_torch

if TYPE_CHECKING:
    import torch
else:
    torch = require_torch("the MLP surrogate (softbend.surrogates)")

__all__ = ["DeviceShuffle", "hash32", "model_keys"]

_MASK32 = 0xFFFFFFFF
_COLUMN_BITS = 22
#: Most rows one model may train on with the device shuffle (column index in 22 bits).
MAX_ROWS = 1 << _COLUMN_BITS


def _mul32(x: torch.Tensor, c: int) -> torch.Tensor:
    """``(x * c) mod 2**32`` for 0 <= x < 2**32, without int64 overflow."""
    hi = torch.bitwise_and(x * (c >> 16), 0xFFFF) << 16
    return torch.bitwise_and(hi + x * (c & 0xFFFF), _MASK32)


def hash32(x: torch.Tensor) -> torch.Tensor:
    """The lowbias32 finalizer of 32-bit values held in an int64 tensor (0 <= x < 2**32)."""
    x = torch.bitwise_xor(x, x >> 16)
    x = _mul32(x, 0x7FEB352D)
    x = torch.bitwise_xor(x, x >> 15)
    x = _mul32(x, 0x846CA68B)
    return torch.bitwise_xor(x, x >> 16)


def model_keys(seed: int, sizes_and_splits: list[tuple[int, int, int]]) -> np.ndarray:
    """A 32-bit shuffle key per model, from ``(seed, h1, h2, split_index)`` alone.

    Drawn from its own :class:`numpy.random.SeedSequence` (spawn key 1), so it is
    independent of the stream that draws the model's initial weights.
    """
    return np.array(
        [
            np.random.SeedSequence([seed, h1, h2, split], spawn_key=(1,)).generate_state(1)[0]
            for h1, h2, split in sizes_and_splits
        ],
        dtype=np.int64,
    )


class DeviceShuffle:
    """The shuffled (M, n_cols) row table of every epoch, computed on the device.

    Parameters
    ----------
    train_idx : list of ndarray of int
        Each model's training rows (indices into the data), at most :data:`MAX_ROWS`.
    keys : ndarray of int64, shape (M,)
        Each model's 32-bit key (:func:`model_keys`).
    n_cols : int
        Columns of the table (>= every model's row count).
    device : str
        Where the table lives.
    """

    def __init__(
        self, train_idx: list[np.ndarray], keys: np.ndarray, n_cols: int, device: str
    ) -> None:
        n_train = np.array([idx.size for idx in train_idx])
        if n_train.max() > MAX_ROWS:
            raise ValueError(
                f"The device shuffle takes at most {MAX_ROWS} training rows per model; "
                f"got {int(n_train.max())}. Use shuffle='host'."
            )
        table = np.zeros((len(train_idx), n_cols), dtype=np.int64)
        for m, idx in enumerate(train_idx):
            table[m, : idx.size] = idx
        self.table = torch.from_numpy(table).to(device)
        columns = torch.arange(n_cols, dtype=torch.int64, device=device)
        self.columns = columns.expand(len(train_idx), n_cols)
        self.padding = columns[None, :] >= torch.tensor(n_train, device=device)[:, None]
        # Padding sorts after every real key (those are < 2**54) and keeps its order.
        self.padding_keys = (1 << 60) + columns
        self.base = torch.tensor(keys, dtype=torch.int64, device=device)[:, None]

    def rows(self, epoch: torch.Tensor | int) -> torch.Tensor:
        """The row table of ``epoch`` (an int, or a 0-d int64 tensor on the device).

        Each model's first ``n_m`` columns are its rows in the epoch's order; a 0-d
        tensor lets a captured CUDA graph advance the epoch without host work.
        """
        seed = hash32(torch.bitwise_and(self.base + epoch * 0x9E3779B9, _MASK32))
        keys = hash32(torch.bitwise_xor(seed, self.columns))
        keys = torch.where(self.padding, self.padding_keys, (keys << _COLUMN_BITS) + self.columns)
        order = torch.argsort(keys, dim=1)
        return self.table.gather(1, order)
