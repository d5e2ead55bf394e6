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

The backends simulate paper B's actuator only (the FEM family ``"sfrba"``): a
search of another actuator is not verified, and says so
(:attr:`SearchResult.verify_skipped
<softbend.design_search.search.SearchResult.verify_skipped>`, :func:`verify_skipped`).
"""

from __future__ import annotations

import math
import os
from collections.abc import Sequence
from pathlib import Path
from typing import TYPE_CHECKING

import numpy as np

from softbend._validation import check_int
from softbend.design_search.search import Candidate, SearchResult

if TYPE_CHECKING:
    from softbend.campaign.backends import MaterialGiven

__all__ = ["fem_angle_at", "verify_candidates", "verify_skipped"]

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


def verify_skipped(result: SearchResult, backend: str = "fem") -> str | None:
    """Why the candidates of ``result`` cannot be swept by ``backend`` (None: they can).

    The campaign backends simulate the actuator of the FEM family ``"sfrba"``
    (paper B's); any other actuator's designs are not theirs to check.
    """
    space = result.spec.space
    if space.verifiable:
        return None
    who = "the FEM" if backend == "fem" else f"the {backend} backend"
    return f"{who} does not model actuator {space.actuator.name}"


def _sweep_pressures(result: SearchResult, candidates: Sequence[Candidate]) -> np.ndarray:
    """0 to the highest pressure any check needs, on the campaign's step, that pressure kept."""
    from softbend.models import default_pressures_mpa

    needed = [p for c in candidates for p in _check_pressures(result, c) if math.isfinite(p)]
    top = max(needed) if needed else PRESSURE_STEP_MPA
    steps = math.ceil(top / PRESSURE_STEP_MPA - 1e-9)
    return default_pressures_mpa(max(steps, 1) * PRESSURE_STEP_MPA, PRESSURE_STEP_MPA)


def _check_pressures(result: SearchResult, candidate: Candidate) -> list[float]:
    target = result.spec.target
    if target.kind == "curve":
        return list(target.pressures_mpa)
    return [candidate.pressure_mpa]


def _verdict(result: SearchResult, candidate: Candidate, p: np.ndarray, a: np.ndarray) -> None:
    target = result.spec.target
    if target.kind == "curve":
        fem = [fem_angle_at(p, a, q) for q, _ in target.points]
        misses = [abs(f - want) for f, (_, want) in zip(fem, target.points, strict=True)]
        candidate.fem_angle_deg = fem[-1]
        candidate.fem_error_deg = max(misses)
    else:
        fem_angle = fem_angle_at(p, a, candidate.pressure_mpa)
        goal = candidate.angle_deg if target.kind == "max_angle" else target.angle_deg
        candidate.fem_angle_deg = fem_angle
        candidate.fem_error_deg = abs(fem_angle - goal)
    error = candidate.fem_error_deg
    candidate.fem_meets = bool(
        error is not None and math.isfinite(error) and error <= target.tolerance_deg
    )


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
        ``"analytical"`` for a quick check.
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

    Returns
    -------
    list of Candidate
        The candidates verified (with ``fem_angle_deg``, ``fem_error_deg`` and
        ``fem_meets`` set; NaN and False for a sweep that failed or stopped before
        the pressure). Empty for another actuator than the FEM's: then
        ``result.verify_skipped`` says why (:func:`verify_skipped`) and nothing runs.

    Raises
    ------
    ValueError
        A bad ``k``.
    """
    import tempfile

    from softbend._progress import report
    from softbend.campaign import load_samples, run_campaign

    check_int(k, "k", low=1)
    skipped = verify_skipped(result, backend)
    if skipped is not None:
        result.verify_skipped = skipped
        return []
    chosen = result.candidates[:k]
    if not chosen:
        return []
    pressures = _sweep_pressures(result, chosen)
    designs = list(dict.fromkeys(c.design for c in chosen))
    with tempfile.TemporaryDirectory(prefix="softbend-verify-", dir=scratch_dir) as scratch:
        db = Path(db_path) if db_path is not None else Path(scratch) / "verify.duckdb"
        total = len(designs)

        def progress(done: int, failed: int, running: int, _total: int) -> None:
            report(f"verifying {total} design{'s' * (total > 1)} ({backend})", done + failed, total)

        run_campaign(
            db,
            designs,
            backend=backend,
            pressures_mpa=pressures,
            workers=workers,
            scheduler=scheduler,
            progress=progress,
            material=material,
        )
        samples = load_samples(db)
    samples = samples[samples["converged"].astype(bool)]
    by_id = {key: part for key, part in samples.groupby("design_id")}
    for candidate in chosen:
        part = by_id.get(candidate.design.design_id)
        if part is None:
            candidate.fem_angle_deg = math.nan
            candidate.fem_error_deg = math.nan
            candidate.fem_meets = False
            continue
        p = part["pressure_mpa"].to_numpy(dtype=float)
        a = part["angle_deg"].to_numpy(dtype=float)
        order = np.argsort(p)
        candidate.fem_curve = (p[order], a[order])
        _verdict(result, candidate, p, a)
    return chosen
