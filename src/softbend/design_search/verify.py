"""The best candidates of a design search swept by the FEM, beside the surrogate.

A surrogate's answer is checked where it matters: each of the best ``k``
designs is swept by a campaign backend (the FEM by default, the analytical
model for a quick check) with the campaign machinery, so the sweeps run in
parallel (local processes or a Dask cluster), are recorded in a campaign
database as they finish and resume if interrupted. The FEM's angle is read at
the candidate's pressure (linear interpolation between converged steps); a
candidate whose FEM angle misses the target by more than its tolerance is
marked (``fem_meets`` False). For ``max_angle`` (no target angle) the check is
that the FEM confirms the surrogate's angle within the tolerance.

Every actuator is swept by the FEM family its description names
(:attr:`Actuator.fem_family <softbend.actuators.Actuator.fem_family>`: paper
B's ``"sfrba"``, the PneuNet's ``"pneunet"``), with a backend the family
takes (:attr:`FEMFamily.backends <softbend.fem.families.FEMFamily.backends>`:
the FEM, or for paper B's any campaign backend, its analytical model too): each
candidate becomes the family's design (:meth:`FEMFamily.design
<softbend.fem.families.FEMFamily.design>`, the model's codes as the family's
values, the pressures converted to MPa), swept from 0 to the pressure checked
on the family's step. A sweep that stops before that pressure (neighbouring
chamber walls touch, no convergence) gives no angle: the candidate fails the
check and keeps the FEM's stop reason (:attr:`Candidate.fem_stop
<softbend.design_search.search.Candidate.fem_stop>`). An actuator that names
no family is not verified, and says so (:attr:`SearchResult.verify_skipped
<softbend.design_search.search.SearchResult.verify_skipped>`, :func:`verify_skipped`).
"""

from __future__ import annotations

import math
import os
from collections.abc import Sequence
from pathlib import Path
from typing import TYPE_CHECKING, Any

import numpy as np

from softbend._validation import check_int
from softbend.design_search.search import Candidate, SearchResult
from softbend.errors import InputError

if TYPE_CHECKING:
    import pandas as pd

    from softbend.campaign.backends import MaterialGiven
    from softbend.design_search.space import SearchSpace
    from softbend.fem.families import FEMFamily

__all__ = ["fem_angle_at", "verify_candidates", "verify_family", "verify_skipped"]

#: Pressure step of a verification sweep, MPa (the campaign's default grid step).
PRESSURE_STEP_MPA = 0.005


def fem_angle_at(pressures: np.ndarray, angles: np.ndarray, pressure_mpa: float) -> float:
    """The angle at ``pressure_mpa`` on a converged sweep (linear), degrees; NaN past its end."""
    p = np.asarray(pressures, dtype=np.float64)
    a = np.asarray(angles, dtype=np.float64)
    ok = np.isfinite(p) & np.isfinite(a)
    p, a = p[ok], a[ok]
    if p.size < 2 or pressure_mpa > p.max() + 1e-12:
        return math.nan
    order = np.argsort(p)
    return float(np.interp(pressure_mpa, p[order], a[order]))


def verify_family(space: SearchSpace) -> FEMFamily | None:
    """The FEM family that sweeps the designs of ``space`` (None: its actuator names none).

    Paper B's actuator is the family ``"sfrba"``; another actuator's
    ``fem_family`` must be registered and have the model's design parameters,
    by name and in order.

    Raises
    ------
    InputError
        Keyed ``model``: the family is not registered (the message lists those
        that are), or its parameters are not the model's.
    """
    from softbend.fem.families import FEM_FAMILIES

    name = space.actuator.fem_family
    if name is None:
        return None
    if name not in FEM_FAMILIES:
        known = ", ".join(FEM_FAMILIES.names()) or "none"
        raise InputError(
            f"names the FEM family {name!r} for actuator {space.actuator.name}, which is not "
            f"one softbend simulates ({known}); --verify cannot sweep its designs",
            key="model",
        )
    family = FEM_FAMILIES.get(name)
    if tuple(family.names) != tuple(space.columns):
        raise InputError(
            f"has the parameters {', '.join(space.columns)}, not those of the FEM family "
            f"{name!r} its actuator {space.actuator.name} names ({', '.join(family.names)}); "
            "--verify cannot sweep its designs",
            key="model",
        )
    return family


def verify_skipped(result: SearchResult, backend: str = "fem") -> str | None:
    """Why the candidates of ``result`` cannot be swept by ``backend`` (None: they can).

    An actuator is swept by the backends of the FEM family its description names
    (:attr:`FEMFamily.backends <softbend.fem.families.FEMFamily.backends>`: the FEM,
    or for paper B's any campaign backend), and not at all when it names none.

    Raises
    ------
    InputError
        The actuator names a family that cannot sweep its designs (:func:`verify_family`).
    """
    space = result.spec.space
    who = "the FEM" if backend == "fem" else f"the {backend} backend"
    if not space.verifiable:
        return f"{who} does not model actuator {space.actuator.name}"
    family = verify_family(space)
    assert family is not None  # verifiable: it names one
    if family.backends is None or backend in family.backends:
        return None
    return (
        f"{who} does not model actuator {space.actuator.name} (the FEM of its family "
        f"{family.name} does: --backend fem)"
    )


def _sweep_pressures(
    result: SearchResult, candidates: Sequence[Candidate], step_mpa: float = PRESSURE_STEP_MPA
) -> np.ndarray:
    """0 to the highest pressure any check needs (MPa), on ``step_mpa``, that pressure kept."""
    from softbend.models import default_pressures_mpa

    needed = [p for c in candidates for p in _check_pressures(result, c) if math.isfinite(p)]
    top = max(needed) if needed else step_mpa
    steps = math.ceil(top / step_mpa - 1e-9)
    return default_pressures_mpa(max(steps, 1) * step_mpa, step_mpa)


def _check_pressures(result: SearchResult, candidate: Candidate) -> list[float]:
    """The pressures the check of ``candidate`` reads the FEM at, MPa."""
    target = result.spec.target
    to_mpa = result.spec.space.to_mpa
    if target.kind == "curve":
        return [q * to_mpa for q in target.pressures_mpa]
    return [candidate.pressure_mpa * to_mpa]


def _verdict(result: SearchResult, candidate: Candidate, p: np.ndarray, a: np.ndarray) -> None:
    target = result.spec.target
    to_mpa = result.spec.space.to_mpa
    if target.kind == "curve":
        fem = [fem_angle_at(p, a, q * to_mpa) for q, _ in target.points]
        misses = [abs(f - want) for f, (_, want) in zip(fem, target.points, strict=True)]
        candidate.fem_angle_deg = fem[-1]
        candidate.fem_error_deg = max(misses)
    else:
        fem_angle = fem_angle_at(p, a, candidate.pressure_mpa * to_mpa)
        goal = candidate.angle_deg if target.kind == "max_angle" else target.angle_deg
        candidate.fem_angle_deg = fem_angle
        candidate.fem_error_deg = abs(fem_angle - goal)
    error = candidate.fem_error_deg
    candidate.fem_meets = bool(
        error is not None and math.isfinite(error) and error <= target.tolerance_deg
    )


def _no_angle(candidate: Candidate, why: str | None) -> None:
    """Mark ``candidate`` unverified by a number: no angle, the check failed, and why."""
    candidate.fem_angle_deg = math.nan
    candidate.fem_error_deg = math.nan
    candidate.fem_meets = False
    candidate.fem_stop = why


def _stop_reasons(designs: pd.DataFrame) -> dict[str, str]:
    """``{design_id: why}`` of a campaign's ``designs`` table: a failed design's error,
    else the FEM's stop reason (its ``stats``), else the pressure its sweep ended at."""
    import json

    out: dict[str, str] = {}
    for row in designs.itertuples(index=False):
        if row.status == "failed":
            out[row.design_id] = f"the sweep failed: {row.error}"
            continue
        try:
            stats = json.loads(row.stats) if isinstance(row.stats, str) else {}
        except ValueError:
            stats = {}
        reason = stats.get("stop_reason") if isinstance(stats, dict) else None
        if not reason:
            top = row.max_pressure_mpa
            reason = "the sweep ended" + (f" at {top:g} MPa" if top == top else "")
        out[row.design_id] = str(reason)
    return out


def verify_candidates(
    result: SearchResult,
    k: int = 5,
    *,
    db_path: str | os.PathLike[str] | None = None,
    backend: str = "fem",
    workers: int | None = None,
    scheduler: str | None = None,
    material: MaterialGiven | None = None,
    scratch_dir: str | os.PathLike[str] | None = None,
    replace_stopped: bool = False,
) -> list[Candidate]:
    """Sweep the best ``k`` candidates of ``result`` and set their FEM figures in place.

    Parameters
    ----------
    result : SearchResult
        From :func:`~softbend.design_search.search.find_designs`.
    k : int, default 5
        How many of the best candidates, >= 1 (fewer if there are fewer).
    db_path : path, optional
        The campaign database of the sweeps (resumed if present); default a
        temporary one, removed at the end.
    backend : str, default "fem"
        A campaign backend (:data:`softbend.campaign.BACKENDS`): ``"fem"``, or
        ``"analytical"`` for a quick check of paper B's actuator. Another
        actuator is swept by its family's FEM (``"fem"`` only).
    workers : int, optional
        Local processes (default: as :func:`softbend.campaign.run_campaign`).
    scheduler : str, optional
        A Dask scheduler address to run the sweeps on.
    material : str, path, Material or ResolvedMaterial, optional
        The elastomer of the backend, as :func:`~softbend.campaign.run_campaign` takes it.
    scratch_dir : path, optional
        The folder the temporary folder of the sweeps is made in (default: the
        system's). A command passes the staging folder of its output, so that a
        run killed before the end leaves it where the next run removes it.
    replace_stopped : bool, default False
        Replace each candidate that gives no angle (its sweep stopped before the
        pressure checked, failed, or the family refused the design) by the next
        listed one, until ``k`` reach the pressure or the list ends: a surrogate
        trained on the swept range does not know where a sweep would stop. All
        batches share one pressure grid, to the highest pressure any listed
        candidate is checked at.

    Returns
    -------
    list of Candidate
        The candidates verified (with ``fem_angle_deg``, ``fem_error_deg`` and
        ``fem_meets`` set; NaN and False, with ``fem_stop`` saying why, for a
        sweep that failed or stopped before the pressure, or a design the
        family refuses). ``result.verified_by`` names the backend and family
        and counts the designs swept.
        Empty for an actuator no backend models: then ``result.verify_skipped``
        says why (:func:`verify_skipped`) and nothing runs.

    Raises
    ------
    ValueError
        A bad ``k``.
    InputError
        Keyed ``model``: the actuator names an FEM family that cannot sweep its
        designs (:func:`verify_family`).
    """
    import tempfile

    check_int(k, "k", low=1)
    skipped = verify_skipped(result, backend)
    if skipped is not None:
        result.verify_skipped = skipped
        return []
    pool = result.candidates if replace_stopped else result.candidates[:k]
    if not pool:
        return []
    family = verify_family(result.spec.space)
    assert family is not None  # not skipped: the actuator names one
    step = family.pstep_mpa
    sweep = _Sweep(
        result,
        family,
        backend,
        workers=workers,
        scheduler=scheduler,
        material=material,
    )
    verified: list[Candidate] = []
    with tempfile.TemporaryDirectory(prefix="softbend-verify-", dir=scratch_dir) as scratch:
        sweep.db = Path(db_path) if db_path is not None else Path(scratch) / "verify.duckdb"
        if replace_stopped:  # one grid for every batch: the database keeps its first
            sweep.pressures = _sweep_pressures(result, pool, step)
        while len(verified) < len(pool):
            reached = sum(c.fem_stop is None for c in verified)
            batch = pool[len(verified) : len(verified) + k - reached]
            if not batch:
                break
            if sweep.pressures is None:
                sweep.pressures = _sweep_pressures(result, batch, step)
            sweep.run(batch)
            verified += batch
    result.verified_by = {"backend": backend, "family": family.name, "designs": len(verified)}
    return verified


class _Sweep:
    """The campaign that sweeps batches of candidates (one database, one pressure grid)."""

    def __init__(
        self,
        result: SearchResult,
        family: FEMFamily,
        backend: str,
        *,
        workers: int | None,
        scheduler: str | None,
        material: MaterialGiven | None,
    ) -> None:
        self.result = result
        self.family = family
        self.backend = backend
        self.workers = workers
        self.scheduler = scheduler
        self.material = material
        self.db = Path("verify.duckdb")
        self.pressures: np.ndarray | None = None

    def run(self, batch: Sequence[Candidate]) -> None:
        """Sweep ``batch`` and set each candidate's FEM figures (or why it has none)."""
        from softbend._progress import report
        from softbend.campaign import load_samples, run_campaign
        from softbend.campaign.store import load_designs

        result, family = self.result, self.family
        swept, refused = _campaign_designs(batch, family)
        for index, why in refused.items():
            _no_angle(batch[index], why)
        if not swept:
            return
        designs = list(dict.fromkeys(swept.values()))
        total = len(designs)
        what = self.backend

        def progress(done: int, failed: int, running: int, to_run: int) -> None:
            swept = total - to_run  # recorded by an interrupted run of the same command
            report(
                f"verifying {total} design{'s' * (total > 1)} ({what})",
                swept + done + failed,
                total,
            )

        run_campaign(
            self.db,
            designs,
            backend=self.backend,
            pressures_mpa=self.pressures,
            workers=self.workers,
            scheduler=self.scheduler,
            progress=progress,
            material=self.material,
        )
        samples = load_samples(self.db)
        stops = _stop_reasons(load_designs(self.db))
        samples = samples[samples["converged"].astype(bool)]
        by_id = {key: part for key, part in samples.groupby("design_id")}
        for index, design in swept.items():
            candidate = batch[index]
            part = by_id.get(design.design_id)
            if part is None:
                why = stops.get(design.design_id, "the sweep gave no converged step")
                _no_angle(candidate, why)
                continue
            p = part["pressure_mpa"].to_numpy(dtype=float)
            a = part["angle_deg"].to_numpy(dtype=float)
            order = np.argsort(p)
            candidate.fem_curve = (p[order], a[order])
            _verdict(result, candidate, p, a)
            needed = [q for q in _check_pressures(result, candidate) if math.isfinite(q)]
            if needed and max(needed) > p.max() + 1e-12:  # stopped before the pressure checked
                ended = f"the sweep ended at {p.max():g} MPa"
                candidate.fem_stop = stops.get(design.design_id, ended)
            else:
                candidate.fem_stop = None


def _campaign_designs(
    chosen: Sequence[Candidate], family: FEMFamily
) -> tuple[dict[int, Any], dict[int, str]]:
    """The design each candidate is swept as (by its index in ``chosen``), and why the
    family refuses those it cannot build: the model's codes are the family's values
    (:meth:`FEMFamily.design <softbend.fem.families.FEMFamily.design>`).
    """
    swept: dict[int, Any] = {}
    refused: dict[int, str] = {}
    for i, candidate in enumerate(chosen):
        codes = candidate.design.as_array()
        values = dict(zip(family.names, (float(v) for v in codes), strict=True))
        try:
            swept[i] = family.design(values)
        except (InputError, ValueError) as exc:
            refused[i] = f"the {family.name} family refuses the design: {exc}"
    return swept, refused
