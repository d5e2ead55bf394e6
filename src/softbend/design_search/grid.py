"""The grid a design search scores: its ranges checked and counted, its designs, their ranking.

:func:`searched_ranges` resolves a specification's ranges and refuses, before
anything is built, a grid over :data:`MAX_DESIGNS`, ranges in which no design
meets a constraint of the actuator's description, and a long list with a
continuous parameter; :func:`grid_axes` and :func:`designs_at` build the grid's
designs chunk by chunk; :func:`pareto_front` and :func:`rank_order` order the
designs that meet the target, and :class:`Listed` keeps the listed designs
distinct (more than a step apart).
"""

from __future__ import annotations

import dataclasses
import itertools
import math
import re
from collections.abc import Mapping
from typing import Any

import numpy as np

from softbend._validation import must_be
from softbend.design_search.space import SearchSpace
from softbend.design_search.spec import ParameterRange, Specification
from softbend.errors import InputError
from softbend.parameters import Range

__all__ = [
    "CONTINUOUS_POINTS",
    "MAX_DESIGNS",
    "TOP_CONTINUOUS",
    "Listed",
    "designs_at",
    "grid_axes",
    "grid_size",
    "pareto_front",
    "rank_order",
    "searched_ranges",
]

#: Values a continuous parameter is screened at before the best designs are polished.
CONTINUOUS_POINTS = 17

#: The most designs one search scores (a larger grid: a larger step, or narrower ranges).
MAX_DESIGNS = 20_000_000

#: The candidates a search with a continuous parameter (step 0) lists.
TOP_CONTINUOUS = Range(
    1,
    25,
    "candidates",
    "each of the best 4 × top designs is polished by an optimisation of its own, about a "
    "second each",
)


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
        in which no design meets a constraint of the actuator's description
        (paper B's t < r); a ``top`` over :data:`TOP_CONTINUOUS` with a continuous
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


def grid_axes(ranges: Mapping[str, ParameterRange]) -> list[np.ndarray]:
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


def designs_at(axes: list[np.ndarray], flat: np.ndarray) -> np.ndarray:
    index = np.unravel_index(flat, tuple(a.size for a in axes))
    return np.column_stack([a[i] for a, i in zip(axes, index, strict=True)])


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


def rank_order(objectives: np.ndarray, error: np.ndarray) -> np.ndarray:
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


class Listed:
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
