"""Design to a specification on the shipped FEM surrogate, the best designs checked by the FEM.

:func:`run_design` answers :data:`SPECIFICATIONS`, three questions a designer
asks of paper B's actuator, with :func:`softbend.design_search.find_designs`
on the shipped FEM-trained MLP, and sweeps the best design of each with the
FEM (:func:`softbend.design_search.verify_candidates`) so the report sets the
FEM's angle beside the surrogate's.
"""

from __future__ import annotations

import time
from dataclasses import dataclass
from typing import Any

from softbend.design_search.search import LoadedModel, SearchResult
from softbend.design_search.spec import (
    Objective,
    ParameterRange,
    Specification,
    Target,
)
from softbend.pipeline import Progress

__all__ = ["SPECIFICATIONS", "DesignRun", "run_design"]

#: Three questions of a designer, with a 1° margin against the surrogate's own error.
SPECIFICATIONS: tuple[Specification, ...] = (
    Specification(
        Target("angle_at", angle_deg=90.0, pressure_mpa=0.08),
        {"t": ParameterRange(3.0, 4.0, 0.5), "phi": ParameterRange(10.0, 10.0)},
        (Objective("l"),),
        name="short-finger",
        margin_deg=1.0,
    ),
    Specification(
        Target("pressure_for", angle_deg=120.0, pressure_mpa=0.1),
        {"l": ParameterRange(100.0, 130.0, 0.5)},
        (Objective("volume"),),
        name="light-reach",
        margin_deg=1.0,
    ),
    Specification(
        Target("curve", tolerance_deg=4.0, points=((0.03, 30.0), (0.06, 70.0), (0.09, 115.0))),
        {"phi": ParameterRange(10.0, 10.0)},
        name="follow-a-curve",
        margin_deg=1.0,
    ),
)


@dataclass(frozen=True)
class DesignRun:
    """What :func:`run_design` found: per specification its search result (the verified
    candidates carry the FEM's figures), headline figures, and the model searched (read
    once, for the figures drawn from it)."""

    results: list[SearchResult]
    summary: dict[str, Any]
    model: LoadedModel


def run_design(
    progress: Progress | None = None,
    *,
    verify: int = 1,
    backend: str = "fem",
    specifications: tuple[Specification, ...] = SPECIFICATIONS,
) -> DesignRun:
    """Search each specification on the shipped MLP, verify the best ``verify`` designs.

    Parameters
    ----------
    progress : callable, optional
        ``progress(phase, done, total)``.
    verify : int, default 1
        Designs verified per specification (0: none).
    backend : str, default "fem"
        Backend of the verification (``"analytical"`` for a quick run).
    specifications : tuple of Specification
    """
    from softbend._progress import listening
    from softbend.design_search.search import find_designs
    from softbend.design_search.verify import verify_candidates
    from softbend.transfer.base import shipped_base_path

    model = LoadedModel.load(shipped_base_path())  # read once for every specification
    results, rows = [], []
    for spec in specifications:
        start = time.perf_counter()
        with listening(progress):
            result = find_designs(model, spec, top=5)
            if verify and result.candidates:
                verify_candidates(result, verify, backend=backend, workers=1)
        results.append(result)
        best = result.candidates[0] if result.candidates else None
        rows.append(
            {
                "name": spec.name,
                "target": spec.target.describe(),
                "designs": result.n_designs,
                "meeting": result.n_meeting,
                "search_s": result.seconds,
                "best": None if best is None else best.to_dict(),
                "verified": sum(c.fem_meets is not None for c in result.candidates),
                "confirmed": sum(bool(c.fem_meets) for c in result.candidates),
                "seconds": time.perf_counter() - start,
            }
        )
    summary = {"backend": backend, "verify": verify, "specifications": rows}
    return DesignRun(results, summary, model)
