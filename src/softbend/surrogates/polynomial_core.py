"""Evaluation of a fitted polynomial surrogate with NumPy alone (no SciPy, no scikit-learn).

:class:`~softbend.surrogates.polynomial.PolynomialRegressor` fits the polynomial;
this module holds what its prediction needs, so that a saved polynomial
(:mod:`softbend.surrogates.persistence`) is checked and evaluated without
importing the estimator: :func:`plan` builds every monomial of an exponent table
as a lower monomial times one feature, :func:`design_t` evaluates them on
standardized rows and :func:`polynomial_predict` gives the angles, the same
operations in the same order as the estimator's ``predict`` (bit for bit).
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from softbend.errors import InputError

__all__ = ["Plan", "design_t", "plan", "polynomial_predict"]


@dataclass(frozen=True)
class Plan:
    """How to build every monomial as (a lower monomial) × (one feature).

    ``levels[k] = (rows, parents, features)``: the monomials of total degree
    k + 1, each the product of the monomial ``parents[i]`` and feature
    ``features[i]``. Evaluating all T terms costs T multiplications per sample.
    """

    powers: np.ndarray
    levels: tuple[tuple[np.ndarray | slice, np.ndarray, np.ndarray], ...]


def plan(powers: np.ndarray) -> Plan:
    """Evaluation plan for any exponent table closed under removing one factor."""
    powers = np.ascontiguousarray(powers, dtype=np.int64)
    incomplete = InputError(
        "must be a 2-D table of non-negative exponents with one constant row and, with "
        "every monomial, the monomial with one factor fewer; got an incomplete exponent table",
        key="powers_",
    )
    if powers.ndim != 2 or powers.min(initial=0) < 0:
        raise incomplete
    terms, d = powers.shape
    totals = powers.sum(axis=1)
    nonconstant = np.flatnonzero(totals > 0)
    # The factor removed is the last feature with a nonzero exponent.
    last = d - 1 - np.argmax(powers[nonconstant, ::-1] > 0, axis=1)
    parent_powers = powers[nonconstant].copy()
    parent_powers[np.arange(nonconstant.size), last] -= 1
    index = {row.tobytes(): k for k, row in enumerate(powers)}
    parents = np.array([index.get(row.tobytes(), -1) for row in parent_powers], dtype=np.int64)
    if np.count_nonzero(totals == 0) != 1 or len(index) != terms or np.any(parents < 0):
        raise incomplete
    parent_of = np.zeros(terms, dtype=np.int64)
    feature_of = np.zeros(terms, dtype=np.int64)
    parent_of[nonconstant] = parents
    feature_of[nonconstant] = last
    levels = []
    for total in range(1, int(totals.max(initial=0)) + 1):
        rows = np.flatnonzero(totals == total)
        parents_k, features_k = parent_of[rows], feature_of[rows]
        where: np.ndarray | slice = rows
        if rows.size and rows[-1] - rows[0] + 1 == rows.size:
            where = slice(int(rows[0]), int(rows[-1]) + 1)  # graded order: write in place
        levels.append((where, parents_k, features_k))
    return Plan(powers=powers, levels=tuple(levels))


def design_t(plan: Plan, Zt: np.ndarray, constant_row: int, out: np.ndarray) -> np.ndarray:
    """Transposed design matrix Φᵀ (T, m) of the standardized rows ``Zt`` (d, m)."""
    out[constant_row] = 1.0
    for rows, parents, features in plan.levels:
        if isinstance(rows, slice):
            np.multiply(out[parents], Zt[features], out=out[rows])
        else:
            out[rows] = out[parents] * Zt[features]
    return out


def polynomial_predict(
    rows: np.ndarray,
    plan_: Plan,
    coef: np.ndarray,
    x_mean: np.ndarray,
    x_scale: np.ndarray,
    y_mean: float,
    y_scale: float,
    chunk_rows: int,
) -> np.ndarray:
    """The polynomial's values on float rows, chunk by chunk (target units, e.g. degrees).

    Parameters
    ----------
    rows : ndarray of float64, shape (n, d)
        Finite inputs in the training units (mm, deg, MPa).
    plan_ : Plan
        :func:`plan` of the exponent table ``powers_``.
    coef : ndarray of float64, shape (T,)
        Coefficients of the monomials of the standardized inputs.
    x_mean, x_scale : ndarray of shape (d,)
        Standardization of the inputs, z = (x − mean)/scale.
    y_mean, y_scale : float
        Standardization of the target.
    chunk_rows : int
        Rows evaluated at once (>= 1).

    Returns
    -------
    ndarray of float64, shape (n,)
    """
    constant_row = int(np.flatnonzero(plan_.powers.sum(axis=1) == 0)[0])
    chunk = max(1, min(int(chunk_rows), rows.shape[0]))
    buffer = np.empty(coef.size * chunk)
    out = np.empty(rows.shape[0])
    for start in range(0, rows.shape[0], chunk):
        stop = min(start + chunk, rows.shape[0])
        Zt = np.ascontiguousarray(((rows[start:stop] - x_mean) / x_scale).T)
        terms = buffer[: coef.size * (stop - start)].reshape(coef.size, stop - start)
        out[start:stop] = coef @ design_t(plan_, Zt, constant_row, terms)
    return y_mean + y_scale * out
