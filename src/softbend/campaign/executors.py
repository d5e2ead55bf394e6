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
  own, and the pool is restarted at most three times. Workers ignore Ctrl-C
  (SIGINT reaches the whole process group from a terminal): the coordinating
  process alone stops, ends its workers and keeps what they recorded;
* :func:`run_dask`: a Dask ``distributed`` client from :func:`connect`, which
  checks the scheduler address (:func:`parse_scheduler_address`) and gives up
  within its deadline when nothing Dask-like answers there.

Both wait on their workers in short polls and raise a Ctrl-C between them
(:func:`softbend._interrupts.interrupts_deferred`): raised wherever the signal
lands, it could leave a lock held that the pool's or the client's own thread
needs, and the command would hang instead of stopping.

:func:`softbend.campaign.runner.run_campaign` picks one of them.
"""

from __future__ import annotations

import json
import logging
import math
import multiprocessing
import os
import re
import signal
import socket
import threading
import time
from collections import deque
from collections.abc import Callable, Iterable, Sequence
from concurrent.futures import FIRST_COMPLETED, ProcessPoolExecutor, wait
from concurrent.futures.process import BrokenProcessPool
from dataclasses import dataclass
from pathlib import Path
from typing import TYPE_CHECKING, Any, cast

import numpy as np

from softbend._extras import require
from softbend._interrupts import interrupts_deferred
from softbend._validation import must_be
from softbend.campaign.backends import Backend, SweepResult
from softbend.campaign.family_schema import CampaignDesign
from softbend.campaign.schema import first_line
from softbend.errors import InputError, SoftbendError, keyed
from softbend.limits import check_file_size

if TYPE_CHECKING:
    from distributed import Client

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

_ADDRESS = re.compile(
    r"^(?P<protocol>tcp|tls)://(?P<host>\[[0-9A-Fa-f:.]+\]|[A-Za-z0-9._-]+):(?P<port>\d{1,5})$"
)
# Tasks in flight per worker: enough to keep workers busy while results are recorded.
_TASKS_PER_WORKER = 2
# A local pool whose worker processes keep dying is restarted at most this often.
_MAX_POOL_RESTARTS = 3
# Seconds between two looks for a Ctrl-C while the coordinating process waits on its workers.
_POLL_S = 0.1
# Seconds between two looks at a Dask cluster's finished tasks (a look costs no round trip).
_DASK_POLL_S = 0.02


# -- one design's sweep, in a worker -------------------------------------------------


@dataclass(frozen=True)
class Outcome:
    """One design's sweep, as sent back by a worker."""

    design: CampaignDesign
    result: SweepResult | None
    error: str | None
    wall_time_s: float


def _error_text(exc: BaseException) -> str:
    message = " ".join(str(exc).split())
    return f"{type(exc).__name__}: {message}" if message else type(exc).__name__


def _sweep_one(backend: Backend, design: CampaignDesign, pressures_mpa: np.ndarray) -> Outcome:
    start = time.perf_counter()
    try:
        # A family's backend sweeps its Design; the protocol names paper B's design.
        result = backend.sweep(cast(Any, design), pressures_mpa)
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
    backend: Backend, designs: Sequence[CampaignDesign], pressures_mpa: np.ndarray
) -> list[Outcome]:
    """Worker task: sweep each design of the chunk independently."""
    return [_sweep_one(backend, design, pressures_mpa) for design in designs]


def _lost_chunk(designs: Sequence[CampaignDesign], exc: BaseException) -> list[Outcome]:
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
    backend: Backend, todo: Sequence[CampaignDesign], pressures: np.ndarray, recorder: Recorder
) -> None:
    """Sweep the designs one after another in this process."""
    for design in todo:
        recorder.set_running(1)
        recorder.record([_sweep_one(backend, design, pressures)], running=0)


def _ignore_interrupts() -> None:
    """Worker initializer: leave Ctrl-C to the coordinating process.

    A terminal sends SIGINT to every process of its foreground group; a worker
    would print a traceback of its own, and so would the processes it starts
    (the FEM's compilers). Each worker ignores SIGINT and leads a process group
    of its own, with the processes it starts, which the coordinating process
    ends as one (:func:`_stop_pool`). Out of the terminal's foreground group,
    it ignores SIGTTOU too, so that its output (and its compilers') is written
    rather than stopping it where the terminal is set to ``stty tostop``.
    """
    signal.signal(signal.SIGINT, signal.SIG_IGN)
    signal.signal(signal.SIGTTOU, signal.SIG_IGN)
    os.setpgid(0, 0)


def _new_pool(workers: int, context: multiprocessing.context.BaseContext) -> ProcessPoolExecutor:
    return ProcessPoolExecutor(
        max_workers=workers, mp_context=context, initializer=_ignore_interrupts
    )


def _stop_pool(pool: ProcessPoolExecutor) -> None:
    """End ``pool`` at once: pending tasks cancelled, each worker's process group terminated.

    On an interruption the designs in flight are given up (a resumed run sweeps
    them again); waiting for them could take as long as an FEM sweep.
    """
    processes = list((getattr(pool, "_processes", None) or {}).values())
    pool.shutdown(wait=False, cancel_futures=True)
    for process in processes:
        if process.is_alive() and process.pid is not None:
            try:
                os.killpg(process.pid, signal.SIGTERM)  # the worker and what it started
            except OSError:  # not (yet) leading a group of its own
                process.terminate()
    for process in processes:
        process.join(timeout=5.0)


def _mp_context() -> multiprocessing.context.BaseContext:
    if "forkserver" in multiprocessing.get_all_start_methods():
        context = multiprocessing.get_context("forkserver")
        # Workers fork from a server that has already imported the model code.
        context.set_forkserver_preload(
            ["__main__", "softbend.campaign.executors", "softbend.analytical"]
        )
        _start_forkserver()
        return context
    return multiprocessing.get_context("spawn")


def _start_forkserver() -> None:
    """Start the fork server (if not yet running) with Ctrl-C ignored from its start.

    The server ignores SIGINT only once its imports are done (a second or two);
    a Ctrl-C meanwhile would print its traceback. Started while this process
    ignores SIGINT, it inherits that, and so do the workers it forks. (Blocking
    the signal instead does not reach the server: the child's signal mask is
    reset.) A Ctrl-C in the millisecond the start takes is lost. Only the main
    thread may change a signal's handler; elsewhere the server starts as it would.
    """
    from multiprocessing import forkserver

    if threading.current_thread() is not threading.main_thread():
        forkserver.ensure_running()
        return
    previous = signal.signal(signal.SIGINT, signal.SIG_IGN)
    try:
        forkserver.ensure_running()
    finally:
        signal.signal(signal.SIGINT, previous)


def _run_isolated(
    backend: Backend,
    suspects: deque[CampaignDesign],
    pressures: np.ndarray,
    context: multiprocessing.context.BaseContext,
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
        pool = _new_pool(1, context)
        try:
            with interrupts_deferred() as deliver:  # Ctrl-C at safe points only
                future = pool.submit(sweep_chunk, backend, [design], pressures)
                while not wait([future], timeout=_POLL_S).done:
                    deliver()
            outcomes = future.result()
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
        except BaseException:  # Ctrl-C: stop now, the design is left for a resumed run
            _stop_pool(pool)
            raise
        finally:
            pool.shutdown(wait=True, cancel_futures=True)
        recorder.record(outcomes, running=0)


def run_local(
    backend: Backend,
    chunks: deque[list[CampaignDesign]],
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
    suspects: deque[CampaignDesign] = deque()
    while chunks or suspects:
        _run_isolated(backend, suspects, pressures, context, recorder)
        if not chunks:
            break
        pool = _new_pool(workers, context)
        pending: dict[Any, list[CampaignDesign]] = {}
        broken = False
        clean = False
        try:
            # Ctrl-C is raised at safe points only: between waits, never inside
            # a submission (which may start a worker) or a future's lock.
            with interrupts_deferred() as deliver:
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
                    finished, _ = wait(pending, timeout=_POLL_S, return_when=FIRST_COMPLETED)
                    deliver()
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
        except BaseException:  # Ctrl-C: stop now; what was recorded stays, the rest resumes
            _stop_pool(pool)
            raise
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
    --scheduler-file``) is read and its ``address`` returned; the file is at most
    the ``file_mib`` limit of :mod:`softbend.limits` and must hold a JSON object.

    Raises
    ------
    ValueError
        Keyed ``scheduler``: the expected form and the value received.
    FileNotFoundError
        The scheduler file does not exist.
    LimitError
        The scheduler file is larger than the ``file_mib`` limit.
    """
    text = str(scheduler).strip()
    if text.endswith(".json") and "://" not in text:
        text = _scheduler_file_address(Path(text))
    match = _ADDRESS.match(text)
    if match is None or not 1 <= int(match["port"]) <= 65535:
        raise InputError(
            must_be(
                "an address of the form tcp://HOST:PORT (PORT 1-65535) or a Dask scheduler file",
                scheduler,
            ),
            key="scheduler",
        )
    return text


_JSON_KINDS = {list: "array", str: "string", int: "number", float: "number", bool: "boolean"}


def _scheduler_file_address(path: Path) -> str:
    """The ``address`` of a Dask scheduler file, checked: a JSON object with a string there."""
    if not path.is_file():
        raise FileNotFoundError(f"No Dask scheduler file at {str(path)!r}.")
    with keyed("scheduler"):
        check_file_size(path, f"The Dask scheduler file {path}")
    try:
        payload = json.loads(path.read_bytes())
    except (ValueError, RecursionError) as exc:  # not JSON, not UTF-8, nested too deeply
        reason = "nested too deeply" if isinstance(exc, RecursionError) else first_line(exc)
        raise InputError(
            f"must be a Dask scheduler file, JSON with an 'address'; got a file that is not "
            f"JSON ({reason})",
            file=str(path),
        ) from None
    except OSError as exc:
        raise InputError(f"cannot be read: {exc.strerror or exc}", file=str(path)) from None
    address = payload.get("address") if isinstance(payload, dict) else None
    if not isinstance(address, str):
        if not isinstance(payload, dict):
            found = f"a JSON {_JSON_KINDS.get(type(payload), 'value')}"
        elif "address" in payload:
            found = f"'address' {address!r}"
        else:
            found = "no 'address'"
        raise InputError(
            f"must be a Dask scheduler file, a JSON object with an 'address' string "
            f"(tcp://HOST:PORT); got {found[:200]}",
            file=str(path),
        )
    return address


def _probe(address: str, timeout_s: float) -> None:
    """Fail fast, with one clear line, when nothing listens at the scheduler address."""
    match = _ADDRESS.match(parse_scheduler_address(address))
    assert match is not None  # parse_scheduler_address returns only matching addresses
    host = match["host"].strip("[]")
    try:
        with socket.create_connection((host, int(match["port"])), timeout=timeout_s):
            pass
    except OSError as exc:
        reason = exc.strerror or type(exc).__name__
        raise SoftbendError(
            f"cannot reach the Dask scheduler at {address} ({reason}); start it with "
            "'dask scheduler' or check the address",
            key="scheduler",
        ) from None


def _in_thread(work: Callable[[], Any], deadline_s: float) -> tuple[bool, Any, Any]:
    """Run ``work()`` in a daemon thread for at most ``deadline_s``.

    Returns ``(finished, value, error)``: ``finished`` False when the deadline
    passed (the thread is given up), else the value returned or the exception raised.
    """
    box: dict[str, Any] = {}

    def attempt() -> None:
        try:
            box["value"] = work()
        except BaseException as exc:  # reported in the caller's thread
            box["error"] = exc.with_traceback(None)  # keep no frame (and no object) alive

    thread = threading.Thread(target=attempt, name="softbend-dask-connect", daemon=True)
    thread.start()
    thread.join(deadline_s)
    if thread.is_alive():
        return False, None, None
    return True, box.get("value"), box.get("error")


def _not_dask(address: str, why: str) -> SoftbendError:
    return SoftbendError(
        f"{address} did not answer as a Dask scheduler ({why}); give the address the "
        "scheduler prints as 'Scheduler at: tcp://HOST:PORT' (port 8786 by default), not its "
        "dashboard or another service",
        key="scheduler",
    )


def _identify(address: str, timeout_s: float) -> None:
    """Raise one line unless a Dask scheduler answers Dask's ``identity`` at ``address``.

    Dask's own connection code reads the first 8 bytes of the answer as a message
    length: a web server's ``HTTP/1.1`` becomes a request for 3 EiB
    (``MemoryError``). Asked here, in a short-lived event loop of its own, such an
    answer is one error and leaves no half-made client behind.
    """
    import asyncio

    from distributed.comm import connect as dask_connect
    from distributed.security import Security

    args = Security().get_connection_args("client")

    async def ask() -> Any:
        comm = await dask_connect(address, timeout=timeout_s, **args)
        try:
            await comm.write({"op": "identity", "reply": True})
            return await comm.read()
        finally:
            comm.abort()

    def run() -> Any:
        return asyncio.run(asyncio.wait_for(ask(), timeout_s))

    finished, reply, error = _in_thread(run, timeout_s + 5.0)
    if not finished or isinstance(error, asyncio.TimeoutError | TimeoutError):
        raise SoftbendError(
            f"{address} did not answer within {timeout_s:g} s: something listens there but "
            "does not speak Dask's protocol; check the address",
            key="scheduler",
        )
    if error is not None:
        if isinstance(error, MemoryError):
            why = "it answered in another protocol, e.g. HTTP"
        else:
            why = f"{type(error).__name__}: {first_line(error)}"
        raise _not_dask(address, why)
    kind = reply.get("type") if isinstance(reply, dict) else None
    if not isinstance(kind, str) or "Scheduler" not in kind:
        why = f"it is a Dask {kind}" if isinstance(kind, str) else "it answered something else"
        raise _not_dask(address, why)


def _closing_client(Client: type) -> type:
    """A subclass of Dask's ``Client`` that closes itself when its start fails.

    A client whose connection fails in its constructor is otherwise left
    half-started, and its destructor later fails with a traceback of its own.
    """

    class ClosingClient(Client):  # type: ignore[misc, valid-type]
        def start(self, **kwargs: object) -> None:
            try:
                super().start(**kwargs)
            except BaseException:
                try:
                    self.close(timeout=5)
                except Exception:  # the start's error is the one to report
                    logger.debug("closing a Dask client that failed to start failed too")
                raise

    return ClosingClient


def connect(address: str, timeout_s: float) -> Client:
    """A Dask client of the scheduler at ``address``, or one line within the deadline.

    Every wait has a deadline: something that accepts TCP but is not a Dask
    scheduler (a web server, a silent listener) may never finish Dask's
    handshake, so the address is first asked who it is (:func:`_identify`) and
    the client is made in a helper thread that is given up after ``timeout_s``
    (plus a grace of 5 s).
    """
    Client = require("distributed", "A campaign on a Dask cluster").Client

    _probe(address, timeout_s)
    _identify(address, timeout_s)
    ClosingClient = _closing_client(Client)
    finished, client, error = _in_thread(
        lambda: ClosingClient(address, timeout=timeout_s, set_as_default=False), timeout_s + 5.0
    )
    if not finished:
        raise SoftbendError(
            f"the Dask scheduler at {address} did not answer within {timeout_s:g} s: something "
            "listens there but does not speak Dask's protocol; check the address",
            key="scheduler",
        )
    if error is not None:
        raise SoftbendError(
            f"cannot connect to the Dask scheduler at {address}: {type(error).__name__}: "
            f"{first_line(error)}",
            key="scheduler",
        ) from None
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
    chunks: deque[list[CampaignDesign]],
    pressures: np.ndarray,
    client: Client,
    recorder: Recorder,
) -> None:
    """Sweep the chunks on the Dask cluster of ``client``; pending tasks are cancelled on exit."""
    from distributed import as_completed

    n_threads = max(1, sum(client.nthreads().values()))
    pending: dict[Any, list[CampaignDesign]] = {}

    def submit() -> Any:
        chunk = chunks.popleft()
        future = client.submit(sweep_chunk, backend, chunk, pressures, pure=False)
        pending[future] = chunk
        return future

    initial = [submit() for _ in range(min(len(chunks), _TASKS_PER_WORKER * n_threads))]
    recorder.set_running(sum(len(c) for c in pending.values()))
    queue = as_completed(initial, loop=client.loop)
    try:
        # As run_local: Ctrl-C is raised between polls, never inside as_completed's locks,
        # which the client's event loop takes to hand over each finished task.
        with interrupts_deferred() as deliver:
            while not queue.is_empty():
                ready = queue.next_batch(block=False)
                deliver()
                if not ready:
                    time.sleep(_DASK_POLL_S)
                for future in ready:
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
