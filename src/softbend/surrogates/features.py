"""Inputs and target of the surrogate models: an actuator's design parameters and pressure → θ.

Every surrogate in :mod:`softbend.surrogates` takes a float array of shape
``(n_samples, d)`` whose columns are its actuator's
:attr:`~softbend.actuators.Actuator.features` in this order and units (paper B's
:data:`FEATURES`, (l, r, t, b, φ, lc, P) of §4.1, for a model that records no
actuator), and predicts the bending angle in degrees. The functions here take
those columns as an argument. :func:`training_data` builds that array from a
campaign's samples table (:func:`softbend.campaign.load_samples`), with the
design ids as CV groups so that a sweep never spans two folds.
"""

from __future__ import annotations

import hashlib
import os
from collections.abc import Sequence
from dataclasses import dataclass
from typing import TYPE_CHECKING

import numpy as np
from numpy.typing import ArrayLike

from softbend.design import FEATURES as DESIGN_FEATURES
from softbend.errors import DatasetError, InputError

if TYPE_CHECKING:  # a table only for training: predicting needs no pandas
    import pandas as pd

    from softbend.actuators import Actuator

#: Paper B's input columns, in the order its surrogates expect them (a model without an
#: actuator record takes these).
FEATURES: tuple[str, ...] = DESIGN_FEATURES

#: Unit of each input and of the target.
UNITS: dict[str, str] = {
    "l_mm": "mm",
    "r_mm": "mm",
    "t_mm": "mm",
    "b_mm": "mm",
    "phi_deg": "deg",
    "lc_mm": "mm",
    "pressure_mpa": "MPa",
    "angle_deg": "deg",
}

#: Target column.
TARGET = "angle_deg"

#: Group column: one group per design (one pressure sweep).
GROUP = "design_id"


@dataclass(frozen=True)
class TrainingData:
    """Arrays for fitting and cross-validating a surrogate.

    Attributes
    ----------
    X : ndarray, shape (n_samples, d)
        Inputs, columns the actuator's features (:data:`FEATURES` for paper B's).
    y : ndarray, shape (n_samples,)
        Bending angle, degrees.
    groups : ndarray of str, shape (n_samples,)
        Design id of each row (CV groups).
    data_hash : str
        SHA-256 of ``X``, ``y`` and ``groups`` (hex, first 16 characters):
        identifies the training data in a saved model's metadata.
    n_dropped : int
        Rows left out: not converged, or a non-finite input or angle.
    actuator : Actuator, optional
        The description of the actuator the rows are of (None: paper B's).
    """

    X: np.ndarray
    y: np.ndarray
    groups: np.ndarray
    data_hash: str
    n_dropped: int = 0
    actuator: Actuator | None = None

    @property
    def n_samples(self) -> int:
        """Number of rows."""
        return int(self.y.size)

    @property
    def n_groups(self) -> int:
        """Number of distinct designs."""
        return len(set(np.asarray(self.groups).ravel().tolist()))  # hashed: no sort of the rows


def data_hash(X: ArrayLike, y: ArrayLike, groups: ArrayLike | None = None) -> str:
    """Short SHA-256 of the training arrays (first 16 hex characters).

    The hash covers the float64 bytes of ``X`` (C order) and ``y`` and the
    group labels, so the same data in the same row order give the same hash.
    """
    digest = hashlib.sha256()
    # the arrays' own buffers (no copy); the same bytes as their ``tobytes()``
    digest.update(np.ascontiguousarray(X, dtype=np.float64).data.cast("B"))
    digest.update(np.ascontiguousarray(y, dtype=np.float64).data.cast("B"))
    if groups is not None:
        labels = np.asarray(groups).tolist()
        try:
            joined = "\x1f".join(labels)  # labels that are text already, as most are
        except TypeError:
            joined = "\x1f".join(map(str, labels))
        digest.update(joined.encode())
    return digest.hexdigest()[:16]


def training_data(
    samples: pd.DataFrame, *, converged_only: bool = True, actuator: Actuator | None = None
) -> TrainingData:
    """Inputs, target and CV groups from a campaign samples table.

    Parameters
    ----------
    samples : pandas.DataFrame
        One row per (design, pressure) with the columns :data:`FEATURES`,
        ``angle_deg`` and ``design_id`` (and optionally ``converged``), as
        returned by :func:`softbend.campaign.load_samples`.
    converged_only : bool
        Leave out rows whose ``converged`` flag is false (default True).
    actuator : Actuator, optional
        Whose columns to read: its :attr:`~softbend.actuators.Actuator.features`
        and angle column (default paper B's :data:`FEATURES` and ``angle_deg``).

    Returns
    -------
    TrainingData

    Raises
    ------
    DatasetError
        If a column is missing or no usable row remains.
    """
    features = FEATURES if actuator is None else actuator.features
    target = TARGET if actuator is None else actuator.angle_column
    needed = [*features, target, GROUP]
    missing = [c for c in needed if c not in samples.columns]
    if missing:
        raise DatasetError(
            f"The samples table lacks the column(s) {', '.join(missing)}; "
            f"a surrogate needs {', '.join(needed)}."
        )
    keep = np.ones(len(samples), dtype=bool)
    if converged_only and "converged" in samples.columns:
        keep &= samples["converged"].to_numpy(dtype=bool, na_value=False)
    X = samples[list(features)].to_numpy(dtype=np.float64, na_value=np.nan)
    y = samples[target].to_numpy(dtype=np.float64, na_value=np.nan)
    keep &= np.isfinite(X).all(axis=1) & np.isfinite(y)
    if not keep.any():
        raise DatasetError(
            f"The samples table has no converged row with finite {', '.join(needed[:-1])} "
            f"({len(samples)} rows in all)."
        )
    X, y = np.ascontiguousarray(X[keep]), np.ascontiguousarray(y[keep])
    groups = samples[GROUP].astype(str).to_numpy()[keep]
    return TrainingData(
        X=X,
        y=y,
        groups=groups,
        data_hash=data_hash(X, y, groups),
        n_dropped=int((~keep).sum()),
        actuator=actuator,
    )


def dataset_training_data(source: str | os.PathLike[str]) -> TrainingData:
    """Inputs, target and CV groups of a verified dataset, by folder or shipped name.

    ``source`` is a folder of ``softbend campaign dataset`` or the name of a
    dataset softbend ships (``"table1_fem"``, a family's name), read by
    :func:`softbend.datasets.dataset_samples`. Table 1's gives paper B's
    :data:`FEATURES`; another family's its parameters and pressure (in its
    actuator's unit) with the recorded actuator.
    """
    from softbend.datasets import dataset_samples

    return family_training_data(*dataset_samples(source))


def family_training_data(samples: pd.DataFrame, actuator: Actuator | None) -> TrainingData:
    """Inputs, target and CV groups of a family's samples table (paper B's for None).

    The table has :func:`softbend.campaign.load_samples`'s columns, pressure in
    MPa (``pressure_mpa``) and angle in deg (``angle_deg``); the actuator's own
    pressure and angle columns (pressure in its unit) are added to it in place
    when they are named otherwise, then :func:`training_data` reads them.
    """
    if actuator is None:
        return training_data(samples)
    if actuator.pressure_column != "pressure_mpa":
        samples[actuator.pressure_column] = samples["pressure_mpa"] / actuator.to_mpa
    if actuator.angle_column != "angle_deg":
        samples[actuator.angle_column] = samples["angle_deg"]
    return training_data(samples, actuator=actuator)


def check_features(X: ArrayLike, features: Sequence[str] = FEATURES) -> np.ndarray:
    """``X`` as a finite float64 array of shape (n, d), or one :class:`InputError` (key ``X``).

    Parameters
    ----------
    X : array_like of shape (n, d) or (d,)
        Model inputs, one column per name of ``features`` in its units; a single
        sample may be given as a 1-D array.
    features : sequence of str
        The model's input columns (an actuator's
        :attr:`~softbend.actuators.Actuator.features`; default paper B's :data:`FEATURES`).
    """
    array = np.asarray(X, dtype=np.float64)
    if array.ndim == 1:
        array = array[None, :]
    if array.ndim != 2 or array.shape[1] != len(features):
        raise InputError(
            f"must have {len(features)} columns ({', '.join(features)}); got shape {np.shape(X)}",
            key="X",
        )
    bad = ~np.isfinite(array)
    if bad.any():
        row, col = np.argwhere(bad)[0]
        raise InputError(
            f"must be finite; got {array[row, col]} in column '{features[col]}' of row {row}",
            key="X",
        )
    return array


def training_ranges(X: ArrayLike, features: Sequence[str] = FEATURES) -> dict[str, list[float]]:
    """``{feature: [min, max]}`` of the rows a surrogate was trained on, in the inputs' units.

    Saved with a model (``metadata["training_ranges"]``, in the order of
    ``features``) so that a prediction outside them can be flagged
    (:func:`outside_training_ranges`).

    Parameters
    ----------
    X : array_like of shape (n, d)
        The training inputs, columns ``features``.
    features : sequence of str
        The model's input columns (default paper B's :data:`FEATURES`).
    """
    array = check_features(X, features)
    return {
        name: [float(array[:, j].min()), float(array[:, j].max())]
        for j, name in enumerate(features)
    }


def outside_training_ranges(
    ranges: dict[str, list[float]], X: ArrayLike, features: Sequence[str] | None = None
) -> list[str]:
    """One phrase per feature whose values in ``X`` leave ``ranges``; empty when all inside.

    Parameters
    ----------
    ranges : dict
        As :func:`training_ranges` returns (features missing from it are not checked).
    X : array_like of shape (n, d)
        Rows to predict, columns ``features``.
    features : sequence of str, optional
        The model's input columns; default the names of ``ranges`` in their order
        (a saved model's ranges name each of its inputs, in input order).
    """
    names = tuple(ranges) if features is None else tuple(features)
    array = check_features(X, names)
    out = []
    for j, name in enumerate(names):
        if name not in ranges:
            continue
        low, high = (float(v) for v in ranges[name])
        column = array[:, j]
        if column.min() < low or column.max() > high:
            worst = column.min() if column.min() < low else column.max()
            out.append(f"{name} {worst:g} outside [{low:g}, {high:g}]")
    return out
