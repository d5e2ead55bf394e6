"""Design spaces named by a short text, and what a campaign over one will need.

``table1`` (paper B Table 1, 972 designs), ``corners`` (its 64 corners),
``lhs:N`` and ``sobol:N`` (``N`` space-filling designs over the Table 1 ranges, or over
ranges of one's own: :func:`parse_ranges` and :meth:`SpaceSpec.with_ranges`).
Names are lower case, like every other choice of the command line.

:func:`parse_space` reads the text and knows the number of designs before any
design is built, so :func:`campaign_footprint` can estimate the memory and the
disk a campaign needs and :func:`check_footprint` can refuse one that does not
fit before it starts (``lhs:10000000`` would need about 25 GB of memory and
90 GB of disk). Every space is also bounded by the ``designs`` limit of
:mod:`softbend.limits` (``SOFTBEND_MAX_DESIGNS``), checked on the text alone.
"""

from __future__ import annotations

import math
import os
import re
import shutil
from collections.abc import Sequence
from dataclasses import dataclass, replace
from pathlib import Path
from typing import Literal, cast

from softbend._validation import must_be
from softbend.design import DESIGN_LIMITS, PARAMETERS, TABLE1_LEVELS, DesignSpace
from softbend.errors import InputError, keyed
from softbend.limits import check_count_text, check_limit

__all__ = [
    "DISK_LIMIT_BYTES",
    "MEMORY_LIMIT_BYTES",
    "SPACE_FORMS",
    "CampaignFootprint",
    "SpaceSpec",
    "campaign_footprint",
    "check_footprint",
    "parse_ranges",
    "parse_shard",
    "parse_space",
]

#: Short names of the parameters (``l``, ``phi``, ...), as the command line writes them.
_SHORT = {name.rsplit("_", 1)[0]: name for name in PARAMETERS}

#: The forms :func:`parse_space` accepts, for messages and help texts.
SPACE_FORMS = "table1, corners, lhs:N or sobol:N"

#: Memory per design while a campaign runs: the design objects and their ids,
#: the to-do and in-flight lists, and the sampler's working arrays (measured:
#: about 0.9 kB per Sobol design and 2.5 kB per optimised Latin hypercube design).
MEMORY_PER_DESIGN_BYTES = 2_500
#: DuckDB bytes per stored sample (one pressure of one design) and per design row
#: (measured: about 8.8 kB per analytical design of 101 pressures).
DISK_PER_SAMPLE_BYTES = 90
DISK_PER_DESIGN_BYTES = 200
#: Campaigns estimated above either limit need ``allow_large`` (``--allow-large``).
MEMORY_LIMIT_BYTES = 2 * 1024**3
DISK_LIMIT_BYTES = 20 * 1024**3


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


def parse_shard(shard: str) -> tuple[int, int]:
    """``(K, N)`` from ``K/N``: shard K (0-based) of N, every N-th design from the K-th.

    Raises
    ------
    InputError
        Keyed ``shard``, unless ``N >= 1`` and ``K`` in ``0..N-1``.
    """
    match = re.fullmatch(r"\s*(\d+)\s*/\s*(\d+)\s*", str(shard))
    if match is None or int(match[2]) < 1 or int(match[1]) >= int(match[2]):
        raise InputError(must_be("K/N with N >= 1 and K in 0..N-1 (e.g. 0/8)", shard), key="shard")
    return int(match[1]), int(match[2])


@dataclass(frozen=True)
class CampaignFootprint:
    """Estimated memory and disk of a campaign.

    Attributes
    ----------
    n_designs : int
        Designs held in memory (the whole space, also when a shard runs).
    n_stored : int
        Designs this run stores (those of the shard).
    n_pressures : int
        Pressures of each sweep.
    memory_bytes, disk_bytes : int
        Estimates for the run's coordinating process and for its database.
    """

    n_designs: int
    n_stored: int
    n_pressures: int
    memory_bytes: int
    disk_bytes: int

    def describe(self) -> str:
        """``about 2.33 GiB of memory and 8.65 GiB of disk for 1000000 designs x 101 pressures``."""
        return (
            f"about {_size(self.memory_bytes)} of memory and {_size(self.disk_bytes)} of disk "
            f"for {self.designs()}"
        )

    def designs(self) -> str:
        """``1000000 designs x 101 pressures``, with the shard's share when it differs."""
        stored = f" ({self.n_stored} in this shard)" if self.n_stored != self.n_designs else ""
        return f"{self.n_designs} designs{stored} x {self.n_pressures} pressures"


def campaign_footprint(
    n_designs: int, n_pressures: int, *, n_stored: int | None = None
) -> CampaignFootprint:
    """Estimate memory and disk of a campaign of ``n_designs`` at ``n_pressures`` pressures.

    ``n_stored`` (default ``n_designs``) is the number of designs the database
    will hold: fewer when one shard of the space runs.
    """
    stored = n_designs if n_stored is None else n_stored
    return CampaignFootprint(
        n_designs=n_designs,
        n_stored=stored,
        n_pressures=n_pressures,
        memory_bytes=n_designs * MEMORY_PER_DESIGN_BYTES,
        disk_bytes=stored * (n_pressures * DISK_PER_SAMPLE_BYTES + DISK_PER_DESIGN_BYTES),
    )


def _size(n_bytes: float) -> str:
    for unit in ("B", "kB", "MiB", "GiB", "TiB", "PiB", "EiB"):
        if n_bytes < 1024 or unit == "EiB":
            return f"{n_bytes:.3g} {unit}" if unit != "B" else f"{n_bytes:.0f} B"
        n_bytes /= 1024
    raise AssertionError  # pragma: no cover


def _available_memory_bytes() -> int | None:
    """``MemAvailable`` of Linux (free memory and reclaimable caches), else all memory."""
    try:
        with open("/proc/meminfo", encoding="ascii") as meminfo:
            for line in meminfo:
                if line.startswith("MemAvailable:"):
                    return int(line.split()[1]) * 1024
    except (OSError, ValueError, IndexError):
        pass
    try:
        return os.sysconf("SC_PHYS_PAGES") * os.sysconf("SC_PAGE_SIZE")
    except (AttributeError, OSError, ValueError):  # neither Linux nor POSIX
        return None


def _free_disk_bytes(db: Path) -> int | None:
    existing = Path(os.path.abspath(db)).parent
    while not existing.exists():
        existing = existing.parent
    try:
        return shutil.disk_usage(existing).free
    except OSError:
        return None


def check_footprint(
    footprint: CampaignFootprint,
    db: str | os.PathLike[str],
    *,
    allow_large: bool = False,
) -> None:
    """Refuse a campaign that does not fit, or that is large and not ``allow_large``.

    A campaign whose estimate exceeds the memory available now or the free disk
    of the database's folder is refused in any case; one above
    :data:`MEMORY_LIMIT_BYTES` or :data:`DISK_LIMIT_BYTES` only without
    ``allow_large``. The disk already used by an existing database counts as
    available (a resumed campaign only grows it).

    Raises
    ------
    InputError
        Keyed ``space`` (the space sets the campaign's size) for one that does
        not fit, keyed ``allow_large`` for a large one; both with the estimate.
    """
    db = Path(db)
    used = db.stat().st_size if db.is_file() else 0
    memory, disk = _available_memory_bytes(), _free_disk_bytes(db)
    short_of_memory = memory is not None and footprint.memory_bytes > memory
    short_of_disk = disk is not None and footprint.disk_bytes > disk + used
    if short_of_memory or short_of_disk:
        have_memory = "unknown" if memory is None else _size(memory)
        have_disk = "unknown" if disk is None else _size(disk + used)
        raise InputError(
            f"must give a campaign that fits this machine; got {footprint.designs()}, which "
            f"need about {_size(footprint.memory_bytes)} of memory ({have_memory} available) "
            f"and {_size(footprint.disk_bytes)} of disk ({have_disk} free for {db})",
            key="space",
        )
    if not allow_large and (
        footprint.memory_bytes > MEMORY_LIMIT_BYTES or footprint.disk_bytes > DISK_LIMIT_BYTES
    ):
        raise InputError(
            f"must be set to run a large campaign, {footprint.describe()} (more than "
            f"{_size(MEMORY_LIMIT_BYTES)} of memory or {_size(DISK_LIMIT_BYTES)} of disk)",
            key="allow_large",
        )
