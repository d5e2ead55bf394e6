"""The three ways a campaign's designs are swept: serially, in local processes, on Dask.

Each executor takes the designs left to do (one list, or chunks of several
designs per task) and hands every :class:`Outcome` to a :class:`Recorder`,
which writes it to the campaign database in the coordinating process and
reports progress. Workers only compute: :func:`sweep_chunk` is the task they
run, and it never raises for one design's sake (the exception becomes that
design's failure, ``"ExceptionType: message"``).

* :func:`run_serial`: in this process, one design after another;
* :func:`run_local`: a :class:`concurrent.futures.ProcessPoolExecutor` started
  through a fork server (``spawn`` where there is none); when a worker process
  dies the designs then in flight are rerun one by one, each in a process of its
  own, and the pool is restarted at most three times;
* :func:`run_dask`: a Dask ``distributed`` client from :func:`connect`, which
  checks the scheduler address (:func:`parse_scheduler_address`) and gives up
  within its deadline when nothing Dask-like answers there.

:func:`softbend.campaign.runner.run_campaign` picks one of them.
"""

from __future__ import annotations

import json
import logging
import math
import multiprocessing
import re
import socket
import threading
import time
from collections import deque
from collections.abc import Callable, Iterable, Sequence
from concurrent.futures import FIRST_COMPLETED, ProcessPoolExecutor, wait
from concurrent.futures.process import BrokenProcessPool
from dataclasses import dataclass
from pathlib import Path
from typing import TYPE_CHECKING, Any

import numpy as np

from softbend._extras import require
from softbend.campaign.backends import Backend, SweepResult
from softbend.design import SFRBADesign
from softbend.errors import SoftbendError

if TYPE_CHECKING:
    from softbend.campaign.store import CampaignStore

__all__ = [
    "Outcome",
    "ProgressCallback",
    "Recorder",
    "connect",
    "parse_scheduler_address",
    "run_dask",
    "run_local",
    "run_serial",
    "sweep_chunk",
]

logger = logging.getLogger(__name__)

#: ``progress(done, failed, running, total)``: designs finished and failed in this
#: run, designs handed to workers and not yet back, designs this run has to do.
ProgressCallback = Callable[[int, int, int, int], None]

_OWNER = "run_campaign"
_ADDRESS = re.compile(
    r"^(?P<protocol>tcp|tls)://(?P<host>\[[0-9A-Fa-f:.]+\]|[A-Za-z0-9._-]+):(?P<port>\d{1,5})$"
)
# Tasks in flight per worker: enough to keep workers busy while results are recorded.
_TASKS_PER_WORKER = 2
# A local pool whose worker processes keep dying is restarted at most this often.
_MAX_POOL_RESTARTS = 3


# -- one design's sweep, in a worker -------------------------------------------------


@dataclass(frozen=True)
class Outcome:
    """One design's sweep, as sent back by a worker."""

    design: SFRBADesign
    result: SweepResult | None
    error: str | None
    wall_time_s: float


def _error_text(exc: BaseException) -> str:
    message = " ".join(str(exc).split())
    return f"{type(exc).__name__}: {message}" if message else type(exc).__name__


def _sweep_one(backend: Backend, design: SFRBADesign, pressures_mpa: np.ndarray) -> Outcome:
    start = time.perf_counter()
    try:
        result = backend.sweep(design, pressures_mpa)
        if not isinstance(result, SweepResult):
            raise SoftbendError(
                f"backend {backend.name!r} returned {type(result).__name__}, not a SweepResult"
            )
        if result.design.design_id != design.design_id:
            raise SoftbendError(
                f"backend {backend.name!r} returned the sweep of design {result.design} "
                f"for design {design}"
            )
    except Exception as exc:
        return Outcome(design, None, _error_text(exc), time.perf_counter() - start)
    return Outcome(design, result, None, result.wall_time_s)


def sweep_chunk(
    backend: Backend, designs: Sequence[SFRBADesign], pressures_mpa: np.ndarray
) -> list[Outcome]:
    """Worker task: sweep each design of the chunk independently."""
    return [_sweep_one(backend, design, pressures_mpa) for design in designs]


def _lost_chunk(designs: Sequence[SFRBADesign], exc: BaseException) -> list[Outcome]:
    text = _error_text(exc)
    if isinstance(exc, BrokenProcessPool):
        text = (
            "BrokenProcessPool: a worker process died while this design's task was pending "
            "(killed, out of memory or crashed)"
        )
    return [Outcome(design, None, text, float("nan")) for design in designs]


# -- the outcomes, in the coordinating process ---------------------------------------


class Recorder:
    """Writes outcomes to the store as they arrive and reports progress.

    Parameters
    ----------
    store : CampaignStore
        The campaign database, open for writing.
    backend : str
        Backend name recorded with every design.
    total : int
        Designs this run has to do.
    progress : callable, optional
        ``progress(done, failed, running, total)``.
    """

    def __init__(
        self, store: CampaignStore, backend: str, total: int, progress: ProgressCallback | None
    ) -> None:
        self.store = store
        self.backend = backend
        self.total = total
        self.progress = progress
        self.done = 0
        self.failed = 0
        self.running = 0
        self.sweep_time_s = 0.0
        self.failures: list[tuple[str, str]] = []

    def report(self) -> None:
        """Call the progress callback, if any, with the current counts."""
        if self.progress is not None:
            self.progress(self.done, self.failed, self.running, self.total)

    def set_running(self, running: int) -> None:
        """Set the number of designs handed out and not yet back; report a change."""
        if running != self.running:
            self.running = running
            self.report()

    def record(self, outcomes: Iterable[Outcome], running: int) -> None:
        """Write each outcome (a result off the campaign grid as a failure), then report."""
        for outcome in outcomes:
            error = outcome.error
            if outcome.result is not None:
                try:
                    self.store.record_success(outcome.result, backend=self.backend)
                except ValueError as exc:  # a result off the campaign grid
                    error = _error_text(exc)
            if error is not None:
                self.store.record_failure(
                    outcome.design, error, outcome.wall_time_s, backend=self.backend
                )
                self.failed += 1
                self.failures.append((outcome.design.design_id, error))
                logger.warning("design %s failed: %s", outcome.design, error)
            else:
                self.done += 1
            if math.isfinite(outcome.wall_time_s):
                self.sweep_time_s += outcome.wall_time_s
        self.running = running
        self.report()


# -- serial and local processes ------------------------------------------------------


def run_serial(
    backend: Backend, todo: Sequence[SFRBADesign], pressures: np.ndarray, recorder: Recorder
) -> None:
    """Sweep the designs one after another in this process."""
    for design in todo:
        recorder.set_running(1)
        recorder.record([_sweep_one(backend, design, pressures)], running=0)


def _mp_context() -> multiprocessing.context.BaseContext:
    if "forkserver" in multiprocessing.get_all_start_methods():
        context = multiprocessing.get_context("forkserver")
        # Workers fork from a server that has already imported the model code.
        context.set_forkserver_preload(
            ["__main__", "softbend.campaign.executors", "softbend.analytical"]
        )
        return context
    return multiprocessing.get_context("spawn")


def _run_isolated(
    backend: Backend,
    suspects: deque[SFRBADesign],
    pressures: np.ndarray,
    context: Any,
    recorder: Recorder,
) -> None:
    """Run each design that was in flight when a worker died alone, in its own process.

    A worker that dies takes every pending task of its pool with it, so those
    designs cannot be blamed: each is run again by itself, and only a design
    whose own process dies is recorded as failed (with that reason).
    """
    while suspects:
        design = suspects.popleft()
        recorder.set_running(1)
        pool = ProcessPoolExecutor(max_workers=1, mp_context=context)
        try:
            outcomes = pool.submit(sweep_chunk, backend, [design], pressures).result()
        except BrokenProcessPool:
            outcomes = [
                Outcome(
                    design,
                    None,
                    "BrokenProcessPool: the worker process died while sweeping this design "
                    "alone (killed, out of memory or crashed)",
                    float("nan"),
                )
            ]
        except Exception as exc:
            outcomes = _lost_chunk([design], exc)
        finally:
            pool.shutdown(wait=True, cancel_futures=True)
        recorder.record(outcomes, running=0)


def run_local(
    backend: Backend,
    chunks: deque[list[SFRBADesign]],
    pressures: np.ndarray,
    workers: int,
    recorder: Recorder,
) -> None:
    """Sweep the chunks in a pool of ``workers`` local processes.

    Raises
    ------
    SoftbendError
        Worker processes died more than three times (the designs not run are
        left for a resumed run).
    """
    context = _mp_context()
    restarts = 0
    suspects: deque[SFRBADesign] = deque()
    while chunks or suspects:
        _run_isolated(backend, suspects, pressures, context, recorder)
        if not chunks:
            break
        pool = ProcessPoolExecutor(max_workers=workers, mp_context=context)
        pending: dict[Any, list[SFRBADesign]] = {}
        broken = False
        clean = False
        try:
            while chunks or pending:
                while chunks and not broken and len(pending) < _TASKS_PER_WORKER * workers:
                    chunk = chunks.popleft()
                    try:
                        future = pool.submit(sweep_chunk, backend, chunk, pressures)
                    except BrokenProcessPool:
                        chunks.appendleft(chunk)
                        broken = True
                        break
                    pending[future] = chunk
                recorder.set_running(sum(len(c) for c in pending.values()))
                if not pending:
                    break
                finished, _ = wait(pending, return_when=FIRST_COMPLETED)
                for future in finished:
                    chunk = pending.pop(future)
                    try:
                        outcomes = future.result()
                    except BrokenProcessPool:
                        broken = True
                        suspects.extend(chunk)  # not blamed yet: rerun alone
                        continue
                    except Exception as exc:
                        outcomes = _lost_chunk(chunk, exc)
                    recorder.record(outcomes, running=sum(len(c) for c in pending.values()))
            clean = True
        finally:
            pool.shutdown(wait=clean, cancel_futures=True)
        if broken:
            restarts += 1
            if restarts > _MAX_POOL_RESTARTS:
                raise SoftbendError(
                    f"Worker processes died {restarts} times; {sum(map(len, chunks))} designs "
                    "were not run. Check memory and the backend, then re-run to resume."
                )
            logger.warning(
                "a worker process died; rerunning the %d designs it took down one by one",
                len(suspects),
            )


# -- a Dask cluster ------------------------------------------------------------------


def parse_scheduler_address(scheduler: str) -> str:
    """Check a Dask scheduler address ``tcp://HOST:PORT`` (or ``tls://``) and return it.

    A path to an existing JSON scheduler file (written by ``dask scheduler
    --scheduler-file``) is read and its ``address`` returned.

    Raises
    ------
    ValueError
        Naming ``--scheduler``, the expected form and the value received.
    """
    text = str(scheduler).strip()
    if text.endswith(".json") and "://" not in text:
        path = Path(text)
        if not path.is_file():
            raise FileNotFoundError(f"No Dask scheduler file at {text!r} (--scheduler).")
        try:
            text = str(json.loads(path.read_text())["address"])
        except (ValueError, KeyError, TypeError):
            raise ValueError(
                f"The Dask scheduler file {str(path)!r} (--scheduler) has no 'address'."
            ) from None
    match = _ADDRESS.match(text)
    if match is None or not 1 <= int(match["port"]) <= 65535:
        raise ValueError(
            f"The 'scheduler' (--scheduler) of {_OWNER} must be an address of the form "
            f"tcp://HOST:PORT (PORT 1-65535) or a Dask scheduler file. Got {scheduler!r} instead."
        )
    return text


def _probe(address: str, timeout_s: float) -> None:
    """Fail fast, with one clear line, when nothing listens at the scheduler address."""
    match = _ADDRESS.match(parse_scheduler_address(address))
    host = match["host"].strip("[]")
    try:
        with socket.create_connection((host, int(match["port"])), timeout=timeout_s):
            pass
    except OSError as exc:
        reason = exc.strerror or type(exc).__name__
        raise SoftbendError(
            f"Cannot reach the Dask scheduler at {address} ({reason}); start it with "
            "'dask scheduler' or check --scheduler."
        ) from None


def connect(address: str, timeout_s: float) -> Any:
    """A Dask client of the scheduler at ``address``, or one line within the deadline.

    Every wait has a deadline: something that accepts TCP but is not a Dask
    scheduler (a web server, a silent listener) may never finish Dask's
    handshake, so the connection runs in a helper thread that is given up after
    ``timeout_s`` (plus a grace of 5 s).
    """
    Client = require("distributed", "A campaign on a Dask cluster (--scheduler)").Client

    _probe(address, timeout_s)
    box: dict[str, Any] = {}

    def attempt() -> None:
        try:
            box["client"] = Client(address, timeout=timeout_s, set_as_default=False)
        except BaseException as exc:  # reported below, in the caller's thread
            box["error"] = exc

    thread = threading.Thread(target=attempt, name="softbend-dask-connect", daemon=True)
    thread.start()
    thread.join(timeout_s + 5.0)
    if thread.is_alive():
        raise SoftbendError(
            f"The Dask scheduler at {address} did not answer within {timeout_s:g} s: something "
            "listens there but does not speak Dask's protocol; check --scheduler."
        )
    if "error" in box:
        exc = box["error"]
        reason = " ".join(str(exc).split()) or type(exc).__name__
        raise SoftbendError(
            f"Cannot connect to the Dask scheduler at {address}: {type(exc).__name__}: "
            f"{reason[:200]}"
        ) from None
    client = box["client"]
    try:
        client.wait_for_workers(1, timeout=timeout_s)
    except Exception:
        client.close()
        raise SoftbendError(
            f"The Dask scheduler at {address} has no workers (waited {timeout_s:g} s); "
            "start some with 'dask worker ADDRESS'."
        ) from None
    return client


def run_dask(
    backend: Backend,
    chunks: deque[list[SFRBADesign]],
    pressures: np.ndarray,
    client: Any,
    recorder: Recorder,
) -> None:
    """Sweep the chunks on the Dask cluster of ``client``; pending tasks are cancelled on exit."""
    from distributed import as_completed

    n_threads = max(1, sum(client.nthreads().values()))
    pending: dict[Any, list[SFRBADesign]] = {}

    def submit() -> Any:
        chunk = chunks.popleft()
        future = client.submit(sweep_chunk, backend, chunk, pressures, pure=False)
        pending[future] = chunk
        return future

    initial = [submit() for _ in range(min(len(chunks), _TASKS_PER_WORKER * n_threads))]
    recorder.set_running(sum(len(c) for c in pending.values()))
    queue = as_completed(initial, loop=client.loop)
    try:
        for future in queue:
            chunk = pending.pop(future)
            try:
                outcomes = future.result()
            except Exception as exc:  # task lost: KilledWorker, unpicklable result, ...
                outcomes = _lost_chunk(chunk, exc)
            if chunks:
                queue.add(submit())
            recorder.record(outcomes, running=sum(len(c) for c in pending.values()))
    finally:
        if pending:
            client.cancel(list(pending))
