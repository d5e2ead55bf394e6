"""Ctrl-C held back across a step that must finish whole."""

from __future__ import annotations

import signal
import threading
from collections.abc import Iterator
from contextlib import contextmanager

__all__ = ["interrupts_deferred"]


@contextmanager
def interrupts_deferred() -> Iterator[None]:
    """Hold a Ctrl-C back until the block ends, then raise it (KeyboardInterrupt).

    Around a database transaction (a Ctrl-C inside a DuckDB query otherwise
    surfaces as ``RuntimeError: Query interrupted`` and the finished work in
    the transaction is rolled back) and around a task's submission, which may
    start a worker. Only the main thread receives signals and may change a
    handler; elsewhere, and where Ctrl-C is ignored, the block runs as it is.
    A command's own handler is called once the block ends.
    """
    if (
        threading.current_thread() is not threading.main_thread()
        or signal.getsignal(signal.SIGINT) is signal.SIG_IGN
    ):
        yield
        return
    received: list[int] = []
    previous = signal.signal(signal.SIGINT, lambda signum, frame: received.append(signum))
    try:
        yield
    finally:
        signal.signal(signal.SIGINT, previous)
    if received:
        if callable(previous) and previous is not signal.default_int_handler:
            previous(signal.SIGINT, None)
        raise KeyboardInterrupt
