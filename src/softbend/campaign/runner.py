"""Run a campaign: sweep many designs in parallel and record each one as it finishes.

:func:`run_campaign` is the whole orchestration. The coordinating process (the one
calling it) owns the database; worker processes only compute sweeps and send
back :class:`~softbend.campaign.backends.SweepResult` objects, which the
coordinator writes one transaction per design as they arrive. Three ways to run:

* ``workers`` 0 or 1: in-process and serial (debugging, tests, tiny campaigns);
* default: a local :class:`concurrent.futures.ProcessPoolExecutor` with
  ``workers`` processes (default: all cores). Workers are started through a fork
  server (``spawn`` where there is none), so they never inherit the coordinator's
  open database or threads; as with any ``multiprocessing`` code, a script that
  calls :func:`run_campaign` needs an ``if __name__ == "__main__":`` guard;
* ``scheduler="tcp://HOST:PORT"`` (or the path of a Dask scheduler file): an
  existing Dask ``distributed`` cluster, e.g. started with ``dask scheduler`` and
  ``dask worker`` on a lab machine or a batch queue. Every worker must be able to
  import the same softbend.

Designs are sent in chunks of several designs per task so that the overhead per
design stays far below the cost of a sweep (chunks of 1 for backends that ask
for it, such as the FEM). Within a chunk every design is swept on its own: an
exception in one design (a :class:`~softbend.errors.ConvergenceError` or anything
else) is recorded as that design's failure, ``"ExceptionType: message"``, and the
others go on. If a whole task is lost (a worker process killed, out of memory or
crashed in native code), the designs of that task are recorded as failed with
that reason. A local pool cannot tell which task killed it, so every task in
flight at that moment is recorded as failed, and the pool is restarted for the
rest (at most three times per run); Dask re-runs tasks of a lost worker on
others by itself and reports ``KilledWorker`` only for a task that keeps killing
workers.

Resume: designs already recorded as done are skipped, so re-running the same
command after a crash or kill continues where it stopped and never duplicates a
design. Designs recorded as failed are retried by default (``retry_failed``):
failures are often transient (a killed worker, a cluster node lost) and a retry
that succeeds replaces the failed row; pass ``retry_failed=False`` to keep them.
"""

from __future__ import annotations

import json
import logging
import math
import multiprocessing
import os
import re
import socket
import threading
import time
from collections import deque
from collections.abc import Callable, Iterable, Sequence
from concurrent.futures import FIRST_COMPLETED, ProcessPoolExecutor, wait
from concurrent.futures.process import BrokenProcessPool
from dataclasses import asdict, dataclass, field
from pathlib import Path
from typing import Any

import numpy as np
from numpy.typing import ArrayLike

from softbend import __version__
from softbend._extras import require
from softbend._validation import check_range
from softbend.campaign.backends import (
    Backend,
    SweepResult,
    check_pressures_mpa,
    default_pressures_mpa,
    get_backend,
)
from softbend.campaign.store import CampaignStore
from softbend.design import SFRBADesign
from softbend.errors import SoftbendError

__all__ = ["CampaignSummary", "parse_scheduler_address", "run_campaign"]

logger = logging.getLogger(__name__)

#: ``progress(done, failed, running, total)``: designs finished and failed in this
#: run, designs handed to workers and not yet back, designs this run has to do.
ProgressCallback = Callable[[int, int, int, int], None]

_OWNER = "run_campaign"
_ADDRESS = re.compile(
    r"^(?P<protocol>tcp|tls)://(?P<host>\[[0-9A-Fa-f:.]+\]|[A-Za-z0-9._-]+):(?P<port>\d{1,5})$"
)
# Largest batch sent to a worker in one task when the backend states no preference.
_MAX_AUTO_CHUNK = 16
# Tasks in flight per worker: enough to keep workers busy while results are recorded.
_TASKS_PER_WORKER = 2
# A local pool whose worker processes keep dying is restarted at most this often.
_MAX_POOL_RESTARTS = 3


@dataclass(frozen=True)
class CampaignSummary:
    """What a call of :func:`run_campaign` did.

    Attributes
    ----------
    db_path : str
        The campaign database.
    backend : str
        Backend name.
    executor : str
        ``"serial"``, ``"processes:N"`` or the Dask scheduler address.
    n_designs : int
        Designs asked for.
    n_skipped_done : int
        Designs already done in the database before this run (not re-run).
    n_skipped_failed : int
        Designs recorded as failed before and not retried (``retry_failed=False``).
    n_done, n_failed : int
        Designs finished and failed in this run.
    wall_time_s : float
        Wall-clock time of the run, s.
    sweep_time_s : float
        Sum of the sweep times of the designs run, s (compute time in workers).
    chunk_size : int
        Designs per worker task.
    failures : tuple of (design_id, error)
        The designs that failed in this run and why.
    """

    db_path: str
    backend: str
    executor: str
    n_designs: int
    n_skipped_done: int
    n_skipped_failed: int
    n_done: int
    n_failed: int
    wall_time_s: float
    sweep_time_s: float
    chunk_size: int
    failures: tuple[tuple[str, str], ...] = field(default=())

    @property
    def n_run(self) -> int:
        """Designs attempted in this run."""
        return self.n_done + self.n_failed

    @property
    def designs_per_s(self) -> float:
        """Designs attempted per second of wall time in this run (NaN if none)."""
        if self.n_run == 0 or self.wall_time_s <= 0.0:
            return float("nan")
        return self.n_run / self.wall_time_s

    def as_dict(self) -> dict[str, Any]:
        """JSON-friendly mapping, with ``n_run`` and ``designs_per_s`` added."""
        data = asdict(self)
        data["failures"] = [{"design_id": i, "error": e} for i, e in self.failures]
        data["n_run"] = self.n_run
        data["designs_per_s"] = self.designs_per_s
        return data


@dataclass(frozen=True)
class _Outcome:
    """One design's sweep, as sent back by a worker."""

    design: SFRBADesign
    result: SweepResult | None
    error: str | None
    wall_time_s: float


def _error_text(exc: BaseException) -> str:
    message = " ".join(str(exc).split())
    return f"{type(exc).__name__}: {message}" if message else type(exc).__name__


def _sweep_one(backend: Backend, design: SFRBADesign, pressures_mpa: np.ndarray) -> _Outcome:
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
        return _Outcome(design, None, _error_text(exc), time.perf_counter() - start)
    return _Outcome(design, result, None, result.wall_time_s)


def _sweep_chunk(
    backend: Backend, designs: Sequence[SFRBADesign], pressures_mpa: np.ndarray
) -> list[_Outcome]:
    """Worker task: sweep each design of the chunk independently."""
    return [_sweep_one(backend, design, pressures_mpa) for design in designs]


def _lost_chunk(designs: Sequence[SFRBADesign], exc: BaseException) -> list[_Outcome]:
    text = _error_text(exc)
    if isinstance(exc, BrokenProcessPool):
        text = (
            "BrokenProcessPool: a worker process died while this design's task was pending "
            "(killed, out of memory or crashed)"
        )
    return [_Outcome(design, None, text, float("nan")) for design in designs]


class _Recorder:
    """Writes outcomes to the store as they arrive and reports progress."""

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
        if self.progress is not None:
            self.progress(self.done, self.failed, self.running, self.total)

    def set_running(self, running: int) -> None:
        if running != self.running:
            self.running = running
            self.report()

    def record(self, outcomes: Iterable[_Outcome], running: int) -> None:
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


def _check_designs(designs: Iterable[SFRBADesign]) -> list[SFRBADesign]:
    if isinstance(designs, SFRBADesign):
        designs = [designs]
    try:
        items = list(designs)
    except TypeError:
        raise ValueError(
            f"The 'designs' of {_OWNER} must be an iterable of SFRBADesign. "
            f"Got {designs!r} instead."
        ) from None
    if not items:
        raise ValueError(f"The 'designs' of {_OWNER} must not be empty. Got 0 designs.")
    for i, design in enumerate(items):
        if not isinstance(design, SFRBADesign):
            raise ValueError(
                f"The 'designs' of {_OWNER} must all be SFRBADesign. "
                f"Got {design!r} at position {i} instead."
            )
    ids = [d.design_id for d in items]
    if len(set(ids)) != len(ids):
        raise ValueError(
            f"The 'designs' of {_OWNER} must be unique. Got {len(ids) - len(set(ids))} duplicates."
        )
    return items


def _resolve_backend(backend: str | Backend, options: dict[str, Any] | None) -> Backend:
    if isinstance(backend, str):
        return get_backend(backend, **dict(options or {}))
    if not isinstance(backend, Backend):
        raise ValueError(
            f"The 'backend' of {_OWNER} must be a backend name or an object with 'name' and "
            f"'sweep'. Got {backend!r} instead."
        )
    if options:
        raise ValueError(
            f"The 'backend_options' of {_OWNER} apply to a backend name only. "
            f"Got {sorted(options)} with a backend object."
        )
    return backend


def _mp_context() -> multiprocessing.context.BaseContext:
    if "forkserver" in multiprocessing.get_all_start_methods():
        context = multiprocessing.get_context("forkserver")
        # Workers fork from a server that has already imported the model code.
        context.set_forkserver_preload(
            ["__main__", "softbend.campaign.runner", "softbend.analytical"]
        )
        return context
    return multiprocessing.get_context("spawn")


def _auto_chunk_size(backend: Backend, n_designs: int, n_slots: int) -> int:
    preferred = getattr(backend, "preferred_chunk_size", None)
    if preferred:
        return max(1, int(preferred))
    return max(1, min(_MAX_AUTO_CHUNK, math.ceil(n_designs / (8 * max(1, n_slots)))))


def _chunks(designs: Sequence[SFRBADesign], size: int) -> deque[list[SFRBADesign]]:
    return deque(list(designs[i : i + size]) for i in range(0, len(designs), size))


def _run_serial(
    backend: Backend, todo: Sequence[SFRBADesign], pressures: np.ndarray, recorder: _Recorder
) -> None:
    for design in todo:
        recorder.set_running(1)
        recorder.record([_sweep_one(backend, design, pressures)], running=0)


def _run_isolated(
    backend: Backend,
    suspects: deque[SFRBADesign],
    pressures: np.ndarray,
    context: Any,
    recorder: _Recorder,
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
            outcomes = pool.submit(_sweep_chunk, backend, [design], pressures).result()
        except BrokenProcessPool:
            outcomes = [
                _Outcome(
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


def _run_local(
    backend: Backend,
    chunks: deque[list[SFRBADesign]],
    pressures: np.ndarray,
    workers: int,
    recorder: _Recorder,
) -> None:
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
                        future = pool.submit(_sweep_chunk, backend, chunk, pressures)
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


def _connect(address: str, timeout_s: float) -> Any:
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


def _run_dask(
    backend: Backend,
    chunks: deque[list[SFRBADesign]],
    pressures: np.ndarray,
    client: Any,
    recorder: _Recorder,
) -> None:
    from distributed import as_completed

    n_threads = max(1, sum(client.nthreads().values()))
    pending: dict[Any, list[SFRBADesign]] = {}

    def submit() -> Any:
        chunk = chunks.popleft()
        future = client.submit(_sweep_chunk, backend, chunk, pressures, pure=False)
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


def run_campaign(
    db_path: str | os.PathLike[str],
    designs: Iterable[SFRBADesign],
    *,
    backend: str | Backend = "analytical",
    backend_options: dict[str, Any] | None = None,
    pressures_mpa: ArrayLike | None = None,
    workers: int | None = None,
    scheduler: str | None = None,
    retry_failed: bool = True,
    progress: ProgressCallback | None = None,
    chunk_size: int | None = None,
    connect_timeout_s: float = 5.0,
) -> CampaignSummary:
    """Sweep every design not yet done and record each in the campaign database.

    Parameters
    ----------
    db_path : str or os.PathLike
        DuckDB file of the campaign; created if missing, resumed if present.
    designs : iterable of SFRBADesign
        The designs (e.g. a :class:`~softbend.design.DesignSpace`), non-empty and
        unique.
    backend : str or Backend
        Registered backend name (``"analytical"``, ``"fem"``, ...) or a backend
        object. A database keeps the backend of its first run; another is refused.
    backend_options : dict, optional
        Keyword options of the named backend.
    pressures_mpa : array_like, optional
        Sweep grid, MPa: 1-D, >= 0, strictly increasing. Default
        :func:`~softbend.campaign.backends.default_pressures_mpa` (0–0.5 MPa,
        step 0.005). A database keeps the grid of its first run.
    workers : int, optional
        Local worker processes; default ``os.cpu_count()``. 0 or 1 runs serially
        in this process. Ignored with ``scheduler``.
    scheduler : str, optional
        Dask scheduler address ``tcp://HOST:PORT`` (or a scheduler-file path) to
        run on an existing cluster instead of local processes.
    retry_failed : bool
        Re-run designs recorded as failed (default) or leave them as they are.
    progress : callable, optional
        ``progress(done, failed, running, total)`` after each recorded design and
        when work is handed out; counts refer to this run.
    chunk_size : int, optional
        Designs per worker task; default: the backend's ``preferred_chunk_size``,
        else enough designs per task to give each worker about eight tasks, at
        most 16.
    connect_timeout_s : float
        Time allowed to reach the Dask scheduler and find a worker, s, in (0, 600].

    Returns
    -------
    CampaignSummary
        Counts, times and the failures of this run.

    Raises
    ------
    ValueError
        Bad input: unknown backend or option, empty or duplicate designs, a
        negative or non-increasing pressure grid, ``workers < 0``, a malformed
        scheduler address, or a database holding another backend or grid.
    SchemaError
        The database has a newer schema or is not a campaign database.
    SoftbendError
        The database is locked by another process, the scheduler is unreachable
        or has no workers, or local workers keep dying.
    """
    start = time.perf_counter()
    backend_obj = _resolve_backend(backend, backend_options)
    design_list = _check_designs(designs)
    grid = check_pressures_mpa(
        default_pressures_mpa() if pressures_mpa is None else pressures_mpa, _OWNER
    )
    if workers is None:
        workers = os.cpu_count() or 1
    workers = int(
        check_range(
            workers, "workers", _OWNER, low=0, low_inclusive=True, high=4096, high_inclusive=True
        )
    )
    if chunk_size is not None:
        chunk_size = int(
            check_range(
                chunk_size,
                "chunk_size",
                _OWNER,
                low=1,
                low_inclusive=True,
                high=100_000,
                high_inclusive=True,
            )
        )
    timeout_s = check_range(
        connect_timeout_s, "connect_timeout_s", _OWNER, low=0.0, high=600.0, high_inclusive=True
    )
    address = parse_scheduler_address(scheduler) if scheduler is not None else None
    if progress is not None and not callable(progress):
        raise ValueError(f"The 'progress' of {_OWNER} must be callable. Got {progress!r} instead.")

    # Connect first: an unreachable cluster fails before the database is touched.
    client = _connect(address, timeout_s) if address is not None else None
    try:
        with CampaignStore(db_path) as store:
            store.bind(
                backend_obj.name,
                grid,
                space=getattr(designs, "name", None),
                n_designs_planned=len(design_list),
            )
            done_ids = store.finished_ids()
            failed_ids = store.failed_ids()
            todo = [
                d
                for d in design_list
                if d.design_id not in done_ids and (retry_failed or d.design_id not in failed_ids)
            ]
            n_skipped_done = sum(d.design_id in done_ids for d in design_list)
            n_skipped_failed = len(design_list) - n_skipped_done - len(todo)
            if address is not None:
                executor = address
            elif workers <= 1 or len(todo) <= 1:
                executor = "serial"
            else:
                workers = min(workers, len(todo))
                executor = f"processes:{workers}"
            logger.info(
                "campaign %s: %d designs, %d already done, %d failed before and %s; "
                "%d to run on %s",
                store.path,
                len(design_list),
                n_skipped_done,
                sum(d.design_id in failed_ids for d in design_list),
                "retried" if retry_failed else "kept",
                len(todo),
                executor,
            )
            recorder = _Recorder(store, backend_obj.name, len(todo), progress)
            recorder.report()
            if executor == "serial":
                chunk_size = 1
                _run_serial(backend_obj, todo, grid, recorder)
            elif client is None:
                chunk_size = chunk_size or _auto_chunk_size(backend_obj, len(todo), workers)
                _run_local(backend_obj, _chunks(todo, chunk_size), grid, workers, recorder)
            elif todo:
                n_threads = max(1, sum(client.nthreads().values()))
                chunk_size = chunk_size or _auto_chunk_size(backend_obj, len(todo), n_threads)
                _run_dask(backend_obj, _chunks(todo, chunk_size), grid, client, recorder)
            if recorder.done or recorder.failed:
                store.log_run(
                    {
                        "space": getattr(designs, "name", None),
                        "executor": executor,
                        "host": socket.gethostname(),
                        "cpu_count": os.cpu_count(),
                        "softbend_version": __version__,
                        "done": recorder.done,
                        "failed": recorder.failed,
                        "sweep_time_s": recorder.sweep_time_s,
                        "wall_time_s": time.perf_counter() - start,
                        "finished_at": time.strftime("%Y-%m-%dT%H:%M:%SZ", time.gmtime()),
                    }
                )
    finally:
        if client is not None:
            client.close()

    summary = CampaignSummary(
        db_path=str(Path(db_path)),
        backend=backend_obj.name,
        executor=executor,
        n_designs=len(design_list),
        n_skipped_done=n_skipped_done,
        n_skipped_failed=n_skipped_failed,
        n_done=recorder.done,
        n_failed=recorder.failed,
        wall_time_s=time.perf_counter() - start,
        sweep_time_s=recorder.sweep_time_s,
        chunk_size=chunk_size or 1,
        failures=tuple(recorder.failures),
    )
    logger.info(
        "campaign %s: %d done, %d failed in %.1f s",
        db_path,
        summary.n_done,
        summary.n_failed,
        summary.wall_time_s,
    )
    return summary
