"""Multi-output NARX: every output's regressor holds the lags of every output, run free jointly.

For m outputs and k inputs the regressor at time t is

    φ(t) = [y(t−1), …, y(t−na), u(t), …, u(t−nb+1)]      (y: all m outputs, u: all k inputs)

of length na·m + nb·k, and one static map per output gives y_j(t) = f_j(φ(t)).
The x and y of an arm's tip, or paper A's ρ and L, are coupled through the
body that carries both; a model that sees only its own output's past cannot
say so. Free-run simulation feeds every output's prediction back into every
regressor, all experiments stepped together.

The static maps are one of :data:`STRUCTURES`:

- ``arx``: linear (least squares with a tiny ridge), the baseline every model
  must beat;
- ``poly2``: every product of two regressors (degree-2 polynomial), least squares;
- ``gg-svr``: paper A's generalized-Gaussian kernel SVR
  (:class:`~softbend.identification.svr.GeneralizedGaussianSVR`; ``shape=2``
  is the Gaussian RBF kernel), fitted on at most ``max_rows`` evenly spaced
  regressor rows (a kernel fit grows with the square of the rows);
- ``arx-sim``, ``poly2-sim``, ``nn-sim``: the linear and degree-2 maps, and a
  small neural map, started from the one-step fit and fitted by their free-run
  error, optionally behind a first-order filter on every input whose time
  constant is estimated with the map (:mod:`softbend.identification.simfit`).

Signals are standardized per signal (each output's mean and standard
deviation from the training data, shared by its lags), so ``epsilon`` of an
SVR is in output standard deviations. A free run is kept within the training
outputs' range widened by :data:`FREE_RUN_MARGIN` ranges on each side: a model
that diverges saturates there instead of overflowing, and its error shows it.
"""

from __future__ import annotations

import functools
import json
import math
import os
from collections.abc import Callable, Mapping, Sequence
from pathlib import Path
from typing import Any

import numpy as np
from numpy.typing import ArrayLike

from softbend._validation import check_choice, check_finite_array, check_int, must_be
from softbend.errors import InputError, SchemaError, SoftbendError
from softbend.identification.freerun import free_run
from softbend.identification.narx import _row_index, _segments
from softbend.identification.persistence import svr_from_state, svr_state
from softbend.identification.simfit import Start, refine
from softbend.identification.simmaps import (
    MAX_SEARCHED_DELAY,
    SIM_FAMILIES,
    NeuralMap,
    check_sim_params,
    delay_inputs,
    filter_inputs,
)
from softbend.identification.svr import GeneralizedGaussianSVR

__all__ = [
    "FREE_RUN_MARGIN",
    "STRUCTURES",
    "TAU_GRID",
    "MultiNARX",
    "load_multi_narx",
    "save_multi_narx",
]

#: The static maps a :class:`MultiNARX` may use (its ``family``; not the surrogate
#: families of :data:`softbend.surrogates.FAMILIES`).
STRUCTURES: tuple[str, ...] = ("arx", "poly2", "gg-svr", *SIM_FAMILIES)

#: A free run stays within the training range widened by this many ranges per side.
FREE_RUN_MARGIN = 1.0

#: Input time constants (samples) whose one-step fits are run free when ``tau_init`` is None.
TAU_GRID: tuple[float, ...] = (0.25, 0.5, 1.0, 2.0, 4.0, 8.0, 16.0)

_FORMAT = "softbend-multi-narx"
_SCORE_ROWS = 200
_SEARCH_ROWS = 10_000
_GOLDEN_STEPS = 5
_SCHEMA = 1
_RIDGE = 1e-8


@functools.lru_cache(maxsize=64)
def _pairs(d: int) -> tuple[np.ndarray, np.ndarray]:
    """Row and column of every product of two of ``d`` regressors (upper triangle)."""
    return np.triu_indices(d)


class _Ridge:
    """Least squares with a tiny ridge on standardized regressors (closed form, exact reload)."""

    def __init__(self, degree: int = 1) -> None:
        self.degree = degree

    def _features(self, X: np.ndarray) -> np.ndarray:
        if self.degree == 1:
            return X
        i, j = _pairs(X.shape[1])
        return np.hstack([X, X[:, i] * X[:, j]])

    def fit(self, X: np.ndarray, y: np.ndarray) -> _Ridge:
        from threadpoolctl import threadpool_limits

        F = self._features(X)
        A = np.hstack([F, np.ones((F.shape[0], 1))])
        # one BLAS thread: a Gram matrix of a hundred columns gains little from more, and
        # on a busy machine threads waiting on each other made it 40 times slower
        with threadpool_limits(1, user_api="blas"):
            gram = A.T @ A
            rhs = A.T @ y
        gram[np.diag_indices_from(gram)] += _RIDGE * max(1.0, float(np.trace(gram)) / len(gram))
        solution = np.linalg.solve(gram, rhs)
        self.coef_, self.intercept_ = solution[:-1], float(solution[-1])
        return self

    def predict(self, X: np.ndarray) -> np.ndarray:
        return self._features(X) @ self.coef_ + self.intercept_

    def state(self) -> dict[str, Any]:
        return {"degree": self.degree, "coef": self.coef_.tolist(), "intercept": self.intercept_}

    @classmethod
    def from_state(cls, state: Mapping[str, Any]) -> _Ridge:
        model = cls(int(state["degree"]))
        model.coef_ = np.asarray(state["coef"], dtype=np.float64)
        model.intercept_ = float(state["intercept"])
        return model


class MultiNARX:
    """NARX with several outputs whose regressors share every output's lags.

    Parameters
    ----------
    family : {"arx", "poly2", "gg-svr", "arx-sim", "poly2-sim", "nn-sim"}, default "arx"
        The static map of each output (module docstring).
    output_lags : int, default 2
        na ≥ 1: past samples of every output in the regressor.
    input_lags : int, default 2
        nb ≥ 1: samples of every input, u(t) … u(t−nb+1).
    params : dict, optional
        Parameters of the static map: for ``gg-svr`` those of
        :class:`~softbend.identification.svr.GeneralizedGaussianSVR` (``C``,
        ``epsilon``, ``shape``, ...; default paper A's C = 100, ε = 0.1); for
        the ``-sim`` families the settings of
        :func:`~softbend.identification.simmaps.check_sim_params` (``steps``,
        ``epochs``, ``window``, ``batch``, ``lr``, ``filter``, ``tau_init`` in
        samples, ``delay`` in samples (None: searched per input), ``hidden``,
        ``pretrain``, ``seed``).
    max_rows : int, default 4000
        Regressor rows a ``gg-svr`` map is fitted on (evenly spaced; all when fewer).

    Attributes
    ----------
    estimators_ : list
        One fitted static map per output (in standardized units).
    y_mean_, y_std_, u_mean_, u_std_ : ndarray
        Standardization of the outputs and inputs.
    y_low_, y_high_ : ndarray
        The bounds of a free run (training range widened by :data:`FREE_RUN_MARGIN`).
    input_tau_ : ndarray or None
        The time constant of each input's first-order filter, in samples (None:
        no filter); :meth:`input_time_constants_s` in seconds.
    input_delay_ : ndarray of int or None
        Each input's delay (dead time) in samples, before its filter (None: none).
    n_outputs_, n_inputs_, max_lag_ : int
    """

    def __init__(
        self,
        family: str = "arx",
        *,
        output_lags: int = 2,
        input_lags: int = 2,
        params: Mapping[str, Any] | None = None,
        max_rows: int = 4000,
    ) -> None:
        check_choice(family, "family", STRUCTURES)
        check_int(output_lags, "output_lags", low=1)
        check_int(input_lags, "input_lags", low=1)
        check_int(max_rows, "max_rows", low=10)
        if family in SIM_FAMILIES:
            check_sim_params(dict(params or {}), family)
        self.family = family
        self.output_lags = output_lags
        self.input_lags = input_lags
        self.params = dict(params or {})
        self.max_rows = max_rows

    @property
    def max_lag(self) -> int:
        """Samples of initial conditions per experiment: max(na, nb − 1)."""
        return max(self.output_lags, self.input_lags - 1)

    def describe(self) -> str:
        """The model in one line: family, lags and the map's settings."""
        settings = ", ".join(f"{k}={v:g}" if isinstance(v, float) else f"{k}={v}"
                             for k, v in sorted(self.params.items()))  # fmt: skip
        text = f"{self.family} na={self.output_lags} nb={self.input_lags}"
        text = f"{text} ({settings})" if settings else text
        tau = getattr(self, "input_tau_", None)
        if tau is not None:
            text += f", input tau = {', '.join(f'{t:.3g}' for t in tau)} samples"
        delay = getattr(self, "input_delay_", None)
        if delay is not None:
            text += f", input delay = {', '.join(str(int(d)) for d in delay)} samples"
        return text

    def input_time_constants_s(self, sample_period_s: float | None) -> list[float] | None:
        """Each input filter's time constant in seconds (None without a filter).

        Parameters
        ----------
        sample_period_s : float or None
            The sampling interval, s; None (unknown) gives the time constants in samples.
        """
        tau = getattr(self, "input_tau_", None)
        if tau is None:
            return None
        scale = 1.0 if sample_period_s is None else float(sample_period_s)
        return [float(t) * scale for t in tau]

    def _inputs_standard(self, U: np.ndarray, segments: Any) -> np.ndarray:
        """Standardized inputs, delayed and through the input filters when the model has them."""
        Us = self._delayed((U - self.u_mean_) / self.u_std_, segments)
        tau = getattr(self, "input_tau_", None)
        if tau is None:
            return Us
        return filter_inputs(Us, segments.starts, segments.lengths, tau)

    def _delayed(self, Us: np.ndarray, segments: Any) -> np.ndarray:
        """Each input delayed by its ``input_delay_`` samples, held at the experiment's first
        sample before (started at rest, as the filter is: the two commute)."""
        delay = getattr(self, "input_delay_", None)
        if delay is None:
            return Us
        return delay_inputs(Us, segments.starts, segments.lengths, delay)

    def _map(self) -> _Ridge | GeneralizedGaussianSVR:
        if self.family in ("arx", "arx-sim", "nn-sim"):
            return _Ridge(1)
        if self.family in ("poly2", "poly2-sim"):
            return _Ridge(2)
        return GeneralizedGaussianSVR(**{"C": 100.0, "epsilon": 0.1, **self.params})

    def _regressors(self, U: np.ndarray, Y: np.ndarray, t: np.ndarray) -> np.ndarray:
        """Rows φ(t) for the time indices ``t`` of standardized U and Y."""
        na, nb = self.output_lags, self.input_lags
        blocks = [Y[t - k] for k in range(1, na + 1)] + [U[t - k] for k in range(nb)]
        return np.hstack(blocks)

    def fit(self, U: ArrayLike, Y: ArrayLike, groups: ArrayLike | None = None) -> MultiNARX:
        """Fit every output's map on the one-step regressors of every experiment.

        Parameters
        ----------
        U : array_like, shape (n, k)
            Inputs.
        Y : array_like, shape (n, m)
            Outputs.
        groups : array_like, shape (n,), optional
            Experiment label per sample (contiguous runs); default one experiment.
        """
        U, Y = self._arrays(U, Y)
        lag = self.max_lag
        segments = _segments(groups, U.shape[0], lag)
        self.u_mean_, self.u_std_ = U.mean(axis=0), U.std(axis=0)
        self.y_mean_, self.y_std_ = Y.mean(axis=0), Y.std(axis=0)
        self.u_std_[self.u_std_ == 0] = 1.0
        self.y_std_[self.y_std_ == 0] = 1.0
        low, high = Y.min(axis=0), Y.max(axis=0)
        span = np.maximum(high - low, np.finfo(np.float64).tiny)
        self.y_low_ = low - FREE_RUN_MARGIN * span
        self.y_high_ = high + FREE_RUN_MARGIN * span
        Ys = (Y - self.y_mean_) / self.y_std_
        sim = self.family in SIM_FAMILIES
        settings = check_sim_params(self.params, self.family) if sim else None
        self.input_tau_ = self.input_delay_ = None
        self.n_inputs_, self.n_outputs_ = U.shape[1], Y.shape[1]
        if settings is not None and settings["filter"]:
            tau = settings["tau_init"]
            tau = self._search_tau(U, Y, Ys, segments) if tau is None else float(tau)
            self.input_tau_ = np.full(U.shape[1], tau)
        if settings is not None and settings["delay"] != 0:
            delay = settings["delay"]
            self.input_delay_ = (
                self._search_delay(U, Y, Ys, segments)
                if delay is None
                else np.full(U.shape[1], int(delay))
            )
        Us = self._delayed((U - self.u_mean_) / self.u_std_, segments)
        Phi, target = self._fit_one_step(U, Ys, segments)
        self.n_train_rows_ = int(Phi.shape[0])
        if settings is not None:
            self._refine(settings, Us, Ys, segments, Phi, target)
        return self

    def _fit_one_step(
        self, U: np.ndarray, Ys: np.ndarray, segments: Any, rows: int | None = None
    ) -> tuple[np.ndarray, np.ndarray]:
        """The maps fitted one step ahead (least squares or SVR); returns their rows and targets.

        ``rows``: at most that many regressor rows (evenly spaced); a ``gg-svr``'s ``max_rows``.
        """
        index = _row_index(segments, self.max_lag)
        rows = self.max_rows if self.family == "gg-svr" else rows
        if rows is not None and index.size > rows:  # only the rows kept are formed
            index = index[np.unique(np.linspace(0, index.size - 1, rows).round().astype(int))]
        Phi = self._regressors(self._inputs_standard(U, segments), Ys, index)
        target = Ys[index]
        self.estimators_: list[Any] = [
            self._map().fit(Phi, target[:, j]) for j in range(Ys.shape[1])
        ]
        return Phi, target

    def _search_tau(self, U: np.ndarray, Y: np.ndarray, Ys: np.ndarray, segments: Any) -> float:
        """The input time constant (samples, one for all inputs) whose one-step fit runs free best.

        Scored on :data:`TAU_GRID`, then by a golden-section search in log τ between the
        best point's neighbours; each one-step fit on at most ``_SEARCH_ROWS`` rows.
        """
        k = U.shape[1]

        def score(tau: float) -> float:
            self.input_tau_ = np.full(k, tau)
            self._fit_one_step(U, Ys, segments, rows=_SEARCH_ROWS)
            return self._start_score(U, Y, segments)

        scores = [score(t) for t in TAU_GRID]
        i = int(np.argmin(scores))
        best, best_score = TAU_GRID[i], scores[i]
        # golden-section search in log τ between the best point's neighbours
        a = math.log(TAU_GRID[max(i - 1, 0)])
        b = math.log(TAU_GRID[min(i + 1, len(TAU_GRID) - 1)])
        ratio = (math.sqrt(5.0) - 1.0) / 2.0
        c, d = b - ratio * (b - a), a + ratio * (b - a)
        fc, fd = score(math.exp(c)), score(math.exp(d))
        for _ in range(_GOLDEN_STEPS):
            if fc < fd:
                b, d, fd = d, c, fc
                c = b - ratio * (b - a)
                fc = score(math.exp(c))
            else:
                a, c, fc = c, d, fd
                d = a + ratio * (b - a)
                fd = score(math.exp(d))
        for x, f in ((c, fc), (d, fd)):
            if f < best_score:
                best, best_score = math.exp(x), f
        return best

    def _search_delay(
        self, U: np.ndarray, Y: np.ndarray, Ys: np.ndarray, segments: Any
    ) -> np.ndarray:
        """Each input's delay (samples, in 0 … :data:`MAX_SEARCHED_DELAY`) whose one-step fit
        runs free best: one input at a time, in order, the others as found so far (from 0)."""
        k = U.shape[1]
        self.input_delay_ = np.zeros(k, dtype=np.int64)

        def score(delays: np.ndarray) -> float:
            self.input_delay_ = delays
            self._fit_one_step(U, Ys, segments, rows=_SEARCH_ROWS)
            return self._start_score(U, Y, segments)

        best = np.zeros(k, dtype=np.int64)
        best_score = score(best.copy())
        for i in range(k):
            chosen = best
            for d in range(1, MAX_SEARCHED_DELAY + 1):
                trial = best.copy()
                trial[i] = d
                value = score(trial)
                if value < best_score:
                    best_score, chosen = value, trial
            best = chosen
        self.input_delay_ = best
        return best

    def _start_score(self, U: np.ndarray, Y: np.ndarray, segments: Any) -> float:
        """Mean squared free-run error (standardized) over each experiment's first samples."""
        counts = np.minimum(segments.lengths, _SCORE_ROWS)
        starts = segments.starts
        rows = np.concatenate([np.arange(s, s + c) for s, c in zip(starts, counts, strict=True)])
        labels = np.repeat(np.arange(len(counts)), counts)
        simulated = self.simulate(U[rows], Y[rows], labels)
        return float(np.mean(((simulated - Y[rows]) / self.y_std_) ** 2))

    def _refine(
        self,
        settings: dict[str, Any],
        Us: np.ndarray,
        Ys: np.ndarray,
        segments: Any,
        Phi: np.ndarray,
        target: np.ndarray,
    ) -> None:
        """Replace the one-step maps by their simulation-error refinement."""
        ridges = self.estimators_
        start = Start(
            degree=ridges[0].degree,
            coef=np.column_stack([r.coef_ for r in ridges]),
            intercept=np.array([r.intercept_ for r in ridges]),
        )
        bounds = self._standard_bounds()
        refined = refine(
            self.family, settings, Us, Ys, (segments.starts, segments.lengths),
            (self.output_lags, self.input_lags), bounds, start, self.input_tau_,
            (Phi, target) if self.family == "nn-sim" else None,
        )  # fmt: skip
        if refined.neural is not None:
            self.estimators_ = refined.neural
        else:
            self.estimators_ = [
                _Ridge.from_state({"degree": start.degree, "coef": refined.coef[:, j],
                                   "intercept": refined.intercept[j]})
                for j in range(refined.coef.shape[1])
            ]  # fmt: skip
        self.input_tau_ = refined.tau
        self.sim_steps_ = refined.steps_run

    def _arrays(
        self, inputs: ArrayLike, outputs: ArrayLike, outputs_key: str = "Y"
    ) -> tuple[np.ndarray, np.ndarray]:
        U = check_finite_array(inputs, "U")
        Y = check_finite_array(outputs, outputs_key)
        U = U[:, None] if U.ndim == 1 else U
        Y = Y[:, None] if Y.ndim == 1 else Y
        if U.ndim != 2:
            raise InputError(f"must be an array (n, k); got shape {U.shape}", key="U")
        if Y.ndim != 2 or U.shape[0] != Y.shape[0]:
            raise InputError(
                f"must be an array (n, m) with the n of U ({U.shape[0]}); got shape {Y.shape}",
                key=outputs_key,
            )
        return U, Y

    def _check_fitted(self, U: np.ndarray) -> None:
        if not hasattr(self, "estimators_"):
            raise ValueError("This MultiNARX is not fitted yet: call fit first.")
        if U.shape[1] != self.n_inputs_:
            raise InputError(
                f"must have the {self.n_inputs_} input column(s) of fit; got {U.shape[1]}",
                key="U",
            )

    def predict_one_step(
        self, U: ArrayLike, Y: ArrayLike, groups: ArrayLike | None = None
    ) -> np.ndarray:
        """Each output at t from the measured past (NaN for the initial conditions)."""
        U, Y = self._arrays(U, Y)
        self._check_fitted(U)
        segments = _segments(groups, U.shape[0], self.max_lag)
        Us, Ys = self._inputs_standard(U, segments), (Y - self.y_mean_) / self.y_std_
        out = np.full(Y.shape, np.nan)
        index = _row_index(segments, self.max_lag)
        Phi = self._regressors(Us, Ys, index)
        out[index] = np.column_stack([e.predict(Phi) for e in self.estimators_])
        return out * self.y_std_ + self.y_mean_

    def simulate(
        self, U: ArrayLike, Y_init: ArrayLike, groups: ArrayLike | None = None
    ) -> np.ndarray:
        """Free run: every output fed back, every experiment stepped together.

        Parameters
        ----------
        U : array_like, shape (n, k)
            Inputs of all experiments, concatenated.
        Y_init : array_like, shape (n, m)
            Outputs whose first ``max_lag`` samples of each experiment are the
            initial conditions (the rest is not read).
        groups : array_like, optional
            Experiment label per sample.

        Returns
        -------
        ndarray, shape (n, m)
            The simulated outputs (the initial conditions copied).
        """
        U, Y0 = self._arrays(U, Y_init, "Y_init")
        self._check_fitted(U)
        segments = _segments(groups, U.shape[0], self.max_lag)
        Ys = free_run(
            self._step_map(),
            self._inputs_standard(U, segments),
            (Y0 - self.y_mean_) / self.y_std_,
            (segments.starts, segments.lengths),
            (self.output_lags, self.input_lags),
            self._standard_bounds(),
        )
        return Ys * self.y_std_ + self.y_mean_

    def _standard_bounds(self) -> tuple[np.ndarray, np.ndarray]:
        """The free run's bounds in standardized units."""
        return ((self.y_low_ - self.y_mean_) / self.y_std_,
                (self.y_high_ - self.y_mean_) / self.y_std_)  # fmt: skip

    def _step_map(self) -> Callable[[np.ndarray], np.ndarray]:
        """Every output's map as one call ``Phi (r, d) → (r, m)``, its constants hoisted.

        A polynomial's products are formed once for all outputs; a kernel map is
        evaluated without scikit-learn's per-call validation.
        """
        maps = self.estimators_
        if all(isinstance(e, _Ridge) for e in maps):
            coef = np.column_stack([e.coef_ for e in maps])
            intercept = np.array([e.intercept_ for e in maps])
            d = self.output_lags * self.n_outputs_ + self.input_lags * self.n_inputs_
            i, j = _pairs(d) if maps[0].degree == 2 else (None, None)

            def polynomial(Phi: np.ndarray) -> np.ndarray:
                F = Phi if i is None else np.hstack([Phi, Phi[:, i] * Phi[:, j]])
                out = F @ coef
                out += intercept
                return out

            return polynomial
        evaluate = [e._evaluator() if isinstance(e, GeneralizedGaussianSVR) else e.predict
                    for e in maps]  # fmt: skip

        def columns(Phi: np.ndarray) -> np.ndarray:
            return np.column_stack([f(Phi) for f in evaluate])

        return columns

    # -- persistence ------------------------------------------------------------------

    def to_dict(self, metadata: Mapping[str, Any] | None = None) -> dict[str, Any]:
        """The fitted model as JSON-ready data (:func:`save_multi_narx`)."""
        if not hasattr(self, "estimators_"):
            raise ValueError("This MultiNARX is not fitted yet: call fit first.")
        maps = [
            svr_state(e) if isinstance(e, GeneralizedGaussianSVR) else e.state()
            for e in self.estimators_
        ]
        tau = getattr(self, "input_tau_", None)
        delay = getattr(self, "input_delay_", None)
        return {
            "format": _FORMAT,
            "schema_version": _SCHEMA,
            "metadata": dict(metadata or {}),
            "family": self.family,
            "output_lags": self.output_lags,
            "input_lags": self.input_lags,
            "params": self.params,
            "max_rows": self.max_rows,
            "n_inputs": self.n_inputs_,
            "n_outputs": self.n_outputs_,
            "n_train_rows": self.n_train_rows_,
            **{
                name: getattr(self, f"{name}_").tolist()
                for name in ("u_mean", "u_std", "y_mean", "y_std", "y_low", "y_high")
            },
            "maps": maps,
            **({} if tau is None else {"input_tau": tau.tolist()}),
            **({} if delay is None else {"input_delay": [int(d) for d in delay]}),
        }

    @classmethod
    def from_dict(cls, data: object) -> MultiNARX:
        """Rebuild a fitted model from :meth:`to_dict` data.

        Raises
        ------
        SchemaError
            Keyed by the entry at fault (``"u_mean"``); ``"format"`` for data that
            is not a saved model.
        """
        if not isinstance(data, Mapping) or data.get("format") != _FORMAT:
            raise SchemaError(
                f"must be {_FORMAT!r}: the data is not a saved softbend multi-output NARX model",
                key="format",
            )
        if data.get("schema_version") != _SCHEMA:
            raise SchemaError(
                must_be(f"{_SCHEMA}, the version this softbend reads", data.get("schema_version")),
                key="schema_version",
            )
        try:
            model = cls(
                data["family"],
                output_lags=int(data["output_lags"]),
                input_lags=int(data["input_lags"]),
                params=data["params"],
                max_rows=int(data["max_rows"]),
            )
            model.n_inputs_, model.n_outputs_ = int(data["n_inputs"]), int(data["n_outputs"])
            model.n_train_rows_ = int(data["n_train_rows"])
            sizes = {"u_mean": model.n_inputs_, "u_std": model.n_inputs_}
            sizes |= dict.fromkeys(("y_mean", "y_std", "y_low", "y_high"), model.n_outputs_)
            for name, size in sizes.items():
                values = np.asarray(data[name], dtype=np.float64)
                if values.shape != (size,) or not np.isfinite(values).all():
                    raise SchemaError(f"must hold {size} finite numbers", key=name)
                setattr(model, f"{name}_", values)
            maps = data["maps"]
            if not isinstance(maps, list) or len(maps) != model.n_outputs_:
                raise SchemaError(f"must hold one map per output ({model.n_outputs_})", key="maps")
            d = model.output_lags * model.n_outputs_ + model.input_lags * model.n_inputs_
            model.estimators_ = [
                svr_from_state(m) if model.family == "gg-svr"
                else NeuralMap.from_state(m, d) if model.family == "nn-sim"
                else _Ridge.from_state(m)
                for m in maps
            ]  # fmt: skip
            model.input_tau_ = None
            if data.get("input_tau") is not None:
                tau = np.asarray(data["input_tau"], dtype=np.float64)
                if tau.shape != (model.n_inputs_,) or not (np.isfinite(tau) & (tau >= 0)).all():
                    raise SchemaError(
                        f"must hold {model.n_inputs_} finite non-negative numbers",
                        key="input_tau",
                    )
                model.input_tau_ = tau
            model.input_delay_ = None
            if data.get("input_delay") is not None:
                delay = np.asarray(data["input_delay"])
                if (
                    delay.shape != (model.n_inputs_,)
                    or delay.dtype.kind not in "iu"
                    or not (delay >= 0).all()
                ):
                    raise SchemaError(
                        f"must hold {model.n_inputs_} non-negative integers (samples)",
                        key="input_delay",
                    )
                model.input_delay_ = delay.astype(np.int64)
        except SoftbendError as err:
            raise SchemaError(err.detail, key=err.key) from None
        except KeyError as err:
            raise SchemaError("is missing", key=str(err.args[0])) from None
        except (TypeError, ValueError) as err:
            raise SchemaError(f"is not a saved model's entry: {err}") from None
        return model


def save_multi_narx(
    model: MultiNARX, path: str | os.PathLike[str], metadata: Mapping[str, Any] | None = None
) -> Path:
    """Write a fitted :class:`MultiNARX` to ``path`` (strict JSON, atomic); returns the path.

    Floats are written with their shortest round-trip text, so a reloaded model
    simulates bit for bit as the saved one.
    """
    from softbend._io import json_text, write_text_atomic

    target = Path(path)
    write_text_atomic(target, json_text(model.to_dict(metadata)) + "\n")
    return target


def load_multi_narx(path: str | os.PathLike[str]) -> tuple[MultiNARX, dict[str, Any]]:
    """A model written by :func:`save_multi_narx` and its metadata.

    Raises
    ------
    FileNotFoundError
        No such file.
    SchemaError
        Not a saved model, or a broken one (naming the file).
    """
    file = Path(path)
    try:
        data = json.loads(file.read_text(encoding="utf-8"))
    except json.JSONDecodeError as err:
        raise SchemaError(f"is not JSON: {err}", file=str(file)) from None
    try:
        model = MultiNARX.from_dict(data)
    except SchemaError as error:
        error.file = str(file)
        raise
    return model, dict(data.get("metadata", {}))


def nrmse(
    measured: np.ndarray, simulated: np.ndarray, ranges: Sequence[float] | np.ndarray
) -> np.ndarray:
    """RMSE of each output over its range (the ranges given), dimensionless.

    A range of zero counts as the smallest positive double, so that a tiny but
    non-zero range (an output in small units) is used as it is.
    """
    error = np.sqrt(np.nanmean((np.asarray(simulated) - np.asarray(measured)) ** 2, axis=0))
    floor = np.finfo(np.float64).tiny
    return error / np.maximum(np.asarray(ranges, dtype=np.float64), floor)
