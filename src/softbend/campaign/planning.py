"""What one campaign run has to do: its checked inputs, the designs left, the executor.

:func:`check_designs`, :func:`resolve_backend` and :func:`check_run_options`
check the arguments of :func:`~softbend.campaign.runner.run_campaign`;
:func:`plan_run` binds the database to the backend, its settings and the
pressure grid (or checks them on resume), leaves out the designs already done
(and those that failed before, unless they are retried) and names the executor;
:func:`auto_chunk_size` and :func:`chunks` cut the designs left into worker tasks.
"""

from __future__ import annotations

import logging
import math
import os
from collections import deque
from collections.abc import Iterable, Sequence
from dataclasses import dataclass
from typing import TYPE_CHECKING, Any

import numpy as np

from softbend._validation import check_range, must_be
from softbend.actuators import Design
from softbend.campaign.backends import Backend, get_backend
from softbend.campaign.family_schema import CampaignDesign
from softbend.errors import InputError

if TYPE_CHECKING:
    from softbend.campaign.store import CampaignStore

__all__ = [
    "RunPlan",
    "auto_chunk_size",
    "check_designs",
    "check_run_options",
    "chunks",
    "design_family",
    "plan_run",
    "resolve_backend",
]

logger = logging.getLogger(__name__)

# Largest batch sent to a worker in one task when the backend states no preference.
_MAX_AUTO_CHUNK = 16


@dataclass(frozen=True)
class RunPlan:
    """What one run of a campaign does.

    Attributes
    ----------
    todo : list of Design
        The designs to sweep, in the order asked for.
    n_skipped_done : int
        Designs already done in the database (not re-run).
    n_skipped_failed : int
        Designs recorded as failed before and not retried.
    executor : str
        ``"serial"``, ``"processes:N"`` or the Dask scheduler address.
    workers : int
        Local worker processes: those asked for, at most one per design left
        when the designs run in local processes.
    """

    todo: list[CampaignDesign]
    n_skipped_done: int
    n_skipped_failed: int
    executor: str
    workers: int


# -- the arguments -------------------------------------------------------------------


def check_designs(designs: Iterable[CampaignDesign]) -> list[CampaignDesign]:
    """The designs as a list: non-empty, all :class:`Design`, no two alike.

    Designs of another FEM family (:class:`~softbend.actuators.Design`)
    are accepted too, all of one family.

    Raises
    ------
    ValueError
        Not an iterable of designs, empty, of two families, or with duplicates.
    """
    if isinstance(designs, Design):
        designs = [designs]
    try:
        items = list(designs)
    except TypeError:
        raise InputError(must_be("an iterable of Design", designs), key="designs") from None
    if not items:
        raise InputError("must not be empty; got 0 designs", key="designs")
    family = None
    for i, design in enumerate(items):
        if not isinstance(design, Design):
            raise InputError(f"must all be Design; got {design!r} at position {i}", key="designs")
        family = design_family(design) if family is None else family
        if design_family(design) != family:
            raise InputError(
                f"must all be of one family; got a design of {design_family(design)!r} at "
                f"position {i} after designs of {family!r}",
                key="designs",
            )
    ids = [d.design_id for d in items]
    if len(set(ids)) != len(ids):
        raise InputError(
            f"must be unique; got {len(ids) - len(set(ids))} duplicates", key="designs"
        )
    return items


def design_family(design: object) -> str:
    """The FEM family of a design: its actuator's (``"sfrba"`` for paper B's).

    Raises
    ------
    InputError
        Keyed ``designs``: not a design of an actuator an FEM family simulates.
    """
    if isinstance(design, Design) and design.actuator.fem_family is not None:
        return design.actuator.fem_family
    raise InputError(
        must_be("Design objects of an actuator an FEM family simulates", design), key="designs"
    )


def resolve_backend(backend: str | Backend, options: dict[str, Any] | None) -> Backend:
    """The backend object of a registered name (with its options), or ``backend`` itself.

    Raises
    ------
    ValueError
        Neither a name nor a backend object, or options given with an object.
    """
    if isinstance(backend, str):
        return get_backend(backend, **dict(options or {}))
    if not isinstance(backend, Backend):
        raise InputError(
            must_be("a backend name or an object with 'name' and 'sweep'", backend),
            key="backend",
        )
    if options:
        raise InputError(
            f"apply to a backend name only; got {sorted(options)} with a backend object",
            key="backend_options",
        )
    return backend


def check_run_options(
    workers: int | None, chunk_size: int | None, connect_timeout_s: float
) -> tuple[int, int | None, float]:
    """Checked ``(workers, chunk_size, connect_timeout_s)``; ``workers`` None is every core.

    Raises
    ------
    ValueError
        ``workers`` outside 0..4096, ``chunk_size`` outside 1..100000 or
        ``connect_timeout_s`` outside (0, 600].
    """
    if workers is None:
        workers = os.cpu_count() or 1
    workers = int(
        check_range(workers, "workers", low=0, low_inclusive=True, high=4096, high_inclusive=True)
    )
    if chunk_size is not None:
        chunk_size = int(
            check_range(
                chunk_size,
                "chunk_size",
                low=1,
                low_inclusive=True,
                high=100_000,
                high_inclusive=True,
            )
        )
    timeout_s = check_range(
        connect_timeout_s, "connect_timeout_s", low=0.0, high=600.0, high_inclusive=True
    )
    return workers, chunk_size, timeout_s


# -- the designs left and who runs them ----------------------------------------------


def plan_run(
    store: CampaignStore,
    backend: str,
    pressures_mpa: np.ndarray,
    designs: Sequence[CampaignDesign],
    *,
    space: str | None,
    retry_failed: bool,
    workers: int,
    address: str | None,
    settings: dict[str, Any] | None = None,
    accept_new_settings: bool = False,
    in_process: bool = True,
) -> RunPlan:
    """Bind the campaign, find the designs left and name the executor.

    Parameters
    ----------
    store : CampaignStore
        The campaign database, open for writing.
    backend : str
        Backend name.
    pressures_mpa : numpy.ndarray
        Checked sweep grid, MPa.
    designs : sequence of Design
        The designs asked for (checked by :func:`check_designs`).
    space : str, optional
        Label of the design space, stored for reports.
    retry_failed : bool
        Run the designs recorded as failed again.
    workers : int
        Local worker processes asked for (checked).
    address : str, optional
        Dask scheduler address (checked); None for this machine.
    settings : dict, optional
        The backend's settings (:func:`~softbend.campaign.settings.backend_settings`),
        recorded by the first run and checked by later ones.
    accept_new_settings : bool
        Run even if ``settings`` differ from the recorded ones.
    in_process : bool
        Whether the backend may sweep in this process (:func:`runs_in_process`);
        if not, the designs a serial run would sweep here run in one worker process.

    Returns
    -------
    RunPlan
        The designs to sweep, the designs skipped and the executor.

    Raises
    ------
    ValueError
        The database holds a campaign with another backend or grid.
    SettingsMismatchError
        Other recorded settings, not accepted.
    """
    store.bind(
        backend,
        pressures_mpa,
        space=space,
        n_designs_planned=len(designs),
        settings=settings,
        accept_new_settings=accept_new_settings,
    )
    done_ids = store.finished_ids()
    failed_ids = store.failed_ids()
    todo = [
        d
        for d in designs
        if d.design_id not in done_ids and (retry_failed or d.design_id not in failed_ids)
    ]
    n_skipped_done = sum(d.design_id in done_ids for d in designs)
    if address is not None:
        executor = address
    elif (workers <= 1 or len(todo) <= 1) and (in_process or not todo):
        executor = "serial"
    else:
        workers = max(1, min(workers, len(todo)))
        executor = f"processes:{workers}"
    logger.info(
        "campaign %s: %d designs, %d already done, %d failed before and %s; %d to run on %s",
        store.path,
        len(designs),
        n_skipped_done,
        sum(d.design_id in failed_ids for d in designs),
        "retried" if retry_failed else "kept",
        len(todo),
        executor,
    )
    return RunPlan(
        todo=todo,
        n_skipped_done=n_skipped_done,
        n_skipped_failed=len(designs) - n_skipped_done - len(todo),
        executor=executor,
        workers=workers,
    )


def runs_in_process(backend: Backend) -> bool:
    """Whether ``backend`` may sweep in the coordinating process (a serial run).

    Not the FEM that compiles its energy (``compiled``, also inside a wrapper's
    ``inner`` backend): NGSolve runs its compilers through the C library's
    ``system()``, which ignores SIGINT in the calling process while they run
    (half a minute), so Ctrl-C would neither stop the campaign nor reach a
    KeyboardInterrupt. In a worker process the coordinating process stays
    interruptible and ends the worker.
    """
    current: object = backend
    while current is not None:
        if getattr(current, "compiled", False) is True:
            return False
        current = getattr(current, "inner", None)
    return True


def auto_chunk_size(backend: Backend, n_designs: int, n_slots: int) -> int:
    """Designs per task: the backend's ``preferred_chunk_size``, else about eight tasks a slot.

    At most 16 designs per task when the backend states no preference.
    """
    preferred = getattr(backend, "preferred_chunk_size", None)
    if preferred:
        return max(1, int(preferred))
    return max(1, min(_MAX_AUTO_CHUNK, math.ceil(n_designs / (8 * max(1, n_slots)))))


def chunks(designs: Sequence[CampaignDesign], size: int) -> deque[list[CampaignDesign]]:
    """The designs cut into consecutive tasks of ``size`` designs (the last may be shorter)."""
    return deque(list(designs[i : i + size]) for i in range(0, len(designs), size))
