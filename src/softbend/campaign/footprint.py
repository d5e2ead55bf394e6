"""What a campaign will need: the memory and the disk of its designs, and its shards.

:func:`campaign_footprint` estimates the memory and the disk a campaign needs from
the number of designs alone (known from the ``--space`` text before any design is
built, :mod:`softbend.campaign.spaces`), and :func:`check_footprint` refuses one
that does not fit before it starts (``lhs:10000000`` would need about 25 GB of
memory and 90 GB of disk). :func:`parse_shard` reads ``K/N``: one shard of a space.
"""

from __future__ import annotations

import os
import re
import shutil
from dataclasses import dataclass
from pathlib import Path

from softbend._validation import must_be
from softbend.errors import InputError

__all__ = [
    "DISK_LIMIT_BYTES",
    "MEMORY_LIMIT_BYTES",
    "CampaignFootprint",
    "campaign_footprint",
    "check_footprint",
    "parse_shard",
]

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
