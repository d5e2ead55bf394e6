"""Find the designs that meet a specification, on a surrogate: exhaustive on the mould's grid.

The parameters are those of the model's actuator
(:mod:`softbend.design_search.space`): paper B's six, or another description's
own, each on its kind's values (whole numbers, levels, multiples of a
resolution) and the designs kept to its constraints; pressures are in the
model's pressure unit.

The grid and its ranking are :mod:`.grid`'s, the answer's records :mod:`.result`'s.

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

import math
import os
import time
from collections.abc import Callable, Mapping
from dataclasses import dataclass
from typing import TYPE_CHECKING, Any, Protocol

import numpy as np

from softbend._validation import must_be
from softbend.design_search.grid import (
    CONTINUOUS_POINTS,
    MAX_DESIGNS,
    TOP_CONTINUOUS,
    Listed,
    designs_at,
    grid_axes,
    grid_size,
    pareto_front,
    rank_order,
    searched_ranges,
)
from softbend.design_search.result import Candidate, SearchResult
from softbend.design_search.space import space_of
from softbend.design_search.spec import ParameterRange, Specification, search_resolution
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

#: The candidates one search lists (``top``).
TOP = Range(
    1,
    1000,
    "candidates",
    "a shortlist: each is scored again in float64, checked against the training data, "
    "written and drawn; every design of the grid is scored whatever the shortlist",
)

#: Rows per evaluation chunk (memory: about 70 MB of activations for an MLP).
CHUNK = 1 << 17

#: Designs whose support is checked at once, ahead of listing them.
_AHEAD = 64

#: Pressure step of the finite difference of the sensitivity dθ/dp, MPa.
_DP = 0.0025


def elastomer_volume_mm3(actuator: Actuator, designs: np.ndarray) -> np.ndarray:
    """Elastomer of each design (rows of the actuator's parameters), mm³, from its description
    (:attr:`~softbend.actuators.Actuator.elastomer_volume`; paper B's wall, layer and caps).

    Raises
    ------
    InputError
        When the description gives no elastomer volume (key ``objectives``).
    """
    volume = actuator.elastomer_volume
    if volume is None:
        raise InputError(
            f"The actuator {actuator.name} gives no elastomer volume of its designs: "
            "the objective 'volume' is not available for it.",
            key="objectives",
        )
    return volume(np.atleast_2d(np.asarray(designs, dtype=np.float64)))


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
            value = elastomer_volume_mm3(spec.space.actuator, designs)
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
            out["volume"] = float(elastomer_volume_mm3(spec.space.actuator, design)[0])
        else:
            out[objective.name] = float(scores[objective.name])
    return out


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
    Designs of the grid that break a constraint of the actuator's description
    (paper B's: a wall not thinner than the radius, t >= r) are not actuators:
    they are left out of the scores and of ``n_designs``.
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
    mine = f"the actuator {space.actuator.name} ({space.actuator.title})"
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
    axes = grid_axes(ranges)
    exact = predictor.predict
    screen = getattr(predictor, "predict32", exact)
    scorer = _Scorer(screen, spec)
    tolerance = spec.target.tolerance_deg - spec.margin_deg
    error = np.empty(total)
    valid = np.empty(total, dtype=bool)
    objectives = np.empty((total, len(spec.objectives)))
    for first in range(0, total, CHUNK):
        flat = np.arange(first, min(first + CHUNK, total))
        designs = designs_at(axes, flat)
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
        order = rank_order(objectives[meeting], error[meeting])
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
    listed = Listed(ranges, space)
    for first in range(0, ranked.size, 4 * top):
        batch = ranked[first : first + 4 * top]
        designs = designs_at(axes, batch)
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
    return [meeting[i] for i in rank_order(values, errors)]


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
    for j, name in zip(which, continuous, strict=True):  # ends on the resolution searched
        if search_resolution(space, name) is not None:
            out[:, j] = space.snap(name, out[:, j], ranges[name].low, ranges[name].high)
    return out
