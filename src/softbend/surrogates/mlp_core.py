"""The normalized two-hidden-layer tanh MLP of paper B §4.1: the pieces shared by
the estimator (:mod:`softbend.surrogates.mlp`) and the batched grid trainer
(:mod:`softbend.surrogates.batched`).

The NumPy forward pass (the fast path of a fitted model), the choice of torch
device, the per-model random stream and initial weights, and the input/target
standardization. Each model of a grid is exactly what it would be if trained
alone, because both trainers draw from these.
"""

from __future__ import annotations

import math
from collections.abc import Sequence
from numbers import Integral
from typing import Any, cast

import numpy as np

from softbend._validation import check_choice, must_be
from softbend.errors import InputError

__all__ = [
    "check_hidden_pair",
    "init_parameters",
    "mlp_forward",
    "model_rng",
    "resolve_device",
    "standardization",
]


def mlp_forward(
    X: np.ndarray,
    x_mean: np.ndarray,
    x_scale: np.ndarray,
    y_mean: float,
    y_scale: float,
    coefs: Sequence[np.ndarray],
    intercepts: Sequence[np.ndarray],
) -> np.ndarray:
    """Forward pass of a normalized two-hidden-layer tanh MLP, NumPy float64.

    Parameters
    ----------
    X : ndarray of shape (n, d)
        Inputs, in their units (mm, deg, MPa for softbend's features).
    x_mean, x_scale : ndarray of shape (d,)
        Input standardization.
    y_mean, y_scale : float
        Target standardization (degrees for the bending angle).
    coefs : sequence of 3 ndarray
        Weights of shapes (d, h1), (h1, h2), (h2, 1).
    intercepts : sequence of 3 ndarray
        Biases of shapes (h1,), (h2,), (1,).

    Returns
    -------
    ndarray of shape (n,)
        Predictions in the target's units, float64.
    """
    z = (np.asarray(X, dtype=np.float64) - x_mean) / x_scale
    a = np.tanh(z @ coefs[0] + intercepts[0])
    a = np.tanh(a @ coefs[1] + intercepts[1])
    return y_mean + y_scale * (a @ coefs[2] + intercepts[2])[:, 0]


def check_hidden_pair(value: object) -> tuple[int, int]:
    """``value`` as a pair of positive integers (h1, h2), the sizes of the two hidden layers.

    Raises
    ------
    softbend.errors.InputError
        Key ``hidden_sizes``: anything else.
    """
    error = InputError(must_be("a pair of positive integers (h1, h2)", value), key="hidden_sizes")
    try:
        pair: tuple[Any, ...] = tuple(value)  # type: ignore[arg-type]
    except TypeError:
        raise error from None
    if len(pair) != 2 or not all(
        isinstance(h, Integral) and not isinstance(h, bool) and cast(int, h) >= 1 for h in pair
    ):
        raise error
    return int(pair[0]), int(pair[1])


def resolve_device(device: object) -> str:
    """The torch device a ``device`` parameter means: ``"cpu"`` or ``"cuda"``.

    Parameters
    ----------
    device : {"auto", "cpu", "cuda"}
        ``"auto"`` is ``"cuda"`` when :func:`torch.cuda.is_available`, else ``"cpu"``.

    Returns
    -------
    str
        ``"cpu"`` or ``"cuda"``.

    Raises
    ------
    softbend.errors.InputError
        Key ``device``: another value, or ``"cuda"`` without a usable GPU.
    """
    check_choice(device, "device", ("auto", "cpu", "cuda"))
    # PyTorch only here (training): a fitted model predicts with NumPy alone
    from softbend._torch import require_torch

    torch = require_torch("the MLP surrogate (softbend.surrogates)")
    if device == "auto":
        return "cuda" if torch.cuda.is_available() else "cpu"
    if device == "cuda" and not torch.cuda.is_available():
        raise InputError(
            f"must be 'auto' or 'cpu' without a usable GPU (torch.cuda.is_available() is False, "
            f"torch {torch.__version__}); got 'cuda'",
            key="device",
        )
    return str(device)


def model_rng(seed: int, h1: int, h2: int, split_index: int) -> np.random.Generator:
    """The random stream of one model of the grid.

    Derived from ``(seed, h1, h2, split_index)`` only, so a model draws the same
    initial weights and row permutations whatever else is trained beside it.

    Parameters
    ----------
    seed : int
        Seed of the grid, >= 0.
    h1, h2 : int
        Hidden layer sizes of the model.
    split_index : int
        Index of the model's (train, validation) split.

    Returns
    -------
    numpy.random.Generator
    """
    return np.random.Generator(np.random.PCG64(np.random.SeedSequence([seed, h1, h2, split_index])))


def init_parameters(
    rng: np.random.Generator, n_features: int, h1: int, h2: int
) -> tuple[list[np.ndarray], list[np.ndarray]]:
    """Initial weights and biases, as ``torch.nn.Linear`` draws them.

    Every weight and bias of a layer with ``fan_in`` inputs is uniform on
    (-1/sqrt(fan_in), 1/sqrt(fan_in)). Drawn in the order W1, b1, W2, b2, W3, b3.

    Parameters
    ----------
    rng : numpy.random.Generator
        The model's stream (:func:`model_rng`).
    n_features, h1, h2 : int
        Layer sizes d, h1, h2.

    Returns
    -------
    coefs, intercepts : list of ndarray
        Float64 arrays of shapes (d, h1), (h1, h2), (h2, 1) and (h1,), (h2,), (1,).
    """
    coefs, intercepts = [], []
    for fan_in, fan_out in ((n_features, h1), (h1, h2), (h2, 1)):
        bound = 1.0 / math.sqrt(fan_in)
        coefs.append(rng.uniform(-bound, bound, size=(fan_in, fan_out)))
        intercepts.append(rng.uniform(-bound, bound, size=fan_out))
    return coefs, intercepts


def standardization(values: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
    """Mean and standard deviation along axis 0; scale 1 for a constant column."""
    mean = values.mean(axis=0)
    scale = values.std(axis=0)
    constant = np.ptp(values, axis=0) == 0.0
    return mean, np.where(constant | (scale == 0.0), 1.0, scale)
