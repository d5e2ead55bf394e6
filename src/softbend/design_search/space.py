"""The design parameters a search names: paper B's six, or a model's own description.

A design search works over the parameters of the actuator its model was trained
on (:attr:`SavedSurrogate.actuator <softbend.surrogates.persistence.SavedSurrogate.actuator>`).
:class:`SearchSpace` says how a specification names them and what they are:

- paper B's actuator (:data:`softbend.actuators.SFRBA`) is named by the short
  names of its description (``l, r, t, b, phi, lc``, mm and degrees; its column
  names ``l_mm`` … are accepted too), with the mould's default step (0.5 mm,
  1°) and the objective ``volume`` (of elastomer);
- any other actuator is named by its description's parameters
  (``n_chambers``, ``wall_mm``, ``layer``), each searched on its own kind: an
  integer on whole numbers, a categorical parameter on its levels (stored as
  their index; a level is given and shown by name), a continuous one on
  multiples of its step (by default its declared resolution, else a round
  step of about a hundredth of its range, :meth:`SearchSpace.grid_steps`); its
  constraints
  (:meth:`~softbend.actuators.Actuator.constraints_met`) decide which designs
  are actuators, and its pressure unit is the unit of every pressure of the
  search; a description that names an FEM family (``fem_family``) is verified
  by that family's FEM.

A design found is a :class:`~softbend.actuators.Design` of the actuator.
"""

from __future__ import annotations

import math
from collections.abc import Sequence
from dataclasses import dataclass
from typing import Any

import numpy as np

from softbend.actuators import ACTUATORS, PRESSURE_UNITS, SFRBA, Actuator, Design, DesignParameter

__all__ = [
    "DEFAULT_GRID",
    "GRID_INTERVALS",
    "PAPER_B",
    "QUANTITIES",
    "SearchSpace",
    "aligned",
    "pressure_key",
    "round_step",
    "space_of",
]

#: Objectives that are not design parameters (``volume`` for paper B's actuator only).
QUANTITIES: tuple[str, ...] = ("pressure", "volume", "sensitivity", "angle", "error")

#: About how many designs the default grid of a description holds
#: (:meth:`SearchSpace.grid_steps`).
DEFAULT_GRID = 1_000_000

#: The intervals a continuous parameter without a resolution is split into by
#: default: at least, at most (:meth:`SearchSpace.grid_steps`).
GRID_INTERVALS = (10, 100)


def pressure_key(unit: str) -> str:
    """The key of a pressure in tables and JSON: ``pressure_mpa``, ``pressure_kpa`` …"""
    return f"pressure_{unit.lower()}"


@dataclass(frozen=True)
class SearchSpace:
    """The parameters of one actuator as a design search names them.

    Attributes
    ----------
    actuator : Actuator
    names : tuple of str
        The names a specification gives them, in model-input order: the
        description's short names (paper B's), else its own.
    """

    actuator: Actuator
    names: tuple[str, ...]

    def __post_init__(self) -> None:
        clash = [n for n in self.names if n in QUANTITIES]
        if clash:
            raise ValueError(
                f"The actuator {self.actuator.name} has a design parameter called "
                f"{clash[0]!r}, the name of an objective of the design search "
                f"({', '.join(QUANTITIES)}); rename the parameter to search its designs."
            )

    @property
    def columns(self) -> tuple[str, ...]:
        """The model-input column of each name."""
        return self.actuator.names

    @property
    def features(self) -> tuple[str, ...]:
        """The model inputs: the design columns then the pressure column."""
        return self.actuator.features

    @property
    def pressure_unit(self) -> str:
        """Unit of every pressure of a search (the model's pressure input)."""
        return self.actuator.pressure_unit

    @property
    def to_mpa(self) -> float:
        """Factor from :attr:`pressure_unit` to MPa."""
        return PRESSURE_UNITS[self.pressure_unit]

    @property
    def verifiable(self) -> bool:
        """Whether the actuator names an FEM family (``--verify``): paper B's ``"sfrba"``,
        or another registered in :data:`~softbend.fem.families.FEM_FAMILIES` (checked when
        it is verified, :func:`~softbend.design_search.verify.verify_family`)."""
        return self.actuator.fem_family is not None

    def parameter(self, name: str) -> DesignParameter:
        """The description of the parameter ``name`` (a name of :attr:`names`)."""
        return self.actuator.parameters[self.names.index(name)]

    def kind(self, name: str) -> str:
        """``continuous``, ``integer`` or ``categorical``."""
        return self.parameter(name).kind

    def unit(self, name: str) -> str:
        """The unit of ``name`` (``""`` for a count or a level)."""
        return self.parameter(name).unit

    @property
    def units(self) -> dict[str, str]:
        """Unit of every name."""
        return {n: self.unit(n) for n in self.names}

    def canonical(self, text: str) -> str | None:
        """The name ``text`` stands for (paper B's column ``l_mm`` is ``l``), or None."""
        if text in self.names:
            return text
        if text in self.columns:
            return self.names[self.columns.index(text)]
        return None

    @property
    def objectives(self) -> dict[str, str]:
        """What an objective may name, with its unit: a parameter (not a categorical one),
        ``pressure``, ``volume`` (when the description gives the elastomer volume),
        ``sensitivity``, ``angle``, ``error``."""
        unit = self.pressure_unit
        out = {n: self.unit(n) for n in self.names if self.kind(n) != "categorical"}
        out["pressure"] = unit
        if self.actuator.elastomer_volume is not None:
            out["volume"] = "mm³"
        out.update({"sensitivity": f"deg/{unit}", "angle": "deg", "error": "deg"})
        return out

    def listing(self) -> str:
        """The names, comma-separated, for messages."""
        return ", ".join(self.names)

    def feasible(self, designs: np.ndarray) -> np.ndarray:
        """Which rows of designs are actuators: every constraint of the description met
        (paper B's wall thinner than the radius, ``t_mm < r_mm``)."""
        if not self.actuator.constraints:
            return np.ones(designs.shape[0], dtype=bool)
        return self.actuator.constraints_met(designs)

    def design_of(self, codes: Sequence[float]) -> Design:
        """One design of the actuator, by its codes in model-input order."""
        return Design(self.actuator, dict(zip(self.actuator.names, map(float, codes), strict=True)))

    def decode(self, name: str, code: float) -> Any:
        """The value of ``name`` a code stands for (a level by name, a whole number)."""
        return self.parameter(name).decode(code)

    def shown(self, name: str, code: float) -> str:
        """A value of ``name`` for messages and tables (``10``, ``1.5``, ``paper``)."""
        value = self.decode(name, code)
        return f"{value:g}" if isinstance(value, float) else str(value)

    # --- another actuator's rules (paper B's are those of spec.py) -------------------------

    def default_step(self, name: str) -> float:
        """The step of ``name`` when none is given: a continuous parameter's declared
        resolution, else :meth:`grid_steps`' round step (0, continuous, for an unbounded
        range), 1 for an integer or a level."""
        p = self.parameter(name)
        if p.kind == "continuous":
            if p.resolution is not None:
                return float(p.resolution)
            return self.grid_steps().get(name, 0.0)
        return 1.0

    def grid_steps(self) -> dict[str, float]:
        """The step of each continuous parameter that declares no resolution (and a finite
        range): the round step (1, 2, 2.5 or 5 × 10^k) that splits its described range
        into ``n`` intervals at most, ``n`` the same for all of them and as large as keeps
        the grid of the whole description near :data:`DEFAULT_GRID` designs, held to 10
        to 100."""
        free, others = [], 1
        for p, name in zip(self.actuator.parameters, self.names, strict=True):
            span = p.high - p.low
            if not math.isfinite(span):
                continue
            if p.kind == "continuous" and p.resolution is None:
                if span > 0:
                    free.append((name, span))
            elif p.kind == "continuous":
                others *= math.floor(span / p.resolution + 1e-9) + 1  # type: ignore[operator]
            else:
                others *= math.floor(p.high + 1e-9) - math.ceil(p.low - 1e-9) + 1
        if not free:
            return {}
        n = math.floor((DEFAULT_GRID / max(others, 1)) ** (1.0 / len(free)) + 1e-9)
        n = min(max(n, GRID_INTERVALS[0]), GRID_INTERVALS[1])
        return {name: round_step(span, n) for name, span in free}

    def value_problem(self, name: str, code: float) -> str | None:
        """Why ``code`` cannot be a value of ``name`` (outside the description, not a
        whole number), or None."""
        p = self.parameter(name)
        eps = 1e-9 * max(1.0, abs(p.low), abs(p.high))
        if not math.isfinite(code):
            return "is not a finite number"
        outside = code < p.low - eps or code > p.high + eps
        if outside and not (p.sampled and p.kind != "categorical"):  # sampled: training ranges
            span = f"[{p.low:g}, {p.high:g}]" + (f" {p.unit}" if p.unit else "")
            return f"leaves the range {span} the actuator {self.actuator.name} describes"
        if p.kind == "integer" and abs(code - round(code)) > 1e-9:
            return f"is not a whole number ({name} is an integer parameter)"
        return None

    def step_problem(self, name: str, step: float) -> str | None:
        """Why ``step`` cannot be the step of ``name``, or None."""
        p = self.parameter(name)
        if p.kind == "categorical":
            return (
                f"does not apply to the categorical parameter {name!r}: every level "
                f"({'/'.join(map(str, p.levels or ()))}) is searched"
            )
        if p.kind == "integer" and (step < 1 or abs(step - round(step)) > 1e-9):
            return f"must be a whole number >= 1 ({name} is an integer parameter)"
        if p.kind == "continuous" and step > 0 and p.resolution is not None:
            ratio = step / p.resolution
            if abs(ratio - round(ratio)) > 1e-6 or round(ratio) < 1:
                return (
                    f"must be 0 or a whole multiple of the resolution {p.resolution:g}"
                    + (f" {p.unit}" if p.unit else "")
                    + f" the actuator {self.actuator.name} declares for {name!r}"
                )
        return None

    def snap(self, name: str, values: np.ndarray, low: float, high: float) -> np.ndarray:
        """``values`` of a continuous ``name`` moved to the nearest multiple of its declared
        resolution inside ``[low, high]`` (unchanged where it declares none)."""
        resolution = self.parameter(name).resolution
        if resolution is None:
            return values
        first, last = _multiples(low, high, resolution)
        snapped = np.round(np.asarray(values, dtype=float) / resolution) * resolution
        return np.round(np.clip(snapped, first, last), 9)


def round_step(span: float, intervals: int) -> float:
    """The smallest step of 1, 2, 2.5 or 5 × 10^k that splits ``span`` into at most
    ``intervals``."""
    raw = span / intervals
    exponent = math.floor(math.log10(raw))
    for mantissa in (1.0, 2.0, 2.5, 5.0, 10.0):
        step = float(f"{mantissa * 10.0**exponent:.12g}")
        if step >= raw * (1 - 1e-12):
            return step
    return float(f"{10.0 ** (exponent + 1):.12g}")  # pragma: no cover - 10 × 10^k ends it


def _multiples(low: float, high: float, step: float) -> tuple[float, float]:
    """The first and last multiple of ``step`` in ``[low, high]`` (first > last: none)."""
    first = round(math.ceil(low / step - 1e-9) * step, 9)
    last = round(math.floor(high / step + 1e-9) * step, 9)
    return first, last


def aligned(low: float, high: float, step: float) -> tuple[float, float]:
    """``[low, high]`` narrowed to its first and last multiple of ``step`` (first > last: none)."""
    return _multiples(low, high, step)


#: Paper B's actuator, by the short names of its description (``l, r, t, b, phi, lc``).
PAPER_B = SearchSpace(SFRBA, SFRBA.short_names)


def space_of(actuator: Actuator | None) -> SearchSpace:
    """The search space of ``actuator`` (None: paper B's, :data:`PAPER_B`).

    A record of a registered actuator (its columns, pressure unit and FEM family,
    as a model saved before its description changed records it) is searched as
    the registered one; any actuator is named by its short names, else its own.
    """
    if actuator is None:
        return PAPER_B
    for _, known in ACTUATORS.items():
        if (
            actuator.names == known.names
            and actuator.pressure_unit == known.pressure_unit
            and actuator.fem_family == known.fem_family
        ):
            actuator = known
            break
    return SearchSpace(actuator, actuator.short_names or actuator.names)
