"""Progress of long library work, reported to whoever listens.

A step that takes more than a couple of seconds deep inside the library (the
epochs of a network's refit, the pressures of an FEM sweep) calls
:func:`report`; nothing happens unless a caller listens (:func:`listening`),
as the command line does to draw a bar or a line per tenth. The listener is
held in a context variable, so the steps in between need no callback argument
and a listener set in one thread is not heard in another.

Example
-------
>>> from softbend._progress import listening, report
>>> seen = []
>>> with listening(lambda phase, done, total: seen.append((phase, done, total))):
...     report("fitting", 1, 4)
>>> seen
[('fitting', 1, 4)]
"""

from __future__ import annotations

import os
from collections.abc import Callable, Iterator
from contextlib import contextmanager
from contextvars import ContextVar
from pathlib import Path

__all__ = ["READ_REPORT_BYTES", "Listener", "every", "listening", "read_phase", "report"]

#: ``listener(phase, done, total)``: ``done`` of ``total`` units of ``phase``.
Listener = Callable[[str, int, int], None]

_LISTENER: ContextVar[Listener | None] = ContextVar("softbend_progress", default=None)


@contextmanager
def listening(listener: Listener | None) -> Iterator[None]:
    """Hear every :func:`report` made inside the block (None: hear nothing)."""
    token = _LISTENER.set(listener)
    try:
        yield
    finally:
        _LISTENER.reset(token)


def report(phase: str, done: int, total: int) -> None:
    """Tell the listener, if any, that ``done`` of ``total`` units of ``phase`` are done."""
    listener = _LISTENER.get()
    if listener is not None:
        listener(phase, int(done), int(total))


def every(total: int, steps: int = 50) -> int:
    """The stride of reports for ``total`` units: about ``steps`` reports in all."""
    return max(1, total // steps)


#: A file at least this large (bytes) reports its read (:func:`read_phase`); a smaller one
#: is read in well under a second, silently.
READ_REPORT_BYTES = 1 << 20


def read_phase(path: str | os.PathLike[str]) -> str | None:
    """The phase a read of ``path`` reports its percent under (``"reading sims.csv, %"``),
    or None for a file smaller than :data:`READ_REPORT_BYTES` (or one that is not there)."""
    try:
        size = Path(path).stat().st_size
    except OSError:
        return None
    return f"reading {Path(path).name}, %" if size >= READ_REPORT_BYTES else None
