"""The answer of a design search: the candidates scored, and the search's record.

:class:`Candidate` is one design scored against a specification (and, once
verified, swept by the FEM); :class:`SearchResult` the answer to one
specification, with its figures, the message when no design meets the target
and the JSON record of ``search.json``.
"""

from __future__ import annotations

import math
from dataclasses import dataclass, field
from typing import Any

import numpy as np

from softbend.actuators import Design
from softbend.design_search.space import SearchSpace, pressure_key, space_of
from softbend.design_search.spec import ParameterRange, Specification

__all__ = ["Candidate", "SearchResult"]


@dataclass
class Candidate:
    """A design scored against a specification.

    Attributes
    ----------
    design : Design
        Paper B's design, or another actuator's (its codes).
    angle_deg : float
        The surrogate's angle at the target's pressure (degrees); for a curve,
        at its last point.
    pressure_mpa : float
        The target's pressure, or for ``pressure_for`` the pressure that reaches
        the angle (in ``pressure_unit``, MPa for paper B's actuator; NaN if it is
        not reached).
    error_deg : float
        How far the surrogate misses the target (degrees; a curve's largest miss;
        0 for ``max_angle``).
    meets : bool
        Whether the error is within the tolerance (less the specification's margin).
    objectives : dict of str to float
        Each objective's value, in the units of :data:`~softbend.design_search.spec.OBJECTIVES`.
    interval_deg : (float, float) or None
        The model's 90 % interval of ``angle_deg`` where it has one.
    flags : list of str
        Why the answer is outside the model's training data (empty inside).
    fem_angle_deg, fem_error_deg : float or None
        The FEM's angle at the target's pressure and its miss, once verified.
    fem_meets : bool or None
        Whether the FEM confirms the target within its tolerance.
    fem_curve : (ndarray, ndarray) or None
        The FEM's converged sweep, pressures (MPa) and angles (degrees).
    pressure_unit : str
        Unit of ``pressure_mpa`` (the model's pressure unit).
    fem_stop : str or None
        Why the FEM gave no angle, once verified: the sweep stopped before the
        pressure checked (its stop reason, such as neighbouring chamber walls
        touching), failed, or the FEM family refused the design; None when the
        sweep reached every pressure checked.
    """

    design: Design
    angle_deg: float
    pressure_mpa: float
    error_deg: float
    meets: bool
    objectives: dict[str, float]
    interval_deg: tuple[float, float] | None = None
    flags: list[str] = field(default_factory=list)
    fem_angle_deg: float | None = None
    fem_error_deg: float | None = None
    fem_meets: bool | None = None
    fem_curve: tuple[np.ndarray, np.ndarray] | None = field(default=None, repr=False)
    pressure_unit: str = "MPa"
    fem_stop: str | None = None

    @property
    def supported(self) -> bool:
        """Whether the answer lies inside the model's training data (no flag), as
        ``softbend predict`` says "trained there"."""
        return not self.flags

    def to_dict(self) -> dict[str, Any]:
        """JSON-friendly: the design by the names of its search (paper B's short names),
        in their units, whole numbers as integers and levels by name, every figure (the
        pressure keyed by its unit), the ``flags`` and ``supported`` (no flag: inside the
        model's training data)."""
        space = space_of(getattr(self.design, "actuator", None))
        record = space.actuator.design_record(self.design.as_array())
        design = dict(zip(space.names, record.values(), strict=True))
        out: dict[str, Any] = {
            "design": design,
            "angle_deg": self.angle_deg,
            pressure_key(self.pressure_unit): self.pressure_mpa,
            "error_deg": self.error_deg,
            "meets": self.meets,
            "objectives": dict(self.objectives),
            "flags": list(self.flags),
            "supported": self.supported,
        }
        if self.interval_deg is not None:
            out["interval_deg"] = list(self.interval_deg)
        if self.fem_angle_deg is not None or self.fem_meets is not None:
            out["fem_angle_deg"] = self.fem_angle_deg
            out["fem_error_deg"] = self.fem_error_deg
            out["fem_meets"] = self.fem_meets
            out["fem_stop_reason"] = self.fem_stop
        return out


@dataclass
class SearchResult:
    """The answer to a specification.

    Attributes
    ----------
    spec : Specification
    candidates : list of Candidate
        Best first: the designs that meet the target, or the closest when none does.
    feasible : bool
        Whether any design meets the target.
    ranges : dict of str to ParameterRange
        The ranges searched (the given ones and the model's training ranges).
    n_designs, n_meeting : int
        Designs scored, and those meeting the target.
    n_passed_over : int
        Designs that would have ranked but lie outside the training data's support.
    front : ndarray
        The objective values of the meeting designs' Pareto front (rows; in the
        objectives' units), for a plot.
    model : str
        The model file.
    seconds : float
        Time of the search (not of any verification), s.
    verify_skipped : str, optional
        Why ``--verify`` checked nothing (the FEM does not model the actuator).
    verified_by : dict, optional
        What verified the candidates, once verified: ``backend`` (``"fem"``,
        ``"analytical"``), ``family`` (the FEM family, ``"sfrba"`` for paper B's
        actuator) and ``designs`` (how many were swept).
    pressure_range : (float, float), optional
        The pressures the model was trained on, in the target's unit
        (:func:`softbend.surrogates.support.trained_pressure_range`); None if unrecorded.
    rounds : list of dict, optional
        The verification's rounds when the surrogate was refined on its FEM sweeps
        (:meth:`softbend.design_search.rounds.Round.to_dict`, the first on the
        given surrogate); then this result is the last round's search.
    """

    spec: Specification
    candidates: list[Candidate]
    feasible: bool
    ranges: dict[str, ParameterRange]
    n_designs: int
    n_meeting: int
    n_passed_over: int
    front: np.ndarray
    model: str
    seconds: float
    verify_skipped: str | None = None
    verified_by: dict[str, Any] | None = None
    pressure_range: tuple[float, float] | None = None
    rounds: list[dict[str, Any]] | None = None

    @property
    def outside_pressures(self) -> list[float]:
        """The target's pressures outside :attr:`pressure_range` (its unit)."""
        from softbend.units import outside

        return outside(self.spec.target.pressures_mpa, self.pressure_range)

    def pressure_warning(self) -> str | None:
        """The target's pressures outside the model's trained range, and the range; else None."""
        outside = self.outside_pressures
        if not outside or self.pressure_range is None:
            return None
        from softbend.surrogates.support import pressures_text

        unit = self.spec.target.unit
        low, high = self.pressure_range
        return (
            f"{pressures_text(outside, unit)} lies outside the pressures the model was trained "
            f"on ({low:.4g}–{high:.4g} {unit}): its angles there are extrapolations"
        )

    def message(self) -> str | None:
        """One line when no design meets the target: the closest, and by how much it misses;
        and the target's pressures outside the model's trained range, if any."""
        if self.feasible:
            return None
        line = self._miss()
        outside = self.pressure_warning()
        return line if outside is None else f"{line[:-1]}; {outside}."

    def _miss(self) -> str:
        """What :meth:`message` says of the designs: none meets the target, or the closest."""
        space = self.spec.space
        if not self.candidates and self.n_designs == 0 and space.actuator.constraints:
            return (
                f"No design in the ranges searched meets the constraints of "
                f"{space.actuator.name} ({'; '.join(space.actuator.constraints)})."
            )
        if not self.candidates:
            return f"No design in the ranges searched meets {self.spec.target.describe()}."
        best = self.candidates[0]
        allowed = self.spec.target.tolerance_deg - self.spec.margin_deg
        return (
            f"No design in the ranges searched meets {self.spec.target.describe()}: the "
            f"closest, {best.design}, misses by {best.error_deg:.3g}° "
            f"({best.error_deg - allowed:.3g}° beyond the {allowed:g}° allowed)."
        )

    def to_dict(self) -> dict[str, Any]:
        """JSON-friendly: the specification, the search's figures and ``candidates``, best first.

        For another actuator than paper B's the ranges name its parameters with
        their unit (a categorical one its levels searched), the pressures are
        keyed by their unit (``pressure_kpa``), and ``actuator`` and
        ``pressure_unit`` say whose they are; a skipped ``--verify`` adds
        ``verified`` (null) and ``verify_skipped`` (why), a verification
        ``verified`` (its backend, FEM family and number of designs, and each
        verified candidate its ``fem_stop_reason``, null where the sweep
        reached the pressure). ``outside_pressure_range`` lists the target's
        pressures outside the model's trained range, with the range and its unit
        (null when all lie inside or the model records none).
        """
        space = self.spec.space
        target = self.spec.target
        out: dict[str, Any] = {
            "spec": {
                "name": self.spec.name,
                "target": target.describe(),
                "kind": target.kind,
                "angle_deg": _finite_or_none(target.angle_deg),
                pressure_key(target.unit): _finite_or_none(target.pressure_mpa),
                "tolerance_deg": target.tolerance_deg,
                "objectives": [str(o) for o in self.spec.objectives],
                "ranges": {n: _range_record(space, n, r) for n, r in self.ranges.items()},
            },
        }
        out["actuator"] = space.actuator.name
        out["pressure_unit"] = space.pressure_unit
        out.update(
            {
                "model": self.model,
                "feasible": self.feasible,
                "message": self.message(),
                "n_designs": self.n_designs,
                "n_meeting": self.n_meeting,
                "n_passed_over": self.n_passed_over,
                "search_s": self.seconds,
                "candidates": [c.to_dict() for c in self.candidates],
            }
        )
        out["outside_pressure_range"] = (
            {
                "pressures": self.outside_pressures,
                "trained_range": list(self.pressure_range),
                "unit": target.unit,
            }
            if self.outside_pressures and self.pressure_range is not None
            else None
        )
        if self.verify_skipped is not None:
            out["verified"] = None
            out["verify_skipped"] = self.verify_skipped
        elif self.verified_by is not None:
            out["verified"] = dict(self.verified_by)
        if self.rounds is not None:
            out["rounds"] = list(self.rounds)
        return out


def _range_record(space: SearchSpace, name: str, r: ParameterRange) -> dict[str, Any]:
    """A searched range for the JSON: low, high, step and unit, whole numbers as integers
    and a categorical parameter's levels."""
    kind = space.kind(name)
    if kind == "categorical":
        codes = [r.low] if r.fixed else r.values()
        return {"levels": [space.decode(name, c) for c in codes]}
    if kind == "integer":
        return {"low": round(r.low), "high": round(r.high), "step": round(r.step or 1.0)}
    return {"low": r.low, "high": r.high, "step": r.step, "unit": space.unit(name)}


def _finite_or_none(value: float) -> float | None:
    return float(value) if math.isfinite(value) else None
