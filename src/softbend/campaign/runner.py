"""Run a campaign: sweep many designs in parallel and record each one as it finishes.

:func:`run_campaign` is the whole orchestration. The coordinating process (the one
calling it) owns the database; worker processes only compute sweeps and send
back :class:`~softbend.campaign.backends.SweepResult` objects, which the
coordinator writes one transaction per design as they arrive. What a run has to
do (the designs left, the executor) is worked out in
:mod:`~softbend.campaign.planning`; the executors live in
:mod:`~softbend.campaign.executors`. Three ways to run:

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

import logging
import os
import socket
import time
from collections.abc import Iterable
from dataclasses import asdict, dataclass, field
from pathlib import Path
from typing import TYPE_CHECKING, Any

import numpy as np
from numpy.typing import ArrayLike

from softbend import __version__
from softbend._validation import must_be
from softbend.campaign.backends import (
    Backend,
    MaterialGiven,
    check_pressures_mpa,
    resolve_material,
    with_material,
)
from softbend.campaign.executors import (
    ProgressCallback,
    Recorder,
    connect,
    parse_scheduler_address,
    run_dask,
    run_local,
    run_serial,
)
from softbend.campaign.family_schema import (
    CampaignDesign,
    FamilyBackend,
    FamilySchema,
    family_backend,
)
from softbend.campaign.planning import (
    RunPlan,
    auto_chunk_size,
    check_designs,
    check_run_options,
    chunks,
    design_family,
    plan_run,
    resolve_backend,
    runs_in_process,
)
from softbend.campaign.settings import backend_settings, fem_options_of
from softbend.campaign.store import CampaignStore
from softbend.errors import InputError
from softbend.fem.families import get_family

if TYPE_CHECKING:
    from distributed import Client

__all__ = ["CampaignSummary", "count_designs_to_run", "parse_scheduler_address", "run_campaign"]

logger = logging.getLogger(__name__)


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


def run_campaign(
    db_path: str | os.PathLike[str],
    designs: Iterable[CampaignDesign],
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
    material: MaterialGiven | None = None,
    accept_new_settings: bool = False,
) -> CampaignSummary:
    """Sweep every design not yet done and record each in the campaign database.

    Parameters
    ----------
    db_path : str or os.PathLike
        DuckDB file of the campaign; created if missing, resumed if present.
    designs : iterable of Design
        The designs (e.g. a :class:`~softbend.design.DesignSpace`, or a
        :class:`~softbend.campaign.spaces.FamilySpace` of another FEM
        family), non-empty, unique and of one family. A database keeps the
        family of its first run; another is refused.
    backend : str or Backend
        Registered backend name (``"analytical"``, ``"fem"``, ...) or a backend
        object. A database keeps the backend of its first run; another is refused.
        For another family's designs: ``"fem"`` (the family's own FEM sweep,
        :class:`~softbend.campaign.family_schema.FamilyBackend`, with
        ``backend_options`` ``maxh_mm`` at most) or a backend object that sweeps them.
    backend_options : dict, optional
        Keyword options of the named backend.
    pressures_mpa : array_like, optional
        Sweep grid, MPa: 1-D, >= 0, strictly increasing. Default
        :func:`~softbend.campaign.backends.default_pressures_mpa` (0–0.5 MPa,
        step 0.005; for another family's designs 0 to its ``pmax_mpa`` by its
        ``pstep_mpa``). A database keeps the grid of its first run.
    workers : int, optional
        Local worker processes; default ``os.cpu_count()``. 0 or 1 runs serially
        in this process (in one worker process for the FEM that compiles its
        energy, which would keep Ctrl-C from this one:
        :func:`~softbend.campaign.planning.runs_in_process`). Ignored with ``scheduler``.
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
    material : str, path, Material or ResolvedMaterial, optional
        Elastomer of a backend that takes one (``"fem"``, ``"analytical"``): a
        preset name, ``fit.json[#model]`` (as
        :func:`~softbend.materials.choice.material_from_spec`), a material, or
        one :func:`~softbend.campaign.backends.resolve_material` read (a spec is
        read once); it reaches every sweep, in every worker and is recorded
        with what named it. Default: the backend's own.
    accept_new_settings : bool
        Resume even if the backend's settings (mesh size and other FEM options,
        material, see :mod:`~softbend.campaign.settings`) differ from those the
        database recorded at its first run; each run's settings stay in its record.

    Returns
    -------
    CampaignSummary
        Counts, times and the failures of this run.

    Raises
    ------
    ValueError
        Bad input: unknown backend or option, empty or duplicate designs, an
        FEM mesh size that would mesh one of the designs with more elements than
        the FEM allows (:func:`softbend.fem.options.check_mesh_size`; another
        family's own estimate, :meth:`~softbend.fem.families.FEMFamily.check_mesh`), a
        negative or non-increasing pressure grid, ``workers < 0``, a malformed
        scheduler address, a material given to a backend that takes none, or a
        database holding another backend or grid.
    SettingsMismatchError
        The database recorded other backend settings (not accepted); the message
        names each differing setting with both values.
    SchemaError
        The database has a newer schema or is not a campaign database.
    SoftbendError
        The database is locked by another process, the scheduler is unreachable
        or has no workers, or local workers keep dying.
    """
    start = time.perf_counter()
    design_list = check_designs(designs)
    family = design_family(design_list[0])
    backend_obj = _family_backend(family, backend, backend_options)
    given = None
    if material is not None:
        chosen = resolve_material(material)
        backend_obj, given = with_material(backend_obj, chosen.material), chosen.given
    # The FEM's own rule on the mesh size, for every design before any is swept:
    # a mesh size too fine for them would otherwise fail each design in turn.
    _check_meshes(backend_obj, family, design_list)
    if pressures_mpa is None:
        pressures_mpa = get_family(family).campaign_pressures_mpa()
    grid = check_pressures_mpa(pressures_mpa)
    settings = backend_settings(backend_obj, grid, material_given=given)
    workers, chunk_size, timeout_s = check_run_options(workers, chunk_size, connect_timeout_s)
    address = parse_scheduler_address(scheduler) if scheduler is not None else None
    if progress is not None and not callable(progress):
        raise InputError(must_be("callable", progress), key="progress")
    space = getattr(designs, "name", None)

    # Connect first: an unreachable cluster fails before the database is touched.
    client = connect(address, timeout_s) if address is not None else None
    try:
        with CampaignStore(db_path, family=FamilySchema.of(family)) as store:
            plan = plan_run(
                store,
                backend_obj.name,
                grid,
                design_list,
                space=space,
                retry_failed=retry_failed,
                workers=workers,
                address=address,
                settings=settings,
                accept_new_settings=accept_new_settings,
                in_process=runs_in_process(backend_obj),
            )
            recorder = Recorder(store, backend_obj.name, len(plan.todo), progress)
            recorder.report()
            chunk_size = _execute(plan, backend_obj, grid, client, chunk_size, recorder)
            if recorder.done or recorder.failed:
                store.log_run(_run_record(space, plan.executor, recorder, start, settings))
    finally:
        if client is not None:
            client.close()

    summary = CampaignSummary(
        db_path=str(Path(db_path)),
        backend=backend_obj.name,
        executor=plan.executor,
        n_designs=len(design_list),
        n_skipped_done=plan.n_skipped_done,
        n_skipped_failed=plan.n_skipped_failed,
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


def _check_meshes(backend: Backend, family: str, designs: list[CampaignDesign]) -> None:
    """Refuse an FEM backend's mesh size that would mesh one of ``designs`` too finely.

    The designs are checked with their family's own estimate (:meth:`FEMFamily.check_meshes
    <softbend.fem.families.FEMFamily.check_meshes>`, microseconds a design), before
    NGSolve is loaded. A backend that is not the FEM is not checked.
    """
    options = fem_options_of(backend)
    if options is None:
        return
    fem_family = backend.family if isinstance(backend, FamilyBackend) else get_family(family)
    fem_family.check_meshes(designs, options)


def _family_backend(family: str, backend: str | Backend, options: dict[str, Any] | None) -> Backend:
    """The backend sweeping the designs of ``family``.

    A backend object is taken as given (a :class:`FamilyBackend` must be of
    ``family``). A family swept by the registered backends
    (:attr:`~softbend.fem.families.FEMFamily.backends` None, paper B's)
    takes any of them by name, with ``options``; for another, ``"fem"`` is the
    family's own FEM sweep with ``options`` ``maxh_mm`` (mm) at most and paper B's
    models (``"analytical"``, paper B's FEM) are refused.
    """
    fem_family = get_family(family)
    if isinstance(backend, FamilyBackend):
        if backend.family.name != family:
            raise InputError(
                f"must sweep the designs' family {family!r}; got the FEM of the "
                f"{backend.family.name!r} family",
                key="backend",
            )
        return resolve_backend(backend, options)
    if fem_family.backends is None:
        return resolve_backend(backend, options)
    if backend == "fem":
        options = dict(options or {})
        unknown = sorted(set(options) - {"maxh_mm"})
        if unknown:
            raise InputError(
                f"must be maxh_mm alone for the FEM of the {family!r} family; got {unknown}",
                key="backend_options",
            )
        return family_backend(fem_family, maxh_mm=options.get("maxh_mm"))
    if isinstance(backend, str) or getattr(backend, "name", None) in ("analytical", "fem"):
        shown = backend if isinstance(backend, str) else backend.name
        raise InputError(
            f"must be 'fem' for designs of the {family!r} family (its own FEM sweep); got "
            f"{shown!r}, a model of paper B's actuator",
            key="backend",
        )
    return resolve_backend(backend, options)


def count_designs_to_run(
    db: str | os.PathLike[str], designs: Iterable[CampaignDesign], retry_failed: bool = True
) -> int:
    """How many of ``designs`` a run on ``db`` will sweep (all of them for a new database).

    The designs already done are left out, and those recorded as failed unless
    ``retry_failed``: the total of a progress bar, and what a resumed run says
    it skips.
    """
    designs = list(designs)
    if not Path(db).exists():
        return len(designs)
    with CampaignStore(db, read_only=True) as store:
        skip = store.finished_ids(include_failed=not retry_failed)
    return sum(d.design_id not in skip for d in designs)


def _execute(
    plan: RunPlan,
    backend: Backend,
    grid: np.ndarray,
    client: Client | None,
    chunk_size: int | None,
    recorder: Recorder,
) -> int | None:
    """Sweep the designs of the plan on its executor; return the designs per task used.

    Serial: one design at a time. Local processes or Dask: ``chunk_size``
    designs per task, by default :func:`~softbend.campaign.planning.auto_chunk_size`
    for the workers (local) or the threads of the cluster (Dask). Nothing runs on
    Dask when no design is left.
    """
    if plan.executor == "serial":
        run_serial(backend, plan.todo, grid, recorder)
        return 1
    if client is None:
        size = chunk_size or auto_chunk_size(backend, len(plan.todo), plan.workers)
        run_local(backend, chunks(plan.todo, size), grid, plan.workers, recorder)
        return size
    if plan.todo:
        n_threads = max(1, sum(client.nthreads().values()))
        size = chunk_size or auto_chunk_size(backend, len(plan.todo), n_threads)
        run_dask(backend, chunks(plan.todo, size), grid, client, recorder)
        return size
    return chunk_size


def _run_record(
    space: str | None,
    executor: str,
    recorder: Recorder,
    start: float,
    settings: dict[str, Any],
) -> dict[str, Any]:
    """The record of this run kept in the campaign's ``runs`` metadata (and a dataset's)."""
    return {
        "space": space,
        "executor": executor,
        "host": socket.gethostname(),
        "cpu_count": os.cpu_count(),
        "softbend_version": __version__,
        "done": recorder.done,
        "failed": recorder.failed,
        "sweep_time_s": recorder.sweep_time_s,
        "wall_time_s": time.perf_counter() - start,
        "finished_at": time.strftime("%Y-%m-%dT%H:%M:%SZ", time.gmtime()),
        "material": settings.get("material"),
        "settings": settings,
    }
