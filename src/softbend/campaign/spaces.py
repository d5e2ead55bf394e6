"""Design spaces named by a short text: the designs a campaign of one FEM family sweeps.

Every family has ``lhs:N`` and ``sobol:N`` (``N`` space-filling designs over each
parameter's range, ``DesignParameter.low`` to ``high`` of the family's
:class:`~softbend.actuators.Actuator`, or a narrower ``NAME=LOW:HIGH`` of its
own), ``grid`` (3 levels a parameter) and ``grid:K`` (``K`` levels, 2 to 50): the
full-factorial grid over the ranges. A drawn value is made buildable: an
integer (or categorical) parameter is a whole number, drawn uniformly over its
values, and a continuous one is rounded to its ``resolution``. A design that
breaks one of the actuator's constraints, that the family refuses
(:meth:`~softbend.fem.families.FEMFamily.design`), or that repeats one already
drawn (rounding makes designs alike) is rejected: ``lhs`` and ``sobol`` draw
again until they have ``N`` designs, the grid leaves it out; the counts are
kept in :attr:`FamilySpace.rejected`. Every draw is seeded.

A family may have spaces of its own instead (:data:`OWN_SPACES`): paper B's
actuator has ``table1`` (paper B Table 1, 972 designs, the default), ``corners``
(its 64 corners), ``lhs:N`` and ``sobol:N`` over the Table 1 ranges, or over
ranges of one's own in its short names (``l=60:90``: :func:`parse_ranges`,
:meth:`SpaceSpec.with_ranges`). :func:`campaign_space` reads ``--space`` and
``--range`` for any family. Names are lower case, like every other choice of the
command line.

The number of designs is known from the text alone (for a grid, before the
rejections) and checked against the ``designs`` limit of :mod:`softbend.limits`
(``SOFTBEND_MAX_DESIGNS``) before any design is built, so
:func:`softbend.campaign.footprint.check_footprint` can refuse a campaign that
does not fit first.
"""

from __future__ import annotations

import itertools
import math
import re
import warnings
from collections.abc import Callable, Iterator, Mapping, Sequence
from dataclasses import dataclass, field, replace
from typing import TYPE_CHECKING, Any, Literal, NamedTuple, cast

import numpy as np

from softbend._validation import must_be
from softbend.design import DESIGN_LIMITS, PARAMETERS, TABLE1_LEVELS, DesignSpace
from softbend.errors import InputError, SoftbendError, keyed
from softbend.limits import check_count_text, check_limit

if TYPE_CHECKING:
    from softbend.actuators import DesignParameter
    from softbend.fem.families import FEMFamily

__all__ = [
    "DEFAULT_GRID_LEVELS",
    "FAMILY_SPACE_FORMS",
    "OWN_SPACES",
    "SPACE_FORMS",
    "FamilySpace",
    "FamilySpaceSpec",
    "OwnSpaces",
    "SpaceSpec",
    "campaign_space",
    "check_sampled_size",
    "parse_family_ranges",
    "parse_family_space",
    "parse_ranges",
    "parse_space",
    "space_forms",
]

#: Short names of paper B's parameters (``l``, ``phi``, ...), as the command line writes them.
_SHORT = {name.rsplit("_", 1)[0]: name for name in PARAMETERS}

#: The forms :func:`parse_space` accepts (paper B's actuator), for messages and help texts.
SPACE_FORMS = "table1, corners, lhs:N or sobol:N"


@dataclass(frozen=True)
class SpaceSpec:
    """A design space named by text, not built yet.

    Attributes
    ----------
    text : str
        The text it was read from.
    kind : {"table1", "corners", "lhs", "sobol"}
    n_designs : int
        Number of designs of the whole space.
    ranges : tuple of (str, float, float)
        ``(parameter, low, high)`` of the parameters sampled over a range of their own
        (mm, or degrees for ``phi``); the others span paper B's Table 1 ranges.
    """

    text: str
    kind: str
    n_designs: int
    ranges: tuple[tuple[str, float, float], ...] = ()

    def with_ranges(self, ranges: dict[str, tuple[float, float]]) -> SpaceSpec:
        """The same space sampled over ``ranges`` (from :func:`parse_ranges`).

        Raises
        ------
        InputError
            Keyed ``ranges``: only the sampled spaces (``lhs:N``, ``sobol:N``) take ranges.
        """
        if self.kind not in ("lhs", "sobol"):
            raise InputError(
                f"applies to the sampled spaces lhs:N and sobol:N, not to {self.text!r}, "
                "whose designs are paper B's Table 1 levels",
                key="ranges",
            )
        ordered = tuple((p, *ranges[p]) for p in _SHORT if p in ranges)
        return replace(self, ranges=ordered)

    def build(self, seed: int = 0) -> DesignSpace:
        """The designs; ``seed`` seeds the ``lhs`` and ``sobol`` samplers."""
        if self.kind == "table1":
            return DesignSpace.table1()
        if self.kind == "corners":
            return DesignSpace.corners()
        method = cast(Literal["lhs", "sobol"], self.kind)
        if not self.ranges:
            return DesignSpace.sample(self.n_designs, method=method, seed=seed)
        bounds = {p: (min(v), max(v)) for p, v in TABLE1_LEVELS.items()}
        bounds.update({_SHORT[p]: (low, high) for p, low, high in self.ranges})
        space = DesignSpace.sample(self.n_designs, method=method, seed=seed, bounds=bounds)
        own = " ".join(f"{p}={low:g}:{high:g}" for p, low, high in self.ranges)
        return DesignSpace(space.designs, name=f"{space.name} {own}")


#: The step to which sampled design values are rounded (DesignSpace.sample), mm or degrees.
_RECORDED = 1e-6


def parse_ranges(ranges: Sequence[str]) -> dict[str, tuple[float, float]]:
    """``{parameter: (low, high)}`` from ``NAME=LOW:HIGH`` texts (``l=60:90``).

    ``NAME`` is one of ``l, r, t, b, phi, lc``; ``LOW < HIGH`` in mm (degrees for
    ``phi``), within what a design accepts: lengths above 0, ``phi`` in [0, 60],
    and the wall thinner than the radius everywhere (``t``'s high below ``r``'s low).

    Raises
    ------
    InputError
        Keyed ``ranges``: the allowed form and values, and the text received.
    """
    out: dict[str, tuple[float, float]] = {}
    for text in ranges:
        match = re.fullmatch(r"\s*([a-z]+)\s*=\s*([^:]+):(.+)", str(text))
        name = match[1] if match else None
        try:
            low, high = (float(match[2]), float(match[3])) if match else (math.nan, math.nan)
        except ValueError:
            low, high = math.nan, math.nan
        if name not in DESIGN_LIMITS or not (math.isfinite(low) and math.isfinite(high)):
            raise InputError(
                must_be(
                    f"NAME=LOW:HIGH with NAME one of {', '.join(_SHORT)} and LOW, HIGH numbers "
                    "(mm; degrees for phi)",
                    text,
                ),
                key="ranges",
            )
        least, most, closed = DESIGN_LIMITS[name]
        unit = "deg" if name == "phi" else "mm"
        if not (least <= low if closed else least < low) or not low < high <= most:
            opening = "[" if closed else "("
            bound = f"{opening}{least:g}, {most:g}] {unit}"
            raise InputError(
                must_be(f"a range of {name} LOW < HIGH within {bound}", text), key="ranges"
            )
        if (
            high - low < _RECORDED
            or round(low, 6) == round(high, 6)
            or (not closed and round(low, 6) <= least)
        ):
            start = "" if closed else f" from at least {_RECORDED:g} {unit}"
            raise InputError(
                must_be(
                    f"a range of {name} at least {_RECORDED:g} {unit} wide{start} (designs are "
                    f"sampled to {_RECORDED:g} {unit})",
                    text,
                ),
                key="ranges",
            )
        if name in out:
            raise InputError(f"gives {name} twice; got {text!r} again", key="ranges")
        out[name] = (low, high)
    t_high = out.get("t", (0.0, max(TABLE1_LEVELS["t_mm"])))[1]
    r_low = out.get("r", (min(TABLE1_LEVELS["r_mm"]), 0.0))[0]
    if t_high >= r_low:
        raise InputError(
            "must keep the wall thinner than the radius in every design: t's high must be "
            f"below r's low; got t up to {t_high:g} mm and r from {r_low:g} mm",
            key="ranges",
        )
    return out


def parse_space(space: str) -> SpaceSpec:
    """Read ``table1``, ``corners``, ``lhs:N`` or ``sobol:N`` (lower case, ``N >= 1``).

    The number of designs is known from the text alone and checked against the
    ``designs`` limit of :mod:`softbend.limits` before anything is built, so a
    number of any length is one clear error.

    Raises
    ------
    InputError
        Keyed ``space``: the accepted forms and the text received.
    LimitError
        Keyed ``space``: the space has more designs than the ``designs`` limit
        (``SOFTBEND_MAX_DESIGNS``).
    """
    text = space
    match = re.fullmatch(r"(table1|corners)|(lhs|sobol):([0-9]+)", str(text))
    digits = None if match is None or match[3] is None else match[3].lstrip("0")
    if match is None or digits == "":
        raise InputError(must_be(f"one of {SPACE_FORMS} (lower case, N >= 1)", text), key="space")
    shown = text if len(text) <= 40 else f"{text[:30]}...({len(text)} characters)"
    what = shown
    with keyed("space"):
        if match[1] == "table1":
            spec = SpaceSpec(text, "table1", math.prod(len(v) for v in TABLE1_LEVELS.values()))
        elif match[1] == "corners":
            spec = SpaceSpec(text, "corners", 2 ** len(TABLE1_LEVELS))
        else:
            assert digits is not None  # the lhs:N / sobol:N branch always has digits
            spec = SpaceSpec(text, match[2], check_count_text("designs", digits, what))
        check_limit("designs", spec.n_designs, what)
    return spec


# -- the spaces of any family -----------------------------------------------------------

#: The forms :func:`parse_family_space` accepts, for messages and help texts.
FAMILY_SPACE_FORMS = "lhs:N, sobol:N, grid or grid:K"

#: Levels a parameter of ``grid`` (without ``:K``).
DEFAULT_GRID_LEVELS = 3

#: The most levels a parameter of ``grid:K``.
_MAX_GRID_LEVELS = 50

#: Draws a sampled space may make in all, per design asked for (and 100 more),
#: before it gives up on constraints that leave too few designs.
_DRAWS_PER_DESIGN = 20


@dataclass(frozen=True)
class FamilySpace:
    """The designs of a family's campaign, in order.

    Attributes
    ----------
    family : str
        The family's name.
    designs : tuple
        The checked designs (:meth:`FEMFamily.design`).
    name : str
        Label of the space, stored with the campaign (``"pneunet sobol-256-seed0"``).
    rejected : mapping of str to int
        Draws rejected, by reason: ``constraints``, ``family`` (refused by the
        family's own checks) and ``duplicates``.
    """

    family: str
    designs: tuple[Any, ...]
    name: str
    rejected: Mapping[str, int] = field(default_factory=dict)

    def __iter__(self) -> Iterator[Any]:
        return iter(self.designs)

    def __len__(self) -> int:
        return len(self.designs)

    def __getitem__(self, index: int) -> Any:
        return self.designs[index]

    @property
    def n_rejected(self) -> int:
        """Draws rejected in all."""
        return sum(self.rejected.values())

    def shard(self, index: int, count: int) -> FamilySpace:
        """Every ``count``-th design from the ``index``-th (as :meth:`DesignSpace.shard`)."""
        return FamilySpace(
            self.family, self.designs[index::count], f"{self.name}[{index}/{count}]", self.rejected
        )

    def describe_rejected(self) -> str:
        """``"12 draws rejected (constraints 10, duplicates 2)"``, or ``""`` when none were."""
        if not self.n_rejected:
            return ""
        parts = ", ".join(f"{k} {v}" for k, v in self.rejected.items() if v)
        return f"{self.n_rejected} draws rejected ({parts})"


@dataclass(frozen=True)
class FamilySpaceSpec:
    """A family's design space named by text, not built yet.

    Attributes
    ----------
    family : FEMFamily
        The family.
    text : str
        The text it was read from.
    kind : {"lhs", "sobol", "grid"}
    n_designs : int
        Designs asked for (``lhs``, ``sobol``) or the grid's points before the
        constraints (``grid``).
    levels : int
        Levels a parameter of a grid (0 for the sampled spaces).
    ranges : tuple of (str, float, float)
        ``(parameter, low, high)`` of the parameters sampled over a range of
        their own, in their units.
    """

    family: FEMFamily
    text: str
    kind: str
    n_designs: int
    levels: int = 0
    ranges: tuple[tuple[str, float, float], ...] = ()

    def with_ranges(self, ranges: Mapping[str, tuple[float, float]]) -> FamilySpaceSpec:
        """The same space over ``ranges`` (from :func:`parse_family_ranges`); grids keep theirs.

        Raises
        ------
        InputError
            Keyed ``ranges``: a grid was asked for.
        """
        if self.kind == "grid":
            raise InputError(
                f"applies to the sampled spaces lhs:N and sobol:N, not to {self.text!r}",
                key="ranges",
            )
        ordered = tuple((n, *ranges[n]) for n in self.family.names if n in ranges)
        return FamilySpaceSpec(
            self.family, self.text, self.kind, self.n_designs, self.levels, ordered
        )

    def bounds(self) -> dict[str, tuple[float, float]]:
        """``{parameter: (low, high)}``: the description's ranges, with those given instead."""
        out = {p.name: (p.low, p.high) for p in self.family.actuator.parameters}
        out.update({n: (low, high) for n, low, high in self.ranges})
        return out

    def build(self, seed: int = 0) -> FamilySpace:
        """The designs; ``seed`` seeds the ``lhs`` and ``sobol`` samplers (a grid has none).

        Raises
        ------
        InputError
            Keyed ``space``: the constraints and the family's checks leave fewer
            than the designs asked for (or none of a grid).
        """
        if self.kind == "grid":
            return self._grid()
        return self._sampled(seed)

    # -- grids -------------------------------------------------------------------
    def _grid(self) -> FamilySpace:
        actuator = self.family.actuator
        levels = [_levels(p, self.levels) for p in actuator.parameters]
        rows = np.array(list(itertools.product(*levels)), dtype=float)
        rejected = {"constraints": 0, "family": 0, "duplicates": 0}
        designs = _accept(self.family, rows, {}, rejected)
        name = f"{self.family.name} grid-{self.levels}"
        if not designs:
            raise InputError(
                f"must leave designs within the constraints of the {self.family.name} family; "
                f"got none of the {len(rows)} points of {self.text!r}",
                key="space",
            )
        return FamilySpace(self.family.name, tuple(designs.values()), name, rejected)

    # -- sampled spaces ------------------------------------------------------------
    def _sampled(self, seed: int) -> FamilySpace:
        from scipy.stats import qmc

        actuator = self.family.actuator
        dims = len(actuator.parameters)
        sampler = (
            qmc.LatinHypercube(d=dims, seed=seed)
            if self.kind == "lhs"
            else qmc.Sobol(d=dims, scramble=True, seed=seed)
        )
        bounds = self.bounds()
        rejected = {"constraints": 0, "family": 0, "duplicates": 0}
        designs: dict[str, Any] = {}
        budget = _DRAWS_PER_DESIGN * self.n_designs + 100
        drawn = 0
        while len(designs) < self.n_designs and drawn < budget:
            batch = min(self.n_designs - len(designs), budget - drawn)
            with warnings.catch_warnings():  # Sobol's balance of powers of two: not needed here
                warnings.simplefilter("ignore", UserWarning)
                unit = sampler.random(batch)
            drawn += batch
            rows = np.column_stack(
                [_values(p, unit[:, j], *bounds[p.name]) for j, p in enumerate(actuator.parameters)]
            )
            _accept(self.family, rows, designs, rejected)
        name = f"{self.family.name} {self.kind}-{self.n_designs}-seed{seed}"
        if self.ranges:
            name += " " + " ".join(f"{n}={low:g}:{high:g}" for n, low, high in self.ranges)
        if len(designs) < self.n_designs:
            raise InputError(
                f"must leave {self.n_designs} distinct designs within the constraints of the "
                f"{self.family.name} family; got {len(designs)} in {drawn} draws "
                f"({', '.join(f'{k} {v}' for k, v in rejected.items())} rejected): ask for "
                "fewer designs or wider ranges",
                key="space",
            )
        return FamilySpace(self.family.name, tuple(designs.values()), name, rejected)


def _values(p: DesignParameter, unit: np.ndarray, low: float, high: float) -> np.ndarray:
    """Unit draws as buildable values of ``p`` within ``[low, high]``."""
    if p.kind in ("integer", "categorical"):
        first, last = math.ceil(low), math.floor(high)
        return np.minimum(first + np.floor(unit * (last - first + 1)), last)
    values = p.snap(low + unit * (high - low))
    return np.round(np.clip(values, low, high), 6)


def _levels(p: DesignParameter, count: int) -> np.ndarray:
    """``count`` evenly spread buildable values of ``p`` (fewer where they coincide)."""
    if p.kind in ("integer", "categorical"):
        first, last = math.ceil(p.low), math.floor(p.high)
        return np.unique(np.round(np.linspace(first, last, count)))
    return np.unique(np.round(p.snap(np.linspace(p.low, p.high, count)), 6))


def _accept(
    family: FEMFamily, rows: np.ndarray, designs: dict[str, Any], rejected: dict[str, int]
) -> dict[str, Any]:
    """Add the designs of ``rows`` that pass to ``designs`` (by id); count the others."""
    met = family.actuator.constraints_met(rows)
    rejected["constraints"] += int((~met).sum())
    for row in rows[met]:
        try:
            design = family.design(dict(zip(family.names, row.tolist(), strict=True)))
        except (InputError, ValueError, SoftbendError):
            rejected["family"] += 1
            continue
        if design.design_id in designs:
            rejected["duplicates"] += 1
            continue
        designs[design.design_id] = design
    return designs


def parse_family_space(text: str, family: FEMFamily) -> FamilySpaceSpec:
    """Read ``lhs:N``, ``sobol:N``, ``grid`` or ``grid:K`` for ``family`` (``N >= 1``, K 2..50).

    Raises
    ------
    InputError
        Keyed ``space``: the accepted forms and the text received.
    LimitError
        Keyed ``space``: more designs than the ``designs`` limit (``SOFTBEND_MAX_DESIGNS``).
    """
    match = re.fullmatch(r"(lhs|sobol):([0-9]+)|grid(?::([0-9]{1,3}))?", str(text))
    digits = None if match is None or match[2] is None else match[2].lstrip("0")
    levels = DEFAULT_GRID_LEVELS if match is None or match[3] is None else int(match[3])
    if match is None or digits == "" or not 2 <= levels <= _MAX_GRID_LEVELS:
        raise InputError(
            must_be(
                f"one of {FAMILY_SPACE_FORMS} for the {family.name} family (lower case, N >= 1, "
                f"K from 2 to {_MAX_GRID_LEVELS})",
                text,
            ),
            key="space",
        )
    shown = text if len(text) <= 40 else f"{text[:30]}...({len(text)} characters)"
    with keyed("space"):
        if match[1] is not None:
            assert digits is not None
            spec = FamilySpaceSpec(
                family, text, match[1], check_count_text("designs", digits, shown)
            )
        else:
            count = math.prod(len(_levels(p, levels)) for p in family.actuator.parameters)
            spec = FamilySpaceSpec(family, text, "grid", count, levels)
        check_limit("designs", spec.n_designs, shown)
    return spec


def parse_family_ranges(ranges: Sequence[str], family: FEMFamily) -> dict[str, tuple[float, float]]:
    """``{parameter: (low, high)}`` from ``NAME=LOW:HIGH`` texts over ``family``'s parameters.

    ``NAME`` is a parameter of the family and ``LOW < HIGH`` lies within its
    description's range, in its unit.

    Raises
    ------
    InputError
        Keyed ``ranges``: the names and ranges allowed, and the text received.
    """
    out: dict[str, tuple[float, float]] = {}
    parameters = {p.name: p for p in family.actuator.parameters}
    for text in ranges:
        match = re.fullmatch(r"\s*([A-Za-z_][A-Za-z0-9_]*)\s*=\s*([^:]+):(.+)", str(text))
        try:
            low, high = (float(match[2]), float(match[3])) if match else (math.nan, math.nan)
        except ValueError:
            low, high = math.nan, math.nan
        p = parameters.get(match[1]) if match else None
        if p is None or not (math.isfinite(low) and math.isfinite(high)):
            raise InputError(
                must_be(
                    f"NAME=LOW:HIGH with NAME one of {', '.join(parameters)} and LOW, HIGH numbers",
                    text,
                ),
                key="ranges",
            )
        unit = f" {p.unit}" if p.unit else ""
        if p.kind == "categorical" or not (p.low <= low < high <= p.high):
            raise InputError(
                must_be(
                    f"a range of {p.name} LOW < HIGH within [{p.low:g}, {p.high:g}]{unit}", text
                ),
                key="ranges",
            )
        if p.name in out:
            raise InputError(f"gives {p.name} twice; got {text!r} again", key="ranges")
        out[p.name] = (low, high)
    return out


# -- one entry for every family --------------------------------------------------------


class OwnSpaces(NamedTuple):
    """The design spaces of a family that has its own (see :data:`OWN_SPACES`).

    Attributes
    ----------
    forms : str
        The forms of ``--space``, for messages and help texts.
    default : str
        The space a campaign sweeps without ``--space``.
    parse : callable
        ``parse(text) -> spec``: the unbuilt space (``spec.n_designs``,
        ``spec.with_ranges(ranges)``, ``spec.build(seed)``).
    parse_ranges : callable
        ``parse_ranges(texts) -> {name: (low, high)}`` of ``--range``.
    """

    forms: str
    default: str
    parse: Callable[[str], Any]
    parse_ranges: Callable[[Sequence[str]], dict[str, tuple[float, float]]]


#: The families whose designs have spaces of their own, by registry name: paper B's
#: actuator, whose campaigns sweep its Table 1 levels. Every other family has the
#: spaces of :func:`parse_family_space`.
OWN_SPACES: dict[str, OwnSpaces] = {
    "sfrba": OwnSpaces(SPACE_FORMS, "table1", parse_space, parse_ranges),
}


def check_sampled_size(text: str) -> None:
    """Refuse ``lhs:N`` or ``sobol:N`` over the ``designs`` limit, whatever the family.

    The sampled spaces of every family hold ``N`` designs: their size is checked
    before the family is known (before a campaign database is read); other
    texts pass, checked by :func:`campaign_space`.

    Raises
    ------
    LimitError
        Keyed ``space``: more designs than the ``designs`` limit.
    """
    match = re.fullmatch(r"(lhs|sobol):0*([0-9]+)", str(text))
    if match is not None:
        shown = text if len(text) <= 40 else f"{text[:30]}...({len(text)} characters)"
        with keyed("space"):
            check_limit("designs", check_count_text("designs", match[2], shown), shown)


def space_forms(family: FEMFamily) -> str:
    """The forms of ``--space`` for ``family``."""
    own = OWN_SPACES.get(family.name)
    return FAMILY_SPACE_FORMS if own is None else own.forms


def campaign_space(text: str | None, family: FEMFamily, ranges: Sequence[str] | None = None) -> Any:
    """The checked, unbuilt design space of ``--space`` (and ``--range``) for ``family``.

    ``text`` None: the family's default space where it has one
    (:data:`OWN_SPACES`), else an error keyed ``space``.

    Raises
    ------
    InputError
        Keyed ``space`` or ``ranges``: the accepted forms and the text received.
    LimitError
        Keyed ``space``: more designs than the ``designs`` limit.
    """
    own = OWN_SPACES.get(family.name)
    if own is None:
        own = OwnSpaces(
            FAMILY_SPACE_FORMS,
            "",
            lambda t: parse_family_space(t, family),
            lambda r: parse_family_ranges(r, family),
        )
    if text is None and not own.default:
        raise InputError(
            f"must be given for the {family.name} family: one of {own.forms} "
            "over the ranges of its description",
            key="space",
        )
    spec = own.parse(own.default if text is None else text)
    if ranges:
        spec = spec.with_ranges(own.parse_ranges(ranges))
    return spec
