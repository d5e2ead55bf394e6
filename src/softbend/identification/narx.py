"""NARX models of an actuator: lagged regressors fed to a static regressor (paper A eq. 27).

A nonlinear autoregressive model with exogenous input predicts the output from
its own past and the input::

    y(t) = f(φ(t)),   φ(t) = [y(t−1), …, y(t−na), u(t), …, u(t−nb+1)]

With ``na = nb = 2`` this is paper A's regressor φ(t) = [y(t−1), y(t−2), u(t),
u(t−1)], with u the supply pressure and y one output (bending grade ρ or arc
length L); one model is fitted per output. ``f`` is any scikit-learn regressor,
by default the generalized-Gaussian SVR of paper A with C = 100 and ε = 0.1.

The model is used in two ways:

* **one-step-ahead** (:meth:`NARXRegressor.predict_one_step`): the regressor
  holds *measured* past outputs; this is what the SVR was trained on.
* **free run** (:meth:`NARXRegressor.simulate`): only the input and the first
  ``max_lag_`` measured outputs (initial conditions) are given; the model feeds
  back its own predictions. Errors accumulate, so this is the honest test of a
  dynamic model and what :meth:`NARXRegressor.score` reports.

Several experiments may be concatenated; ``groups`` labels the experiment of
each sample. A regressor row never reaches across a change of label, and each
experiment starts from its own initial conditions.
"""

from __future__ import annotations

import logging
import numbers
import warnings
from dataclasses import dataclass
from typing import Any

import numpy as np
from numpy.typing import ArrayLike
from sklearn.base import BaseEstimator, RegressorMixin, clone
from sklearn.preprocessing import StandardScaler
from sklearn.utils.validation import check_is_fitted

from softbend._validation import check_choice, check_finite_array, check_int, must_be
from softbend.errors import DatasetError, InputError
from softbend.metrics import r2

__all__ = ["NARXRegressor", "lagged_matrix"]

logger = logging.getLogger(__name__)


@dataclass(frozen=True)
class _LagStructure:
    """Which past samples enter the regressor (offsets back in time)."""

    output_offsets: np.ndarray  # 1 … na
    input_offsets: np.ndarray  # 0 … nb−1 (current input) or 1 … nb
    max_lag: int

    def n_features(self, n_inputs: int) -> int:
        """Number of regressor columns with ``n_inputs`` input signals.

        Parameters
        ----------
        n_inputs : int
            Number of input signals (columns of ``X``); each contributes one
            column per input lag.

        Returns
        -------
        int
            na + n_inputs · nb, the width of the rows built by :func:`_rows`.
        """
        return self.output_offsets.size + n_inputs * self.input_offsets.size


@dataclass(frozen=True)
class _Segments:
    """Contiguous experiments inside a concatenated time series."""

    starts: np.ndarray
    lengths: np.ndarray
    labels: list[Any]


def _lag_structure(
    output_lags: object, input_lags: object, include_current_input: object
) -> _LagStructure:
    na = check_int(output_lags, "output_lags", low=1)
    nb = check_int(input_lags, "input_lags", low=1)
    check_choice(include_current_input, "include_current_input", (True, False))
    first = 0 if include_current_input else 1
    input_offsets = np.arange(first, first + nb)
    return _LagStructure(
        output_offsets=np.arange(1, na + 1),
        input_offsets=input_offsets,
        max_lag=int(max(na, input_offsets[-1])),
    )


def _as_inputs(X: ArrayLike) -> np.ndarray:
    """Time-ordered inputs as a finite float array of shape (n_samples, n_inputs)."""
    try:
        array = np.asarray(X, dtype=float)
    except (TypeError, ValueError):
        raise InputError(
            "must be a numeric array (n_samples,) or (n_samples, n_inputs); "
            f"got {type(X).__name__}",
            key="X",
        ) from None
    if array.ndim == 1:
        array = array[:, None]
    if array.ndim != 2 or array.shape[0] == 0 or array.shape[1] == 0:
        raise InputError(
            "must be a non-empty array (n_samples,) or (n_samples, n_inputs); "
            f"got shape {np.shape(X)}",
            key="X",
        )
    return check_finite_array(array, "X")


def _as_output(y: ArrayLike, key: str, n_samples: int) -> np.ndarray:
    """One output series as a 1-D float array of length ``n_samples`` (NaN not checked)."""
    try:
        array = np.asarray(y, dtype=float)
    except (TypeError, ValueError):
        raise InputError(
            f"must be a numeric array (n_samples,); got {type(y).__name__}", key=key
        ) from None
    if array.ndim == 2 and array.shape[1] == 1:
        array = array[:, 0]
    if array.ndim != 1:
        raise InputError(
            "must be one output of shape (n_samples,), one model per output; "
            f"got shape {array.shape}",
            key=key,
        )
    if array.size != n_samples:
        raise InputError(
            f"must have one value per sample of 'X' ({n_samples}); got {array.size}", key=key
        )
    return array


def _segments(groups: ArrayLike | None, n_samples: int, max_lag: int) -> _Segments:
    """Split ``0 … n_samples−1`` at every change of the ``groups`` label."""
    if groups is None:
        starts = np.array([0])
        labels: list[Any] = [0]
    else:
        labels_array = np.asarray(groups)
        if labels_array.ndim != 1 or labels_array.size != n_samples:
            raise InputError(
                f"must be a 1-D array with one experiment label per sample ({n_samples}); "
                f"got shape {labels_array.shape}",
                key="groups",
            )
        change = np.asarray(labels_array[1:] != labels_array[:-1], dtype=bool)
        starts = np.concatenate(([0], np.flatnonzero(change) + 1))
        labels = labels_array[starts].tolist()
    lengths = np.diff(np.append(starts, n_samples))
    short = np.flatnonzero(lengths < max_lag + 1)
    if short.size:
        k = int(short[0])
        if groups is None:
            raise DatasetError(
                f"must have at least max_lag + 1 = {max_lag + 1} samples (the first "
                f"{max_lag} are initial conditions); got {int(lengths[k])}",
                key="X",
            )
        raise DatasetError(
            f"must label experiments of at least max_lag + 1 = {max_lag + 1} samples (the "
            f"first {max_lag} are initial conditions); got experiment {labels[k]!r} with "
            f"{int(lengths[k])} samples",
            key="groups",
        )
    return _Segments(starts=starts, lengths=lengths, labels=labels)


def _row_index(segments: _Segments, max_lag: int) -> np.ndarray:
    """Time index of every sample that has a complete regressor inside its experiment."""
    return np.concatenate(
        [
            np.arange(start + max_lag, start + length)
            for start, length in zip(segments.starts, segments.lengths, strict=True)
        ]
    )


def _input_block(X: np.ndarray, index: np.ndarray, structure: _LagStructure) -> np.ndarray:
    """Lagged inputs of the rows ``index``: columns input by input, lags in order."""
    lagged = X[index[:, None] - structure.input_offsets[None, :], :]  # (rows, lags, inputs)
    return lagged.transpose(0, 2, 1).reshape(index.size, -1)


def _rows(X: np.ndarray, y: np.ndarray, index: np.ndarray, structure: _LagStructure) -> np.ndarray:
    past = y[index[:, None] - structure.output_offsets[None, :]]
    return np.hstack([past, _input_block(X, index, structure)])


def _regressor_names(structure: _LagStructure, n_inputs: int) -> tuple[str, ...]:
    def term(symbol: str, lag: int) -> str:
        return f"{symbol}(t)" if lag == 0 else f"{symbol}(t-{lag})"

    names = [term("y", int(k)) for k in structure.output_offsets]
    for i in range(n_inputs):
        symbol = "u" if n_inputs == 1 else f"u{i}"
        names.extend(term(symbol, int(k)) for k in structure.input_offsets)
    return tuple(names)


def lagged_matrix(
    X: ArrayLike,
    y: ArrayLike,
    groups: ArrayLike | None = None,
    *,
    output_lags: int = 2,
    input_lags: int = 2,
    include_current_input: bool = True,
) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
    """Build the NARX regression problem from time series.

    Parameters
    ----------
    X : array-like, shape (n_samples,) or (n_samples, n_inputs)
        Time-ordered inputs (e.g. pressure in kPa), finite.
    y : array-like, shape (n_samples,)
        Time-ordered output (e.g. ρ, or L in mm), finite.
    groups : array-like, shape (n_samples,), optional
        Experiment label of each sample. A new experiment starts wherever the
        label changes; no row uses samples of two experiments.
    output_lags : int
        na ≥ 1, number of past outputs y(t−1) … y(t−na).
    input_lags : int
        nb ≥ 1, number of input samples: u(t) … u(t−nb+1) if
        ``include_current_input`` else u(t−1) … u(t−nb).
    include_current_input : bool
        Whether u(t) enters the regressor (paper A: yes).

    Returns
    -------
    Phi : ndarray, shape (n_rows, na + n_inputs·nb)
        Regressors [y(t−1) … y(t−na), u₀ lags …, u₁ lags …], unscaled.
    target : ndarray, shape (n_rows,)
        y(t) of each row.
    index : ndarray of int, shape (n_rows,)
        The time index t of each row in the original arrays. The first
        ``max_lag`` samples of every experiment have no row, so
        n_rows = Σ_k (n_k − max_lag), with max_lag = max(na, largest input lag).
    """
    structure = _lag_structure(output_lags, input_lags, include_current_input)
    inputs = _as_inputs(X)
    output = check_finite_array(_as_output(y, "y", inputs.shape[0]), "y")
    segments = _segments(groups, inputs.shape[0], structure.max_lag)
    index = _row_index(segments, structure.max_lag)
    return _rows(inputs, output, index, structure), output[index], index


class NARXRegressor(RegressorMixin, BaseEstimator):
    """NARX model y(t) = f(y(t−1), …, y(t−na), u(t), …, u(t−nb+1)) with any regressor f.

    Parameters
    ----------
    estimator : scikit-learn regressor, optional
        The static map f; it is cloned in :meth:`fit`. ``None`` means
        ``GeneralizedGaussianSVR(C=100.0, epsilon=0.1)`` (paper A §4).
    output_lags : int
        na ≥ 1, number of past outputs in the regressor. Default 2.
    input_lags : int
        nb ≥ 1, number of samples of each input in the regressor. Default 2.
    include_current_input : bool
        If True (default) the input lags are u(t) … u(t−nb+1), else
        u(t−1) … u(t−nb). The defaults give paper A's
        φ(t) = [y(t−1), y(t−2), u(t), u(t−1)].
    scale : bool
        Standardize signals before ``f`` sees them (default True). Scaling is per
        *signal*: the output y is mapped to (y − mean)/std with the statistics
        of the training output, and that same map applies to the target y(t)
        and to the lagged columns y(t−k); each input is standardized with its
        own mean and std, shared by all its lags. The target scaling makes the
        ε of an SVR mean the same for ρ (dimensionless) and L (mm), and the
        model invariant to the output's unit. Predictions are mapped back.

    Attributes
    ----------
    estimator_ : regressor
        The fitted clone of ``estimator``; it works in scaled units.
    y_scaler_, u_scaler_ : StandardScaler or None
        Scalers of the output and of the inputs (``None`` when ``scale=False``).
        A signal with zero variance keeps unit scale.
    n_inputs_ : int
        Number of input signals (columns of ``X``); also ``n_features_in_``.
    max_lag_ : int
        Largest lag in the regressor: max(na, nb − 1) with the current input,
        max(na, nb) without. The first ``max_lag_`` samples of every experiment
        are initial conditions.
    output_offsets_, input_offsets_ : ndarray of int
        The lags k of y(t−k) and u(t−k) in the regressor.
    regressor_names_ : tuple of str
        Column names of the regressor, e.g. ``("y(t-1)", "y(t-2)", "u(t)", "u(t-1)")``.
    n_train_rows_ : int
        Number of regressor rows the estimator was fitted on.
    n_experiments_ : int
        Number of experiments in the training data.

    Notes
    -----
    Experiments are contiguous runs of equal ``groups`` labels; a label that
    reappears later starts a new experiment. Every experiment needs at least
    ``max_lag_ + 1`` samples.
    """

    def __init__(
        self,
        *,
        estimator: object = None,
        output_lags: int = 2,
        input_lags: int = 2,
        include_current_input: bool = True,
        scale: bool = True,
    ) -> None:
        self.estimator = estimator
        self.output_lags = output_lags
        self.input_lags = input_lags
        self.include_current_input = include_current_input
        self.scale = scale

    # ------------------------------------------------------------------ helpers
    def _structure(self) -> _LagStructure:
        return _lag_structure(self.output_lags, self.input_lags, self.include_current_input)

    def _make_estimator(self) -> Any:
        if self.estimator is None:
            from softbend.identification.svr import GeneralizedGaussianSVR

            return GeneralizedGaussianSVR(C=100.0, epsilon=0.1)
        if not (hasattr(self.estimator, "fit") and hasattr(self.estimator, "predict")):
            raise InputError(
                must_be("None or a regressor with fit and predict", type(self.estimator).__name__),
                key="estimator",
            )
        return clone(self.estimator)

    def _fitted_structure(self) -> _LagStructure:
        check_is_fitted(self, "estimator_")
        return _LagStructure(self.output_offsets_, self.input_offsets_, self.max_lag_)

    def _affine(self) -> tuple[float, float, np.ndarray, np.ndarray]:
        """(y mean, y std, u means, u stds) of the scaling; identity when not scaling."""
        if self.y_scaler_ is None:
            return 0.0, 1.0, np.zeros(self.n_inputs_), np.ones(self.n_inputs_)
        return (
            float(self.y_scaler_.mean_[0]),
            float(self.y_scaler_.scale_[0]),
            self.u_scaler_.mean_,
            self.u_scaler_.scale_,
        )

    def _prepare(
        self, X: ArrayLike, groups: ArrayLike | None
    ) -> tuple[np.ndarray, _Segments, _LagStructure]:
        structure = self._fitted_structure()
        inputs = _as_inputs(X)
        if inputs.shape[1] != self.n_inputs_:
            raise InputError(
                f"must have {self.n_inputs_} input column(s) as in fit; got {inputs.shape[1]}",
                key="X",
            )
        segments = _segments(groups, inputs.shape[0], structure.max_lag)
        return inputs, segments, structure

    # ---------------------------------------------------------------------- API
    def fit(self, X: ArrayLike, y: ArrayLike, *, groups: ArrayLike | None = None) -> NARXRegressor:
        """Fit the static map f on the lagged regressors of one or several experiments.

        Parameters
        ----------
        X : array-like, shape (n_samples,) or (n_samples, n_inputs)
            Time-ordered input(s), e.g. supply pressure in kPa. Finite.
        y : array-like, shape (n_samples,)
            Time-ordered measured output (ρ, or L in mm). Finite.
        groups : array-like, shape (n_samples,), optional
            Experiment label of each sample; rows never cross a change of label.

        Returns
        -------
        NARXRegressor
            ``self``, fitted.

        Raises
        ------
        ValueError
            Bad lags, shapes or lengths (naming the field).
        DatasetError
            NaN/inf in ``X`` or ``y``, or an experiment shorter than max_lag + 1.
        """
        structure = self._structure()
        check_choice(self.scale, "scale", (True, False))
        estimator = self._make_estimator()
        inputs = _as_inputs(X)
        output = check_finite_array(_as_output(y, "y", inputs.shape[0]), "y")
        segments = _segments(groups, inputs.shape[0], structure.max_lag)

        if self.scale:
            self.u_scaler_ = StandardScaler().fit(inputs)
            self.y_scaler_ = StandardScaler().fit(output[:, None])
            inputs = self.u_scaler_.transform(inputs)
            output = self.y_scaler_.transform(output[:, None])[:, 0]
        else:
            self.u_scaler_ = None
            self.y_scaler_ = None
        index = _row_index(segments, structure.max_lag)
        Phi = _rows(inputs, output, index, structure)
        estimator.fit(Phi, output[index])

        self.estimator_ = estimator
        self.n_inputs_ = inputs.shape[1]
        self.n_features_in_ = self.n_inputs_
        self.max_lag_ = structure.max_lag
        self.output_offsets_ = structure.output_offsets
        self.input_offsets_ = structure.input_offsets
        self.regressor_names_ = _regressor_names(structure, self.n_inputs_)
        self.n_train_rows_ = int(index.size)
        self.n_experiments_ = len(segments.starts)
        logger.debug(
            "NARX fitted on %d rows from %d experiment(s), regressor %s",
            self.n_train_rows_,
            self.n_experiments_,
            self.regressor_names_,
        )
        return self

    def lagged_matrix(
        self, X: ArrayLike, y: ArrayLike, groups: ArrayLike | None = None
    ) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
        """Unscaled regressors, targets and time indices with this model's lags.

        Works before fitting; see the module-level :func:`lagged_matrix`.
        """
        return lagged_matrix(
            X,
            y,
            groups,
            output_lags=self.output_lags,
            input_lags=self.input_lags,
            include_current_input=self.include_current_input,
        )

    def warmup_mask(self, n_samples: int, *, groups: ArrayLike | None = None) -> np.ndarray:
        """Boolean mask of the initial-condition samples (first ``max_lag_`` of each experiment).

        Both prediction modes return the measured values there, so metrics should
        be computed on ``~mask``.

        Parameters
        ----------
        n_samples : int
            Length of the (concatenated) series.
        groups : array-like, shape (n_samples,), optional
            Experiment labels, as passed to the prediction.

        Returns
        -------
        ndarray of bool, shape (n_samples,)
        """
        structure = self._fitted_structure()
        if isinstance(n_samples, bool) or not isinstance(n_samples, numbers.Integral):
            raise InputError(must_be("an integer", n_samples), key="n_samples")
        segments = _segments(groups, int(n_samples), structure.max_lag)
        mask = np.zeros(int(n_samples), dtype=bool)
        for start in segments.starts:
            mask[start : start + structure.max_lag] = True
        return mask

    def predict_one_step(
        self, X: ArrayLike, y: ArrayLike, *, groups: ArrayLike | None = None
    ) -> np.ndarray:
        """One-step-ahead prediction from measured past outputs.

        "One step" is the system-identification notion: every sample is
        predicted from the *measured* outputs before it, as opposed to the free
        run of :meth:`simulate`. It is not a one-sample fast path; that is the
        estimator's ``predictor()``.

        Parameters
        ----------
        X : array-like, shape (n_samples,) or (n_samples, n_inputs)
            Input(s).
        y : array-like, shape (n_samples,)
            Measured output (finite); y(t−1) … y(t−na) of every row come from it.
        groups : array-like, shape (n_samples,), optional
            Experiment labels.

        Returns
        -------
        ndarray, shape (n_samples,)
            ŷ(t) in the unit of ``y``. The first ``max_lag_`` samples of each
            experiment are the measured values (initial conditions); leave them
            out of metrics (:meth:`warmup_mask`).
        """
        inputs, segments, structure = self._prepare(X, groups)
        output = check_finite_array(_as_output(y, "y", inputs.shape[0]), "y")
        y_mean, y_std, u_mean, u_std = self._affine()
        index = _row_index(segments, structure.max_lag)
        Phi = _rows((inputs - u_mean) / u_std, (output - y_mean) / y_std, index, structure)
        predicted = output.copy()
        scaled = np.asarray(self.estimator_.predict(Phi), dtype=float).reshape(-1)
        predicted[index] = scaled * y_std + y_mean
        return predicted

    def simulate(
        self, X: ArrayLike, y_init: ArrayLike, *, groups: ArrayLike | None = None
    ) -> np.ndarray:
        """Free-run simulation: the model feeds back its own predicted outputs.

        All experiments are simulated together, time step by time step, with
        one batched prediction per step over the experiments still running
        (they may differ in length). When a single experiment is running and
        the estimator offers a one-sample fast path ``predictor()`` (as
        :class:`~softbend.identification.svr.GeneralizedGaussianSVR` does), that
        path is used. The estimator is called on already scaled float64 rows.

        Parameters
        ----------
        X : array-like, shape (n_samples,) or (n_samples, n_inputs)
            Input(s) of all experiments, concatenated.
        y_init : array-like, shape (n_samples,) or (n_experiments, ``max_lag_``)
            Initial outputs: either the measured output of full length, of which
            only the first ``max_lag_`` samples of each experiment are read
            (the rest may be anything, even NaN), or the initial conditions of
            each experiment as rows.
        groups : array-like, shape (n_samples,), optional
            Experiment labels.

        Returns
        -------
        ndarray, shape (n_samples,)
            Simulated output in the unit of ``y``; the first ``max_lag_``
            samples of each experiment are the initial conditions. If an
            experiment's prediction becomes non-finite, a ``RuntimeWarning`` is
            issued and the rest of that experiment is NaN; the others go on.
        """
        inputs, segments, structure = self._prepare(X, groups)
        n_samples = inputs.shape[0]
        m = structure.max_lag
        na = structure.output_offsets.size
        initial = self._initial_conditions(y_init, segments, m, n_samples)

        y_mean, y_std, u_mean, u_std = self._affine()
        index = _row_index(segments, m)
        n_features = structure.n_features(inputs.shape[1])
        input_rows = np.empty((n_samples, n_features - na))
        input_rows[index] = _input_block((inputs - u_mean) / u_std, index, structure)
        state = np.full(n_samples, np.nan)
        for k, start in enumerate(segments.starts):
            state[start : start + m] = (initial[k] - y_mean) / y_std

        predict = self.estimator_.predict
        predictor = getattr(self.estimator_, "predictor", None)
        predict_one = predictor() if callable(predictor) else None
        starts, lengths = segments.starts, segments.lengths
        running = np.ones(starts.size, dtype=bool)
        rows = np.empty((starts.size, n_features))
        back = structure.output_offsets[None, :]
        for step in range(m, int(lengths.max())):
            active = np.flatnonzero(running & (lengths > step))
            if active.size == 0:
                break
            t = starts[active] + step
            batch = rows[: active.size]
            batch[:, :na] = state[t[:, None] - back]
            batch[:, na:] = input_rows[t]
            with np.errstate(over="ignore", invalid="ignore"):
                if active.size == 1 and predict_one is not None:
                    value = np.array([float(predict_one(batch[0]))])
                else:
                    value = np.asarray(predict(batch), dtype=float).reshape(-1)
                # A value that is finite only in scaled units also counts as diverged.
                finite = np.isfinite(value) & np.isfinite(value * y_std + y_mean)
            state[t] = value
            for position in np.flatnonzero(~finite):
                k = int(active[position])
                end = int(starts[k] + lengths[k])
                state[t[position] : end] = np.nan
                running[k] = False
                warnings.warn(
                    f"Free-run simulation of experiment {segments.labels[k]!r} diverged at "
                    f"sample {step} of {int(lengths[k])} (non-finite output); the rest of "
                    "that experiment is NaN.",
                    RuntimeWarning,
                    stacklevel=2,
                )

        simulated = state * y_std + y_mean
        for k, start in enumerate(starts):
            simulated[start : start + m] = initial[k]
        return simulated

    @staticmethod
    def _initial_conditions(
        y_init: ArrayLike, segments: _Segments, m: int, n_samples: int
    ) -> np.ndarray:
        """Initial outputs as an array (n_experiments, m), checked finite."""
        n_experiments = segments.starts.size
        array = np.asarray(y_init, dtype=float)
        if array.ndim == 1 and array.size == n_samples:
            initial = np.stack([array[s : s + m] for s in segments.starts])
        elif array.shape == (n_experiments, m):
            initial = array
        else:
            raise InputError(
                f"must be the measured output of shape ({n_samples},) or initial conditions "
                f"of shape ({n_experiments}, {m}); got shape {array.shape}",
                key="y_init",
            )
        return check_finite_array(initial, "y_init")

    def score(self, X: ArrayLike, y: ArrayLike, groups: ArrayLike | None = None) -> float:
        """R² of the free-run simulation (not of the one-step prediction).

        The simulation starts from the first ``max_lag_`` measured samples of
        each experiment; those initial conditions are excluded, and R² is
        computed over the remaining samples of all experiments pooled. A
        diverged simulation gives NaN.

        Parameters
        ----------
        X : array-like, shape (n_samples,) or (n_samples, n_inputs)
            Input(s).
        y : array-like, shape (n_samples,)
            Measured output, finite.
        groups : array-like, shape (n_samples,), optional
            Experiment labels.

        Returns
        -------
        float
            1 − Σ(y − ŷ)² / Σ(y − ȳ)² over the simulated samples.
        """
        inputs, _, _ = self._prepare(X, groups)
        n_samples = inputs.shape[0]
        output = check_finite_array(_as_output(y, "y", n_samples), "y")
        simulated = self.simulate(X, output, groups=groups)
        keep = ~self.warmup_mask(n_samples, groups=groups)
        return r2(output[keep], simulated[keep])
