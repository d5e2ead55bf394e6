"""Design to a specification on the shipped FEM surrogate: search time and the FEM's verdict.

1. ``softbend design find --angle 90 --at 0.08`` on the shipped FEM-trained MLP
   over the whole default grid (Table 1's box at 0.5 mm and 1°, about 2.7
   million designs): the search's wall time (best of three), then the FEM
   sweep of its best design and its angle at 0.08 MPa.
2. The three specifications of the report's design section
   (:data:`softbend.pipeline.design.SPECIFICATIONS`): each searched, and its
   top five designs swept by the FEM; how many the FEM confirms within the
   tolerance.

Prints one line per figure and records them in benchmarks/results/. About two minutes on two cores
(16 FEM sweeps, none past 0.1 MPa).

Usage: python benchmarks/bench_design_search.py [--workers N]
"""

from __future__ import annotations

import argparse
import os
import time

from _record import record

from softbend.design_search.search import find_designs
from softbend.design_search.spec import Specification, Target
from softbend.design_search.verify import verify_candidates
from softbend.pipeline.design import SPECIFICATIONS
from softbend.transfer.base import shipped_base_path


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--workers", type=int, default=os.cpu_count() or 1)
    args = parser.parse_args()
    model = shipped_base_path()
    spec = Specification(Target("angle_at", angle_deg=90.0, pressure_mpa=0.08), name="90-at-0.08")
    times = []
    for _ in range(3):
        start = time.perf_counter()
        result = find_designs(model, spec, top=5)
        times.append(time.perf_counter() - start)
    print(
        f"search 90° ± 3° at 0.08 MPa: {result.n_designs:,} designs, {result.n_meeting:,} meet "
        f"it, best of 3: {min(times):.2f} s (on {os.cpu_count()} CPUs)"
    )
    (best,) = verify_candidates(result, 1, workers=args.workers)
    print(
        f"  best {best.design}: surrogate {best.angle_deg:.2f}°, FEM {best.fem_angle_deg:.2f}° "
        f"at 0.08 MPa ({'within' if best.fem_meets else 'OUTSIDE'} ± 3°)"
    )
    figures = {
        "90-at-0.08: designs searched": result.n_designs,
        "90-at-0.08: designs meeting it": result.n_meeting,
        "90-at-0.08: search, best of 3": round(min(times), 3),
        "90-at-0.08: best design": str(best.design),
        "90-at-0.08: best design, surrogate angle": round(best.angle_deg, 2),
        "90-at-0.08: best design, FEM angle": round(best.fem_angle_deg, 2),
    }
    units = {"90-at-0.08: search, best of 3": "s"}
    units.update({k: "°" for k in figures if k.endswith(" angle")})
    for spec in SPECIFICATIONS:
        start = time.perf_counter()
        result = find_designs(model, spec, top=5)
        searched = time.perf_counter() - start
        verified = verify_candidates(result, 5, workers=args.workers)
        confirmed = sum(bool(c.fem_meets) for c in verified)
        figures[f"{spec.name}: designs meeting it"] = result.n_meeting
        figures[f"{spec.name}: search"], units[f"{spec.name}: search"] = round(searched, 2), "s"
        figures[f"{spec.name}: FEM confirms (of top)"] = f"{confirmed} of {len(verified)}"
        print(
            f"{spec.name}: {spec.describe()}: {result.n_meeting:,} of {result.n_designs:,} meet "
            f"it ({searched:.1f} s); the FEM confirms {confirmed} of the top {len(verified)}"
        )
        for rank, c in enumerate(verified, start=1):
            print(
                f"  {rank}. {c.design}  p {c.pressure_mpa:.4g} MPa  surrogate "
                f"{c.angle_deg:.2f}°  FEM {c.fem_angle_deg:.2f}°  miss {c.fem_error_deg:.2f}°"
            )

    record("design_search", figures, units=units, notes=f"{os.cpu_count()} CPUs")


if __name__ == "__main__":
    main()
