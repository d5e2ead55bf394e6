"""Support vector regression with the generalized-Gaussian kernel (paper A §4).

The kernel's hyperparameters (σ, γ) are estimator parameters, so grid search
and ``get_params`` see them. How the ε-SVR dual is solved depends on the shape:

* **γ = 2** is the Gaussian kernel, exp(−‖x − z‖²/(2σ²)): LIBSVM's own RBF
  kernel solves it (:class:`sklearn.svm.SVR`, ``kernel="rbf"``). The density's
  normalization c is a constant factor of the kernel, equivalent to the penalty
  c·C (the dual coefficients are divided by c), so this is the same model as
  the precomputed-Gram formulation, to solver tolerance. LIBSVM computes kernel
  rows on demand into a cache of ``cache_size`` MB: memory grows as n, not n².
* **γ ≠ 2** has no LIBSVM kernel. An active-set (chunking) decomposition keeps
  the dense n × n Gram matrix out of memory: LIBSVM solves the dual restricted
  to a working set W of at most ``max_working_set`` rows on its precomputed
  Gram block, the rows outside W keep their coefficients, and W is rebuilt from
  the support vectors and the rows that violate the optimality (KKT) conditions
  most, until none outside W violates them by more than ``tol``. Kernel columns
  of the support vectors over all rows are computed in blocks of bounded size
  and cached (up to ``cache_size`` MB). The SVR dual is sparse (paper A's data:
  about 40 support vectors of 3 060 rows), so W stays small and the fit is
  exact to solver tolerance, as the dense formulation is; memory is at most
  about 16·``|W|``² bytes (256 MiB at 4 096 rows) plus the two caches. When the
  support vectors and the violators do not fit in ``max_working_set`` rows, W
  is the set of most violating rows (Joachims' SVMlight selection), the other
  rows keep their coefficients, and the equality constraint of the dual is kept
  with one auxiliary variable (see :func:`_solve_active_set`); this converges
  more slowly.

Prediction is a NumPy kernel expansion over the stored support vectors, in
row blocks of bounded size, and :meth:`GeneralizedGaussianSVR.predictor` returns a
low-overhead one-sample evaluator for control loops and free-run simulation (the
fast path of every softbend regressor has that name).
"""

from __future__ import annotations

import logging
import math
import warnings
from collections.abc import Callable
from numbers import Integral
from typing import NamedTuple

import numpy as np
from numpy.typing import ArrayLike
from scipy.spatial.distance import cdist
from sklearn import config_context
from sklearn.base import BaseEstimator, RegressorMixin
from sklearn.exceptions import ConvergenceWarning, NotFittedError
from sklearn.svm import SVR
from sklearn.utils.validation import _check_sample_weight, check_is_fitted, validate_data

from softbend._validation import check_choice, check_int, check_range, must_be
from softbend.errors import ConvergenceError, InputError
from softbend.identification.kernels import (
    MOMENTS_OF,
    ShapeEstimate,
    _kernel_block,
    _kernel_from_sqdist,
    _kernel_shape_estimate,
    _power_in_place,
    _warn_clipped,
    gg_normalization,
    gg_scale,
)

logger = logging.getLogger(__name__)

__all__ = ["GeneralizedGaussianSVR"]

_OWNER = "GeneralizedGaussianSVR"

#: Default cap on the working set of the γ ≠ 2 solver: 8·4096² bytes = 128 MiB of Gram.
DEFAULT_MAX_WORKING_SET = 4096
#: Size of the first working set (a fixed-seed random subset of the rows).
_INITIAL_WORKING_SET = 256
#: Most violating rows added to the working set per round (bounds the Gram block).
_MAX_ADDED = 512
#: Rounds of the active-set loop before it gives up with a ConvergenceWarning: this
#: many, plus _ROUNDS_PER_CHUNK per max_working_set rows (a small working set needs more).
_MAX_ROUNDS = 200
_ROUNDS_PER_CHUNK = 50
#: Bytes of one block of kernel values (rows × support vectors) in fit and predict.
_BLOCK_BYTES = 32 * 2**20
#: predictor()'s factored RBF path is used while rate·|s − m|² and rate·|x − m|² stay
#: below this (so no exponent exceeds 2·50 and rounding stays ~1e-14 relative).
_FAST_EXPONENT = 50.0


def _check_max_iter(value: object) -> int:
    if isinstance(value, bool) or not isinstance(value, Integral) or value < -1 or value == 0:
        raise InputError(must_be("-1 (no limit) or a positive integer", value), key="max_iter")
    return int(value)


def _merge_duplicates(
    X: np.ndarray, y: np.ndarray, weight: np.ndarray
) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
    """Drop zero-weight rows, merge identical (x, y) rows and sort them.

    Identical training pairs have identical slacks in the SVR primal, so one row
    carrying the summed weight is the same problem with a smaller Gram matrix.
    The lexicographic order makes the fit independent of the sample order, and
    makes an integer weight k exactly equivalent to k copies of the sample.
    """
    keep = weight > 0.0
    rows = np.column_stack([X[keep], y[keep]])
    order = np.lexsort(rows.T[::-1])  # first column primary, as np.unique(axis=0) sorts
    rows = rows[order]
    starts = np.flatnonzero(np.concatenate(([True], np.any(rows[1:] != rows[:-1], axis=1))))
    merged_weight = np.add.reduceat(weight[keep][order], starts)
    unique = rows[starts]
    return np.ascontiguousarray(unique[:, :-1]), unique[:, -1].copy(), merged_weight


class _Solution(NamedTuple):
    """Dual solution for the unnormalized kernel: f(x) = Σ alpha_i K(x_i, x) + intercept."""

    support: np.ndarray  # indices of the rows with alpha != 0, ascending
    alpha: np.ndarray  # their coefficients, target units
    intercept: float
    n_iter: int


def _libsvm_weights(weight: np.ndarray) -> np.ndarray | None:
    """Per-row weights for LIBSVM (its box is C_i = C·w_i), or None when all are 1."""
    return None if bool(np.all(weight == 1.0)) else weight


def _solve_rbf(
    X: np.ndarray,
    y: np.ndarray,
    weight: np.ndarray,
    *,
    C: float,
    epsilon: float,
    gamma: float,
    tol: float,
    cache_size: float,
    max_iter: int,
) -> _Solution:
    """ε-SVR with LIBSVM's RBF kernel exp(−gamma·‖x − z‖²) and box C·w_i."""
    svr = SVR(
        kernel="rbf",
        gamma=gamma,
        C=C,
        epsilon=epsilon,
        tol=tol,
        cache_size=cache_size,
        max_iter=max_iter,
    )
    svr.fit(X, y, sample_weight=_libsvm_weights(weight))
    return _Solution(
        support=np.asarray(svr.support_, dtype=np.intp),
        alpha=np.asarray(svr.dual_coef_, dtype=float).ravel(),
        intercept=float(np.asarray(svr.intercept_).ravel()[0]),
        n_iter=int(np.asarray(svr.n_iter_).ravel()[0]),
    )


def _block_rows(n_columns: int) -> int:
    """Rows per block so that a float64 block of ``n_columns`` stays near _BLOCK_BYTES."""
    return max(1, _BLOCK_BYTES // (8 * max(1, n_columns)))


class _KernelColumns:
    """Columns K(X, x_j) of the unnormalized kernel over all training rows, cached.

    The active-set solver needs, every round, the Gram block of its working set
    and the products K(X, X_moved)·Δα. Columns of rows that moved (support
    vectors, mostly the same from round to round) are kept, one contiguous row
    per column in a (capacity, n) array of at most ``budget_bytes`` (its memory
    is touched only as columns are stored); columns beyond it are computed in
    row blocks of bounded size and dropped.
    """

    def __init__(self, X: np.ndarray, *, sigma: float, shape: float, budget_bytes: float) -> None:
        self.X = X
        self.sigma = sigma
        self.shape = shape
        n = X.shape[0]
        self.capacity = int(min(n, budget_bytes // (8 * n)))
        self.store = np.empty((self.capacity, n))
        self.slot = np.full(n, -1, dtype=np.intp)
        self.used = 0

    def _compute(
        self, rows: slice | np.ndarray, cols: np.ndarray, *, single: bool = False
    ) -> np.ndarray:
        return _kernel_block(
            self.X[rows], self.X[cols], sigma=self.sigma, shape=self.shape, single=single
        )

    def _remember(self, cols: np.ndarray) -> None:
        """Compute and store the columns of ``cols`` that are missing, while room is left."""
        missing = cols[self.slot[cols] < 0][: self.capacity - self.used]
        if missing.size == 0:
            return
        slots = np.arange(self.used, self.used + missing.size)
        n = self.X.shape[0]
        step = _block_rows(missing.size)
        for start in range(0, n, step):
            rows = slice(start, min(n, start + step))
            self.store[self.used : self.used + missing.size, rows] = self._compute(rows, missing).T
        self.slot[missing] = slots
        self.used += missing.size

    def gram(self, rows: np.ndarray) -> np.ndarray:
        """K(X[rows], X[rows]) for LIBSVM, from stored columns where possible.

        Columns not stored are evaluated in float32: LIBSVM keeps its kernel
        values in single precision (``Qfloat``) in any case. Products with the
        coefficients use only stored (float64) columns as long as the store
        holds every row with a nonzero coefficient.
        """
        slots = self.slot[rows]
        known = slots >= 0
        if not known.any():
            return self._compute(rows, rows, single=True)
        gram = np.empty((rows.size, rows.size))
        gram[:, known] = self.store[np.ix_(slots[known], rows)].T
        if not known.all():
            gram[:, ~known] = self._compute(rows, rows[~known], single=True)
        return gram

    def add_product(self, target: np.ndarray, cols: np.ndarray, coef: np.ndarray) -> None:
        """target += K(X, X[cols]) @ coef."""
        self._remember(cols)
        slots = self.slot[cols]
        known = slots >= 0
        if known.any():
            weights = np.zeros(self.used)
            np.add.at(weights, slots[known], coef[known])
            target += weights @ self.store[: self.used]
        if not known.all():
            rest, rest_coef = cols[~known], coef[~known]
            n = self.X.shape[0]
            step = _block_rows(rest.size)
            for start in range(0, n, step):
                rows = slice(start, min(n, start + step))
                target[rows] += self._compute(rows, rest) @ rest_coef


def _most_violating(up: np.ndarray, low: np.ndarray, size: int) -> np.ndarray:
    """Working set of the decomposition method (Joachims' SVMlight selection).

    Half of the rows with the largest up values and half with the smallest low
    values (the two ends of the maximal violating pairs), ``size`` rows in all.
    """
    by_up = np.argsort(-up, kind="stable")
    by_low = np.argsort(low, kind="stable")
    chosen = np.zeros(up.size, dtype=bool)
    count = 0
    for i, j in zip(by_up, by_low, strict=True):
        for row in (i, j):
            if not chosen[row] and count < size:
                chosen[row] = True
                count += 1
        if count >= size:
            break
    return np.flatnonzero(chosen)


def _solve_active_set(
    X: np.ndarray,
    y: np.ndarray,
    weight: np.ndarray,
    *,
    C: float,
    epsilon: float,
    sigma: float,
    shape: float,
    tol: float,
    cache_size: float,
    max_iter: int,
    max_working_set: int,
) -> _Solution:
    """ε-SVR with the unnormalized GG kernel without forming the n × n Gram matrix.

    The dual, for α_i = α⁺_i − α⁻_i, is

        min ½ αᵀKα − yᵀα + ε‖α‖₁   s.t.   Σ α_i = 0,  |α_i| ≤ B_i = C·w_i.

    With e_i = y_i − (Kα)_i, a row offers the "up" value e_i + ε if α_i < 0, else
    e_i − ε if α_i < B_i, and the "low" value e_i − ε if α_i > 0, else e_i + ε if
    α_i > −B_i (LIBSVM's −y∇f of the variables that may move up or down); α is
    optimal when max(up) − min(low) ≤ tol (LIBSVM's stopping rule). Each round
    solves the dual over the working set W with LIBSVM on the Gram block K_WW,
    the rows N outside W held fixed: the linear term becomes y_W − K_WN α_N and
    the equality constraint Σ_W α_i = −Σ_N α_i =: s. LIBSVM's SVR only knows
    s = 0, so when s ≠ 0 one auxiliary row p is appended, orthogonal to W
    (K_pW = 0, K_pp = 1), with box |s| and a target of sign −s larger than
    |s| + 2ε + max|y_W − K_WN α_N| + Σ_W B_i, a bound on the subproblem's offset
    b, so that its coefficient sits at its bound −s (checked after the solve):
    the constraint Σ_W α + α_p = 0 is then Σ_W α = s. Rows outside W whose up
    (low) value exceeds (falls below) W's min(low) (max(up)) by more than ``tol``
    join W, the most violating first, with W's support vectors; without such
    rows, α is optimal to the
    tolerance LIBSVM reached on W. Every round lowers the dual objective (the
    previous α_W is feasible for it), so the loop cannot cycle. The first W is a
    fixed-seed random subset of :data:`_INITIAL_WORKING_SET` rows; at most
    :data:`_MAX_ADDED` violators join per round; when the support vectors and the
    violators exceed ``max_working_set``, W is chosen by :func:`_most_violating`.
    """
    n = y.size
    box = C * weight
    alpha = np.zeros(n)
    kernel_alpha = np.zeros(n)  # (K α)_i, kept up to date with the blocked products
    columns = _KernelColumns(X, sigma=sigma, shape=shape, budget_bytes=cache_size * 2**20)
    limit = min(n, max_working_set)
    first = min(limit, _INITIAL_WORKING_SET)
    if first >= n:
        work = np.arange(n)
    else:
        work = np.sort(np.random.default_rng(0).choice(n, size=first, replace=False))
    n_iter = 0
    converged = False
    max_rounds = _MAX_ROUNDS + _ROUNDS_PER_CHUNK * math.ceil(n / limit)
    for _ in range(max_rounds):
        inside = np.zeros(n, dtype=bool)
        inside[work] = True
        gram = columns.gram(work)
        alpha_work = alpha[work]
        target = y[work] - (kernel_alpha[work] - gram @ alpha_work)
        weights = weight[work]
        total = -float(alpha[~inside].sum())  # s, the sum the working set must keep
        auxiliary = total != 0.0
        if auxiliary:
            size = work.size
            padded = np.zeros((size + 1, size + 1))
            padded[:size, :size] = gram
            padded[size, size] = 1.0
            gram = padded
            push = abs(total) + 2.0 * epsilon + float(np.abs(target).max()) + float(box[work].sum())
            target = np.append(target, -math.copysign(push + 1.0, total))
            weights = np.append(weights, abs(total) / C)
        svr = SVR(
            kernel="precomputed",
            C=C,
            epsilon=epsilon,
            tol=tol,
            cache_size=cache_size,
            max_iter=max_iter,
        )
        # The blocks are built here from validated data: scikit-learn's checks of
        # parameters and finiteness would cost more than LIBSVM's solve of a small block.
        with config_context(skip_parameter_validation=True, assume_finite=True):
            svr.fit(gram, target, sample_weight=_libsvm_weights(weights))
        del gram
        solved = np.zeros(target.size)
        solved[svr.support_] = np.asarray(svr.dual_coef_, dtype=float).ravel()
        n_iter += int(np.asarray(svr.n_iter_).ravel()[0])
        if auxiliary:
            if not math.isclose(solved[-1], -total, rel_tol=1e-9, abs_tol=1e-12 * C):
                raise ConvergenceError(
                    f"The active-set solver of {_OWNER} could not keep the equality "
                    f"constraint (auxiliary coefficient {solved[-1]!r}, expected {-total!r}); "
                    "raise max_working_set."
                )
            solved = solved[:-1]
        change = solved - alpha_work
        moved = np.flatnonzero(change)
        if moved.size:
            columns.add_product(kernel_alpha, work[moved], change[moved])
        alpha[work] = solved

        residual = y - kernel_alpha
        up = np.where(alpha < 0.0, residual + epsilon, residual - epsilon)
        up[alpha >= box] = -np.inf
        low = np.where(alpha > 0.0, residual - epsilon, residual + epsilon)
        low[alpha <= -box] = np.inf
        highest_up = float(up[work].max())
        lowest_low = float(low[work].min())
        violation = np.maximum(up - lowest_low, highest_up - low)
        violation[inside] = -np.inf
        candidates = np.flatnonzero(violation > tol)
        if candidates.size == 0:
            converged = True
            break
        support = work[solved != 0.0]
        if candidates.size > _MAX_ADDED:
            worst = np.argpartition(-violation[candidates], _MAX_ADDED)[:_MAX_ADDED]
            candidates = candidates[worst]
        if support.size + candidates.size <= limit:
            # Sparse case (the usual one): the support vectors and the worst violators fit.
            work = np.sort(np.concatenate([support, candidates]))
        else:
            work = _most_violating(up, low, limit)
    if not converged:
        warnings.warn(
            f"The active-set solver of {_OWNER} stopped after {max_rounds} rounds with rows "
            "still violating the optimality conditions; the fit may be inaccurate. Raise "
            "max_working_set or tol.",
            ConvergenceWarning,
            stacklevel=3,
        )

    residual = y - kernel_alpha
    support = np.flatnonzero(alpha)
    free = support[np.abs(alpha[support]) < box[support]]
    if free.size:
        intercept = float(np.mean(residual[free] - epsilon * np.sign(alpha[free])))
    else:  # LIBSVM's rule: the middle of the interval of feasible offsets
        up = np.where(alpha < 0.0, residual + epsilon, residual - epsilon)
        up[alpha >= box] = -np.inf
        low = np.where(alpha > 0.0, residual - epsilon, residual + epsilon)
        low[alpha <= -box] = np.inf
        intercept = 0.5 * (float(up.max()) + float(low.min()))
    return _Solution(support=support, alpha=alpha[support], intercept=intercept, n_iter=n_iter)


class GeneralizedGaussianSVR(RegressorMixin, BaseEstimator):
    """ε-SVR with the generalized-Gaussian kernel K = c·exp(−(g(γ)‖x − z‖/σ)^γ).

    The model is f(x) = Σᵢ βᵢ K(sᵢ, x) + b over the support vectors sᵢ, the
    solution of LIBSVM's ε-insensitive dual (paper A §4): with LIBSVM's RBF
    kernel at γ = 2, and by an active-set decomposition over Gram blocks of at
    most ``max_working_set`` rows otherwise (see the module docstring); neither
    forms the n × n Gram matrix. When ``sigma`` or ``shape`` is None it is
    estimated from the training inputs by the fourth-moment method of
    :func:`~softbend.identification.kernels.estimate_kernel_shape` applied to
    what ``moments_of`` names (σ: pooled per-feature standard deviation; γ
    clipped to (0.05, 2] with a ``ShapeClippedWarning``).

    Parameters
    ----------
    C : float, default 100.0
        Penalty on errors beyond the ε tube, > 0 (paper A calls it γ and uses 100).
        With ``normalize=True`` the kernel carries the factor c, which is
        equivalent to an RBF-type SVR with penalty c·C.
    epsilon : float, default 0.1
        Half-width of the insensitive tube, ≥ 0, in the units of the target
        (paper A: 0.1 on the scaled target).
    sigma : float or None, default None
        Kernel width σ > 0 in the units of the inputs; estimated when None.
    shape : float or None, default None
        Kernel shape γ in (0, 2] (2 Gaussian, 1 Laplacian); estimated when None.
        Values above 2 are rejected: the kernel would not be positive definite.
    moments_of : {"differences", "regressors", "components"}, default "differences"
        What the fourth-moment estimate of the shape measures: the kernel's
        argument x − z over all pairs of training rows (default), the centred
        rows, or the pooled standardized components (the earlier behaviour).
        Only used when ``shape`` or ``sigma`` is None.
    normalize : bool, default True
        Multiply the kernel by the density normalization c = g(γ)γ/(2σΓ(1/γ)).
    tol : float, default 1e-3
        Stopping tolerance of the solver (LIBSVM's, on the dual's optimality
        conditions), > 0.
    cache_size : float, default 200.0
        Kernel cache of LIBSVM, MB, > 0.
    max_iter : int, default -1
        Iteration limit of each LIBSVM solve, -1 for none.
    max_working_set : int, default 4096
        Most rows whose Gram block the γ ≠ 2 solver holds at once, ≥ 8; its memory
        is about 8·max_working_set² bytes (128 MiB at 4096). Not used at γ = 2.

    Attributes
    ----------
    sigma_ : float
        Kernel width used, input units.
    shape_ : float
        Kernel shape used.
    shape_estimate_ : ShapeEstimate or None
        The moment estimate (measured ratio, its Gaussian value, ``reason``) when
        σ or γ was estimated, else None.
    kernel_scale_ : float
        Constant factor c of the kernel (1 when ``normalize=False``).
    support_vectors_ : ndarray of shape (n_sv, n_features)
        Support vectors, in the lexicographic order of the merged training rows.
    dual_coef_ : ndarray of shape (n_sv,)
        Coefficients βᵢ of the kernel expansion, target units.
    intercept_ : float
        Offset b, target units.
    n_support_ : int
        Number of support vectors.
    n_iter_ : int
        Solver iterations (summed over the rounds of the γ ≠ 2 solver).
    n_features_in_ : int
        Number of input features.
    feature_names_in_ : ndarray of str
        Feature names, when X was a DataFrame with string column names.

    Notes
    -----
    Before solving, zero-weight rows are dropped and identical (x, y) pairs are
    merged into one row carrying the summed sample weight (the SVR primal is
    unchanged by this); rows are sorted, so the fit does not depend on the order
    of the samples and an integer weight k is the same as k copies.
    """

    def __init__(
        self,
        *,
        C: float = 100.0,
        epsilon: float = 0.1,
        sigma: float | None = None,
        shape: float | None = None,
        moments_of: str = "differences",
        normalize: bool = True,
        tol: float = 1e-3,
        cache_size: float = 200.0,
        max_iter: int = -1,
        max_working_set: int = DEFAULT_MAX_WORKING_SET,
    ) -> None:
        self.C = C
        self.epsilon = epsilon
        self.sigma = sigma
        self.shape = shape
        self.moments_of = moments_of
        self.normalize = normalize
        self.tol = tol
        self.cache_size = cache_size
        self.max_iter = max_iter
        self.max_working_set = max_working_set

    def fit(
        self, X: np.ndarray, y: np.ndarray, sample_weight: np.ndarray | None = None
    ) -> GeneralizedGaussianSVR:
        """Estimate the kernel (if needed) and solve the SVR dual.

        Parameters
        ----------
        X : array_like of shape (n_samples, n_features)
            Training inputs (regressor vectors), finite.
        y : array_like of shape (n_samples,)
            Targets, finite.
        sample_weight : array_like of shape (n_samples,), optional
            Non-negative per-sample weights; they multiply C sample by sample.

        Returns
        -------
        GeneralizedGaussianSVR
            The fitted estimator.

        Raises
        ------
        ValueError
            Bad hyperparameter (naming it), non-finite data, or too few distinct
            samples to estimate σ/γ.
        ConvergenceError
            If the solver returns non-finite coefficients.
        """
        C = check_range(self.C, "C", low=0.0)
        epsilon = check_range(self.epsilon, "epsilon", low=0.0, low_inclusive=True)
        tol = check_range(self.tol, "tol", low=0.0)
        cache_size = check_range(self.cache_size, "cache_size", low=0.0)
        max_iter = _check_max_iter(self.max_iter)
        max_working_set = check_int(self.max_working_set, "max_working_set", low=8)
        normalize = bool(check_choice(self.normalize, "normalize", (True, False)))
        moments_of = check_choice(self.moments_of, "moments_of", MOMENTS_OF)
        sigma = None if self.sigma is None else check_range(self.sigma, "sigma", low=0.0)
        shape = (
            None
            if self.shape is None
            else check_range(self.shape, "shape", low=0.0, high=2.0, high_inclusive=True)
        )

        X, y = validate_data(self, X, y, dtype=np.float64, y_numeric=True)
        weight = _check_sample_weight(sample_weight, X, dtype=np.float64, ensure_non_negative=True)
        X_fit, y_fit, w_fit = _merge_duplicates(X, y, weight)

        estimate: ShapeEstimate | None = None
        if sigma is None or shape is None:
            n_distinct = X_fit.shape[0]
            if n_distinct < 4:
                raise InputError(
                    "must contain at least 4 distinct samples to estimate sigma/shape (or "
                    f"pass both); got n_samples = {n_distinct}",
                    key="X",
                )
            try:
                estimate = _kernel_shape_estimate(X_fit, w_fit, moments_of)
            except InputError as err:
                raise InputError(
                    f"{err.detail}: pass sigma and shape explicitly", key=err.key
                ) from None
            if sigma is None:
                sigma = estimate.sigma
            if shape is None:
                shape = estimate.shape
                if estimate.clipped:
                    _warn_clipped(estimate, stacklevel=3)
            logger.debug("%s: kernel sigma=%.6g shape=%.6g", _OWNER, sigma, shape)

        # The normalization c multiplies the kernel; the dual with Gram c·K and box C
        # is the dual with Gram K and box c·C, its coefficients scaled by c.
        scale = gg_normalization(sigma, shape) if normalize else 1.0
        if shape == 2.0:
            solution = _solve_rbf(
                X_fit,
                y_fit,
                w_fit,
                C=C * scale,
                epsilon=epsilon,
                gamma=gg_scale(2.0) ** 2 / sigma**2,
                tol=tol,
                cache_size=cache_size,
                max_iter=max_iter,
            )
        else:
            solution = _solve_active_set(
                X_fit,
                y_fit,
                w_fit,
                C=C * scale,
                epsilon=epsilon,
                sigma=sigma,
                shape=shape,
                tol=tol,
                cache_size=cache_size,
                max_iter=max_iter,
                max_working_set=max_working_set,
            )

        dual_coef = solution.alpha / scale
        intercept = solution.intercept
        if not (np.all(np.isfinite(dual_coef)) and math.isfinite(intercept)):
            raise ConvergenceError(
                f"The SVR solver of {_OWNER} returned non-finite coefficients; "
                "check the scaling of X and y, sigma and C."
            )

        self.sigma_ = float(sigma)
        self.shape_ = float(shape)
        self.shape_estimate_ = estimate
        self.kernel_scale_ = float(scale)
        self.support_vectors_ = np.ascontiguousarray(X_fit[solution.support])
        self.dual_coef_ = dual_coef
        self.intercept_ = intercept
        self.n_support_ = int(dual_coef.size)
        self.n_iter_ = solution.n_iter
        self._precompute()
        return self

    def _precompute(self) -> None:
        """Derive what prediction needs from the public fitted attributes.

        K = c·exp(−(rate·d²)^(γ/2)), with c folded into the coefficients. Called by
        ``fit`` and by :func:`softbend.identification.persistence.load_narx`.
        """
        self._rate = gg_scale(self.shape_) ** 2 / self.sigma_**2
        self._half_shape = 0.5 * self.shape_
        self._coef = self.dual_coef_ * self.kernel_scale_
        self._x_shape = (self.n_features_in_,)
        # predictor()'s RBF path (γ = 2) about the support vectors' centre m:
        # −rate·|s − x|² = 2·rate·(s − m)·x − 2·rate·(s − m)·m − rate·|s − m|² − rate·|x − m|²,
        # so one kernel row is a matrix-vector product, an add and an exp, the
        # |s − m|² factor folded into the coefficients and the |x − m|² one a scalar.
        # Used where every exponent stays small (error ~ exponent × 1e-16).
        support = self.support_vectors_
        # No support vector (every sample inside the ε-tube): the model is its intercept,
        # and any centre will do (the mean of none is NaN).
        center = support.mean(axis=0) if len(support) else np.zeros(support.shape[1])
        centred = support - center
        spread = self._rate * np.einsum("ij,ij->i", centred, centred)
        self._center = center.tolist()
        self._fast = self._half_shape == 1.0 and bool(np.all(spread <= _FAST_EXPONENT))
        if self._fast:
            self._fast_matrix = np.ascontiguousarray(2.0 * self._rate * centred)
            self._fast_bias = -(self._fast_matrix @ center)
            self._fast_coef = self._coef * np.exp(-spread)

    def _expansion(self, X: np.ndarray) -> np.ndarray:
        """Σ βᵢ c K(sᵢ, x) + b for every row of X, in row blocks of bounded memory."""
        out = np.empty(X.shape[0])
        step = _block_rows(self.support_vectors_.shape[0])
        for start in range(0, X.shape[0], step):
            sqdist = cdist(X[start : start + step], self.support_vectors_, "sqeuclidean")
            kernel = _kernel_from_sqdist(sqdist, sigma=self.sigma_, shape=self.shape_, scale=1.0)
            out[start : start + step] = kernel @ self._coef
        out += self.intercept_
        return out

    def _evaluator(self) -> Callable[[np.ndarray], np.ndarray]:
        """:meth:`_expansion` with the fitted arrays and constants bound once (a free run's
        step): the same arithmetic, without looking the kernel's scale up at every call."""
        support, coef, intercept = self.support_vectors_, self._coef, self.intercept_
        rate, exponent = self._rate, self._half_shape
        step = _block_rows(support.shape[0])

        def evaluate(X: np.ndarray) -> np.ndarray:
            if X.shape[0] > step:
                return self._expansion(X)
            arg = cdist(X, support, "sqeuclidean")
            arg *= rate
            _power_in_place(arg, exponent)
            np.negative(arg, out=arg)
            np.exp(arg, out=arg)
            out = arg @ coef
            out += intercept
            return out

        return evaluate

    def predict(self, X: np.ndarray) -> np.ndarray:
        """Predict targets by the kernel expansion f(x) = Σ βᵢ K(sᵢ, x) + b.

        Parameters
        ----------
        X : array_like of shape (n_samples, n_features)
            Inputs, finite, in the units used for training.

        Returns
        -------
        ndarray of shape (n_samples,)
            Predicted targets.
        """
        check_is_fitted(self)
        X = validate_data(self, X, reset=False, dtype=np.float64)
        return self._expansion(X)

    def predictor(self) -> Callable[[ArrayLike], float]:
        """A fast one-sample evaluator, for control loops and free-run NARX simulation.

        The fast path of every softbend regressor has this name (the surrogates'
        ``predictor()`` too): one regressor vector at a time, without DataFrame
        handling or scikit-learn validation, only a shape and a finiteness check.
        The callable holds the fitted arrays of this call: refitting the
        estimator later does not change it.

        Returns
        -------
        callable
            ``f(x) -> float`` for ``x`` array-like of shape (n_features,) (float64
            avoids a conversion), in the training units; equals
            ``predict(x[None, :])[0]`` up to rounding. It raises ``ValueError`` for
            a wrong shape or a non-finite ``x``.

        Raises
        ------
        NotFittedError
            If the estimator is not fitted.
        """
        try:
            support_vectors = self.support_vectors_
        except AttributeError:
            raise NotFittedError(
                f"This {_OWNER} instance is not fitted yet. Call 'fit' before 'predictor'."
            ) from None
        x_shape, rate, center = self._x_shape, self._rate, self._center
        half_shape, coef, intercept = self._half_shape, self._coef, self.intercept_
        fast = self._fast
        if fast:
            fast_matrix, fast_bias, fast_coef = self._fast_matrix, self._fast_bias, self._fast_coef

        def predict_one(x: ArrayLike) -> float:
            x = np.asarray(x, dtype=np.float64)
            if x.shape != x_shape:
                raise InputError(f"must have shape {x_shape}; got shape {x.shape}", key="x")
            # |x − m|: NaN or inf for a non-finite x (math.dist is one C call).
            far = rate * math.dist(x.tolist(), center) ** 2
            if not math.isfinite(far):
                raise InputError(must_be("finite", x.tolist()), key="x")
            if fast and far <= _FAST_EXPONENT:
                row = fast_matrix @ x
                row += fast_bias
                np.exp(row, out=row)
                return float(row @ fast_coef) * math.exp(-far) + intercept
            diff = support_vectors - x
            arg = np.einsum("ij,ij->i", diff, diff)
            arg *= rate
            if half_shape == 0.5:
                np.sqrt(arg, out=arg)
            elif half_shape != 1.0:
                np.power(arg, half_shape, out=arg)
            np.negative(arg, out=arg)
            np.exp(arg, out=arg)
            return float(arg @ coef) + intercept

        return predict_one
