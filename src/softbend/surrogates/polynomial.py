"""Polynomial regression surrogate (paper B §4.1): θ as a polynomial in (l, r, t, b, φ, lc, P).

The inputs are standardized, z = (x − mean)/scale, and the model is a full
polynomial of total degree ≤ ``degree`` in z, fitted by (ridge-regularized)
least squares. The paper's grid search takes orders 2 to 10 on the 7 inputs of
:data:`softbend.surrogates.features.FEATURES`.

The fit never builds the full n × T design matrix: it streams the rows in chunks
and accumulates the normal equations G = ΦᵀΦ and ΦᵀY, then solves the T × T
system by Cholesky, with an eigen-decomposition (pseudo-inverse) when G is
numerically singular, as on a grid design with three levels per parameter, where
z³ and z are collinear. The T × T matrix dominates the memory (8·T² bytes, with
T = C(d + degree, degree)), so the estimator refuses degrees whose system would
not fit in ``max_memory_mb`` before allocating anything.
"""

from __future__ import annotations

import itertools
import logging
import math
from collections.abc import Callable

import numpy as np
from numpy.typing import ArrayLike
from scipy.linalg import LinAlgError, eigh
from scipy.linalg.blas import dsyrk
from scipy.linalg.lapack import dpocon, dpotrf, dpotrs
from sklearn.base import BaseEstimator, RegressorMixin
from sklearn.utils.validation import check_is_fitted, validate_data
from threadpoolctl import threadpool_limits

from softbend._progress import every, report
from softbend._validation import check_int, check_range
from softbend.errors import ConvergenceError, InputError
from softbend.surrogates.polynomial_core import Plan as _Plan
from softbend.surrogates.polynomial_core import design_t as _design_t
from softbend.surrogates.polynomial_core import plan as _plan
from softbend.surrogates.polynomial_core import polynomial_predict

logger = logging.getLogger(__name__)

__all__ = ["PolynomialRegressor", "monomial_powers", "n_terms", "system_memory_mb"]

_OWNER = "PolynomialRegressor"

#: Rows × terms² of a fit that reports its progress (:mod:`softbend._progress`): a fit
#: of about a second or more on one core.
_REPORT_WORK = 5 * 10**10

# _one_thread: the sums of the normal equations are thousands of small BLAS calls (one
# chunk of rows each). With BLAS's own threads, each call waits for every thread: on a
# busy machine, for a core another process holds, which made a degree-2 fit of 800 000
# rows 60 times slower than on one thread (docs/design-log.md). One thread also makes the
# sums the same on every machine, whatever its number of cores.
_BYTES_PER_MB = 1e6
_BLOCK = 512


def n_terms(n_features: int, degree: int) -> int:
    """Number of monomials of total degree ≤ ``degree`` in ``n_features`` variables.

    Parameters
    ----------
    n_features : int
        Number of input variables d, ≥ 1.
    degree : int
        Maximum total degree, ≥ 0.

    Returns
    -------
    int
        T = C(d + degree, degree), the constant term included (7 inputs:
        degree 4 → 330, degree 9 → 11440, degree 10 → 19448).
    """
    n_features = check_int(n_features, "n_features", low=1)
    degree = check_int(degree, "degree", low=0)
    return math.comb(n_features + degree, degree)


def system_memory_mb(n_features: int, degree: int, chunk_rows: int) -> float:
    """Memory the streamed fit allocates, in MB (10⁶ bytes).

    The T × T normal matrix (8·T² bytes) plus one chunk of the transposed
    design matrix (8·T·chunk_rows bytes). The eigen-decomposition used for a
    singular system needs another 8·T² bytes on top of this.

    Parameters
    ----------
    n_features : int
        Number of input variables, ≥ 1.
    degree : int
        Maximum total degree, ≥ 0.
    chunk_rows : int
        Rows per chunk, ≥ 1.

    Returns
    -------
    float
        Megabytes.
    """
    terms = n_terms(n_features, degree)
    return 8.0 * terms * (terms + chunk_rows) / _BYTES_PER_MB


def monomial_powers(n_features: int, degree: int) -> np.ndarray:
    """Exponents of all monomials of total degree ≤ ``degree``, graded lexicographic.

    Row 0 is the constant term (all zeros); then the rows of degree 1, 2, ...;
    within one degree the exponent vectors are in decreasing lexicographic order
    (z₀² before z₀z₁ before z₁²), the column order of
    :class:`sklearn.preprocessing.PolynomialFeatures`.

    Parameters
    ----------
    n_features : int
        Number of variables d, ≥ 1.
    degree : int
        Maximum total degree, ≥ 0.

    Returns
    -------
    ndarray of int64, shape (T, d)
        Exponents, T = :func:`n_terms` (n_features, degree).
    """
    terms = n_terms(n_features, degree)
    powers = np.zeros((terms, n_features), dtype=np.int64)
    row = 1
    for total in range(1, degree + 1):
        for combo in itertools.combinations_with_replacement(range(n_features), total):
            np.add.at(powers[row], list(combo), 1)
            row += 1
    return powers


def _check_finite(values: np.ndarray, name: str) -> None:
    bad = ~np.isfinite(values)
    if bad.any():
        where = np.argwhere(bad)[0]
        position = (
            f"column {where[1]} of row {where[0]}" if values.ndim == 2 else f"position {where[0]}"
        )
        raise InputError(
            f"must be finite (no NaN or inf); got {values[tuple(where)]} in {position} "
            f"({int(bad.sum())} non-finite values)",
            key=name,
        )


def _symmetrize_from_lower(G: np.ndarray) -> None:
    """Copy the lower triangle of the square matrix ``G`` into its upper triangle, in place."""
    size = G.shape[0]
    for start in range(0, size, _BLOCK):
        stop = min(start + _BLOCK, size)
        block = G[start:stop, start:stop]
        block[...] = np.tril(block) + np.tril(block, -1).T
        G[start:stop, stop:] = G[stop:, start:stop].T


class PolynomialRegressor(RegressorMixin, BaseEstimator):
    """Full polynomial of total degree ≤ ``degree`` in the standardized inputs.

    ::

        y = y_mean_ + y_scale_ · Σₖ coef_[k] · Πⱼ zⱼ^powers_[k, j],
        z = (x − x_mean_)/x_scale_,

    fitted by ridge least squares on the standardized target:
    (ΦᵀΦ + α·n·I′) c = Φᵀ y_std, where I′ is the identity without the constant
    term (the intercept is not penalized) and n the number of samples.

    Parameters
    ----------
    degree : int, default 2
        Maximum total degree of the monomials, ≥ 1 (paper B: 2 to 10).
    alpha : float, default 1e-8
        Ridge penalty per sample, ≥ 0, in standardized units (inputs and target
        scaled to unit variance). The default only stabilizes the solve.
    chunk_rows : int, default 8192
        Rows of the design matrix built at a time in ``fit`` and ``predict``, ≥ 1.
        The result does not depend on it (up to rounding).
    max_memory_mb : float, default 2048.0
        Upper bound on the memory of the fit in MB (10⁶ bytes), > 0: the T × T
        normal matrix plus one chunk, see :func:`system_memory_mb`. With 7 inputs
        and the default chunk, degree 9 (11440 terms, 1.05 GB matrix) fits and
        degree 10 (19448 terms, 3.03 GB) does not.

    Attributes
    ----------
    x_mean_ : ndarray of shape (n_features,)
        Input means, input units.
    x_scale_ : ndarray of shape (n_features,)
        Input standard deviations, input units (1 for constant columns).
    y_mean_ : float
        Target mean, target units (degrees for the bending angle).
    y_scale_ : float
        Target standard deviation, target units (1 for a constant target).
    powers_ : ndarray of int64, shape (n_terms, n_features)
        Exponents of each monomial; row 0 is the constant term, rows in graded
        lexicographic order (see :func:`monomial_powers`).
    coef_ : ndarray of shape (n_terms,)
        Coefficients in standardized units.
    n_features_in_ : int
        Number of input features.
    feature_names_in_ : ndarray of str
        Feature names, when X was a DataFrame with string column names.
    solver_ : str
        ``"cholesky"``, or ``"eigh"`` when the normal matrix was numerically
        singular and the minimum-norm (pseudo-inverse) solution was taken.
    rank_ : int
        Numerical rank of the normal matrix (n_terms for ``"cholesky"``).

    Notes
    -----
    Every monomial is built as a lower monomial times one feature, so the T
    terms of a row cost T multiplications. Before solving, the normal matrix is
    scaled to a unit diagonal (Jacobi), which leaves the solution unchanged and
    improves the conditioning of high degrees. The Cholesky solution is kept when
    the estimated reciprocal condition number exceeds T·ε; otherwise the
    eigenvalues below T·ε·λ_max are dropped (pseudo-inverse). On a grid design
    with three levels per parameter, powers ≥ 3 of one parameter are collinear
    with lower ones, and this gives the minimum-norm polynomial through the
    least-squares fit.

    Examples
    --------
    >>> import numpy as np
    >>> X = np.random.default_rng(0).normal(size=(200, 3))
    >>> y = 1.0 + X[:, 0] * X[:, 1] - 2.0 * X[:, 2] ** 2
    >>> model = PolynomialRegressor(degree=2, alpha=0.0).fit(X, y)
    >>> bool(np.allclose(model.predict(X), y))
    True
    """

    def __init__(
        self,
        *,
        degree: int = 2,
        alpha: float = 1e-8,
        chunk_rows: int = 8192,
        max_memory_mb: float = 2048.0,
    ) -> None:
        self.degree = degree
        self.alpha = alpha
        self.chunk_rows = chunk_rows
        self.max_memory_mb = max_memory_mb

    # --- fit ----------------------------------------------------------------------------

    def _check_memory(self, n_features: int, degree: int, chunk_rows: int, limit: float) -> None:
        needed = system_memory_mb(n_features, degree, chunk_rows)
        if needed <= limit:
            return
        fits = [k for k in range(1, degree) if system_memory_mb(n_features, k, chunk_rows) <= limit]
        largest = f"the largest degree that fits is {fits[-1]}" if fits else "no degree fits"
        terms = n_terms(n_features, degree)
        raise InputError(
            f"must fit in max_memory_mb={limit:g} with {n_features} features and "
            f"chunk_rows={chunk_rows} ({largest}); got {degree!r}: {terms} terms need "
            f"{8.0 * terms**2 / _BYTES_PER_MB:.0f} MB for the {terms} x {terms} normal matrix "
            f"plus {8.0 * terms * chunk_rows / _BYTES_PER_MB:.0f} MB per chunk = {needed:.0f} MB",
            key="degree",
        )

    def fit(self, X: ArrayLike, y: ArrayLike) -> PolynomialRegressor:
        """Standardize, stream the normal equations over row chunks and solve them.

        Parameters
        ----------
        X : array_like of shape (n_samples, n_features)
            Training inputs, finite (for the SFRBA surrogate the columns of
            :data:`~softbend.surrogates.features.FEATURES`, in their units).
        y : array_like of shape (n_samples,)
            Targets, finite (bending angle, degrees).

        Returns
        -------
        PolynomialRegressor
            The fitted estimator.

        Raises
        ------
        ValueError
            A bad hyperparameter, non-finite data, or a degree whose normal
            matrix exceeds ``max_memory_mb`` (checked before allocating).
        ConvergenceError
            If the solve produces non-finite coefficients.
        """
        degree = check_int(self.degree, "degree", low=1)
        alpha = check_range(self.alpha, "alpha", low=0.0, low_inclusive=True)
        chunk_rows = check_int(self.chunk_rows, "chunk_rows", low=1)
        limit = check_range(self.max_memory_mb, "max_memory_mb", low=0.0)

        y_values = np.asarray(y)
        if y_values.dtype.kind == "f" and y_values.ndim in (1, 2):
            _check_finite(y_values, "y")  # anything else: validate_data's message
        X_arr, y_arr = validate_data(
            self, X, y, dtype=np.float64, y_numeric=True, ensure_all_finite=False
        )
        _check_finite(X_arr, "X")
        n_samples, n_features = X_arr.shape
        chunk_rows = min(chunk_rows, n_samples)
        self._check_memory(n_features, degree, chunk_rows, limit)

        x_mean = X_arr.mean(axis=0)
        x_scale = X_arr.std(axis=0)
        y_mean = float(y_arr.mean())
        y_scale = float(y_arr.std())
        x_scale = np.where(x_scale > 1e-12 * np.maximum(1.0, np.abs(x_mean)), x_scale, 1.0)
        if not y_scale > 1e-12 * max(1.0, abs(y_mean)):
            y_scale = 1.0

        powers = monomial_powers(n_features, degree)
        plan = _plan(powers)
        terms = powers.shape[0]

        G = np.zeros((terms, terms), order="F")
        rhs = np.zeros(terms)
        buffer = np.empty(terms * chunk_rows)
        # A phase of its own only where the sums take seconds (about 10^10 multiply-adds).
        phase = (
            f"fitting a degree-{degree} polynomial ({terms} terms) to {n_samples} rows"
            if n_samples * terms * terms >= _REPORT_WORK
            else None
        )
        stride = every(n_samples // chunk_rows + 1, 20)
        with threadpool_limits(1, user_api="blas"):  # see _one_thread
            for k, start in enumerate(range(0, n_samples, chunk_rows)):
                if phase is not None and k % stride == 0:
                    report(phase, start, n_samples)
                stop = min(start + chunk_rows, n_samples)
                Zt = np.ascontiguousarray(((X_arr[start:stop] - x_mean) / x_scale).T)
                rows = buffer[: terms * (stop - start)].reshape(terms, stop - start)
                Phi_t = _design_t(plan, Zt, 0, rows)
                target = (y_arr[start:stop] - y_mean) / y_scale
                # Lower triangle of G += Φᵀ Φ (Phi_t.T is Fortran-ordered: no copy).
                G = dsyrk(1.0, Phi_t.T, beta=1.0, c=G, trans=1, lower=1, overwrite_c=1)
                rhs += Phi_t @ target
            del buffer
            coef, solver, rank = _solve(G, rhs, alpha * n_samples)
        if phase is not None:
            report(phase, n_samples, n_samples)
        if not np.all(np.isfinite(coef)):
            raise ConvergenceError(
                f"The normal equations of {_OWNER} gave non-finite coefficients "
                f"(degree={degree}, alpha={alpha:g}); increase alpha or lower the degree."
            )
        logger.debug(
            "%s: degree %d, %d terms, %s solve, rank %d", _OWNER, degree, terms, solver, rank
        )

        self.x_mean_ = x_mean
        self.x_scale_ = x_scale
        self.y_mean_ = y_mean
        self.y_scale_ = y_scale
        self.powers_ = powers
        self.coef_ = coef
        self.solver_ = solver
        self.rank_ = rank
        self._plan = plan
        return self

    # --- predict ------------------------------------------------------------------------

    def _current_plan(self) -> _Plan:
        plan = getattr(self, "_plan", None)
        if plan is not None and plan.powers is self.powers_:
            return plan
        return _plan(self.powers_)  # set from outside (e.g. a loaded model): not cached

    def predict(self, X: ArrayLike) -> np.ndarray:
        """Evaluate the polynomial, chunk by chunk.

        Parameters
        ----------
        X : array_like of shape (n_samples, n_features)
            Inputs, finite, in the units used for training.

        Returns
        -------
        ndarray of float64, shape (n_samples,)
            Predictions in target units (degrees for the bending angle).
        """
        check_is_fitted(self)
        X_arr = validate_data(self, X, reset=False, dtype=np.float64, ensure_all_finite=False)
        _check_finite(X_arr, "X")
        with threadpool_limits(1, user_api="blas"):  # see _one_thread
            return polynomial_predict(
                X_arr,
                self._current_plan(),
                np.asarray(self.coef_, dtype=np.float64),
                self.x_mean_,
                self.x_scale_,
                self.y_mean_,
                self.y_scale_,
                self.chunk_rows,
            )

    def predictor(self) -> Callable[[ArrayLike], float]:
        """A fast one-sample evaluator for control loops (plain NumPy, no validation).

        The callable standardizes one sample, builds the power table
        p[j, k] = z_j^k, gathers p[j, powers_[i, j]] for all terms with one flat
        ``take``, multiplies over the features and contracts with the
        coefficients. It works on copies of the fitted attributes: refitting the
        estimator later does not change it. It only checks the length of the
        sample; NaN in gives NaN out.

        Returns
        -------
        callable
            ``f(x) -> float`` for ``x`` array-like of shape (n_features,), in the
            training units; equals ``predict([x])[0]`` up to rounding.
        """
        check_is_fitted(self)
        powers = np.asarray(self.powers_, dtype=np.int64)
        n_features = powers.shape[1]
        top = int(powers.max(initial=0))
        flat = np.ascontiguousarray(np.arange(n_features)[:, None] * (top + 1) + powers.T)
        coef = self.y_scale_ * np.asarray(self.coef_, dtype=np.float64)
        offset = float(self.y_mean_)
        mean = np.array(self.x_mean_, dtype=np.float64)
        inv_scale = 1.0 / np.asarray(self.x_scale_, dtype=np.float64)
        shape = (n_features,)
        table_shape = (n_features, top + 1)

        def predict_one(x: ArrayLike) -> float:
            z = np.asarray(x, dtype=np.float64)
            if z.shape != shape:
                raise InputError(f"must have shape {shape}; got shape {z.shape}", key="x")
            table = np.empty(table_shape)
            table[:, 0] = 1.0
            table[:, 1:] = ((z - mean) * inv_scale)[:, None]
            np.cumprod(table, axis=1, out=table)
            terms = np.multiply.reduce(table.ravel().take(flat), axis=0)
            return float(terms @ coef) + offset

        return predict_one


def _solve(G: np.ndarray, rhs: np.ndarray, ridge: float) -> tuple[np.ndarray, str, int]:
    """Solve (G + ridge·I′) c = rhs, G given by its lower triangle (overwritten).

    Jacobi-scaled Cholesky with a condition estimate; the minimum-norm
    eigen-solution when the scaled matrix is numerically singular.
    """
    terms = G.shape[0]
    _symmetrize_from_lower(G)
    diagonal = np.diagonal(G).copy()
    diagonal[1:] += ridge
    np.fill_diagonal(G, diagonal)
    scale = np.sqrt(diagonal)
    scale[~(scale > 0.0)] = 1.0
    G /= scale[:, None]
    G /= scale[None, :]
    b = rhs / scale
    scaled_diagonal = np.diagonal(G).copy()
    anorm = max(
        float(np.abs(G[:, i : i + _BLOCK]).sum(axis=0).max()) for i in range(0, terms, _BLOCK)
    )
    threshold = terms * np.finfo(np.float64).eps

    # Upper Cholesky in place: the strict lower triangle keeps the scaled matrix.
    factor, info = dpotrf(G, lower=0, clean=0, overwrite_a=1)
    if info == 0:
        rcond, info_con = dpocon(factor, anorm, uplo="U")
        if info_con == 0 and rcond > threshold:
            solution, info_solve = dpotrs(factor, b, lower=0)
            if info_solve == 0:
                return solution / scale, "cholesky", terms

    np.fill_diagonal(factor, scaled_diagonal)
    try:
        values, vectors = eigh(factor, lower=True, overwrite_a=True, check_finite=False)
    except LinAlgError as err:
        raise ConvergenceError(
            f"The eigen-decomposition of the normal matrix of {_OWNER} failed: {err}"
        ) from None
    keep = values > threshold * max(float(values[-1]), 0.0)
    projected = vectors[:, keep].T @ b
    solution = vectors[:, keep] @ (projected / values[keep])
    return solution / scale, "eigh", int(keep.sum())
