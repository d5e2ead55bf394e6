"""The table base (``table``): the simulation table itself, a Gaussian process between designs.

A table of simulations holds, for each simulated design, its angle at a few
pressures. :class:`TableRegressor` keeps every such curve and answers

- **at a simulated design** (its design parameters equal to a row's of the
  table, by the matching rule below) from that design's own curve: shape-preserving
  piecewise-cubic interpolation (PCHIP, :class:`scipy.interpolate.PchipInterpolator`)
  through its pressure points, so it reproduces the simulated angles exactly and
  a curve that rises between two simulated pressures rises between them (no
  overshoot). Past the curve's last simulated pressure (or below its first) the
  angle goes on **linearly** with the interpolant's slope at that end: the value
  and slope are continuous there, a rising curve keeps rising, and a monotone
  curve stays monotone. A clamp would claim the actuator stops bending at the
  table's last pressure; a cubic extrapolation can turn back. How far beyond is
  safe is the support check of :func:`softbend.surrogates.predict.predict_angles`
  (a pressure past what the nearest designs were swept to is a warning).
  ``extrapolation="clamp"`` holds the end value instead.
- **at any other design** from a Gaussian process (scikit-learn's
  :class:`~sklearn.gaussian_process.GaussianProcessRegressor`, normalized
  target) on the standardized inputs (the design parameters and the pressure):
  the kernel is :func:`~softbend.surrogates.corrected.gp_kernel`, a constant
  times an RBF with one length scale per input (ARD) plus a white-noise term,
  its hyperparameters fitted by the marginal likelihood from ``n_restarts``
  seeded restarts. It also gives the predictive standard deviation, which grows
  with the distance to the simulated designs.

Matching is a clear rule, not a blend: a row is at a simulated design when each
of its design parameters equals that design's to 9 decimals in standardized
units (``(x − mean) / scale``). The prediction therefore switches from the GP to
the curve exactly at a simulated design; the step there is the GP's residual at
that design, of the order of its fitted noise (on the first 30 designs of
``examples/pneunet/simulations.csv``: 0.30° RMS, 2.4° at most, fitted noise
0.44°). The alternative, a GP that interpolates the
curves exactly (no noise term), follows the simulations' noise and is badly
conditioned with many points per curve; the distance rule keeps each part at
what it does best. At a simulated design the standard deviation is the GP's
fitted noise level (the table's own precision, as the GP sees it) within the
curve's pressures, and the GP's at that row beyond them.

Scale: the GP is fitted on at most ``max_gp_points`` rows (default
:data:`MAX_GP_POINTS`): every design contributes
``max(MIN_POINTS_PER_CURVE, max_gp_points // n_designs)`` points of its curve,
evenly spaced along it with both ends kept (all of them when it has fewer);
when even that exceeds the cap, a seeded draw of
``max_gp_points // MIN_POINTS_PER_CURVE`` designs contributes (a table of
1 000 designs × 11 pressures: 3 points of each of 333 designs). Every curve
still answers exactly at its own design. The cap is measured
(``docs/design-log.md``): on the 150 designs × 11 pressures of
``examples/pneunet/simulations.csv`` (grouped 5-fold CV, one thread) 300 rows
gave a held-out RMSE of 5.08° at 1 s a fit, 600 rows 2.22° at 3 s, 1 000 rows
1.67° at 10 s, 1 500 rows 35 s a fit (the GP's cost grows as the cube).

The fitted GP is stored as its log-hyperparameters and training rows and
predicts through :class:`~softbend.surrogates.gp_core.FixedGP` (NumPy), as the
GP correction of :mod:`softbend.surrogates.corrected` does.
"""

from __future__ import annotations

import warnings
from statistics import NormalDist
from typing import Any

import numpy as np
from numpy.typing import ArrayLike
from sklearn.base import BaseEstimator, RegressorMixin

from softbend._validation import check_choice, check_int, check_range
from softbend.errors import InputError
from softbend.surrogates.gp_core import FixedGP

__all__ = [
    "EXTRAPOLATIONS",
    "MAX_GP_POINTS",
    "MIN_POINTS_PER_CURVE",
    "TableRegressor",
    "gp_training_rows",
]

#: What the curve of a simulated design does past its pressures (module docstring).
EXTRAPOLATIONS: tuple[str, ...] = ("linear", "clamp")

#: Default cap on the rows the Gaussian process is fitted on.
MAX_GP_POINTS = 1000

#: Fewest points of each curve in the GP's rows (its two ends and its middle).
MIN_POINTS_PER_CURVE = 3

#: Decimals of the standardized design parameters that must agree for a row to be at a
#: simulated design.
MATCH_DECIMALS = 9

#: Rows evaluated at a time by the GP (the cross-kernel is rows × GP points).
_CHUNK = 4096


def _check_rows(X: ArrayLike, name: str, n_features: int | None = None) -> np.ndarray:
    rows = np.asarray(X, dtype=np.float64)
    wide = rows.ndim == 2 and rows.shape[1] >= 2
    if not wide or (n_features is not None and rows.shape[1] != n_features):
        want = (
            "(n, d >= 2): design parameters, then the pressure"
            if n_features is None
            else f"(n, {n_features})"
        )
        raise InputError(f"must have shape {want}; got {rows.shape}", key=name)
    bad = ~np.isfinite(rows)
    if bad.any():
        row, col = (int(i) for i in np.argwhere(bad)[0])
        raise InputError(
            f"must be finite (no NaN or inf); got {rows[row, col]} in column {col} of row {row}",
            key=name,
        )
    return rows


def gp_training_rows(offsets: np.ndarray, max_points: int, seed: int) -> np.ndarray:
    """Indices into the concatenated curves of the rows the GP is fitted on.

    Each curve ``k`` is ``offsets[k]:offsets[k + 1]`` (sorted by pressure). Every
    curve gives ``max(MIN_POINTS_PER_CURVE, max_points // n_curves)`` of its points,
    evenly spaced with both ends kept (all of them if it has fewer); when that
    still exceeds ``max_points``, a seeded draw of ``max_points // MIN_POINTS_PER_CURVE``
    curves gives them.

    Parameters
    ----------
    offsets : ndarray of int, shape (n_curves + 1,)
        Start of each curve, and the total at the end.
    max_points : int
        Cap on the rows, >= :data:`MIN_POINTS_PER_CURVE`.
    seed : int
        Seed of the draw of curves.

    Returns
    -------
    ndarray of int
        Sorted row indices.
    """
    n_curves = offsets.size - 1
    each = max(MIN_POINTS_PER_CURVE, max_points // max(1, n_curves))
    curves = np.arange(n_curves)
    if each * n_curves > max_points:
        keep = max(1, max_points // each)
        curves = np.sort(np.random.default_rng(seed).choice(n_curves, keep, replace=False))
    picked = []
    for k in curves:
        start, stop = int(offsets[k]), int(offsets[k + 1])
        size = stop - start
        if size <= each:
            picked.append(np.arange(start, stop))
        else:
            picked.append(start + np.unique(np.round(np.linspace(0, size - 1, each)).astype(int)))
    return np.concatenate(picked) if picked else np.zeros(0, dtype=np.int64)


class TableRegressor(RegressorMixin, BaseEstimator):
    """The simulation table as a surrogate: exact curves at simulated designs, a GP elsewhere.

    See the module docstring for the rule between the two. The inputs are the
    design parameters followed by the pressure (last column), in the actuator's
    units; the target is the bending angle in degrees.

    Parameters
    ----------
    extrapolation : {"linear", "clamp"}, default "linear"
        A simulated design's curve past its pressures: on with the end slope, or
        held at the end value.
    max_gp_points : int, default :data:`MAX_GP_POINTS`
        Cap on the rows the Gaussian process is fitted on (>= 3).
    n_restarts : int, default 1
        Restarts of the GP's marginal-likelihood optimizer from seeded draws (>= 0).
    seed : int, default 0
        Seed of the restarts and of the draw of curves (>= 0).

    Attributes
    ----------
    designs_ : ndarray of shape (n_designs, d - 1)
        The simulated designs' parameters, input units.
    curve_offsets_ : ndarray of int64, shape (n_designs + 1,)
        Where each design's curve starts in ``curve_pressures_``.
    curve_pressures_, curve_angles_ : ndarray of shape (n_points,)
        Each design's pressures (ascending, pressure unit) and angles (degrees);
        repeated pressures of a design are averaged.
    x_mean_, x_scale_ : ndarray of shape (d,)
        Standardization of the inputs (scale 1 for a constant column).
    kernel_theta_ : ndarray of shape (d + 2,)
        The GP kernel's log-hyperparameters (constant, d length scales, noise).
    gp_inputs_ : ndarray of shape (m, d)
        The GP's standardized training rows.
    gp_targets_ : ndarray of shape (m,)
        Their angles, degrees.
    n_features_in_ : int
        d.
    """

    def __init__(
        self,
        *,
        extrapolation: str = "linear",
        max_gp_points: int = MAX_GP_POINTS,
        n_restarts: int = 1,
        seed: int = 0,
    ) -> None:
        self.extrapolation = extrapolation
        self.max_gp_points = max_gp_points
        self.n_restarts = n_restarts
        self.seed = seed

    # --- fit ------------------------------------------------------------------------------

    def fit(self, X: ArrayLike, y: ArrayLike) -> TableRegressor:
        """Group the rows by design, keep each curve, and fit the GP across designs.

        Parameters
        ----------
        X : array_like of shape (n, d)
            Design parameters then pressure, finite.
        y : array_like of shape (n,)
            Angles, degrees, finite.

        Returns
        -------
        TableRegressor
            Itself, fitted.

        Raises
        ------
        softbend.errors.InputError
            Bad settings, or rows that are not finite or not of one shape.
        """
        from sklearn.exceptions import ConvergenceWarning
        from sklearn.gaussian_process import GaussianProcessRegressor

        from softbend.surrogates.corrected import gp_kernel

        check_choice(self.extrapolation, "extrapolation", EXTRAPOLATIONS)
        max_points = check_int(self.max_gp_points, "max_gp_points", low=MIN_POINTS_PER_CURVE)
        restarts = check_int(self.n_restarts, "n_restarts", low=0)
        seed = check_int(self.seed, "seed", low=0)
        rows = _check_rows(X, "X")
        target = np.asarray(y, dtype=np.float64)
        if target.shape != (rows.shape[0],) or not np.isfinite(target).all():
            raise InputError(
                f"must be {rows.shape[0]} finite angles (one per row of X); got shape "
                f"{target.shape}",
                key="y",
            )
        designs, inverse = np.unique(rows[:, :-1], axis=0, return_inverse=True)
        inverse = inverse.ravel()
        offsets = [0]
        pressures: list[np.ndarray] = []
        angles: list[np.ndarray] = []
        for k in range(designs.shape[0]):
            mine = inverse == k
            p, where = np.unique(rows[mine, -1], return_inverse=True)
            a = np.bincount(where.ravel(), weights=target[mine]) / np.bincount(where.ravel())
            pressures.append(p)
            angles.append(a)
            offsets.append(offsets[-1] + p.size)
        self.designs_ = designs
        self.curve_offsets_ = np.asarray(offsets, dtype=np.int64)
        self.curve_pressures_ = np.concatenate(pressures)
        self.curve_angles_ = np.concatenate(angles)
        mean = rows.mean(axis=0)
        scale = rows.std(axis=0)
        scale[scale < 1e-12 * np.maximum(1.0, np.abs(mean))] = 1.0
        self.x_mean_, self.x_scale_ = mean, scale
        picked = gp_training_rows(self.curve_offsets_, max_points, seed)
        curve_of = np.repeat(np.arange(designs.shape[0]), np.diff(self.curve_offsets_))
        gp_rows = np.column_stack([designs[curve_of[picked]], self.curve_pressures_[picked]])
        inputs = (gp_rows - mean) / scale
        targets = self.curve_angles_[picked]
        gp = GaussianProcessRegressor(
            kernel=gp_kernel(rows.shape[1]),
            normalize_y=True,
            n_restarts_optimizer=restarts,
            random_state=seed,
        )
        with warnings.catch_warnings():
            # a noise level at its lower bound (1e-5 of the angles' variance) is what a
            # simulation table nearly free of noise gives: no cause for a warning
            warnings.simplefilter("ignore", ConvergenceWarning)
            gp.fit(inputs, targets)
        self.kernel_theta_ = np.asarray(gp.kernel_.theta, dtype=np.float64)
        self.gp_inputs_ = inputs
        self.gp_targets_ = targets
        self.n_features_in_ = int(rows.shape[1])
        self._forget()
        return self

    # --- predict --------------------------------------------------------------------------

    def _forget(self) -> None:
        self._gp: FixedGP | None = None
        self._lookup: dict[tuple[float, ...], int] | None = None
        self._curves: dict[int, Any] = {}

    def _fitted_gp(self) -> FixedGP:
        if getattr(self, "_gp", None) is None:
            self._forget()
            self._gp = FixedGP(self.kernel_theta_, self.gp_inputs_, self.gp_targets_)
        assert self._gp is not None
        return self._gp

    def _key(self, designs: np.ndarray) -> np.ndarray:
        scaled = (designs - self.x_mean_[:-1]) / self.x_scale_[:-1]
        return np.round(scaled, MATCH_DECIMALS) + 0.0  # (-0.0 and 0.0 one key)

    def matched(self, X: ArrayLike) -> np.ndarray:
        """The simulated design each row is at (its index in ``designs_``), or -1 for none.

        Parameters
        ----------
        X : array_like of shape (n, d)
            Rows of the inputs.

        Returns
        -------
        ndarray of int64, shape (n,)
        """
        rows = _check_rows(X, "X", int(self.n_features_in_))
        self._fitted_gp()
        if self._lookup is None:
            self._lookup = {tuple(k): i for i, k in enumerate(self._key(self.designs_).tolist())}
        keys = self._key(rows[:, :-1]).tolist()
        return np.array([self._lookup.get(tuple(k), -1) for k in keys], dtype=np.int64)

    def _curve(self, k: int) -> Any:
        """The PCHIP interpolant of design ``k`` and its end slopes (None for one point)."""
        if k not in self._curves:
            from scipy.interpolate import PchipInterpolator

            start, stop = int(self.curve_offsets_[k]), int(self.curve_offsets_[k + 1])
            p, a = self.curve_pressures_[start:stop], self.curve_angles_[start:stop]
            if p.size < 2:
                self._curves[k] = (p, a, None, 0.0, 0.0)
            else:
                spline = PchipInterpolator(p, a, extrapolate=False)
                slope = spline.derivative()
                self._curves[k] = (p, a, spline, float(slope(p[0])), float(slope(p[-1])))
        return self._curves[k]

    def _on_curve(self, k: int, pressure: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
        """Angles of design ``k`` at ``pressure`` and whether each lies within its pressures."""
        p, a, spline, low_slope, high_slope = self._curve(k)
        inside = (pressure >= p[0]) & (pressure <= p[-1])
        if spline is None:
            return np.full(pressure.shape, a[0]), inside
        out = np.empty_like(pressure)
        out[inside] = spline(pressure[inside])
        linear = self.extrapolation == "linear"
        below, above = pressure < p[0], pressure > p[-1]
        out[below] = a[0] + (low_slope * (pressure[below] - p[0]) if linear else 0.0)
        out[above] = a[-1] + (high_slope * (pressure[above] - p[-1]) if linear else 0.0)
        return out, inside

    def _gp_predict(self, rows: np.ndarray, with_std: bool) -> tuple[np.ndarray, np.ndarray]:
        gp = self._fitted_gp()
        mean = np.empty(rows.shape[0])
        std = np.zeros(rows.shape[0])
        for start in range(0, rows.shape[0], _CHUNK):
            z = (rows[start : start + _CHUNK] - self.x_mean_) / self.x_scale_
            if with_std:
                mean[start : start + _CHUNK], std[start : start + _CHUNK] = gp.predict(z)
            else:
                mean[start : start + _CHUNK] = gp.predict_mean(z)
        return mean, std

    @property
    def noise_std_(self) -> float:
        """The GP's fitted noise standard deviation, degrees: the table's precision."""
        gp = self._fitted_gp()
        return float(np.sqrt(gp.noise) * gp.y_std)

    def predict(
        self, X: ArrayLike, return_std: bool = False
    ) -> np.ndarray | tuple[np.ndarray, np.ndarray]:
        """Angles, degrees (and their standard deviation, degrees, with ``return_std``).

        Parameters
        ----------
        X : array_like of shape (n, d)
            Design parameters then pressure, in the units fitted on.
        return_std : bool, default False
            Also return the predictive standard deviation (module docstring).

        Returns
        -------
        ndarray of shape (n,), or a tuple of two
        """
        rows = _check_rows(X, "X", int(self.n_features_in_))
        design = self.matched(rows)
        angle = np.empty(rows.shape[0])
        std = np.zeros(rows.shape[0])
        needs_gp = design < 0
        for k in np.unique(design[design >= 0]):
            mine = np.flatnonzero(design == k)
            angle[mine], inside = self._on_curve(int(k), rows[mine, -1])
            std[mine] = self.noise_std_
            if return_std:
                needs_gp[mine[~inside]] = True
        if needs_gp.any():
            mean, spread = self._gp_predict(rows[needs_gp], return_std)
            off = design[needs_gp] < 0
            angle[np.flatnonzero(needs_gp)[off]] = mean[off]
            std[needs_gp] = spread
        return (angle, std) if return_std else angle

    def predict_interval(self, X: ArrayLike, level: float = 0.9) -> tuple[np.ndarray, np.ndarray]:
        """Central interval of probability ``level`` for a new reading (Gaussian), degrees."""
        level = check_range(level, "level", low=0.0, high=1.0, high_inclusive=True)
        mean, std = self.predict(X, return_std=True)
        if level == 1.0:
            return mean - np.inf, mean + np.inf
        half = NormalDist().inv_cdf(0.5 + level / 2) * std
        return mean - half, mean + half
