"""Memory an identification will need, and the memory it may use.

``softbend curling identify`` reads experiment CSV files and fits NARX/GG-SVR
models per pressure sign. Neither step holds an n × n matrix any more (see
:mod:`softbend.identification.svr`), so its memory grows linearly with the
number of samples; but a very large CSV can still exceed the memory of the
machine, and the operating system then kills the process without a word. The
check below estimates the peak from the file sizes alone, before anything is
read, and refuses with one line when it exceeds the limit.

The model of the peak (bytes), measured on softbend's synthetic CSV files
(tracemalloc, 10 000-row files of about 39 bytes a row):

* reading: one file at a time is split into lines and fields, about 21 bytes of
  Python objects per byte of the file being read (:data:`PARSE_BYTES_PER_FILE_BYTE`
  = 24 with a margin), plus about 60 bytes per sample kept as arrays
  (:data:`KEPT_BYTES_PER_ROW` = 64);
* fitting (the largest sign, bounded by all samples): regressor, scaled and
  merged copies, LIBSVM's per-row arrays and the held-out predictions, about
  :data:`FIT_BYTES_PER_ROW` = 600 bytes per sample, plus LIBSVM's kernel cache
  and, when the shape is not 2, the active-set solver's Gram block (two copies of
  ``max_working_set²`` doubles), its column cache and its kernel blocks;
* :data:`BASE_BYTES` = 300 MiB for the interpreter, NumPy, scikit-learn,
  pandas and matplotlib.
"""

from __future__ import annotations

import logging
import os
from dataclasses import dataclass
from pathlib import Path

from softbend.errors import DatasetError
from softbend.identification.ranges import MAX_MEMORY_MB_RANGE, check_number

logger = logging.getLogger(__name__)

__all__ = [
    "MemoryEstimate",
    "available_memory_bytes",
    "check_identify_memory",
    "estimate_identify_memory",
    "peak_memory_mib",
]

MIB = 2**20
#: Python objects made while one CSV file is parsed, per byte of that file.
PARSE_BYTES_PER_FILE_BYTE = 24
#: Arrays kept per sample once read (time, pressure, x, y, ρ, L).
KEPT_BYTES_PER_ROW = 64
#: Working arrays per training sample while fitting and evaluating one model.
FIT_BYTES_PER_ROW = 600
#: Interpreter and libraries.
BASE_BYTES = 300 * MIB
#: Bytes of the first data rows sampled to estimate the bytes per row of a file.
_SAMPLE_BYTES = 64 * 1024


@dataclass(frozen=True)
class MemoryEstimate:
    """Estimated peak memory of ``curling identify`` over some CSV files.

    Attributes
    ----------
    csv_bytes : int
        Total size of the CSV files, bytes.
    rows : int
        Estimated number of samples (data rows) in them.
    peak_bytes : int
        Estimated peak memory of reading and identifying, bytes.
    """

    csv_bytes: int
    rows: int
    peak_bytes: int


def _csv_files(path: Path) -> list[Path]:
    if path.is_dir():
        return sorted(p for p in path.iterdir() if p.is_file() and p.suffix.lower() == ".csv")
    return [path] if path.is_file() else []


def _estimated_rows(path: Path, size: int) -> int:
    """Data rows of a CSV file from the mean length of its first lines (comments excluded)."""
    with path.open("rb") as handle:
        head = handle.read(_SAMPLE_BYTES)
    lines = head.splitlines(keepends=True)
    data = [line for line in lines if line.strip() and not line.startswith(b"#")]
    if len(head) < _SAMPLE_BYTES:  # the whole file was read: count exactly
        return max(0, len(data) - 1)
    if len(data) < 3:
        return size // 16
    header_end = head.index(data[1])  # comments and the header row come first
    sample = data[1:-1]  # a last line may be cut
    mean = sum(len(line) for line in sample) / len(sample)
    return int((size - header_end) / mean) + 1


def estimate_identify_memory(
    path: str | os.PathLike[str],
    *,
    cache_size_mb: float = 200.0,
    max_working_set: int = 4096,
) -> MemoryEstimate:
    """Estimate the peak memory of identifying from a CSV file or folder (see module docs).

    Only file sizes and the first 64 KiB of each file are read.

    Parameters
    ----------
    path : str or path-like
        A CSV file, or a folder of CSV files, as for
        :func:`~softbend.identification.data.load_experiments`.
    cache_size_mb : float, default 200
        Kernel cache of the SVR solver, MB.
    max_working_set : int, default 4096
        Working-set cap of the γ ≠ 2 solver, rows.

    Returns
    -------
    MemoryEstimate
        Sizes and the estimated peak, bytes. An empty or missing path gives zeros
        (the loader reports it).
    """
    files = _csv_files(Path(path))
    sizes = [f.stat().st_size for f in files]
    rows = sum(_estimated_rows(f, s) for f, s in zip(files, sizes, strict=True))
    cache = int(cache_size_mb * MIB)
    solver = 2 * cache + 2 * 8 * max_working_set**2 + 64 * MIB
    parse = PARSE_BYTES_PER_FILE_BYTE * max(sizes, default=0)
    peak = BASE_BYTES + parse + KEPT_BYTES_PER_ROW * rows + FIT_BYTES_PER_ROW * rows + solver
    return MemoryEstimate(csv_bytes=sum(sizes), rows=rows, peak_bytes=int(peak))


def _read_int(path: str) -> int | None:
    try:
        text = Path(path).read_text().strip()
    except OSError:
        return None
    return int(text) if text.isdigit() else None


def available_memory_bytes() -> int | None:
    """Memory this process may still use, bytes, or None when it cannot be told.

    The smaller of the kernel's ``MemAvailable`` and the room left under the
    cgroup limit (v2 ``memory.max`` − ``memory.current``, or v1
    ``memory.limit_in_bytes`` − ``memory.usage_in_bytes``), on Linux.
    """
    candidates: list[int] = []
    try:
        for line in Path("/proc/meminfo").read_text().splitlines():
            if line.startswith("MemAvailable:"):
                candidates.append(int(line.split()[1]) * 1024)
                break
    except (OSError, ValueError, IndexError):
        pass
    for limit_file, usage_file in (
        ("/sys/fs/cgroup/memory.max", "/sys/fs/cgroup/memory.current"),
        (
            "/sys/fs/cgroup/memory/memory.limit_in_bytes",
            "/sys/fs/cgroup/memory/memory.usage_in_bytes",
        ),
    ):
        limit, usage = _read_int(limit_file), _read_int(usage_file)
        if limit is not None and usage is not None and limit < 2**60:
            candidates.append(max(0, limit - usage))
    return min(candidates) if candidates else None


def peak_memory_mib() -> float | None:
    """The peak resident memory of this process so far, MiB (None where it cannot be told).

    ``getrusage``'s ``ru_maxrss``: KiB on Linux, bytes on macOS; Windows has no
    :mod:`resource` module.
    """
    try:
        import resource
    except ImportError:  # Windows
        return None
    import sys

    peak = resource.getrusage(resource.RUSAGE_SELF).ru_maxrss
    scale = 1 if sys.platform == "darwin" else 1024
    return peak * scale / MIB if peak > 0 else None


def check_identify_memory(
    path: str | os.PathLike[str],
    *,
    max_memory_mb: float | None = None,
    cache_size_mb: float = 200.0,
    max_working_set: int = 4096,
) -> MemoryEstimate:
    """Refuse, before reading anything, data whose identification would not fit in memory.

    Parameters
    ----------
    path : str or path-like
        A CSV file or a folder of CSV files.
    max_memory_mb : float, optional
        Memory the identification may use, MiB, in (0, 1e9]; default: what
        :func:`available_memory_bytes` reports (no check when it cannot tell).
    cache_size_mb, max_working_set
        Solver settings, as in :func:`estimate_identify_memory`.

    Returns
    -------
    MemoryEstimate
        The estimate, when it fits.

    Raises
    ------
    DatasetError
        One line with the data size, the estimated need and the limit, when the
        estimate exceeds the limit.
    ValueError
        If ``max_memory_mb`` is not a number in (0, 1e9].
    """
    if max_memory_mb is None:
        limit = available_memory_bytes()
        source = "the memory available"
    else:
        checked = check_number(max_memory_mb, MAX_MEMORY_MB_RANGE, "max_memory_mb")
        limit = int(checked * MIB)
        source = "--max-memory-mb"
    estimate = estimate_identify_memory(
        path, cache_size_mb=cache_size_mb, max_working_set=max_working_set
    )
    logger.debug("identify memory: %s, limit %s", estimate, limit)
    if limit is not None and estimate.peak_bytes > limit:
        raise DatasetError(
            f"The data at {path} ({estimate.csv_bytes / MIB:.1f} MiB of CSV, about "
            f"{estimate.rows:,} samples) would need about {estimate.peak_bytes / MIB:,.0f} MiB "
            f"to identify, more than {source} ({limit / MIB:,.0f} MiB); split it into "
            "smaller files, use fewer experiments, or allow more memory with --max-memory-mb."
        )
    return estimate
