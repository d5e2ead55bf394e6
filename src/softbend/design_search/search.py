"""Find the designs that meet a specification, on a surrogate: exhaustive on the mould's grid.

The parameters are those of the model's actuator
(:mod:`softbend.design_search.space`): paper B's six, or another description's
own, each on its kind's values (whole numbers, levels, multiples of a
resolution) and the designs kept to its constraints; pressures are in the
model's pressure unit.

A saved surrogate answers in microseconds, so every design of the grid of
manufacturable values (the step of each parameter, 0.5 mm by default: some
2.7 million designs over Table 1's box) is scored, which is exact on that grid
and faster than any sampler would converge: an MLP is screened in float32
(:meth:`load_predictor <softbend.surrogates.predict.load_predictor>`), and the
designs that rank are scored again in float64. A parameter searched
continuously (step 0) is screened on a grid of :data:`CONTINUOUS_POINTS` values
and the best designs are then polished by SciPy's bounded Powell method.

Among the designs that meet the target (within its tolerance), the
objectives rank them: one objective sorts them (the miss of the target breaks
ties), several give the Pareto front (best first by the first objective,
then the next front). Every answer lies in the model's training ranges and
its support (:mod:`softbend.surrogates.support`: a pressure the training
designs nearest to it were swept to, an angle no larger than the largest
trained on); designs outside are passed over, or with
``allow_extrapolation`` kept and flagged. When no design meets the target,
the closest designs are returned with how far they miss.
"""

from __future__ import annotations

import dataclasses
import itertools
import math
import os
import re
import time
from collections.abc import Callable, Mapping
from dataclasses import dataclass, field
from typing import TYPE_CHECKING, Any, Protocol

import numpy as np

from softbend._validation import must_be
from softbend.design import SFRBADesign
from softbend.design_search.space import ActuatorDesign, SearchSpace, pressure_key, space_of
from softbend.design_search.spec import (
    ParameterRange,
    Specification,
)
from softbend.errors import InputError
from softbend.parameters import Range

if TYPE_CHECKING:
    from softbend.actuators import Actuator
    from softbend.surrogates.persistence import SavedState, SavedSurrogate
    from softbend.surrogates.support import Support

__all__ = [
    "CONTINUOUS_POINTS",
    "MAX_DESIGNS",
    "TOP",
    "TOP_CONTINUOUS",
    "Candidate",
    "LoadedModel",
    "Predictor",
    "SearchResult",
    "elastomer_volume_mm3",
    "find_designs",
    "grid_size",
    "pareto_front",
    "searched_ranges",
]

#: Values a continuous parameter is screened at before the best designs are polished.
CONTINUOUS_POINTS = 17

#: The most designs one search scores (a larger grid: a larger step, or narrower ranges).
MAX_DESIGNS = 20_000_000

#: The candidates one search lists (``top``).
TOP = Range(
    1,
    1000,
    "candidates",
    "a shortlist: each is scored again in float64, checked against the training data, "
    "written and drawn; every design of the grid is scored whatever the shortlist",
)

#: The candidates a search with a continuous parameter (step 0) lists.
TOP_CONTINUOUS = Range(
    1,
    25,
    "candidates",
    "each of the best 4 × top designs is polished by an optimisation of its own, about a "
    "second each",
)

#: Rows per evaluation chunk (memory: about 70 MB of activations for an MLP).
CHUNK = 1 << 17

#: Designs whose support is checked at once, ahead of listing them.
_AHEAD = 64

#: Pressure step of the finite difference of the sensitivity dθ/dp, MPa.
_DP = 0.0025


@dataclass
class Candidate:
    """A design scored against a specification.

    Attributes
    ----------
    design : SFRBADesign or ActuatorDesign
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

    design: SFRBADesign | ActuatorDesign
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


def elastomer_volume_mm3(designs: np.ndarray) -> np.ndarray:
    """Elastomer of each design (rows of 6: l, r, t, b, φ, lc), mm³.

    The half-cylindrical wall ``½·π·((r+t)² − r²)·l``, the strain-limiting layer
    ``2·(r+t)·b·l`` under it, and the two end caps ``π·(r+t)²/2·lc`` (the
    geometry of :class:`~softbend.design.SFRBADesign`, fibres neglected).
    """
    d = np.atleast_2d(np.asarray(designs, dtype=np.float64))
    length, r, t, b, lc = d[:, 0], d[:, 1], d[:, 2], d[:, 3], d[:, 5]
    outer = r + t
    wall = 0.5 * np.pi * (outer**2 - r**2) * length
    layer = 2.0 * outer * b * length
    caps = 0.5 * np.pi * outer**2 * lc
    return wall + layer + caps


def pareto_front(values: np.ndarray) -> np.ndarray:
    """Indices of the rows of ``values`` (n × k, all minimised) that no other row dominates.

    Sorted by the first column (then the others); ties keep the first; NaN counts
    as the worst value. Vectorised: one pass over the rows left per member of the
    front (a running minimum for two columns).
    """
    v = np.asarray(values, dtype=np.float64)
    if v.shape[0] == 0:
        return np.zeros(0, dtype=np.intp)
    v = np.where(np.isnan(v), np.inf, v)
    order = np.lexsort(v.T[::-1])
    ranked = v[order]
    if v.shape[1] == 1:
        return order[:1].astype(np.intp)
    if v.shape[1] == 2:
        best = np.minimum.accumulate(ranked[:, 1])
        keep = np.ones(ranked.shape[0], dtype=bool)
        keep[1:] = ranked[1:, 1] < best[:-1]
        return order[keep].astype(np.intp)
    # A row is on the front unless an earlier one (in this order) is no worse anywhere:
    # the rows before ``i`` left are all on the front, so each pass keeps them.
    alive = np.arange(ranked.shape[0])
    i = 0
    while i < alive.size:
        rows = ranked[alive]
        better = np.any(rows < rows[i], axis=1)
        better[: i + 1] = True
        alive = alive[better]
        i += 1
    return order[alive].astype(np.intp)


def grid_size(ranges: Mapping[str, ParameterRange]) -> int:
    """The designs of the grid of ``ranges`` (every parameter's), counted without building it.

    A fixed parameter counts once, a continuous one :data:`CONTINUOUS_POINTS`
    times (its screening grid), a stepped one :meth:`ParameterRange.count` times.
    """
    return math.prod(_axis_size(r) for r in ranges.values())


def _axis_size(r: ParameterRange) -> int:
    if r.fixed:
        return 1
    return CONTINUOUS_POINTS if r.step == 0 else r.count()


def searched_ranges(
    spec: Specification,
    training_ranges: Mapping[str, Any] | None,
    *,
    allow_extrapolation: bool = False,
    top: int | None = None,
) -> tuple[dict[str, ParameterRange], int]:
    """Every parameter's range a search of ``spec`` scores, and the designs of its grid.

    Checked before anything is built or scored, so that a command refuses a
    search it cannot finish at once.

    Parameters
    ----------
    spec : Specification
    training_ranges : dict, optional
        The model's training ranges (``metadata["training_ranges"]``).
    allow_extrapolation : bool, default False
        As :func:`find_designs`.
    top : int, optional
        The candidates to list, held to :data:`TOP_CONTINUOUS` when a parameter
        is searched continuously.

    Returns
    -------
    (dict of str to ParameterRange, int)

    Raises
    ------
    ValueError
        As :meth:`Specification.resolved`; a grid over :data:`MAX_DESIGNS`
        (counted arithmetically, naming each parameter's count and step); ranges
        in which no design of paper B's actuator has a wall thinner than its
        radius (t < r); a ``top`` over :data:`TOP_CONTINUOUS` with a continuous
        parameter.
    """
    ranges = spec.resolved(
        training_ranges if isinstance(training_ranges, dict) else None,
        allow_extrapolation=allow_extrapolation,
    )
    total = grid_size(ranges)
    space = spec.space
    units = space.units
    if total > MAX_DESIGNS:
        shown = f"{total:,}" if total < 10**15 else f"{float(total):.3g}"
        counts = ", ".join(
            f"{n} {_axis_size(r):,}"
            + (
                ""
                if r.fixed
                else f" at {r.step:g} {units[n]}".rstrip()
                if r.step
                else " (continuous)"
            )
            for n, r in ranges.items()
            if not r.fixed
        )
        raise InputError(
            f"The ranges and steps hold {shown} designs ({counts}), more than the "
            f"{MAX_DESIGNS:,} one search scores; coarsen the resolution or narrow the ranges "
            "(range, fix)",
            key="steps",
        )
    _check_constraints(space, ranges)
    continuous = [n for n, one in ranges.items() if not one.fixed and one.step == 0]
    if continuous and top is not None and not TOP_CONTINUOUS.contains(top):
        raise InputError(
            must_be(
                f"at most {TOP_CONTINUOUS.high:g} with a continuous parameter "
                f"({', '.join(continuous)}: step 0; {TOP_CONTINUOUS.why})",
                top,
            ),
            key="top",
        )
    return ranges, total


def _check_constraints(space: SearchSpace, ranges: Mapping[str, ParameterRange]) -> None:
    """Refuse ranges in which no design meets a constraint of the actuator's description.

    Each constraint is read at the corners of the ranges of the parameters it names
    (exact for a comparison linear, or monotone, in each of them), and shown in the
    names of the search (paper B's ``t < r``).

    Raises
    ------
    ValueError
        Naming the constraint and the parameters whose ranges to widen.
    """
    actuator = space.actuator
    for text in actuator.constraints:
        named = [c for c in actuator.names if re.search(rf"\b{c}\b", text)]
        choices = [
            (ranges[n].low, ranges[n].high) if c in named else (ranges[n].low,)
            for n, c in zip(space.names, space.columns, strict=True)
        ]
        corners = np.array(list(itertools.product(*choices)), dtype=float)
        one = dataclasses.replace(actuator, constraints=(text,))
        if one.constraints_met(corners).any():
            continue
        shown = text
        for column, name in zip(space.columns, space.names, strict=True):
            shown = re.sub(rf"\b{column}\b", name, shown)
        names = [n for n, c in zip(space.names, space.columns, strict=True) if c in named]
        raise ValueError(
            f"No design of the ranges meets {shown} (a constraint of the actuator "
            f"{actuator.name}); widen the ranges of {' or '.join(names)}."
        )


class _Scorer:
    """The target's angle, miss and pressure of rows of designs, from a predictor."""

    def __init__(self, predict: Callable[[np.ndarray], np.ndarray], spec: Specification):
        self.predict = predict
        self.target = spec.target
        self.need_sensitivity = any(o.name == "sensitivity" for o in spec.objectives)
        # the finite difference's step in the target's unit (MPa: _DP itself)
        self.dp = _DP if spec.target.unit == "MPa" else _DP / spec.space.to_mpa

    def _angles(self, designs: np.ndarray, pressure: float | np.ndarray) -> np.ndarray:
        d = designs.shape[1]
        rows = np.empty((designs.shape[0], d + 1))
        rows[:, :d] = designs
        rows[:, d] = pressure
        return np.asarray(self.predict(rows), dtype=np.float64)

    def score(self, designs: np.ndarray) -> dict[str, np.ndarray]:
        """``angle``, ``error``, ``pressure`` (and ``sensitivity``) per design row."""
        target = self.target
        if target.kind == "curve":
            misses = [np.abs(self._angles(designs, p) - a) for p, a in target.points]
            angle = self._angles(designs, target.points[-1][0])
            error = np.max(misses, axis=0)
            pressure = np.full(designs.shape[0], target.points[-1][0])
        elif target.kind == "pressure_for":
            pressure, angle = self._pressure_for(designs)
            error = np.abs(angle - target.angle_deg)
        else:
            pressure = np.full(designs.shape[0], target.pressure_mpa)
            angle = self._angles(designs, target.pressure_mpa)
            error = (
                np.zeros_like(angle)
                if target.kind == "max_angle"
                else np.abs(angle - target.angle_deg)
            )
        out = {"angle": angle, "error": error, "pressure": pressure}
        if self.need_sensitivity:
            p = pressure if target.kind == "pressure_for" else target.pressure_mpa
            dp = self.dp
            lo = self._angles(designs, np.maximum(p - dp, 0.0))
            hi = self._angles(designs, p + dp)
            out["sensitivity"] = (hi - lo) / (np.minimum(p, dp) + dp)
        return out

    def _pressure_for(self, designs: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
        """The lowest pressure up to the limit that reaches the angle (bisection on a
        rising θ(p), to 1e-5 of the limit); NaN and the angle at the limit where it is
        not reached."""
        limit = self.target.pressure_mpa
        goal = self.target.angle_deg
        at_limit = self._angles(designs, limit)
        reached = np.flatnonzero(at_limit >= goal)
        pressure = np.full(designs.shape[0], np.nan)
        angle = at_limit.copy()
        if reached.size:
            rows = designs[reached]
            low = np.zeros(reached.size)
            high = np.full(reached.size, limit)
            for _ in range(17):  # 2**-17 of the limit: below a regulator's resolution
                mid = 0.5 * (low + high)
                above = self._angles(rows, mid) >= goal
                high = np.where(above, mid, high)
                low = np.where(above, low, mid)
            pressure[reached] = high
            angle[reached] = self._angles(rows, high)
        return pressure, angle


def _objective_matrix(
    spec: Specification, designs: np.ndarray, scores: Mapping[str, np.ndarray]
) -> np.ndarray:
    """Each objective per design, signed so that smaller is better."""
    columns = []
    names = spec.space.names
    for objective in spec.objectives:
        if objective.name in names:
            value = designs[:, names.index(objective.name)]
        elif objective.name == "volume":
            value = elastomer_volume_mm3(designs)
        else:
            value = scores[objective.name]
        columns.append(value if objective.sense == "min" else -value)
    return np.column_stack(columns)


def _objective_values(
    spec: Specification, design: np.ndarray, scores: Mapping[str, float]
) -> dict[str, float]:
    out = {}
    names = spec.space.names
    for objective in spec.objectives:
        if objective.name in names:
            out[objective.name] = float(design[names.index(objective.name)])
        elif objective.name == "volume":
            out["volume"] = float(elastomer_volume_mm3(design)[0])
        else:
            out[objective.name] = float(scores[objective.name])
    return out


def _grid(ranges: Mapping[str, ParameterRange]) -> list[np.ndarray]:
    """The values of each parameter, in the order of ``ranges`` (the model's inputs)."""
    axes = []
    for r in ranges.values():
        if r.fixed:
            axes.append(np.array([r.low]))
        elif r.step == 0:
            axes.append(np.linspace(r.low, r.high, CONTINUOUS_POINTS))
        else:
            axes.append(np.asarray(r.values()))
    return axes


def _designs_at(axes: list[np.ndarray], flat: np.ndarray) -> np.ndarray:
    index = np.unravel_index(flat, tuple(a.size for a in axes))
    return np.column_stack([a[i] for a, i in zip(axes, index, strict=True)])


class Predictor(Protocol):
    """What a search asks of a model: the angles (deg) of rows of its inputs.

    :func:`~softbend.surrogates.predict.load_predictor` gives one; an MLP's also
    has ``predict32`` (float32, for screening) and a model with intervals
    ``predict_interval``.
    """

    def predict(self, X: np.ndarray) -> np.ndarray:
        """Angles (deg) of the rows ``X`` (the model's inputs, pressure last)."""
        ...


@dataclass(frozen=True)
class LoadedModel:
    """A saved surrogate read once: its file, its fastest predictor and its record.

    :meth:`load` reads it; :func:`find_designs` takes one (or a path, read then),
    so that a command that searches several specifications and draws the
    answers reads the file once.
    """

    path: str
    predictor: Predictor
    saved: SavedState | SavedSurrogate

    @classmethod
    def load(cls, path: str | os.PathLike[str]) -> LoadedModel:
        """Read the saved surrogate at ``path``, as
        :func:`~softbend.surrogates.predict.load_predictor`."""
        from softbend.surrogates.predict import load_predictor

        predictor, saved = load_predictor(path)
        return cls(os.fspath(path), predictor, saved)

    @property
    def actuator(self) -> Actuator:
        """The description of the actuator the model was trained on."""
        return self.saved.actuator

    @property
    def metadata(self) -> dict[str, Any]:
        """The file's metadata (training ranges, support, interval)."""
        return self.saved.metadata


def find_designs(
    model: str | os.PathLike[str] | LoadedModel,
    spec: Specification,
    *,
    top: int = 10,
    allow_extrapolation: bool = False,
    distinct: bool = True,
    progress: Callable[[int, int], None] | None = None,
) -> SearchResult:
    """The designs that best meet ``spec`` on the saved surrogate ``model``.

    Parameters
    ----------
    model : path or LoadedModel
        A saved surrogate (:func:`softbend.surrogates.save_surrogate`, a refined
        one of ``softbend transfer refine`` included), or one read already.
    spec : Specification
    top : int, default 10
        Candidates returned, >= 1.
    allow_extrapolation : bool, default False
        Let ranges leave the model's training ranges and keep designs outside
        its training data's support, flagged, instead of passing them over.
    distinct : bool, default True
        List only designs that differ from every better-ranked one by more than
        one step in some parameter (a neighbour on the grid is nearly the same
        actuator); False lists every design in rank order.
    progress : callable, optional
        ``progress(done, total)`` in designs scored.

    Returns
    -------
    SearchResult

    Raises
    ------
    ValueError
        A range outside the training ranges (without ``allow_extrapolation``),
        a grid over :data:`MAX_DESIGNS` (:func:`searched_ranges`), a ``top``
        outside :data:`TOP` (:data:`TOP_CONTINUOUS` with a continuous parameter),
        a specification of another actuator than the model's.

    Notes
    -----
    Designs of the grid whose wall is not thinner than their radius (t >= r)
    are not actuators: they are left out of the scores and of ``n_designs``;
    for another actuator, the designs that break a constraint of its description.
    """
    if isinstance(top, bool) or not isinstance(top, int) or not TOP.contains(top):
        raise InputError(must_be(f"an integer in {TOP.describe()} ({TOP.why})", top), key="top")
    start = time.perf_counter()
    loaded = model if isinstance(model, LoadedModel) else LoadedModel.load(model)
    _check_actuator(spec, loaded)
    return _find(
        loaded,
        spec,
        top=top,
        allow_extrapolation=allow_extrapolation,
        distinct=distinct,
        progress=progress,
        start=start,
    )


def _check_actuator(spec: Specification, model: LoadedModel) -> None:
    """Refuse a specification of another actuator than the model's, naming both."""
    space, actuator = spec.space, model.actuator
    if space == space_of(actuator):
        return
    mine = "paper B's actuator" if space.paper_b else f"the actuator {space.actuator.name}"
    raise ValueError(
        f"The specification {spec.name!r} names the parameters of {mine} "
        f"({space.listing()}), but the model {model.path} is of the actuator {actuator.name} "
        f"({', '.join(actuator.names)}); give the specification that actuator "
        "(Specification(..., actuator=...), as the model records it)."
    )


def _find(
    model: LoadedModel,
    spec: Specification,
    *,
    top: int,
    allow_extrapolation: bool,
    distinct: bool,
    progress: Callable[[int, int], None] | None,
    start: float,
) -> SearchResult:
    """:func:`find_designs` once the model is loaded (within its actuator's inputs)."""
    from softbend._progress import report
    from softbend.surrogates.features import outside_training_ranges
    from softbend.surrogates.support import Support, trained_pressure_range

    predictor, metadata = model.predictor, model.metadata
    space = spec.space
    training = metadata.get("training_ranges")
    ranges, total = searched_ranges(
        spec, training, allow_extrapolation=allow_extrapolation, top=top
    )
    axes = _grid(ranges)
    exact = predictor.predict
    screen = getattr(predictor, "predict32", exact)
    scorer = _Scorer(screen, spec)
    tolerance = spec.target.tolerance_deg - spec.margin_deg
    error = np.empty(total)
    valid = np.empty(total, dtype=bool)
    objectives = np.empty((total, len(spec.objectives)))
    for first in range(0, total, CHUNK):
        flat = np.arange(first, min(first + CHUNK, total))
        designs = _designs_at(axes, flat)
        valid[flat] = space.feasible(designs)
        with np.errstate(all="ignore"):
            scores = scorer.score(designs)
            error[flat] = scores["error"]
            objectives[flat] = _objective_matrix(spec, designs, scores)
        done = int(flat[-1]) + 1
        report("scoring designs", done, total)
        if progress is not None:
            progress(done, total)
    error = np.where(np.isfinite(error), error, np.inf)
    meeting = np.flatnonzero((error <= tolerance + 1e-3) & valid)  # float64 decides the edge
    feasible_screen = meeting.size > 0
    if feasible_screen:
        order = _ranked(objectives[meeting], error[meeting])
        ranked = meeting[order]
    else:
        ranked = np.argsort(error, kind="stable")
        ranked = ranked[valid[ranked]]
    support = (
        Support.from_dict(metadata["support"])
        if isinstance(metadata.get("support"), dict)
        else None
    )
    exact_scorer = _Scorer(exact, spec)
    interval = _interval_of(predictor, metadata)
    candidates: list[Candidate] = []
    passed_over = 0
    continuous = [n for n in space.names if not ranges[n].fixed and ranges[n].step == 0]
    listed = _Listed(ranges, space)
    for first in range(0, ranked.size, 4 * top):
        batch = ranked[first : first + 4 * top]
        designs = _designs_at(axes, batch)
        if continuous and feasible_screen:
            designs = _polish(designs, exact_scorer, spec, ranges, continuous)
        with np.errstate(all="ignore"):
            scores = exact_scorer.score(designs)
        meets_all = np.isfinite(scores["error"]) & (scores["error"] <= tolerance)
        rows = np.flatnonzero((meets_all | (not feasible_screen)) & space.feasible(designs))
        cells = listed.cells_of(designs)
        outside = np.zeros(designs.shape[0], dtype=bool)
        known = np.zeros(designs.shape[0], dtype=bool)
        for position, row in enumerate(rows):
            design = designs[row]
            if distinct and listed.near(design, cells[row]):
                continue
            if not known[row]:  # the support of the next rows that may be listed, at once
                ahead = np.array(
                    [
                        r
                        for r in rows[position : position + _AHEAD]
                        if not known[r] and not (distinct and listed.near(designs[r], cells[r]))
                    ]
                )
                picked = {k: np.asarray(v)[ahead] for k, v in scores.items()}
                outside[ahead] = _outside_mask(designs[ahead], picked, spec, training, support)
                known[ahead] = True
            one = {k: float(v[row]) for k, v in scores.items()}
            flags: list[str] = []
            if outside[row]:
                flags = _flags(design, one, spec, training, support, outside_training_ranges)
                if flags and not allow_extrapolation:
                    passed_over += 1
                    continue
            if distinct:
                listed.add(design, cells[row])
            candidates.append(
                Candidate(
                    design=space.design_of(design.tolist()),
                    angle_deg=one["angle"],
                    pressure_mpa=one["pressure"],
                    error_deg=one["error"],
                    meets=bool(meets_all[row]),
                    objectives=_objective_values(spec, design, one),
                    interval_deg=interval(design, one),
                    flags=flags,
                    pressure_unit=space.pressure_unit,
                )
            )
        if len(candidates) >= 2 * top:
            break
    feasible = any(c.meets for c in candidates)
    candidates = _final_order(candidates, spec, feasible)[:top]
    front = np.zeros((0, len(spec.objectives)))
    if feasible_screen:
        signs = np.array([1.0 if o.sense == "min" else -1.0 for o in spec.objectives])
        front_idx = pareto_front(objectives[meeting])
        front = objectives[meeting][front_idx] * signs
    return SearchResult(
        spec=spec,
        candidates=candidates,
        feasible=feasible,
        ranges=ranges,
        n_designs=int(np.count_nonzero(valid)),
        n_meeting=int(meeting.size),
        n_passed_over=passed_over,
        front=front,
        model=model.path,
        seconds=time.perf_counter() - start,
        pressure_range=trained_pressure_range(metadata, spec.space.actuator.pressure_column),
    )


def _ranked(objectives: np.ndarray, error: np.ndarray) -> np.ndarray:
    """Order of the meeting designs: by the one objective (the miss breaks ties), or
    Pareto fronts one after another, each by its first objective."""
    if objectives.shape[1] == 1:
        return np.lexsort((error, objectives[:, 0]))
    remaining = np.arange(objectives.shape[0])
    order: list[np.ndarray] = []
    collected = 0
    while remaining.size and collected < 2000:
        on_front = pareto_front(objectives[remaining])
        order.append(remaining[on_front])
        collected += on_front.size
        left = np.ones(remaining.size, dtype=bool)
        left[on_front] = False
        remaining = remaining[left]
    rest = remaining[np.lexsort((error[remaining], objectives[remaining, 0]))]
    return np.concatenate([*order, rest])


def _final_order(
    candidates: list[Candidate], spec: Specification, feasible: bool
) -> list[Candidate]:
    """The candidates re-ranked on their float64 figures."""
    if not feasible:
        return sorted((c for c in candidates), key=lambda c: c.error_deg)
    meeting = [c for c in candidates if c.meets]
    signs = [1.0 if o.sense == "min" else -1.0 for o in spec.objectives]
    values = np.array(
        [
            [s * c.objectives[o.name] for s, o in zip(signs, spec.objectives, strict=True)]
            for c in meeting
        ]
    ).reshape(len(meeting), len(signs))
    errors = np.array([c.error_deg for c in meeting])
    return [meeting[i] for i in _ranked(values, errors)]


class _Listed:
    """The designs listed so far, filed by grid cell, so that whether a design lies one
    step from one of them (within a step in every parameter) is a lookup, not a scan.

    A design's cell is its index on the grid of each stepped parameter, one
    number in mixed radix; a listed design files every cell within one index of
    its own, so a design one step from it finds its own cell filed. On a grid
    that is the rule exactly. A continuous parameter (polished values) takes no
    part in the cell: a filed cell is then checked against the listed designs.
    For another actuator than paper B's, a continuous parameter's step is that of
    its screening grid (polished designs that met at one optimum are one design)
    and a categorical one has no neighbours (another level is another actuator).
    """

    def __init__(self, ranges: Mapping[str, ParameterRange], space: SearchSpace | None = None):
        names = list(ranges) if space is None else list(space.names)
        chosen = [ranges[n] for n in names]
        stepped = np.array([not r.fixed and r.step > 0 for r in chosen])
        # another level is another actuator: a categorical parameter has no neighbours
        levels = np.array([space is not None and space.kind(n) == "categorical" for n in names])
        self.low = np.array([r.low for r in chosen])
        self.step = np.where(stepped, [r.step for r in chosen], 1.0)
        self.stepped = stepped
        self.exact = not any(not r.fixed and r.step == 0 for r in chosen)
        steps = [
            (r.high - r.low) / (CONTINUOUS_POINTS - 1) if not r.fixed and r.step == 0 else r.step
            for r in chosen
        ]
        self.tolerance = np.where(levels, 0.0, steps) + 1e-9
        # Indices run from -1 to count: radix count + 2, so no neighbour wraps around.
        sizes = np.array([r.count() + 2 if s else 1 for r, s in zip(chosen, stepped, strict=True)])
        self.radix = np.concatenate([[1], np.cumprod(sizes[:-1])]).astype(np.int64)
        dims = np.flatnonzero(stepped & ~levels)
        offsets = np.zeros((3**dims.size, len(names)), dtype=np.int64)
        grids = np.meshgrid(*([np.array([-1, 0, 1])] * dims.size), indexing="ij")
        for k, grid in zip(dims, grids, strict=True):
            offsets[:, k] = grid.ravel()
        self.neighbours = offsets @ self.radix
        self.filed: set[int] = set()
        self.designs: list[np.ndarray] = []

    def cells_of(self, designs: np.ndarray) -> np.ndarray:
        """The cell of each row of ``designs`` (one integer each)."""
        index = np.where(self.stepped, np.rint((designs - self.low) / self.step) + 1, 0.0)
        return index.astype(np.int64) @ self.radix

    def near(self, design: np.ndarray, cell: np.int64) -> bool:
        """Whether ``design`` (in ``cell``) lies within a step of a listed design."""
        if int(cell) not in self.filed:
            return False
        if self.exact:
            return True
        listed = np.asarray(self.designs)
        return bool(np.any(np.all(np.abs(listed - design) <= self.tolerance, axis=1)))

    def add(self, design: np.ndarray, cell: np.int64) -> None:
        """List ``design`` (in ``cell``)."""
        self.filed.update((self.neighbours + cell).tolist())
        self.designs.append(design)


def _outside_mask(
    designs: np.ndarray,
    scores: Mapping[str, np.ndarray],
    spec: Specification,
    training: object,
    support: Support | None,
) -> np.ndarray:
    """Which rows :func:`_flags` would flag, for a batch at once (the same comparisons)."""
    n = designs.shape[0]
    target = spec.target
    if target.kind == "pressure_for":
        reached = np.asarray(scores["pressure"], dtype=np.float64)
        low = high = np.where(np.isfinite(reached), reached, target.pressure_mpa)
    else:
        low = np.full(n, min(target.pressures_mpa))
        high = np.full(n, max(target.pressures_mpa))
    flagged = np.zeros(n, dtype=bool)
    if isinstance(training, dict):
        for j, name in enumerate(spec.space.features):
            if name not in training:
                continue
            lo, hi = (float(v) for v in training[name])
            first, last = (designs[:, j], designs[:, j]) if j < designs.shape[1] else (low, high)
            flagged |= (first < lo) | (last > hi)
    if support is not None:
        flagged |= high > support.max_pressure(designs) * (1 + 1e-9) + 1e-12
        flagged |= np.asarray(scores["angle"], dtype=np.float64) > support.angle_limit_deg
    return flagged


def _flags(
    design: np.ndarray,
    scores: Mapping[str, float],
    spec: Specification,
    training: object,
    support: Support | None,
    outside: Callable[[dict[str, list[float]], np.ndarray], list[str]],
) -> list[str]:
    """Why a design's answer lies outside the model's training data (empty inside)."""
    pressures = [p for p in spec.target.pressures_mpa]
    if spec.target.kind == "pressure_for" and math.isfinite(scores["pressure"]):
        pressures = [scores["pressure"]]
    rows = np.column_stack([np.tile(design, (len(pressures), 1)), pressures])
    flags = outside(training, rows) if isinstance(training, dict) else []
    if support is not None:
        angles = np.full(len(pressures), scores["angle"])
        flags += support.beyond(rows, angles)
    return flags


def _interval_of(
    predictor: Predictor, metadata: Mapping[str, Any]
) -> Callable[[np.ndarray, Mapping[str, float]], tuple[float, float] | None]:
    """The 90 % interval of a candidate's angle: the calibrated one a refined model
    records, else the model's own, else None."""
    from softbend.surrogates.predict import INTERVAL_LEVEL, calibrated_interval

    record = metadata.get("interval")
    own = getattr(predictor, "predict_interval", None)

    def interval(design: np.ndarray, scores: Mapping[str, float]) -> tuple[float, float] | None:
        angle = np.array([scores["angle"]])
        calibrated = calibrated_interval(record, angle)
        if calibrated is not None:
            return float(calibrated[0][0]), float(calibrated[1][0])
        if callable(own) and math.isfinite(scores["pressure"]):
            row = np.append(design, scores["pressure"])[None, :]
            low, high = own(row, INTERVAL_LEVEL)
            return float(np.asarray(low)[0]), float(np.asarray(high)[0])
        return None

    return interval


def _polish(
    designs: np.ndarray,
    scorer: _Scorer,
    spec: Specification,
    ranges: Mapping[str, ParameterRange],
    continuous: list[str],
) -> np.ndarray:
    """Each design moved, in its continuous parameters, to the best of its first objective
    that still meets the target (SciPy's bounded Powell from the grid point)."""
    from scipy.optimize import minimize

    space = spec.space
    which = [space.names.index(n) for n in continuous]
    bounds = [(ranges[n].low, ranges[n].high) for n in continuous]
    tolerance = spec.target.tolerance_deg - spec.margin_deg
    first = spec.objectives[0]
    scale = {n: max(ranges[n].high - ranges[n].low, 1e-9) for n in continuous}
    out = designs.copy()
    for k, design in enumerate(designs):

        def cost(x: np.ndarray, design: np.ndarray = design) -> float:
            trial = design.copy()
            trial[which] = x
            if not space.feasible(trial[None, :])[0]:
                return 1e12
            with np.errstate(all="ignore"):
                scores = scorer.score(trial[None, :])
            miss = float(scores["error"][0])
            if not math.isfinite(miss):
                return 1e12
            value = _objective_matrix(spec, trial[None, :], scores)[0, 0]
            if first.name == "error":
                return float(value)
            return float(value) + 1e3 * max(0.0, miss - 0.999 * tolerance)

        result = minimize(
            cost,
            design[which],
            method="Powell",
            bounds=bounds,
            options={"xtol": 1e-4 * min(scale.values()), "maxfev": 400},
        )
        if cost(result.x) <= cost(design[which]):
            out[k, which] = result.x
    if not space.paper_b:  # a polished value ends on the resolution its description declares
        for j, name in zip(which, continuous, strict=True):
            out[:, j] = space.snap(name, out[:, j], ranges[name].low, ranges[name].high)
    return out
