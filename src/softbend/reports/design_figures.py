"""Figures of a design search: the objectives' trade-off, and θ(p) of the chosen designs."""

from __future__ import annotations

import math
from pathlib import Path
from typing import TYPE_CHECKING

import numpy as np

from softbend.design_search.spec import Objective

if TYPE_CHECKING:
    from softbend.design_search.search import Predictor, SearchResult

__all__ = ["curves_figure", "front_figure"]

_DPI = 120


def _label(objective: Objective) -> str:
    unit = objective.unit
    return f"{objective.name} ({unit})" if unit else objective.name


def front_figure(result: SearchResult, path: str | Path) -> Path:
    """The trade-off of the designs that meet the target, and the candidates' FEM check.

    Left: with two objectives or more, the Pareto front of the first two (every
    design of the front, the candidates ringed); with one, each candidate's
    objective against its miss of the target. Right: each candidate's angle
    by the surrogate and, once verified, by the FEM, against the target's band.
    """
    from matplotlib.figure import Figure

    spec, candidates = result.spec, result.candidates
    fig = Figure(figsize=(10, 4.2))
    left, right = fig.subplots(1, 2)
    objectives = spec.objectives
    if len(objectives) >= 2 and result.front.shape[0]:
        x, y = result.front[:, 0], result.front[:, 1]
        left.plot(x, y, ".", color="0.6", label=f"Pareto front ({x.size} designs)")
        cx = [c.objectives[objectives[0].name] for c in candidates]
        cy = [c.objectives[objectives[1].name] for c in candidates]
        left.plot(cx, cy, "o", mfc="none", color="C3", label="candidates")
        left.set_xlabel(_label(objectives[0]))
        left.set_ylabel(_label(objectives[1]))
    else:
        values = [c.objectives[objectives[0].name] for c in candidates]
        misses = [c.error_deg for c in candidates]
        left.plot(values, misses, "o", color="C0", label="candidates (surrogate)")
        for rank, (v, m) in enumerate(zip(values, misses, strict=True), start=1):
            left.annotate(str(rank), (v, m), fontsize=7, xytext=(3, 3), textcoords="offset points")
        if spec.target.kind != "max_angle":
            left.axhline(spec.target.tolerance_deg, color="C3", lw=0.8, ls="--", label="tolerance")
        left.set_xlabel(_label(objectives[0]))
        left.set_ylabel("miss of the target (°)")
    left.set_title(f"{spec.name}: {result.n_meeting:,} of {result.n_designs:,} designs meet it",
                   fontsize=9)  # fmt: skip
    left.grid(True, alpha=0.3)
    if left.get_legend_handles_labels()[0]:  # no legend without a label
        left.legend(fontsize=7)
    ranks = np.arange(1, len(candidates) + 1)
    right.plot(ranks, [c.angle_deg for c in candidates], "o", label="surrogate")
    fem = [c.fem_angle_deg if c.fem_angle_deg is not None else math.nan for c in candidates]
    if any(math.isfinite(v) for v in fem):
        right.plot(ranks, fem, "s", mfc="none", color="C3", label="FEM")
    target = spec.target
    if target.kind in ("angle_at", "pressure_for"):
        right.axhspan(
            target.angle_deg - target.tolerance_deg,
            target.angle_deg + target.tolerance_deg,
            color="C2",
            alpha=0.15,
            label="target ± tolerance",
        )
    right.set_xlabel("candidate (best first)")
    right.set_ylabel("angle at the target's pressure (°)")
    right.set_xticks(ranks)
    right.set_title(target.describe(), fontsize=9)
    right.grid(True, alpha=0.3)
    if right.get_legend_handles_labels()[0]:  # no legend without a label
        right.legend(fontsize=7)
    fig.tight_layout()
    fig.savefig(path, dpi=_DPI)
    return Path(path)


#: A design's label longer than this is drawn as its values (names in the legend's title).
_LABEL_CHARS = 48


def curves_figure(
    result: SearchResult, predictor: Predictor, path: str | Path, *, count: int = 5
) -> Path:
    """θ(p) of the best ``count`` candidates: the surrogate's line, the FEM's points if verified,
    and the target."""
    from matplotlib.figure import Figure

    spec = result.spec
    target = spec.target
    top = max(target.pressures_mpa) * 1.5
    for c in result.candidates[:count]:
        if c.fem_curve is not None:
            top = max(top, float(np.max(c.fem_curve[0])))
    p = np.linspace(0.0, top, 121)
    fig = Figure(figsize=(7, 4.5))
    ax = fig.subplots()
    shown = result.candidates[:count]
    names = list(shown[0].design.as_dict()) if shown else []
    long = any(len(str(c.design)) > _LABEL_CHARS for c in shown)
    for i, c in enumerate(shown):
        color = f"C{i}"
        rows = c.design.feature_rows(p)
        said = (
            ", ".join(
                f"{v:g}" if isinstance(v, float) else str(v) for v in c.design.record().values()
            )
            if long
            else str(c.design)
        )
        ax.plot(p, predictor.predict(rows), color=color, lw=1.2, label=f"{i + 1}: {said}")
        if c.fem_curve is not None:
            ax.plot(*c.fem_curve, "o", ms=3, color=color, mfc="none")
    if target.kind == "curve":
        ps, angles = zip(*target.points, strict=True)
        ax.errorbar(ps, angles, yerr=target.tolerance_deg, fmt="k*", ms=9, label="target")
    elif target.kind == "max_angle":
        ax.axvline(target.pressure_mpa, color="k", ls="--", lw=0.8, label="target pressure")
    else:
        ax.errorbar(
            [target.pressure_mpa],
            [target.angle_deg],
            yerr=target.tolerance_deg,
            fmt="k*",
            ms=10,
            label="target" if target.kind == "angle_at" else "target (at most this pressure)",
        )
    ax.set_xlabel(f"pressure ({target.unit})")
    ax.set_ylabel("bending angle (°)")
    verified = any(c.fem_curve is not None for c in result.candidates[:count])
    ax.set_title(
        f"{spec.name}: surrogate (lines)" + (", FEM (circles)" if verified else ""), fontsize=9
    )
    ax.grid(True, alpha=0.3)
    if ax.get_legend_handles_labels()[0]:  # no legend without a label
        # a long design is its values, the names once in the legend's title
        title = "rank: " + ", ".join(names) if long else None
        ax.legend(fontsize=7, title=title, title_fontsize=6)
    fig.tight_layout()
    fig.savefig(path, dpi=_DPI)
    return Path(path)
