"""FEM robustness and speed: the 64 corner designs of paper B Table 1.

Every corner design (each parameter at its minimum or maximum) is swept from
0 MPa in 0.005 MPa outputs up to 0.5 MPa, a bending angle of 300° or a
documented stop, on one thread. Prints, per design and in summary: where the sweep
stopped and why, wall time, Newton iterations per step, and the shares of time
in assembly (Hessian and residual) and factorisation. With ``--check-interpolation
N`` it also re-runs N designs spread over the corners solving every 0.005 MPa
output and reports the largest difference of the interpolated angles.

The energy terms are compiled to machine code once for the run (NGSolve's
``realcompile``, in the background while the first sweep runs; ``--no-compile``
for the interpreted terms).

Results are appended to a JSON-lines file as each design finishes, so an
interrupted run resumes where it stopped::

    python benchmarks/bench_fem.py --out results/bench_fem.jsonl
    python benchmarks/bench_fem.py --out results/bench_fem.jsonl --summary   # table only

On a 2-core machine two shards run side by side, one design per core (each
sweep is single-threaded; sharing memory bandwidth makes the times slightly
pessimistic)::

    python benchmarks/bench_fem.py --shard 0/2 & python benchmarks/bench_fem.py --shard 1/2
"""

from __future__ import annotations

import argparse
import json
import os
import statistics
import sys
import time
from pathlib import Path

import numpy as np
from _record import record

from softbend.campaign.backends import default_pressures_mpa
from softbend.design import DesignSpace
from softbend.fem import FEMOptions, simulate, use_compiled


def _row(result, seconds: float) -> dict:
    s = result.stats
    t = s["timings"]
    busy = t["assembly_s"] + t["residual_s"] + t["factorization_s"] + t["solve_s"]
    steps = s["step_iterations"][1:]  # pressure steps (the first is gravity)
    return {
        "design": str(result.design),
        "stop_reason": s["stop_reason"],
        "max_pressure_mpa": result.max_pressure_mpa,
        "max_angle_deg": result.max_angle_deg,
        "outputs": int(result.n_converged),
        "wall_s": seconds,
        "steps": len(steps),
        "rejected_steps": s["rejected_steps"],
        "iterations_total": int(t["iterations"]),
        "chord_steps": int(t.get("chord_steps", 0)),
        "iterations_per_step": float(np.mean(steps)) if steps else 0.0,
        "gravity_iterations": s["step_iterations"][0],
        "assembly_share": (t["assembly_s"] + t["residual_s"]) / seconds,
        "factorization_share": t["factorization_s"] / seconds,
        "solver_share": busy / seconds,
        "elements": result.mesh_size,
        "ndof": s["ndof"],
        "angle_at_0": float(result.angle_deg[0]),
        "angles_deg": [round(float(a), 6) for a in result.angle_deg[: result.n_converged]],
    }


def _is_physical_stop(row: dict) -> bool:
    return row["stop_reason"].startswith(("reached", "bending angle", "stretch", "inflation"))


def summarize(rows: list[dict]) -> None:
    walls = [r["wall_s"] for r in rows]
    print(f"\n{len(rows)} designs")
    print(
        f"{'design':<24} {'stop':<28} {'p max':>6} {'angle':>7} {'wall s':>7} "
        f"{'steps':>5} {'rej':>4} {'it/step':>7} {'asm %':>6} {'fact %':>6}"
    )
    for r in rows:
        print(
            f"{r['design']:<24} {r['stop_reason'][:28]:<28} {r['max_pressure_mpa']:6.3f} "
            f"{r['max_angle_deg']:7.1f} {r['wall_s']:7.1f} {r['steps']:5d} "
            f"{r['rejected_steps']:4d} {r['iterations_per_step']:7.2f} "
            f"{100 * r['assembly_share']:6.1f} {100 * r['factorization_share']:6.1f}"
        )
    stalled = [r for r in rows if not _is_physical_stop(r)]
    print(
        f"\nwall time per sweep: median {statistics.median(walls):.1f} s, "
        f"worst {max(walls):.1f} s, mean {statistics.fmean(walls):.1f} s"
    )
    print(
        "Newton iterations per pressure step: median "
        f"{statistics.median(r['iterations_per_step'] for r in rows):.2f}, "
        f"worst design {max(r['iterations_per_step'] for r in rows):.2f}"
    )
    print(
        f"time in assembly (Hessian + residual): median "
        f"{100 * statistics.median(r['assembly_share'] for r in rows):.1f} %; "
        f"in factorisation: median "
        f"{100 * statistics.median(r['factorization_share'] for r in rows):.1f} %"
    )
    print(f"stopped by the physical criteria: {len(rows) - len(stalled)} of {len(rows)}")
    for r in stalled:
        print(f"  NOT reached: {r['design']}: {r['stop_reason']}")


def compare(rows: list[dict], reference: Path) -> None:
    """Largest change of the angle at any common output against an earlier run's file."""
    before = {}
    for line in reference.read_text().splitlines():
        if line.strip():
            row = json.loads(line)
            before[row["design"]] = row
    worst_abs, worst_rel, lost, where = 0.0, 0.0, 0, ""
    pairs = [(r, before[r["design"]]) for r in rows if r["design"] in before]
    if any("angles_deg" not in old for _, old in pairs):
        raise SystemExit(
            f"{reference} has no 'angles_deg' (written by an older bench_fem.py): copy them in "
            "from a run of the same code, e.g. benchmarks/reference/bench_fem_f814805.jsonl."
        )
    for now, old in pairs:
        a, b = np.array(now["angles_deg"]), np.array(old["angles_deg"])
        n = min(len(a), len(b))
        lost += abs(len(a) - len(b))
        diff = np.abs(a[:n] - b[:n])
        rel = diff / np.maximum(np.abs(b[:n]), 1e-9)
        # An output passes if it is within 0.2° or within 0.2 %: the larger of the two.
        k = int(np.argmax(np.minimum(diff / 0.2, rel / 0.002)))
        if diff[k] > worst_abs:
            worst_abs, worst_rel, where = float(diff[k]), float(rel[k]), now["design"]
    t_now = [r["wall_s"] for r, _ in pairs]
    t_old = [o["wall_s"] for _, o in pairs]
    print(f"\nagainst {reference} ({len(pairs)} designs in both):")
    print(
        f"  wall per sweep: median {statistics.median(t_old):.1f} -> "
        f"{statistics.median(t_now):.1f} s, worst {max(t_old):.1f} -> {max(t_now):.1f} s"
    )
    its_now = sum(r["iterations_total"] for r, _ in pairs)
    its_old = sum(o["iterations_total"] for _, o in pairs)
    print(f"  Newton iterations, all designs: {its_old} -> {its_now}")
    print(
        f"  largest angle change at a common output: {worst_abs:.4f} deg "
        f"({100 * worst_rel:.4f} %) in {where}; outputs gained or lost: {lost}"
    )


def check_interpolation(designs, options: FEMOptions, pressures: np.ndarray) -> None:
    print("\ninterpolated outputs against a Newton solve at every output pressure:")
    for design in designs:
        fast = simulate(design, pressures, options)
        full = simulate(design, pressures, options.replace(output="solve"))
        n = min(fast.n_converged, full.n_converged)
        diff = np.abs(fast.angle_deg[:n] - full.angle_deg[:n])
        print(
            f"  {design}: max |Δθ| {diff.max():.4f}° over {n} outputs "
            f"(max θ {full.angle_deg[:n].max():.1f}°); wall {fast.wall_time_s:.1f} s "
            f"interpolated vs {full.wall_time_s:.1f} s every point"
        )


def main(argv: list[str] | None = None) -> int:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--out", type=Path, default=Path("results/bench_fem.jsonl"))
    parser.add_argument("--limit", type=int, default=None, help="Only the first N corners.")
    parser.add_argument("--maxh", type=float, default=FEMOptions().maxh_mm)
    parser.add_argument("--summary", action="store_true", help="Only print the stored table.")
    parser.add_argument("--check-interpolation", type=int, default=0, metavar="N")
    parser.add_argument(
        "--compare",
        type=Path,
        default=None,
        metavar="FILE",
        help="An earlier run's JSON lines: print the time ratio and the largest angle change.",
    )
    parser.add_argument(
        "--shard", default="0/1", metavar="K/N", help="Only designs i with i %% N == K."
    )
    parser.add_argument(
        "--no-compile",
        action="store_true",
        help="Interpreted energy terms (default: compiled once for the whole run, "
        "softbend.fem.use_compiled; the first sweep pays the compilation).",
    )
    args = parser.parse_args(argv)
    use_compiled(not args.no_compile)

    os.environ.setdefault("OMP_NUM_THREADS", "1")
    options = FEMOptions(maxh_mm=args.maxh, threads=1)
    pressures = default_pressures_mpa()
    designs = list(DesignSpace.corners())[: args.limit]
    shard, shards = (int(v) for v in args.shard.split("/"))
    args.out.parent.mkdir(parents=True, exist_ok=True)
    done = {}
    if args.out.exists():
        for line in args.out.read_text().splitlines():
            if line.strip():
                row = json.loads(line)
                done[row["design"]] = row
    if not args.summary:
        for i, design in enumerate(designs):
            if str(design) in done or i % shards != shard:
                continue
            start = time.perf_counter()
            result = simulate(design, pressures, options)
            row = _row(result, time.perf_counter() - start)
            with args.out.open("a") as handle:  # one short line per write: shards may share
                handle.write(json.dumps(row) + "\n")
            done[row["design"]] = row
            print(
                f"[{i + 1}/{len(designs)}] {design}: {row['stop_reason']} at "
                f"{row['max_pressure_mpa']:.3f} MPa, {row['max_angle_deg']:.1f}°, "
                f"{row['wall_s']:.1f} s",
                flush=True,
            )
    rows = [done[str(d)] for d in designs if str(d) in done]
    if rows:
        summarize(rows)
    if rows and len(rows) == len(designs):  # a shard records once the file holds every design
        walls = [r["wall_s"] for r in rows]
        physical = sum(_is_physical_stop(r) for r in rows)
        record(
            "fem",
            {
                "designs": len(rows),
                "wall time per sweep, median": round(statistics.median(walls), 1),
                "wall time per sweep, worst": round(max(walls), 1),
                "Newton iterations per step, median": round(
                    statistics.median(r["iterations_per_step"] for r in rows), 2
                ),
                "stopped by the physical criteria": f"{physical} of {len(rows)}",
            },
            units={"wall time per sweep, median": "s", "wall time per sweep, worst": "s"},
            notes=f"one thread per sweep, maxh {args.maxh} mm; results in {args.out}",
        )
    if rows and args.compare is not None:
        compare(rows, args.compare)
    if args.check_interpolation:
        picks = np.linspace(0, len(designs) - 1, args.check_interpolation).round().astype(int)
        check_interpolation([designs[i] for i in picks], options, pressures)
    return 0


if __name__ == "__main__":
    sys.exit(main())
