"""Ctrl-C held back across a step that must finish whole, or until a safe point."""

from __future__ import annotations

import signal
import threading
from collections.abc import Callable, Iterator
from contextlib import contextmanager

__all__ = ["interrupts_deferred"]


def _no_interrupt() -> None:
    """Off the main thread, or where Ctrl-C is ignored, there is nothing to deliver."""


@contextmanager
def interrupts_deferred() -> Iterator[Callable[[], None]]:
    """Hold a Ctrl-C back until the block ends, then raise it (KeyboardInterrupt).

    Around a database transaction (a Ctrl-C inside a DuckDB query otherwise
    surfaces as ``RuntimeError: Query interrupted`` and the finished work in
    the transaction is rolled back), around a task's submission, which may
    start a worker, and around a wait on worker processes. The block receives
    ``deliver``: called at a safe point inside the block, it raises a Ctrl-C
    held back so far. A KeyboardInterrupt raised wherever the signal happens to
    land may leave a lock acquired and not released (a future's, while the
    coordinating process waits on its workers); the thread that sets the
    future's result then blocks on it, and so does the interpreter's exit,
    which joins that thread.

    Only the main thread receives signals and may change a handler; elsewhere,
    and where Ctrl-C is ignored, the block runs as it is. A command's own
    handler is called when the Ctrl-C is delivered.
    """
    if (
        threading.current_thread() is not threading.main_thread()
        or signal.getsignal(signal.SIGINT) is signal.SIG_IGN
    ):
        yield _no_interrupt
        return
    received: list[int] = []
    previous = signal.signal(signal.SIGINT, lambda signum, frame: received.append(signum))

    def deliver() -> None:
        if not received:
            return
        received.clear()
        if callable(previous) and previous is not signal.default_int_handler:
            previous(signal.SIGINT, None)
        raise KeyboardInterrupt

    try:
        yield deliver
    finally:
        signal.signal(signal.SIGINT, previous)
    deliver()
