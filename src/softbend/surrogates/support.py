"""Where a surrogate's training data hold: the pressure each design was swept to, and the angles.

A box around each input (:func:`softbend.surrogates.features.training_ranges`)
is not where a bending-angle surrogate holds. The FEM sweeps of Table 1 stop
where the actuator passes 300° (or the solver stops), which is 0.115 MPa for a
long, thin-walled design and 0.5 MPa for a short, thick one: a pressure inside
the box is often far past what any design near the one asked for was swept
to, and there a network's curve bends back or runs on to 500°.

:class:`Support` keeps, with a saved model, each training design's largest
pressure (MPa) and the largest angle seen (degrees). A prediction is *beyond
the support* when

- its pressure exceeds the largest pressure the training designs nearest to
  its design were swept to: the designs' own value for a training design,
  else the inverse-distance-weighted mean (power 2) over the
  :data:`NEIGHBOURS` nearest training designs, distances measured in units of
  each parameter's span over the training designs; or
- its angle exceeds the largest angle in the training data by more than
  :data:`ANGLE_TOLERANCE` of it (the FEM's 300° stop, a network's small
  overshoot at the last swept pressure allowed).

``softbend predict`` flags such a prediction and with ``--strict`` refuses it;
the control plant built from a surrogate tabulates θ(p) only up to the
supported pressure.
"""

from __future__ import annotations

import math
from collections.abc import Mapping, Sequence
from dataclasses import dataclass
from typing import Any

import numpy as np
from numpy.typing import ArrayLike

from softbend._validation import must_be
from softbend.design import PARAMETERS
from softbend.errors import InputError

__all__ = [
    "ANGLE_TOLERANCE",
    "NEIGHBOURS",
    "RULE",
    "Support",
    "pressures_text",
    "support_from_rows",
    "trained_pressure_range",
]

#: Training designs whose swept pressure is interpolated to a new design.
NEIGHBOURS = 12

#: A predicted angle may exceed the largest training angle by this share of it.
ANGLE_TOLERANCE = 0.02

#: The rule, recorded with the support.
RULE = (
    f"pressure <= the largest swept at the design (inverse-distance mean over the "
    f"{NEIGHBOURS} nearest training designs, distances in parameter spans); angle <= "
    f"{1 + ANGLE_TOLERANCE:g} x the largest training angle"
)


@dataclass(frozen=True)
class Support:
    """The training data's support: each design's largest pressure, and the largest angle.

    Attributes
    ----------
    designs : ndarray, shape (n, 6)
        The training designs (mm, deg; columns :data:`softbend.design.PARAMETERS`).
    max_pressure_mpa : ndarray, shape (n,)
        The largest pressure each design was trained at, MPa gauge.
    max_angle_deg : float
        The largest angle in the training data, degrees.
    parameters : tuple of str
        The design parameters' names (paper B's by default).
    pressure_unit : str
        Unit of ``max_pressure_mpa`` and of the pressure input: MPa for paper
        B's actuator, the actuator's own unit for another.
    """

    designs: np.ndarray
    max_pressure_mpa: np.ndarray
    max_angle_deg: float
    parameters: tuple[str, ...] = PARAMETERS
    pressure_unit: str = "MPa"

    def __post_init__(self) -> None:
        designs = np.asarray(self.designs, dtype=np.float64)
        pmax = np.asarray(self.max_pressure_mpa, dtype=np.float64).ravel()
        d = len(self.parameters)
        if designs.ndim != 2 or designs.shape[1] != d or designs.shape[0] == 0:
            raise InputError(
                f"must have shape (n, {d}) with n >= 1; got shape {designs.shape}", key="designs"
            )
        if pmax.shape != (designs.shape[0],):
            raise InputError(
                f"must hold one pressure per design ({designs.shape[0]}); got {pmax.size}",
                key="max_pressure_mpa",
            )
        if not (np.isfinite(designs).all() and np.isfinite(pmax).all() and (pmax >= 0).all()):
            raise InputError(
                "the designs and max_pressure_mpa must be finite, the pressures >= 0 MPa"
            )
        object.__setattr__(self, "parameters", tuple(self.parameters))
        if not (math.isfinite(self.max_angle_deg) and self.max_angle_deg > 0):
            raise InputError(
                must_be("a finite angle > 0 degrees", self.max_angle_deg), key="max_angle_deg"
            )
        object.__setattr__(self, "designs", designs)
        object.__setattr__(self, "max_pressure_mpa", pmax)
        object.__setattr__(self, "max_angle_deg", float(self.max_angle_deg))

    @property
    def angle_limit_deg(self) -> float:
        """The largest angle a supported prediction may have, degrees."""
        return self.max_angle_deg * (1.0 + ANGLE_TOLERANCE)

    def max_pressure(self, designs: ArrayLike) -> np.ndarray:
        """The largest supported pressure at each of ``designs`` (rows of 6), MPa."""
        query = np.atleast_2d(np.asarray(designs, dtype=np.float64))[:, : len(self.parameters)]
        span = np.ptp(self.designs, axis=0)
        span = np.where(span > 0, span, 1.0)
        out = np.empty(query.shape[0])
        unique, inverse = np.unique(query, axis=0, return_inverse=True)
        for i, row in enumerate(unique):
            d = np.sqrt((((self.designs - row) / span) ** 2).sum(axis=1))
            nearest = np.argsort(d, kind="stable")[:NEIGHBOURS]
            if d[nearest[0]] < 1e-9:
                value = float(self.max_pressure_mpa[d < 1e-9].max())
            else:
                w = 1.0 / d[nearest] ** 2
                value = float(w @ self.max_pressure_mpa[nearest] / w.sum())
            out[inverse.ravel() == i] = value
        return out

    def supported(self, X: ArrayLike, angles: ArrayLike | None = None) -> np.ndarray:
        """Whether each row of ``X`` (7 inputs) and its predicted angle lie in the support."""
        rows = np.atleast_2d(np.asarray(X, dtype=np.float64))
        ok = rows[:, -1] <= self.max_pressure(rows) * (1 + 1e-9) + 1e-12
        if angles is not None:
            a = np.asarray(angles, dtype=np.float64).ravel()
            ok &= ~(a > self.angle_limit_deg)
        return ok

    def beyond(self, X: ArrayLike, angles: ArrayLike | None = None) -> list[str]:
        """One phrase per way the rows leave the support; empty when all are inside."""
        rows = np.atleast_2d(np.asarray(X, dtype=np.float64))
        limit = self.max_pressure(rows)
        phrases = []
        over = rows[:, -1] > limit * (1 + 1e-9) + 1e-12
        if over.any():
            i = int(np.flatnonzero(over)[np.argmax(rows[over, -1] - limit[over])])
            unit = self.pressure_unit
            design = rows[i, : len(self.parameters)]
            phrases.append(
                f"pressure {rows[i, -1]:g} {unit} beyond the {limit[i]:.3g} {unit} the training "
                f"designs nearest to ({self._design_text(design)}) "
                "were swept to"
            )
        if angles is not None:
            a = np.asarray(angles, dtype=np.float64).ravel()
            high = a > self.angle_limit_deg
            if high.any():
                phrases.append(
                    f"angle {a[high].max():.4g}° beyond the largest in the training data "
                    f"({self.max_angle_deg:.4g}°)"
                )
        return phrases

    def _design_text(self, design: np.ndarray) -> str:
        """Paper B's design as its six numbers, another actuator's by name."""
        if self.parameters == PARAMETERS:
            return ",".join(f"{v:g}" for v in design)
        return ", ".join(f"{n}={v:g}" for n, v in zip(self.parameters, design, strict=True))

    def merged(self, other: Support) -> Support:
        """The union of two supports (a design in both keeps its larger pressure)."""
        designs = np.vstack([self.designs, other.designs])
        pmax = np.concatenate([self.max_pressure_mpa, other.max_pressure_mpa])
        unique, inverse = np.unique(designs, axis=0, return_inverse=True)
        best = np.zeros(unique.shape[0])
        np.maximum.at(best, inverse.ravel(), pmax)
        return Support(
            unique,
            best,
            max(self.max_angle_deg, other.max_angle_deg),
            self.parameters,
            self.pressure_unit,
        )

    def to_dict(self) -> dict[str, Any]:
        """JSON-friendly record (the ``support`` metadata of a saved surrogate)."""
        out = {
            "rule": RULE,
            "parameters": list(self.parameters),
            "designs": [[float(v) for v in row] for row in self.designs],
            "max_pressure_mpa": [float(v) for v in self.max_pressure_mpa],
            "max_angle_deg": self.max_angle_deg,
        }
        if self.pressure_unit != "MPa":
            out["pressure_unit"] = self.pressure_unit
        return out

    @classmethod
    def from_dict(cls, data: object, parameters: Sequence[str] | None = None) -> Support:
        """The support a :meth:`to_dict` record describes.

        Parameters
        ----------
        data : dict
            The record (a saved model's ``metadata["support"]``).
        parameters : sequence of str, optional
            The design parameters it must be of (its model's actuator's
            :attr:`~softbend.actuators.Actuator.names`); default those the record
            names (paper B's when it names none).

        Raises
        ------
        softbend.errors.InputError
            A record that is not one (missing keys, other parameters, wrong shapes,
            non-finite numbers), naming what is wrong (keyed by the record's field
            where one is at fault).
        """
        if not isinstance(data, dict):
            raise InputError(f"must be an object; got {type(data).__name__}")
        missing = [k for k in ("designs", "max_pressure_mpa", "max_angle_deg") if k not in data]
        if missing:
            raise InputError(
                f"must give designs, max_pressure_mpa and max_angle_deg; lacks {', '.join(missing)}"
            )
        recorded = data.get("parameters", list(PARAMETERS))
        named = isinstance(recorded, list) and all(isinstance(n, str) for n in recorded)
        expected = list(parameters) if parameters is not None else recorded if named else []
        if not named or recorded != expected:
            raise InputError(
                must_be(
                    f"the parameters {', '.join(expected)}"
                    if expected
                    else "a list of the design parameters' names",
                    data.get("parameters"),
                ),
                key="parameters",
            )
        unit = data.get("pressure_unit", "MPa")
        if not isinstance(unit, str):
            raise InputError(must_be("the pressure unit as text", unit), key="pressure_unit")
        try:
            designs = np.asarray(data["designs"], dtype=np.float64)
            pmax = np.asarray(data["max_pressure_mpa"], dtype=np.float64)
            angle = float(data["max_angle_deg"])
        except (TypeError, ValueError):
            raise InputError("must hold numbers only") from None
        return cls(designs, pmax, angle, tuple(expected), unit)


def support_from_rows(
    X: ArrayLike,
    y: ArrayLike,
    *,
    parameters: tuple[str, ...] = PARAMETERS,
    pressure_unit: str = "MPa",
) -> Support:
    """The support of training rows ``X`` (7 inputs, mm, deg, MPa) and angles ``y`` (deg).

    Each distinct design (first six columns) keeps its largest pressure; the
    largest finite angle is the angle limit's base.
    """
    rows = np.asarray(X, dtype=np.float64)
    angles = np.asarray(y, dtype=np.float64).ravel()
    d = len(parameters)
    if rows.ndim != 2 or rows.shape[1] != d + 1 or rows.shape[0] != angles.size:
        raise InputError(
            f"X and y must be rows of {d + 1} inputs and one angle per row; got shapes "
            f"{rows.shape} and {angles.shape}"
        )
    designs = rows[:, :d]
    if rows.shape[0] and np.isfinite(designs).all():
        # the distinct designs in np.unique's (lexicographic) order, by one sort: np.unique
        # over rows and np.maximum.at took seconds on 10^6 rows
        order = np.lexsort(designs.T[::-1])
        ordered = designs[order]
        first = np.ones(order.size, dtype=bool)
        first[1:] = np.any(ordered[1:] != ordered[:-1], axis=1)
        starts = np.flatnonzero(first)
        unique = ordered[starts]
        pmax = np.maximum(np.maximum.reduceat(rows[order, -1], starts), 0.0)
    else:
        unique, inverse = np.unique(designs, axis=0, return_inverse=True)
        pmax = np.zeros(unique.shape[0])
        np.maximum.at(pmax, inverse.ravel(), rows[:, -1])
    finite = angles[np.isfinite(angles)]
    return Support(
        unique,
        pmax,
        float(finite.max()) if finite.size else math.nan,
        tuple(parameters),
        pressure_unit,
    )


def trained_pressure_range(
    metadata: Mapping[str, Any], pressure_column: str
) -> tuple[float, float] | None:
    """The pressures a saved model was trained on, in its pressure unit, or None if unrecorded.

    Parameters
    ----------
    metadata : mapping
        The model file's metadata.
    pressure_column : str
        Its actuator's pressure input (``pressure_mpa``, ``p_kpa``).

    Returns
    -------
    (low, high) or None
        The ``training_ranges`` of ``pressure_column``, else 0 to the largest pressure of
        the ``support`` (each training design's largest); None when the file records neither.
    """
    ranges = metadata.get("training_ranges")
    if isinstance(ranges, Mapping) and pressure_column in ranges:
        low, high = (float(v) for v in ranges[pressure_column])
        return low, high
    support = metadata.get("support")
    if isinstance(support, Mapping) and support.get("max_pressure_mpa"):
        return 0.0, float(np.max(np.asarray(support["max_pressure_mpa"], dtype=np.float64)))
    return None


def pressures_text(pressures: Sequence[float], unit: str) -> str:
    """``"90, 345 kPa"``: pressures as a message shows them, in ``unit``."""
    return f"{', '.join(f'{p:.4g}' for p in pressures)} {unit}"
