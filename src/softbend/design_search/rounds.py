"""Verification in rounds: the surrogate corrected by the FEM sweeps of its own candidates.

A surrogate trained on a few hundred designs misses a tight tolerance by several
degrees where the response is steep (a PneuNet past the touch of its walls: the
MLP of the shipped dataset misses 90° at 30 kPa by 4–21° on its first five
candidates). :func:`verify_in_rounds` closes the loop the way a designer would:

1. sweep the best candidates with the FEM
   (:func:`~softbend.design_search.verify.verify_candidates`);
2. if none is within the tolerance, refine the surrogate on every FEM curve swept
   so far (:func:`softbend.transfer.refine.refine_surrogate`, by default
   ``residual-gp``: a Gaussian process on the surrogate's residuals over the
   design space, so the correction is local to the swept designs and fades away
   from them);
3. search again on the refined surrogate, leaving out the designs already swept,
   and go back to 1, at most ``rounds`` times.

Every round's model and the FEM curves it learnt from are written into a folder
(``round-K.json``, ``fem_curves.csv``): the refined surrogate is a saved model
like any other (``softbend predict``).
"""

from __future__ import annotations

import math
import os
from dataclasses import dataclass, field
from pathlib import Path
from typing import TYPE_CHECKING, Any

from softbend._validation import check_int

if TYPE_CHECKING:
    from softbend.design_search.result import Candidate
    from softbend.design_search.search import LoadedModel, SearchResult
    from softbend.design_search.spec import Specification

__all__ = ["ROUND_STRATEGY", "Round", "rounds_summary", "verify_in_rounds"]

#: The strategy that refines the surrogate between rounds (``softbend transfer strategies``).
ROUND_STRATEGY = "residual-gp"
#: The file of the FEM curves the rounds learn from, in a round's folder.
CURVES_FILE = "fem_curves.csv"


def _finite(value: float | None) -> float | None:
    """``value`` as a float, None where it is missing or not finite (a stopped sweep)."""
    return None if value is None or not math.isfinite(value) else float(value)


@dataclass
class Round:
    """One round of :func:`verify_in_rounds`.

    Attributes
    ----------
    number : int
        0 for the search on the given surrogate, then 1, 2, ...
    model : str
        The surrogate searched (the given one's path, then ``round-K.json``).
    verified : list of Candidate
        The candidates the FEM swept in this round, with their FEM figures.
    """

    number: int
    model: str
    verified: list[Candidate] = field(default_factory=list)

    @property
    def met(self) -> bool:
        """Whether the FEM puts one of this round's candidates within the tolerance."""
        return any(c.fem_meets for c in self.verified)

    def to_dict(self) -> dict[str, Any]:
        """JSON-friendly record: the model and each verified design's figures."""
        return {
            "round": self.number,
            "model": self.model,
            "verified": [
                {
                    "design": c.design.as_dict(),
                    "angle_deg": float(c.angle_deg),
                    "fem_angle_deg": _finite(c.fem_angle_deg),
                    "fem_meets": c.fem_meets,
                    "fem_stop_reason": c.fem_stop,
                }
                for c in self.verified
            ],
        }


def _write_curves(
    verified: list[Candidate], model: LoadedModel, to_mpa: float, path: Path
) -> Path | None:
    """The FEM curves of ``verified`` as a measurements file of the model's actuator
    (marked simulated); None when no sweep gave a curve."""
    import pandas as pd

    from softbend.transfer.measurements import write_measurements

    actuator = model.actuator
    rows = []
    for i, c in enumerate(verified):
        if c.fem_curve is None:
            continue
        values = c.design.as_dict()
        for p, a in zip(*c.fem_curve, strict=True):
            rows.append(
                {
                    "actuator_id": f"fem-{i + 1}",
                    **{name: values[name] for name in actuator.names},
                    actuator.pressure_column: float(p) / to_mpa,
                    "angle_deg": float(a),
                }
            )
    if not rows:
        return None
    note = "FEM sweeps of design-search candidates (softbend design find --refine-rounds)"
    return write_measurements(
        pd.DataFrame(rows), actuator, path, {"synthetic": "true", "note": note}
    )


def verify_in_rounds(
    model: LoadedModel,
    spec: Specification,
    result: SearchResult,
    *,
    verify: int,
    rounds: int,
    folder: str | os.PathLike[str],
    strategy: str = ROUND_STRATEGY,
    seed: int = 0,
    top: int = 10,
    allow_extrapolation: bool = False,
    distinct: bool = True,
    **verify_options: Any,
) -> tuple[SearchResult, LoadedModel, list[Round]]:
    """Verify ``result``'s best candidates, refining the surrogate until one meets ``spec``.

    Parameters
    ----------
    model : LoadedModel
        The surrogate ``result`` was searched on (a saved file: the rounds refine it).
    spec : Specification
        The specification ``result`` answers.
    result : SearchResult
        :func:`~softbend.design_search.search.find_designs` on ``model``.
    verify : int
        Candidates the FEM sweeps per round, >= 1.
    rounds : int
        Refinements at most, >= 0 (0: verify ``result`` once, as
        :func:`~softbend.design_search.verify.verify_candidates`).
    folder : path
        Where the refined surrogates (``round-K.json``) and the FEM curves they
        learn from (``fem_curves.csv``) are written; made if missing.
    strategy : str, default "residual-gp"
        The refinement (a strategy of ``softbend transfer strategies`` that
        learns from measurements and starts from ``model``).
    seed : int
        Seed of the refinement.
    top, allow_extrapolation, distinct
        As :func:`~softbend.design_search.search.find_designs`, for each round's search.
    **verify_options
        Passed to :func:`~softbend.design_search.verify.verify_candidates`
        (``backend``, ``workers``, ``db_path``, ``replace_stopped`` ...): one
        database for every round keeps the sweeps resumable.

    Returns
    -------
    result : SearchResult
        The last round's search, its verified candidates carrying the FEM's figures.
    model : LoadedModel
        The surrogate that search ran on.
    rounds : list of Round
        Every round, the first on ``model``; the last one's candidates met the
        specification when any did.
    """
    from softbend.design_search.search import TOP, LoadedModel, find_designs
    from softbend.design_search.verify import verify_candidates
    from softbend.transfer.refine import refine_surrogate

    check_int(verify, "verify", low=1)
    check_int(rounds, "rounds", low=0)
    out = Path(folder)
    done: list[Round] = []
    swept: list[Candidate] = []
    current = model
    while True:
        verified = verify_candidates(result, verify, **verify_options)
        done.append(Round(len(done), current.path, list(verified)))
        swept += verified
        if rounds:
            result.rounds = [r.to_dict() for r in done]
        if done[-1].met or len(done) > rounds or not verified:
            return result, current, done
        out.mkdir(parents=True, exist_ok=True)
        curves = _write_curves(swept, model, spec.space.to_mpa, out / CURVES_FILE)
        if curves is None:  # no sweep gave a curve: nothing to learn from
            return result, current, done
        refined = refine_surrogate(model.path, curves, strategy, seed=seed, calibrated=False)
        current = LoadedModel.load(refined.save(out / f"round-{len(done)}.json"))
        seen = {c.design.as_text() for c in swept}
        result = find_designs(
            current,
            spec,
            top=min(top + len(seen), int(TOP.high)),  # room for those already swept
            allow_extrapolation=allow_extrapolation,
            distinct=distinct,
        )
        fresh = [c for c in result.candidates if c.design.as_text() not in seen]
        result.candidates = fresh[:top]
        if not result.candidates:
            result.rounds = [r.to_dict() for r in done]
            return result, current, done


def rounds_summary(rounds: list[Round]) -> dict[str, Any]:
    """The rounds in one record: how many, FEM sweeps, and the FEM angles of each."""
    return {
        "rounds": len(rounds),
        "fem_sweeps": sum(len(r.verified) for r in rounds),
        "met": bool(rounds and rounds[-1].met),
        "fem_angles_deg": [[_finite(c.fem_angle_deg) for c in r.verified] for r in rounds],
    }
