"""The size of a control run, checked before it starts: its ticks and its memory.

``softbend control simulate`` logs every step of the rig model and
``softbend control run`` every tick of the loop, in memory, so the size of a
run is known from its duration and its step before anything runs. One function,
:func:`check_run_size`, holds both commands (and their library functions,
:func:`~softbend.control.experiments.simulate` and
:func:`~softbend.control.loop.run_loop`) to:

1. a duration in (0, :data:`MAX_DURATION_S`] s;
2. the ``loop_ticks`` limit of :mod:`softbend.limits` (``SOFTBEND_MAX_LOOP_TICKS``):
   at most that many logged steps or ticks (10 000 000 by default: 10 000 s at
   the default 1 ms);
3. the memory the run needs (its steps times the bytes logged per step, plus the
   interpreter and its libraries), against the memory the machine has left:
   a run that would not fit is refused with one line naming the duration,
   instead of ending in a ``MemoryError`` after minutes of work.

The bytes per step were measured (``tracemalloc``, 1 000 000 steps) on the whole
command: the log while running, the table and the metrics built from it, the
CSV written and the figure (drawn from at most :data:`FIGURE_POINTS` points).
"""

from __future__ import annotations

import math
from dataclasses import dataclass

from softbend._validation import check_range
from softbend.errors import InputError, keyed
from softbend.limits import check_limit

__all__ = [
    "BASE_BYTES",
    "FIGURE_POINTS",
    "LOOP_BYTES_PER_TICK",
    "MAX_DURATION_S",
    "SIMULATE_BYTES_PER_STEP",
    "RunSize",
    "check_run_size",
]

#: The longest run, s (a day); the ``loop_ticks`` limit is usually the tighter bound.
MAX_DURATION_S = 86_400.0
#: Peak bytes per rig step of ``control simulate`` (measured about 200; with a margin).
SIMULATE_BYTES_PER_STEP = 300
#: Peak bytes per tick of ``control run`` (measured about 300; with a margin).
LOOP_BYTES_PER_TICK = 400
#: The interpreter, NumPy, pandas, matplotlib and a controller's model.
BASE_BYTES = 400 * 2**20
#: The most points per line a run's figure draws (its envelope is kept).
FIGURE_POINTS = 20_000

_GIB = 2**30


@dataclass(frozen=True)
class RunSize:
    """The size of a checked run.

    Attributes
    ----------
    ticks : int
        Steps (``simulate``) or ticks (the loop) logged.
    memory_bytes : int
        The estimated peak memory of the run, bytes.
    """

    ticks: int
    memory_bytes: int


def check_run_size(
    duration_s: float,
    step_s: float,
    bytes_per_tick: int,
    *,
    what: str = "A run",
    unit: str = "ticks",
    step_word: str | None = None,
    available_bytes: int | None = -1,
) -> RunSize:
    """Refuse, before it starts, a run too long for the limits or the memory.

    Parameters
    ----------
    duration_s : float
        The run time, s, in (0, :data:`MAX_DURATION_S`].
    step_s : float
        The time between two logged rows (a rig step, a loop tick), s (> 0).
    bytes_per_tick : int
        Peak memory per logged row (:data:`SIMULATE_BYTES_PER_STEP`,
        :data:`LOOP_BYTES_PER_TICK`).
    what : str
        The run, for messages (``"A simulated run"``).
    unit : str
        What a logged row is called in messages (``"rig steps"``, ``"ticks"``).
    step_word : str, optional
        What the step is called in messages (default: ``unit`` in the singular).
    available_bytes : int, optional
        The memory the run may use; default (-1): what the machine has left
        (:func:`softbend.identification.resources.available_memory_bytes`);
        None: no memory check.

    Returns
    -------
    RunSize
        ``round(duration_s / step_s)`` rows (at least 1) and the estimated memory.

    Raises
    ------
    InputError
        A duration or step out of range (key ``duration_s``, ``step_s``), or a
        run whose estimated memory exceeds ``available_bytes`` (key ``duration_s``:
        the one to shorten).
    LimitError
        More rows than the ``loop_ticks`` limit (``SOFTBEND_MAX_LOOP_TICKS``); key
        ``duration_s``.
    """
    duration = check_range(
        duration_s, "duration_s", low=0.0, high=MAX_DURATION_S, high_inclusive=True
    )
    step = check_range(step_s, "step_s", low=0.0)
    word = unit.removesuffix("s") if step_word is None else step_word
    said = f"{what} of {duration:g} s at a {word} of {step:g} s"
    ratio = duration / step
    with keyed("duration_s"):
        check_limit("loop_ticks", round(ratio) if math.isfinite(ratio) else ratio, said)
    ticks = max(1, round(ratio))
    need = BASE_BYTES + ticks * int(bytes_per_tick)
    if available_bytes == -1:
        from softbend.identification.resources import available_memory_bytes

        available_bytes = available_memory_bytes()
    if available_bytes is not None and need > available_bytes:
        raise InputError(
            f"{said} logs {ticks:,} {unit}: about {need / _GIB:.1f} GiB of memory, more than "
            f"the {available_bytes / _GIB:.1f} GiB this machine has left; shorten the run "
            f"or lengthen its {word}",
            key="duration_s",
        )
    return RunSize(ticks=ticks, memory_bytes=need)
