"""Record a benchmark's headline figures as JSON, with where, when and how they were measured.

Every ``benchmarks/bench_*.py`` that prints headline figures calls :func:`record`
once per run (once per variant, under the variant's name), which writes
``benchmarks/results/<name>.json``::

    {
      "benchmark": "predict",
      "command": "python benchmarks/bench_predict.py --runs 10",
      "date": "2026-01-01T12:00:00+00:00",
      "figures": [{"name": "best", "unit": "s", "value": 0.21}, ...],
      "machine": {"cpu": ..., "gpu": null, "logical_cores": 2, "memory_gib": 7.8, ...},
      "notes": "",
      "schema": 1,
      "software": {"git_commit": ..., "git_dirty": true, "numpy": ..., "python": ...,
                   "softbend": ...}
    }

Figures keep the order the benchmark gives them; every other key is sorted, so
two runs that measure the same numbers write the same file up to the date and the
machine's load average before the run. The
file is written to a temporary file in the same folder and renamed over the old
one, so a reader never sees half of it. ``docs/gen_performance.py`` renders the
files as the documentation's Performance page.
"""

from __future__ import annotations

import math
import os
import platform
import re
import shlex
import subprocess
import sys
from collections.abc import Mapping, Sequence
from datetime import UTC, datetime
from pathlib import Path
from typing import Any

import numpy as np

import softbend
from softbend._io import json_text, write_text_atomic

#: Root of the repository (the folder above ``benchmarks/``).
ROOT = Path(__file__).resolve().parents[1]

#: Where the benchmarks' JSON files live.
RESULTS_DIR = ROOT / "benchmarks" / "results"

#: Version of the file layout above.
SCHEMA = 1

_NAME = re.compile(r"[a-z0-9][a-z0-9_.-]*")


def _relative(arg: str) -> str:
    """``arg`` relative to the repository root if it is an absolute path inside it."""
    path = Path(arg)
    if not path.is_absolute():
        return arg
    try:
        return path.resolve().relative_to(ROOT).as_posix()
    except ValueError:
        return arg


def command_line(argv: Sequence[str] | None = None) -> str:
    """The command that ran the benchmark, ``python benchmarks/<script> <args>``.

    Parameters
    ----------
    argv : sequence of str, optional
        The script and its arguments (default :data:`sys.argv`). Absolute paths
        inside the repository are written relative to its root, so the command
        runs as written from a fresh clone.

    Returns
    -------
    str
        The shell-quoted command.
    """
    argv = list(sys.argv if argv is None else argv)
    return shlex.join(["python", *(_relative(a) for a in argv)])


def variant_name(name: str, *parts: object) -> str:
    """``name`` followed by the parts that are not None, as a valid record name.

    >>> variant_name("control", "lab", None)
    'control-lab'
    >>> variant_name("campaign", "lhs:200")
    'campaign-lhs-200'
    """
    words = [name, *(str(p) for p in parts if p is not None)]
    return re.sub(r"[^a-z0-9_.]+", "-", "-".join(words).lower()).strip("-")


def table_figures(
    rows: Mapping[str, Mapping[str, Any]],
    columns: Mapping[str, tuple[str, str]],
    *,
    digits: int = 3,
) -> tuple[dict[str, Any], dict[str, str]]:
    """Figures and units of a table the benchmark already printed, one figure per cell.

    Parameters
    ----------
    rows : mapping of str to mapping
        The benchmark's result rows by label (a model, a controller...).
    columns : mapping of str to (str, str)
        The keys of a row to keep, each with its figure label and unit.
    digits : int
        Floats are rounded to this many decimals.

    Returns
    -------
    figures, units : dict
        For :func:`record`; the figures are named ``"<row>: <label>"``.

    >>> table_figures({"a": {"fit_s": 1.23456, "n": 3}}, {"fit_s": ("fit", "s")})
    ({'a: fit': 1.235}, {'a: fit': 's'})
    """
    figures: dict[str, Any] = {}
    units: dict[str, str] = {}
    for row, values in rows.items():
        for key, (label, unit) in columns.items():
            value = values.get(key)
            if isinstance(value, float | np.floating):
                value = round(float(value), digits)
            figures[f"{row}: {label}"] = value
            if unit:
                units[f"{row}: {label}"] = unit
    return figures, units


def _cpu_model() -> str | None:
    try:
        with open("/proc/cpuinfo", encoding="utf-8", errors="replace") as info:
            for line in info:
                key, _, value = line.partition(":")
                if key.strip() in ("model name", "Model", "Hardware") and value.strip():
                    return value.strip()
    except OSError:
        pass
    return platform.processor() or None


def _memory_gib() -> float | None:
    try:
        pages, page_size = os.sysconf("SC_PHYS_PAGES"), os.sysconf("SC_PAGE_SIZE")
    except (AttributeError, OSError, ValueError):
        return None
    return round(pages * page_size / 2**30, 1) if pages > 0 and page_size > 0 else None


def _gpu_name() -> str | None:
    """The CUDA device's name if this process used one through PyTorch, else None."""
    torch = sys.modules.get("torch")  # never imported here: a NumPy benchmark stays one
    if torch is None:
        return None
    try:
        if torch.cuda.is_available() and torch.cuda.is_initialized():
            return str(torch.cuda.get_device_name(torch.cuda.current_device()))
    except Exception:  # a broken driver must not lose the figures
        return None
    return None


#: The 1-minute load average when the benchmark imported this module, before it ran: other
#: work on the machine (None where the platform has no load average).
_LOAD_AT_START = round(os.getloadavg()[0], 2) if hasattr(os, "getloadavg") else None


def machine() -> dict[str, Any]:
    """Platform, CPU model, logical cores, memory (GiB) and the GPU used (or None)."""
    return {
        "cpu": _cpu_model(),
        "gpu": _gpu_name(),
        "logical_cores": os.cpu_count(),
        "memory_gib": _memory_gib(),
        # How busy the machine was before the benchmark started (1-minute load average, Unix).
        "load_average_1min": _LOAD_AT_START,
        "platform": platform.platform(),
    }


def _git(*args: str) -> str | None:
    try:
        done = subprocess.run(
            ["git", "--no-optional-locks", "-C", str(ROOT), *args],
            capture_output=True,
            text=True,
            timeout=30,
            check=False,
        )
    except (OSError, subprocess.SubprocessError):
        return None
    return done.stdout if done.returncode == 0 else None


def software() -> dict[str, Any]:
    """Python, NumPy and softbend versions, the git commit and whether the tree was dirty.

    ``git_commit`` is ``"unknown"`` and ``git_dirty`` None outside a git checkout.
    Dirty means a tracked file differs from the commit (untracked files do not count).
    """
    commit = _git("rev-parse", "HEAD")
    status = _git("status", "--porcelain", "--untracked-files=no") if commit else None
    return {
        "git_commit": commit.strip() if commit else "unknown",
        "git_dirty": None if status is None else bool(status.strip()),
        "numpy": np.__version__,
        "python": platform.python_version(),
        "softbend": softbend.__version__,
    }


def _figure_value(name: str, value: Any) -> int | float | str | bool | None:
    if isinstance(value, np.generic):
        value = value.item()
    if isinstance(value, bool | int | str) or value is None:
        return value
    if isinstance(value, float):
        return value if math.isfinite(value) else str(value)
    raise TypeError(
        f"The value of figure {name!r} of record must be a number, a string or None. "
        f"Got {type(value).__name__} instead."
    )


def record(
    name: str,
    figures: Mapping[str, Any],
    *,
    units: Mapping[str, str] | None = None,
    notes: str = "",
    out_dir: str | os.PathLike[str] = RESULTS_DIR,
    argv: Sequence[str] | None = None,
) -> Path:
    """Write ``<out_dir>/<name>.json`` with the figures, the command, date, machine and software.

    Parameters
    ----------
    name : str
        The benchmark (or variant) name: lower-case letters, digits, ``_``, ``-``
        and ``.``, starting with a letter or digit; the file's stem.
    figures : mapping of str to number, str or None
        The headline figures in the order the page lists them. NumPy scalars
        become Python numbers; NaN and inf are written as strings.
    units : mapping of str to str, optional
        The unit of each figure that has one (``"s"``, ``"µs"``, ``"MiB"``,
        ``"%"``, ``"deg"``...); a figure without an entry is dimensionless.
    notes : str
        One line on what was measured, shown under the table.
    out_dir : path-like
        Folder of the JSON files (default ``benchmarks/results``).
    argv : sequence of str, optional
        The command line to record (default :data:`sys.argv`).

    Returns
    -------
    pathlib.Path
        The file written.

    Raises
    ------
    ValueError
        If ``name`` is not a valid name or ``units`` names a figure not given.
    TypeError
        If a figure is not a number, a string or None.
    """
    if not isinstance(name, str) or not _NAME.fullmatch(name):
        raise ValueError(
            "The 'name' of record must be lower-case letters, digits, '_', '-' or '.', "
            f"starting with a letter or digit. Got {name!r} instead."
        )
    units = dict(units or {})
    unknown = sorted(set(units) - set(figures))
    if unknown:
        raise ValueError(
            f"The 'units' of record must name figures of {sorted(figures)}. Got {unknown} instead."
        )
    payload = {
        "benchmark": name,
        "command": command_line(argv),
        "date": datetime.now(UTC).isoformat(timespec="seconds"),
        "figures": [
            {"name": str(key), "unit": units.get(key, ""), "value": _figure_value(key, value)}
            for key, value in figures.items()
        ],
        "machine": machine(),
        "notes": notes,
        "schema": SCHEMA,
        "software": software(),
    }
    path = Path(out_dir) / f"{name}.json"
    write_text_atomic(path, json_text(payload, indent=2, sort_keys=True) + "\n")
    return path
