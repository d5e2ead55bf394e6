"""Normalized MLP surrogate (paper B §4.1): standardized inputs, two tanh layers, linear output.

Prediction is plain NumPy float64, so a fitted or reloaded model predicts without
importing torch; :meth:`NormalizedMLPRegressor.fit` trains through
:func:`softbend.surrogates.batched.train_mlp_grid` with one configuration and one
split (all rows), so a single model and a grid of models run the same code.

The forward pass (also the contract of persistence and ONNX export)::

    z  = (x - x_mean_) / x_scale_
    a1 = tanh(z @ W1 + b1);  a2 = tanh(a1 @ W2 + b2)
    y  = y_mean_ + y_scale_ * (a2 @ W3 + b3)[:, 0]          # degrees
"""

from __future__ import annotations

import math
from collections.abc import Callable, Sequence
from typing import TYPE_CHECKING, Any

import numpy as np
from numpy.typing import ArrayLike
from sklearn.base import BaseEstimator, RegressorMixin
from sklearn.utils.validation import check_is_fitted, validate_data

from softbend._validation import check_int, check_range, must_be
from softbend.errors import InputError
from softbend.surrogates.features import FEATURES
from softbend.surrogates.mlp_core import check_hidden_pair, mlp_forward, resolve_device

if TYPE_CHECKING:
    from softbend.surrogates.batched import GridTrainingResult

__all__ = ["NormalizedMLPRegressor", "mlp_forward"]


def _check_finite_x(X: np.ndarray, method: str) -> None:
    bad = ~np.isfinite(X)
    if bad.any():
        row, col = (int(i) for i in np.argwhere(bad)[0])
        column = FEATURES[col] if X.shape[1] == len(FEATURES) else f"column {col}"
        raise InputError(
            f"must be finite (no NaN or inf) in {method}; got {X[row, col]} in '{column}' "
            f"of row {row}",
            key="X",
        )


def _check_finite_y(y: ArrayLike) -> None:
    if y is None:
        return  # scikit-learn's validation reports the missing target
    values = np.asarray(y)
    if values.dtype.kind not in "iuf":
        return  # not real numbers: scikit-learn's validation reports it
    bad = ~np.isfinite(values)
    if bad.any():
        first = int(np.flatnonzero(bad.ravel())[0])
        raise InputError(
            f"must be finite (no NaN or inf); got {values.ravel()[first]} at position {first}",
            key="y",
        )


class NormalizedMLPRegressor(RegressorMixin, BaseEstimator):
    """MLP surrogate of the bending angle: standardized inputs and target, two tanh layers.

    Paper B §4.1: inputs standardized, two tanh hidden layers, linear output, MSE
    loss, Adam (lr 6e-4), mini-batches of 1024 rows, 1000 epochs; the target is
    standardized too. Initial weights as ``torch.nn.Linear`` draws them, from a
    NumPy stream seeded by ``(seed, h1, h2, 0)`` (see
    :func:`softbend.surrogates.mlp_core.model_rng`); the same seed gives identical
    weights on the CPU.

    Parameters
    ----------
    hidden_sizes : tuple of int, default (60, 60)
        Units (h1, h2) of the two hidden layers, each >= 1 (paper B grid: 55–65).
    epochs : int, default 1000
        Passes over the training rows, >= 1.
    batch_size : int, default 1024
        Rows per mini-batch, >= 1 (the last one of an epoch may be smaller).
    learning_rate : float, default 6e-4
        Adam step size, > 0.
    seed : int, default 0
        Seed of the weight initialization and row shuffling, >= 0.
    device : {"auto", "cpu", "cuda"}, default "auto"
        Where to train; "auto" is "cuda" when torch sees a GPU, else "cpu".
        Prediction is always NumPy on the CPU.

    Attributes
    ----------
    x_mean_, x_scale_ : ndarray of shape (n_features,)
        Input standardization, input units (scale 1 for a constant column).
    y_mean_, y_scale_ : float
        Target standardization, degrees.
    coefs_ : list of ndarray
        Float64 weights of shapes (d, h1), (h1, h2), (h2, 1).
    intercepts_ : list of ndarray
        Float64 biases of shapes (h1,), (h2,), (1,).
    loss_curve_ : list of float
        Training MSE per epoch, standardized units.
    device_ : str
        Device the model was trained on ("cpu" or "cuda").
    n_features_in_ : int
        Number of input features (7 for softbend's :data:`FEATURES`).

    Notes
    -----
    Training is float32 (PyTorch); the stored parameters and every prediction are
    float64. Tags: none beyond scikit-learn's regressor defaults; 1-D targets only.
    """

    def __init__(
        self,
        *,
        hidden_sizes: tuple[int, int] = (60, 60),
        epochs: int = 1000,
        batch_size: int = 1024,
        learning_rate: float = 6e-4,
        seed: int = 0,
        device: str = "auto",
    ) -> None:
        self.hidden_sizes = hidden_sizes
        self.epochs = epochs
        self.batch_size = batch_size
        self.learning_rate = learning_rate
        self.seed = seed
        self.device = device

    def fit(
        self,
        X: ArrayLike,
        y: ArrayLike,
        *,
        progress: Callable[[int, int], object] | None = None,
    ) -> NormalizedMLPRegressor:
        """Train the network on all rows.

        Parameters
        ----------
        X : array_like of shape (n_samples, n_features)
            Inputs, finite (softbend: columns :data:`FEATURES`, mm/deg/MPa).
        y : array_like of shape (n_samples,)
            Bending angle, degrees, finite.
        progress : callable, optional
            ``progress(epochs_done, epochs)`` as training goes.

        Returns
        -------
        NormalizedMLPRegressor
            The fitted estimator.

        Raises
        ------
        ValueError
            A bad parameter (naming it) or non-finite / mis-shaped data.
        ConvergenceError
            If training produced non-finite weights.
        """
        hidden = check_hidden_pair(self.hidden_sizes)
        epochs = check_int(self.epochs, "epochs", low=1)
        batch_size = check_int(self.batch_size, "batch_size", low=1)
        learning_rate = check_range(self.learning_rate, "learning_rate", low=0.0, high=math.inf)
        seed = check_int(self.seed, "seed", low=0)
        device = resolve_device(self.device)
        # PyTorch only for training: loading and predicting stay NumPy
        from softbend.surrogates.batched import train_mlp_grid

        _check_finite_y(y)
        X_arr, y_arr = validate_data(
            self, X, y, dtype=np.float64, y_numeric=True, ensure_all_finite=False
        )
        _check_finite_x(X_arr, "fit")
        rows = np.arange(X_arr.shape[0])
        result = train_mlp_grid(
            X_arr,
            y_arr,
            [(rows, rows[:0])],
            [hidden],
            epochs=epochs,
            batch_size=batch_size,
            learning_rate=learning_rate,
            seed=seed,
            device=device,
            progress=progress,
        )
        fitted = result.models[0]
        self._set_fitted(
            fitted.x_mean,
            fitted.x_scale,
            fitted.y_mean,
            fitted.y_scale,
            fitted.coefs,
            fitted.intercepts,
            fitted.loss_curve.tolist(),
            device,
        )
        return self

    def _set_fitted(
        self,
        x_mean: ArrayLike,
        x_scale: ArrayLike,
        y_mean: float,
        y_scale: float,
        coefs: Sequence[ArrayLike],
        intercepts: Sequence[ArrayLike],
        loss_curve: Sequence[float],
        device: str,
    ) -> None:
        self.x_mean_ = np.array(x_mean, dtype=np.float64)
        self.x_scale_ = np.array(x_scale, dtype=np.float64)
        self.y_mean_ = float(y_mean)
        self.y_scale_ = float(y_scale)
        self.coefs_ = [np.array(c, dtype=np.float64) for c in coefs]
        self.intercepts_ = [np.array(b, dtype=np.float64) for b in intercepts]
        self.loss_curve_ = [float(v) for v in loss_curve]
        self.device_ = str(device)
        self.n_features_in_ = int(self.x_mean_.shape[0])

    @classmethod
    def from_grid(
        cls, grid: GridTrainingResult, config_index: int, split_index: int
    ) -> NormalizedMLPRegressor:
        """A fitted model of :func:`~softbend.surrogates.batched.train_mlp_grid`, not retrained.

        Parameters
        ----------
        grid : GridTrainingResult
            What the batched trainer returned.
        config_index, split_index : int
            The configuration (position in its ``hidden_sizes``) and the split.
        """
        fitted = grid.model(config_index, split_index)
        return cls.from_arrays(
            x_mean=fitted.x_mean,
            x_scale=fitted.x_scale,
            y_mean=fitted.y_mean,
            y_scale=fitted.y_scale,
            coefs=fitted.coefs,
            intercepts=fitted.intercepts,
            loss_curve=fitted.loss_curve.tolist(),
            fitted_device=grid.device,
            epochs=grid.epochs,
            batch_size=grid.batch_size,
            learning_rate=grid.learning_rate,
            seed=grid.seed,
        )

    @classmethod
    def from_arrays(
        cls,
        *,
        x_mean: ArrayLike,
        x_scale: ArrayLike,
        y_mean: float,
        y_scale: float,
        coefs: Sequence[ArrayLike],
        intercepts: Sequence[ArrayLike],
        loss_curve: Sequence[float] = (),
        fitted_device: str = "cpu",
        **params: Any,
    ) -> NormalizedMLPRegressor:
        """A fitted estimator from its parameters (e.g. a model of ``train_mlp_grid``).

        Parameters
        ----------
        x_mean, x_scale : array_like of shape (d,)
            Input standardization, input units; scales > 0.
        y_mean, y_scale : float
            Target standardization, degrees; ``y_scale`` > 0.
        coefs : sequence of 3 array_like
            Weights (d, h1), (h1, h2), (h2, 1).
        intercepts : sequence of 3 array_like
            Biases (h1,), (h2,), (1,).
        loss_curve : sequence of float, optional
            Training loss per epoch, standardized units.
        fitted_device : str, default "cpu"
            Stored as ``device_``.
        **params
            Constructor parameters other than ``hidden_sizes`` (taken from ``coefs``).

        Returns
        -------
        NormalizedMLPRegressor

        Raises
        ------
        ValueError
            If the shapes are inconsistent or a value is not finite.
        """
        weights = [np.asarray(c, dtype=np.float64) for c in coefs]
        biases = [np.asarray(b, dtype=np.float64) for b in intercepts]
        mean = np.asarray(x_mean, dtype=np.float64)
        scale = np.asarray(x_scale, dtype=np.float64)
        d = mean.shape[0] if mean.ndim == 1 else -1
        ok = len(weights) == 3 and len(biases) == 3 and d > 0 and scale.shape == (d,)
        if ok:
            h1, h2 = weights[0].shape[-1], weights[1].shape[-1]
            expected = [(d, h1), (h1, h2), (h2, 1)]
            ok = [c.shape for c in weights] == expected and [b.shape for b in biases] == [
                (h1,),
                (h2,),
                (1,),
            ]
        if not ok:
            raise InputError(
                "x_mean, x_scale, coefs and intercepts must have shapes (d,), (d,), "
                "[(d, h1), (h1, h2), (h2, 1)] and [(h1,), (h2,), (1,)]; got "
                f"{mean.shape}, {scale.shape}, {[c.shape for c in weights]} and "
                f"{[b.shape for b in biases]}"
            )
        values = [mean, scale, np.array([y_mean, y_scale], dtype=np.float64)]
        if not all(np.all(np.isfinite(v)) for v in [*values, *weights, *biases]):
            raise InputError("the arrays of from_arrays must be finite; got NaN or inf")
        if np.any(scale <= 0) or not y_scale > 0:
            raise InputError(
                f"x_scale and y_scale must be > 0; got x_scale {scale.tolist()}, "
                f"y_scale {y_scale!r}"
            )
        estimator = cls(hidden_sizes=(int(h1), int(h2)), **params)
        estimator._set_fitted(
            mean, scale, y_mean, y_scale, weights, biases, loss_curve, fitted_device
        )
        return estimator

    def predict(self, X: ArrayLike) -> np.ndarray:
        """Bending angle for each row of ``X``, degrees (NumPy float64).

        Parameters
        ----------
        X : array_like of shape (n_samples, n_features)
            Inputs, finite, with the features seen in ``fit``.

        Returns
        -------
        ndarray of shape (n_samples,)
            Predictions, float64.
        """
        check_is_fitted(self)
        X_arr = validate_data(self, X, reset=False, dtype=np.float64, ensure_all_finite=False)
        _check_finite_x(X_arr, "predict")
        return mlp_forward(
            X_arr,
            self.x_mean_,
            self.x_scale_,
            self.y_mean_,
            self.y_scale_,
            self.coefs_,
            self.intercepts_,
        )

    def predictor(self) -> Callable[[ArrayLike], float]:
        """A fast one-sample predictor for control loops: ``f(x) -> float`` (degrees).

        The standardization is folded into the first layer and the target scale
        into the last, so a call is three small matrix-vector products and two
        tanh in NumPy float64, without scikit-learn validation. It checks only
        the shape of ``x`` and that the result is finite; it equals
        :meth:`predict` up to rounding (about 1e-12 relative). Later changes to
        the fitted attributes are not seen by an existing predictor.

        Returns
        -------
        callable
            ``f(x)`` with ``x`` array-like of shape (n_features,), returning a Python float.
        """
        check_is_fitted(self)
        W1, W2, W3 = self.coefs_
        b1, b2, b3 = self.intercepts_
        W1f = np.ascontiguousarray(W1 / self.x_scale_[:, None])
        b1f = b1 - (self.x_mean_ / self.x_scale_) @ W1
        W2c = np.ascontiguousarray(W2)
        w3 = np.ascontiguousarray(self.y_scale_ * W3[:, 0])
        offset = float(self.y_mean_ + self.y_scale_ * b3[0])
        shape = (self.n_features_in_,)
        dot, tanh, asarray, isfinite = np.dot, np.tanh, np.asarray, math.isfinite

        def predict_one(x: ArrayLike) -> float:
            x = asarray(x, dtype=np.float64)
            if x.shape != shape:
                raise InputError(f"must have shape {shape}; got shape {x.shape}", key="x")
            h = tanh(dot(x, W1f) + b1f)
            h = tanh(dot(h, W2c) + b2)
            value = float(dot(h, w3)) + offset
            if not isfinite(value) or not isfinite(float(dot(x, x))):
                raise InputError(must_be("finite (no NaN or inf)", x.tolist()), key="x")
            return value

        return predict_one
