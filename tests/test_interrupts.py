"""Ctrl-C held back: raised at the block's end, or where the block delivers it."""

from __future__ import annotations

import signal
import threading

import pytest

from softbend._interrupts import interrupts_deferred


@pytest.fixture(autouse=True)
def _default_handler():
    """Python's own SIGINT handler, as in a new process: a test run started as a
    background job inherits SIGINT ignored, and the block then runs as it is."""
    previous = signal.signal(signal.SIGINT, signal.default_int_handler)
    yield
    signal.signal(signal.SIGINT, previous)


def test_where_ctrl_c_is_ignored_the_block_runs_as_it_is():
    signal.signal(signal.SIGINT, signal.SIG_IGN)
    with interrupts_deferred() as deliver:
        _ctrl_c()
        deliver()
    assert signal.getsignal(signal.SIGINT) is signal.SIG_IGN


def _ctrl_c() -> None:
    """SIGINT to this thread (the main one): its handler runs before the next line."""
    signal.raise_signal(signal.SIGINT)


def test_a_ctrl_c_inside_the_block_is_raised_at_its_end_after_the_block_finished():
    steps = []
    with pytest.raises(KeyboardInterrupt), interrupts_deferred():
        _ctrl_c()
        steps.append("finished")
    assert steps == ["finished"]
    assert signal.getsignal(signal.SIGINT) is signal.default_int_handler


def test_deliver_raises_a_held_ctrl_c_where_the_block_calls_it_and_only_once():
    steps = []
    with pytest.raises(KeyboardInterrupt), interrupts_deferred() as deliver:
        deliver()  # nothing held yet
        steps.append("before")
        _ctrl_c()
        steps.append("held")
        deliver()
        steps.append("not reached")
    assert steps == ["before", "held"]
    assert signal.getsignal(signal.SIGINT) is signal.default_int_handler


def test_no_ctrl_c_no_exception_and_the_handler_is_restored():
    with interrupts_deferred() as deliver:
        deliver()
    assert signal.getsignal(signal.SIGINT) is signal.default_int_handler


def test_a_command_s_own_handler_is_called_when_the_ctrl_c_is_delivered():
    called = []
    previous = signal.signal(signal.SIGINT, lambda signum, frame: called.append(signum))
    try:
        with pytest.raises(KeyboardInterrupt), interrupts_deferred():
            _ctrl_c()
            assert called == []
        assert called == [signal.SIGINT]
    finally:
        signal.signal(signal.SIGINT, previous)


def test_off_the_main_thread_the_block_runs_as_it_is():
    seen = []

    def work() -> None:
        with interrupts_deferred() as deliver:
            deliver()
            seen.append(signal.getsignal(signal.SIGINT))

    thread = threading.Thread(target=work)
    thread.start()
    thread.join()
    assert seen == [signal.default_int_handler]
