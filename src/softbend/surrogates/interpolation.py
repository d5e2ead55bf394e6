"""How a surrogate interpolates: held-out pressure points of simulated designs.

The grouped cross-validation of :mod:`softbend.surrogates.search` holds out
whole designs: it says how a family generalises to a design it never saw. A
model used at the simulated designs themselves (between their pressure
points, or refined on measurements of a simulated design) is asked something
else: how it fills in a curve it has seen. :func:`interpolation_scores` scores
that, for each family's chosen configuration:

- the held-out rows are **every other interior pressure point** of each
  design's curve (sorted by pressure, the points at odd positions 1, 3, 5, …
  that are not the curve's last), so each held-out point lies between two
  kept ones of the same design; a curve of fewer than three points holds
  nothing out;
- the family's chosen configuration is fitted once on the kept rows (every
  design, its other points) and scored on the held-out ones (RMSE, largest
  error and R², degrees).

For the table base (:mod:`softbend.surrogates.table`) this is the error of its
shape-preserving interpolation along a simulated curve; for a regression family
the error of its fit between the points it was fitted on.
"""

from __future__ import annotations

from typing import Any

import numpy as np

from softbend.surrogates.families import FAMILIES, FitSettings
from softbend.surrogates.features import TrainingData
from softbend.surrogates.metrics import accuracy

__all__ = ["interpolation_rows", "interpolation_scores"]


def interpolation_rows(X: np.ndarray, groups: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
    """The kept and held-out row indices of the interpolation score (module docstring).

    Parameters
    ----------
    X : ndarray of shape (n, d)
        Inputs, the pressure last.
    groups : ndarray of shape (n,)
        Each row's design.

    Returns
    -------
    kept, held : ndarray of int
        Sorted row indices; ``held`` is every other interior point of each curve.
    """
    import pandas as pd

    n = X.shape[0]
    # each design's rows by pressure, ties in row order (one stable sort; no pass per design:
    # a loop over the designs read every row once per design, minutes on 10^6 rows)
    codes, _ = pd.factorize(np.asarray(groups).ravel())
    order = np.lexsort((X[:, -1], codes))
    sizes = np.bincount(codes)
    firsts = np.concatenate(([0], np.cumsum(sizes)[:-1]))
    sorted_codes = codes[order]
    position = np.arange(n) - firsts[sorted_codes]  # 0 at each curve's lowest pressure
    interior_odd = (position % 2 == 1) & (position < sizes[sorted_codes] - 1)
    held_rows = np.sort(order[interior_odd]).astype(np.int64)
    chosen = np.ones(n, dtype=bool)
    chosen[held_rows] = False
    kept = np.flatnonzero(chosen).astype(np.int64)
    return kept, held_rows


def interpolation_scores(
    data: TrainingData,
    chosen: dict[str, dict[str, Any]],
    settings: FitSettings,
    *,
    mape_threshold_deg: float,
) -> dict[str, dict[str, float]]:
    """Each family's interpolation figures, its chosen configuration fitted on the kept rows.

    Parameters
    ----------
    data : TrainingData
        The table.
    chosen : dict
        ``{family name: configuration}`` (the grouped search's choice).
    settings : FitSettings
        Seed, threads, device and MLP epochs of the fits.
    mape_threshold_deg : float
        The MAPE floor, degrees (as the grouped scores').

    Returns
    -------
    dict
        ``{name: {"rmse_deg", "max_abs_error_deg", "r2", "n_held_out"}}``; empty for a
        table with no curve of three points or more.
    """
    from softbend.surrogates.search import _mlp_threads

    kept, held = interpolation_rows(data.X, data.groups)
    if held.size == 0:
        return {}
    out: dict[str, dict[str, float]] = {}
    for name, params in chosen.items():
        with _mlp_threads(name, settings.device, kept.size):
            model = FAMILIES.get(name).make(dict(params), settings).fit(data.X[kept], data.y[kept])
            pred = np.asarray(model.predict(data.X[held]), dtype=np.float64)
        scores = accuracy(data.y[held], pred, mape_threshold_deg=mape_threshold_deg)
        out[name] = {
            "rmse_deg": float(scores["rmse_deg"]),
            "max_abs_error_deg": float(scores["max_abs_error_deg"]),
            "r2": float(scores["r2"]),
            "n_held_out": int(held.size),
        }
    return out
