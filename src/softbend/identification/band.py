"""An uncertainty band around a free run, from held-out free-run residuals.

A model run free (its own past outputs fed back) drifts from the measurement
by an error no one-step figure shows. The band here says how far, from the
evidence a model selection already has: the free runs of whole experiments
the model was *not* fitted on (the held-out folds of the cross-validation,
:func:`~softbend.identification.selection.select_model`).

For output ``j`` the residual is ``r_j(t) = y_j(t) - ŷ_j(t)``, measured minus
free-run output, in the output's unit, over every sample after each run's
initial conditions (its first ``max_lag`` samples are the measurement itself).
The band at level ``level`` (default :data:`BAND_LEVEL` = 0.90) is

    [ŷ_j(t) + q_j((1 - level)/2),  ŷ_j(t) + q_j((1 + level)/2)]

with ``q_j`` the empirical quantiles of the pooled residuals of output ``j``
(5 % and 95 % by default). Choices and their limits:

* **One offset per output, the same at every time.** A stable model forgets
  its initial conditions within a few of its time constants, after which its
  free-run error no longer grows with the horizon; pooled over the run, the
  residual's spread is the error's. The band is not conditioned on the
  operating point or on how fast the output moves.
* **Asymmetric.** A model biased in one direction gets a band shifted that
  way; nothing assumes a Gaussian.
* **Pointwise and marginal.** A 90 % band holds about 90 % of the samples, not
  90 % of whole runs. Neighbouring residuals are correlated, so the quantiles
  rest on fewer independent samples than they count.
* **Slightly pessimistic.** Each held-out run comes from a model fitted
  without its fold, on fewer experiments than the final model.

The check that makes it honest is its coverage (:func:`coverage`) on samples
the band was not estimated from: validation experiments, or, without them,
each fold's runs against the band of the other folds' residuals
(:func:`fold_coverage`).
"""

from __future__ import annotations

from collections.abc import Sequence
from dataclasses import dataclass
from typing import Any

import numpy as np

from softbend._validation import must_be
from softbend.errors import InputError

__all__ = [
    "BAND_LEVEL",
    "FreeRunBand",
    "coverage",
    "estimate_band",
    "fold_coverage",
    "free_run_residuals",
]

#: Level of the band :func:`~softbend.identification.selection.select_model` reports.
BAND_LEVEL = 0.90


def _check_level(level: Any) -> float:
    if isinstance(level, bool) or not isinstance(level, int | float) or not 0.0 < level < 1.0:
        raise InputError(must_be("a number in (0, 1)", level), key="level")
    return float(level)


@dataclass(frozen=True, eq=False)
class FreeRunBand:
    """A band around a free run: per output, offsets added to the free-run output.

    Attributes
    ----------
    level : float
        Fraction of samples the band is meant to hold, in (0, 1).
    output_names : tuple of str
    low, high : ndarray
        Per output, the residual quantiles ``(1 - level)/2`` and ``(1 + level)/2``,
        in the output's unit; the band is ``ŷ + low`` to ``ŷ + high``.
    n_residuals : int
        Residual samples per output it was estimated from.
    coverage : tuple of float, optional
        Per output, the fraction of samples inside the band on the samples named
        by ``coverage_on`` (None until checked).
    coverage_on : str
        Which samples: ``"validation experiments"`` or ``"cross-validation folds"``.
    coverage_samples : int
        Samples per output the coverage counts.
    """

    level: float
    output_names: tuple[str, ...]
    low: np.ndarray
    high: np.ndarray
    n_residuals: int
    coverage: tuple[float, ...] | None = None
    coverage_on: str = ""
    coverage_samples: int = 0

    def __post_init__(self) -> None:
        _check_level(self.level)
        m = len(self.output_names)
        for key in ("low", "high"):
            value = np.asarray(getattr(self, key), dtype=float)
            if value.shape != (m,) or not np.isfinite(value).all():
                raise InputError(
                    must_be(f"{m} finite numbers (one per output)", getattr(self, key)), key=key
                )
            object.__setattr__(self, key, value)
        if (self.low > self.high).any():
            raise InputError(must_be("at most high, output by output", self.low), key="low")

    def bounds(self, simulated: np.ndarray, *, start: int = 0) -> tuple[np.ndarray, np.ndarray]:
        """``(low, high)`` of a free run, arrays shaped like ``simulated`` (n, m).

        Parameters
        ----------
        simulated : ndarray
            One free run, (n, m), in the outputs' units.
        start : int, default 0
            Rows before it are the run's initial conditions (the measurement):
            the band has no width there.
        """
        run = _run(simulated, len(self.output_names), "simulated")
        low, high = run + self.low, run + self.high
        low[:start] = run[:start]
        high[:start] = run[:start]
        return low, high

    def width(self) -> np.ndarray:
        """Per output, ``high - low``, in the output's unit."""
        return self.high - self.low

    def summary(self) -> str:
        """One line: the level and, when checked, the coverage on held-out samples."""
        level = f"{100 * self.level:.0f} % free-run band"
        if self.coverage is None:
            return f"{level} (not checked on held-out samples)"
        each = ", ".join(
            f"{n} {100 * c:.0f} %" for n, c in zip(self.output_names, self.coverage, strict=True)
        )
        mean = 100 * float(np.mean(self.coverage))
        return (
            f"{level} covers {mean:.0f} % of held-out samples ({self.coverage_on}; {each}; "
            f"{self.coverage_samples:,} samples per output)."
        )

    def to_dict(self) -> dict[str, Any]:
        """JSON-friendly: level, per-output offsets and widths, and the coverage."""
        return {
            "level": self.level,
            "quantiles": [(1 - self.level) / 2, (1 + self.level) / 2],
            "outputs": list(self.output_names),
            "low": self.low.tolist(),
            "high": self.high.tolist(),
            "width": self.width().tolist(),
            "n_residuals": self.n_residuals,
            "coverage": None if self.coverage is None else list(self.coverage),
            "coverage_mean": None if self.coverage is None else float(np.mean(self.coverage)),
            "coverage_on": self.coverage_on,
            "coverage_samples": self.coverage_samples,
            "summary": self.summary(),
        }


def _run(array: Any, m: int | None, key: str) -> np.ndarray:
    """A run as a finite float array (n, m)."""
    run = np.array(array, dtype=float)
    if run.ndim == 1:
        run = run[:, None]
    if run.ndim != 2 or (m is not None and run.shape[1] != m):
        want = "outputs" if m is None else f"{m} output{'s' if m != 1 else ''}"
        raise InputError(must_be(f"an array of shape (samples, {want})", run.shape), key=key)
    if not np.isfinite(run).all():
        raise InputError(must_be("finite", "a value that is not"), key=key)
    return run


def free_run_residuals(
    measured: Sequence[np.ndarray], simulated: Sequence[np.ndarray], *, start: int = 0
) -> np.ndarray:
    """Measured minus free-run outputs of several runs, stacked, initial conditions left out.

    Parameters
    ----------
    measured, simulated : sequence of ndarray
        One (n_i, m) array per run, in the outputs' units, paired in order.
    start : int, default 0
        Rows of each run that are its initial conditions (a NARX model's
        ``max_lag``), left out.

    Returns
    -------
    ndarray
        (sum of n_i - start, m), in the outputs' units.

    Raises
    ------
    InputError
        Runs not paired, not 2-D with the same outputs, or not finite.
    """
    if len(measured) != len(simulated):
        raise InputError(
            must_be(f"one run per measured run ({len(measured)})", len(simulated)),
            key="simulated",
        )
    if isinstance(start, bool) or not isinstance(start, int) or start < 0:
        raise InputError(must_be("an integer in [0, inf)", start), key="start")
    parts = []
    m = None
    for y, s in zip(measured, simulated, strict=True):
        y_run = _run(y, m, "measured")
        m = y_run.shape[1]
        s_run = _run(s, m, "simulated")
        if len(s_run) != len(y_run):
            raise InputError(
                must_be(f"{len(y_run)} samples, as measured", len(s_run)), key="simulated"
            )
        parts.append(y_run[start:] - s_run[start:])
    if not parts:
        raise InputError(must_be("at least one run", 0), key="measured")
    return np.vstack(parts)


def estimate_band(
    residuals: np.ndarray, output_names: Sequence[str], *, level: float = BAND_LEVEL
) -> FreeRunBand:
    """The band of held-out free-run residuals (module docstring).

    Parameters
    ----------
    residuals : ndarray
        (n, m) measured minus free-run outputs (:func:`free_run_residuals`), in
        the outputs' units.
    output_names : sequence of str
        The m outputs.
    level : float, default 0.90
        Fraction of samples the band should hold, in (0, 1).

    Returns
    -------
    FreeRunBand
        Without its coverage (:func:`coverage` checks it on other samples).

    Raises
    ------
    InputError
        A level out of (0, 1), no residuals, residuals that are not finite or
        do not have one column per output.
    """
    level = _check_level(level)
    names = tuple(output_names)
    r = _run(residuals, len(names), "residuals")
    if len(r) == 0:
        raise InputError(must_be("at least one residual sample", 0), key="residuals")
    low, high = np.quantile(r, [(1 - level) / 2, (1 + level) / 2], axis=0)
    return FreeRunBand(level=level, output_names=names, low=low, high=high, n_residuals=len(r))


def coverage(band: FreeRunBand, residuals: np.ndarray) -> np.ndarray:
    """Per output, the fraction of residual samples inside the band (bounds included).

    Parameters
    ----------
    band : FreeRunBand
    residuals : ndarray
        (n, m) measured minus free-run outputs, in the outputs' units; residuals
        the band was not estimated from, for an honest figure.

    Returns
    -------
    ndarray
        (m,), each in [0, 1].

    Raises
    ------
    InputError
        No residuals, residuals that are not finite or do not match the outputs.
    """
    r = _run(residuals, len(band.output_names), "residuals")
    if len(r) == 0:
        raise InputError(must_be("at least one residual sample", 0), key="residuals")
    inside = (r >= band.low) & (r <= band.high)
    return inside.mean(axis=0)


def fold_coverage(
    residuals_by_fold: Sequence[np.ndarray],
    output_names: Sequence[str],
    *,
    level: float = BAND_LEVEL,
) -> tuple[np.ndarray, int]:
    """Coverage of the band on each fold's residuals, the band estimated without that fold.

    Parameters
    ----------
    residuals_by_fold : sequence of ndarray
        Per cross-validation fold, (n_k, m) residuals of its held-out runs, in
        the outputs' units; at least 2 folds.
    output_names : sequence of str
    level : float, default 0.90

    Returns
    -------
    coverage : ndarray
        (m,), the fraction of all samples inside the band of the other folds.
    samples : int
        Samples per output counted.

    Raises
    ------
    InputError
        Fewer than 2 folds, or a fold or level :func:`estimate_band` refuses.
    """
    folds = list(residuals_by_fold)
    if len(folds) < 2:
        raise InputError(must_be("at least 2 folds", len(folds)), key="residuals_by_fold")
    m = len(tuple(output_names))
    runs = [_run(r, m, "residuals_by_fold") for r in folds]
    inside = np.zeros(m)
    total = 0
    for k, held in enumerate(runs):
        if len(held) == 0:
            continue
        others = [r for i, r in enumerate(runs) if i != k]
        band = estimate_band(np.vstack(others), output_names, level=level)
        inside += coverage(band, held) * len(held)
        total += len(held)
    if total == 0:
        raise InputError(must_be("at least one residual sample", 0), key="residuals_by_fold")
    return inside / total, total
