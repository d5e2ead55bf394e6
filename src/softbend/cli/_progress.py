"""Progress on stderr: a rich bar on a terminal, plain lines at every tenth elsewhere."""

from __future__ import annotations

from collections.abc import Callable, Iterator
from contextlib import contextmanager
from typing import Any

from rich.progress import (
    BarColumn,
    MofNCompleteColumn,
    Progress,
    TextColumn,
    TimeElapsedColumn,
    TimeRemainingColumn,
)

from softbend.cli._console import err_console

__all__ = ["library_progress", "phase_progress", "progress_bar"]


@contextmanager
def progress_bar(
    description: str, total: int, *, enabled: bool = True
) -> Iterator[Callable[..., None]]:
    """Yield ``advance(n=1, **fields)``, drawing a rich progress bar on stderr.

    Extra keyword fields (e.g. ``failed=3``) are shown after the bar. Off a
    terminal (a batch queue, a log file) a bar would draw nothing until the end,
    so a plain line with the count, the fields, the elapsed time and an estimate
    of the time left is written at every tenth of the total instead.
    """
    if enabled and not err_console.is_terminal:
        import time

        state = {"done": 0, "tenth": -1, "start": time.monotonic()}

        def advance_plain(n: int = 1, **fields: object) -> None:
            state["done"] += n
            done = state["done"]
            tenth = 10 if total <= 0 else min(10, (10 * done) // total)
            if tenth <= state["tenth"]:
                return
            state["tenth"] = tenth
            elapsed = time.monotonic() - state["start"]
            eta = f", about {elapsed / done * (total - done):.0f} s left" if done else ""
            info = "  ".join(f"{k} {v}" for k, v in fields.items())
            err_console.print(
                f"{description}: {done}/{total}  {info}  {elapsed:.0f} s{eta}",
                highlight=False,
                soft_wrap=True,
            )

        yield advance_plain
        return
    columns = [
        TextColumn("[progress.description]{task.description}"),
        BarColumn(),
        MofNCompleteColumn(),
        TextColumn("{task.fields[info]}"),
        TimeElapsedColumn(),
        TextColumn("ETA"),
        TimeRemainingColumn(),
    ]
    with Progress(*columns, console=err_console, disable=not enabled, transient=False) as bar:
        task = bar.add_task(description, total=total, info="")

        def advance(n: int = 1, **fields: object) -> None:
            info = "  ".join(f"{k} {v}" for k, v in fields.items())
            bar.update(task, advance=n, info=info)

        yield advance


@contextmanager
def phase_progress(*, enabled: bool = True) -> Iterator[Callable[[str, int, int], None]]:
    """Yield ``progress(phase, done, total)`` for jobs with several phases.

    On a terminal each phase gets a rich progress bar on stderr. Elsewhere (a
    batch queue, a CI log) a bar would draw nothing until the end, so a plain
    line is written to stderr when a phase starts, at every further tenth of
    it, and when it ends.
    """
    if not enabled:
        yield lambda phase, done, total: None
        return
    if err_console.is_terminal:
        columns = [
            TextColumn("{task.description}"),
            BarColumn(),
            MofNCompleteColumn(),
            TimeElapsedColumn(),
            TextColumn("ETA"),
            TimeRemainingColumn(),
        ]
        with Progress(*columns, console=err_console) as bar:
            tasks: dict[str, Any] = {}

            def draw(phase: str, done: int, total: int) -> None:
                if phase not in tasks:
                    tasks[phase] = bar.add_task(phase, total=total)
                bar.update(tasks[phase], completed=done, total=total)

            yield draw
        return
    import time

    last_tenth: dict[str, int] = {}
    started: dict[str, float] = {}

    def write(phase: str, done: int, total: int) -> None:
        tenth = 10 if total <= 0 else min(10, (10 * done) // total)
        if done == 0 and last_tenth.get(phase) == 10:  # the phase begins again (the next fit)
            del last_tenth[phase], started[phase]
        if phase in last_tenth and tenth <= last_tenth[phase]:
            return
        started.setdefault(phase, time.monotonic())
        last_tenth[phase] = tenth
        elapsed = time.monotonic() - started[phase]
        err_console.print(f"{phase}: {done}/{total} ({elapsed:.0f} s)", highlight=False)

    yield write


@contextmanager
def library_progress(*, enabled: bool = True) -> Iterator[Callable[[str, int, int], None]]:
    """:func:`phase_progress` that also hears the library's own reports.

    The epochs of a network's refit and the pressures of an FEM sweep report to
    :mod:`softbend._progress`; inside this block they are drawn as phases.
    """
    from softbend._progress import listening

    with phase_progress(enabled=enabled) as progress, listening(progress):
        yield progress
