"""Library progress: reports reach the listener of their context, and nobody else."""

from __future__ import annotations

import threading

from softbend._progress import every, listening, report


def test_reports_reach_the_listener_inside_the_block_only():
    heard = []
    report("before", 1, 2)
    with listening(lambda phase, done, total: heard.append((phase, done, total))):
        report("fit", 1, 4)
        with listening(None):
            report("silenced", 1, 1)
        report("fit", 4, 4)
    report("after", 2, 2)
    assert heard == [("fit", 1, 4), ("fit", 4, 4)]


def test_a_listener_is_not_heard_in_another_thread():
    heard = []
    with listening(lambda *args: heard.append(args)):
        thread = threading.Thread(target=report, args=("elsewhere", 1, 1))
        thread.start()
        thread.join()
    assert heard == []


def test_about_fifty_reports_whatever_the_total():
    assert every(15000) == 300 and every(10) == 1 and every(0) == 1
