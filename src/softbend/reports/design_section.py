"""Design to a specification: three questions answered on the shipped surrogate, checked by the FEM.

:func:`softbend.pipeline.design.run_design` searches and verifies;
:func:`add_section` reports each specification's best designs beside the
FEM's angle, with the figures of ``softbend design find``.
"""

from __future__ import annotations

import math
import time
from collections.abc import Iterable
from pathlib import Path
from typing import TYPE_CHECKING, Any

from softbend.pipeline import Progress
from softbend.reports.html import Report

if TYPE_CHECKING:
    from softbend.design_search.spec import Specification

__all__ = ["add_section"]


def add_section(
    report: Report,
    out_dir: Path,
    progress: Progress | None = None,
    *,
    verify: int = 1,
    backend: str = "fem",
    specifications: Iterable[Specification] | None = None,
) -> dict[str, Any]:
    """Append the design-search section to ``report``; return the headline figures.

    Parameters
    ----------
    report : Report
    out_dir : path
        The report's folder; files go to ``out_dir/design``.
    progress : callable, optional
    verify : int, default 1
        Designs verified by ``backend`` per specification.
    backend : str, default "fem"
        ``"analytical"`` for a quick run.
    specifications : tuple of Specification, optional
        Default :data:`softbend.pipeline.design.SPECIFICATIONS`.
    """
    from softbend.pipeline.design import SPECIFICATIONS, run_design

    start = time.perf_counter()
    design = run_design(
        progress,
        verify=verify,
        backend=backend,
        specifications=SPECIFICATIONS if specifications is None else tuple(specifications),
    )
    from softbend.reports.design_outputs import write_search

    files = {
        r.spec.name: write_search(r, design.model.predictor, Path(out_dir) / "design" / r.spec.name)
        for r in design.results
    }
    section = report.section("Design to a specification (softbend design find)")
    section.text(
        "Three questions a designer asks of paper B's actuator, answered on the shipped "
        "FEM-trained MLP by scoring every design of the grid of manufacturable values "
        "(0.5 mm, 1° of fibre angle) in the training ranges and support, with a 1° margin "
        f"kept from each tolerance against the surrogate's own error; the best "
        f"{verify} design{'s' * (verify != 1)} of each swept by the {backend.upper()} "
        "(which keeps the whole tolerance). Any other specification: "
        "`softbend design find --angle 90 --at 0.08 --minimize l --out DIR`.",
        note=True,
    )
    rows = []
    for result in design.results:
        objectives = ", ".join(str(o) for o in result.spec.objectives)
        for rank, c in enumerate(result.candidates[: max(verify, 3)], start=1):
            fem = (
                ""
                if c.fem_angle_deg is None or not math.isfinite(c.fem_angle_deg)
                else (f"{c.fem_angle_deg:.2f}")
            )
            verdict = "" if c.fem_meets is None else ("yes" if c.fem_meets else "NO")
            rows.append(
                [
                    result.spec.name if rank == 1 else "",
                    result.spec.target.describe() if rank == 1 else "",
                    objectives if rank == 1 else "",
                    rank,
                    str(c.design),
                    f"{c.pressure_mpa:.4g}",
                    f"{c.angle_deg:.2f}",
                    fem,
                    verdict,
                ]
            )
    section.table(
        [
            "specification",
            "target",
            "objectives",
            "rank",
            "design l,r,t,b,φ,lc (mm, °)",
            "pressure (MPa)",
            "surrogate angle (°)",
            f"{backend.upper()} angle (°)",
            "within tolerance",
        ],
        rows,
        caption="For a curve, the angle at its last point; for a pressure target, the "
        "pressure that reaches the angle on the surrogate.",
    )
    for result in design.results:
        name = result.spec.name
        folder = Path(files[name]["curves.png"]).parent
        section.figure(
            folder / "curves.png",
            f"{name}: θ(p) of the best designs, surrogate (lines) and {backend.upper()} (circles)",
            root=out_dir,
        )
    return {**design.summary, "seconds": time.perf_counter() - start}
