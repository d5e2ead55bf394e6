"""FEM of the PneuNet: sweep time of the reference on one core, and its mesh convergence.

Sweeps the reference PneuNet without contact (``softbend fem run --family pneunet
--contact off``: 0 to 0.05 MPa in 1 kPa outputs, stopping where neighbouring chamber
walls touch)
``--runs`` times on one thread at the family's default mesh and reports the
median wall time. Then the mesh study for element sizes from the default to
finer: every output pressure up to the default mesh's last solved on every mesh,
the angles compared at the largest pressure every mesh reaches before its walls
touch, and the change of that angle between the default and the finest mesh (the
acceptance: at most 1°). Newton's iterations are logged step by step::

    python benchmarks/bench_fem_pneunet.py --runs 3

With ``--contact`` the same with the chamber walls in contact (``fem run
--family pneunet``'s default, to 50 kPa or 180°): the reference swept once
without contact (to the touch, the baseline measured in the same process) and
``--runs`` times with it, the wall and CPU time of each and the ratio of the
CPU times (the machine may be shared: CPU time is the budget's measure), the
steps and Newton iterations, the pressure
and angle reached; then the mesh study with contact at every ``--study-step``
up to ``--study-pmax`` (past the touch, where the walls press on each other),
the change of the angle between the two finest meshes at the largest pressure
both reach (the acceptance: at most 2°)::

    python benchmarks/bench_fem_pneunet.py --contact --runs 1 --study-pmax 0.05
"""

from __future__ import annotations

import argparse
import logging
import statistics
import sys
import time

import numpy as np
from _record import record

import softbend._torch  # noqa: F401  (PyTorch before NGSolve)
from softbend.fem.families import get_family
from softbend.fem.verification import mesh_study
from softbend.models import default_pressures_mpa


def main(argv: list[str] | None = None) -> int:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--runs", type=int, default=3, help="Sweeps timed.")
    parser.add_argument(
        "--sizes", default="3,2.5,2", help="Mesh study sizes, mm, the default first, then finer."
    )
    parser.add_argument("--no-record", action="store_true", help="Print only.")
    parser.add_argument("--contact", action="store_true", help="The sweeps with contact.")
    parser.add_argument(
        "--study-pmax", type=float, default=0.012, help="With --contact: mesh study to, MPa."
    )
    parser.add_argument(
        "--study-step", type=float, default=0.001, help="With --contact: mesh study step, MPa."
    )
    args = parser.parse_args(argv)
    # Newton's convergence, step by step (the sweep's debug log).
    logging.basicConfig(level=logging.WARNING, format="%(name)s: %(message)s")
    logging.getLogger("softbend.fem.sweep").setLevel(logging.DEBUG)
    if args.contact:
        return contact_main(args)
    family = get_family("pneunet")
    design = family.parse("")
    options = family.options(threads=1, **family.contact_options("off"))
    grid = default_pressures_mpa(family.pmax_mpa, family.pstep_mpa)
    walls, result = [], None
    for run in range(args.runs):
        start = time.perf_counter()
        result = family.simulate(design, grid, options)
        walls.append(time.perf_counter() - start)
        stats = result.stats
        print(
            f"run {run + 1}: {walls[-1]:.1f} s, {stats['stop_reason']}, "
            f"{result.max_angle_deg:.2f}° at {result.max_pressure_mpa * 1000:.1f} kPa; "
            f"Newton iterations per step {stats['step_iterations']}, "
            f"rejected steps {stats['rejected_steps']}, {stats['ndof']} dofs",
            flush=True,
        )
    assert result is not None
    volumes = result.stats["step_volume_mm3"]
    steps, angles_at_steps = result.stats["steps_mpa"], result.stats["step_angles_deg"]
    print("steps (kPa, angle °, cavity volume mm³):")
    for p, a, v in zip(steps, angles_at_steps, volumes, strict=True):
        print(f"  {p * 1000:7.2f} {a:8.3f} {v:9.1f}")

    sizes = [float(s) for s in args.sizes.split(",")]
    coarse = family.simulate(design, grid, options.replace(maxh_mm=sizes[0]))
    # Every output pressure up to the coarse mesh's last, each solved on every mesh;
    # the comparison is at the largest pressure every mesh reached (its walls touch
    # a little earlier on a finer mesh).
    pressures = [float(p) for p in grid[grid <= coarse.max_pressure_mpa + 1e-12]]
    rows = mesh_study(design, sizes, pressures, options)
    for row in rows:
        print(
            f"maxh {row.maxh_mm:g} mm: {row.elements} elements, {row.ndof} dofs, "
            f"{row.wall_time_s:.1f} s, {row.stop_reason}; angles "
            + ", ".join(f"{a:.3f}" for a in row.angles_deg)
        )
    reached = [i for i in range(len(pressures)) if all(np.isfinite(r.angles_deg[i]) for r in rows)]
    k = reached[-1]
    pressures = pressures[: k + 1]
    print(f"compared at {pressures[-1] * 1000:.1f} kPa")
    angles = [row.angles_deg[k] for row in rows]
    default = sizes.index(family.maxh_mm) if family.maxh_mm in sizes else 1
    change = abs(angles[-1] - angles[default])
    print(f"median sweep {statistics.median(walls):.1f} s; mesh change {change:.3f}°")
    if not args.no_record:
        record(
            "fem_pneunet",
            {
                "sweeps": len(walls),
                "wall time per sweep, median": round(statistics.median(walls), 1),
                "largest output pressure": round(result.max_pressure_mpa * 1000, 2),
                "angle there": round(result.max_angle_deg, 2),
                "mesh study pressure": round(pressures[-1] * 1000, 2),
                **{
                    f"angle at maxh {h:g} mm": round(a, 3)
                    for h, a in zip(sizes, angles, strict=True)
                },
                "angle change, default to finest mesh": round(change, 3),
            },
            units={
                "wall time per sweep, median": "s",
                "largest output pressure": "kPa",
                "angle there": "deg",
                "mesh study pressure": "kPa",
                **{f"angle at maxh {h:g} mm": "deg" for h in sizes},
                "angle change, default to finest mesh": "deg",
            },
            notes=(
                f"reference PneuNet ({design}), one thread, maxh {family.maxh_mm:g} mm; "
                f"stop: {result.stats['stop_reason']}"
            ),
        )
    return 0


def contact_main(args: argparse.Namespace) -> int:
    """The reference with contact: sweep time against the contact-free sweep, mesh study."""
    family = get_family("pneunet")
    design = family.parse("")
    off = family.options(threads=1, **family.contact_options("off"))
    on = family.options(threads=1)  # the family's defaults: what `fem run` sweeps
    grid = default_pressures_mpa(family.pmax_mpa, family.pstep_mpa)
    start, cpu_start = time.perf_counter(), time.process_time()
    baseline = family.simulate(design, grid, off)
    baseline_s = time.perf_counter() - start
    baseline_cpu_s = time.process_time() - cpu_start
    print(
        f"without contact: {baseline_s:.1f} s ({baseline_cpu_s:.1f} CPU s), "
        f"{baseline.stats['stop_reason']}",
        flush=True,
    )
    walls, cpus, result = [], [], None
    for run in range(args.runs):
        start, cpu_start = time.perf_counter(), time.process_time()
        result = family.simulate(design, grid, on)
        walls.append(time.perf_counter() - start)
        cpus.append(time.process_time() - cpu_start)
        stats = result.stats
        print(
            f"run {run + 1}: {walls[-1]:.1f} s, {cpus[-1]:.1f} CPU s "
            f"({cpus[-1] / baseline_cpu_s:.1f} times without), "
            f"{stats['stop_reason']}, {result.max_angle_deg:.2f}° at "
            f"{result.max_pressure_mpa * 1000:.1f} kPa; {len(stats['steps_mpa'])} steps, "
            f"{sum(stats['step_iterations'])} Newton iterations, "
            f"rejected steps {stats['rejected_steps']}",
            flush=True,
        )
    assert result is not None
    stats = result.stats
    print("steps (kPa, angle °, cavity volume mm³, contact force N, contact pressure kPa):")
    for row in zip(
        stats["steps_mpa"],
        stats["step_angles_deg"],
        stats["step_volume_mm3"],
        stats["step_contact_force_n"],
        stats["step_contact_pressure_kpa"],
        strict=True,
    ):
        p, a, v, f, c = row
        print(f"  {p * 1000:7.2f} {a:8.3f} {v:9.1f} {f:8.4f} {c:8.2f}")

    sizes = [float(s) for s in args.sizes.split(",")]
    pressures = [float(p) for p in default_pressures_mpa(args.study_pmax, args.study_step)]
    rows = mesh_study(design, sizes, pressures, on)
    for row in rows:
        print(
            f"maxh {row.maxh_mm:g} mm: {row.elements} elements, {row.ndof} dofs, "
            f"{row.wall_time_s:.1f} s, {row.stop_reason}; angles "
            + ", ".join(f"{a:.3f}" for a in row.angles_deg)
        )
    # The two finest meshes compared at the largest pressure both reach.
    reached = [
        i for i in range(len(pressures)) if all(np.isfinite(r.angles_deg[i]) for r in rows[-2:])
    ]
    k = reached[-1]
    angles = [row.angles_deg[k] for row in rows]
    change = abs(angles[-1] - angles[-2])
    median, median_cpu = statistics.median(walls), statistics.median(cpus)
    print(
        f"compared at {pressures[k] * 1000:.1f} kPa: change between the two finest meshes "
        f"{change:.3f}°; median sweep {median:.1f} s, {median_cpu:.1f} CPU s "
        f"({median_cpu / baseline_cpu_s:.1f} times the {baseline_cpu_s:.1f} CPU s without contact)"
    )
    if not args.no_record:
        record(
            "fem_pneunet_contact",
            {
                "sweeps": len(walls),
                "wall time per sweep, median": round(median, 1),
                "wall time without contact (to the touch)": round(baseline_s, 1),
                "CPU time per sweep, median": round(median_cpu, 1),
                "CPU time without contact (to the touch)": round(baseline_cpu_s, 1),
                "ratio": round(median_cpu / baseline_cpu_s, 2),
                "steps": len(stats["steps_mpa"]),
                "Newton iterations": sum(stats["step_iterations"]),
                "largest output pressure": round(result.max_pressure_mpa * 1000, 2),
                "angle there": round(result.max_angle_deg, 2),
                "largest contact force": round(max(stats["step_contact_force_n"]), 4),
                "mesh study pressure": round(pressures[k] * 1000, 2),
                **{
                    f"angle at maxh {h:g} mm": round(a, 3)
                    for h, a in zip(sizes, angles, strict=True)
                },
                "angle change, two finest meshes": round(change, 3),
            },
            units={
                "wall time per sweep, median": "s",
                "wall time without contact (to the touch)": "s",
                "CPU time per sweep, median": "s",
                "CPU time without contact (to the touch)": "s",
                "largest output pressure": "kPa",
                "angle there": "deg",
                "largest contact force": "N",
                "mesh study pressure": "kPa",
                **{f"angle at maxh {h:g} mm": "deg" for h in sizes},
                "angle change, two finest meshes": "deg",
            },
            notes=(
                f"reference PneuNet ({design}) with contact (penalty "
                f"{on.contact_penalty_mpa_per_mm:g} MPa/mm), one thread, maxh "
                f"{family.maxh_mm:g} mm; stop: {stats['stop_reason']}"
            ),
        )
    return 0


if __name__ == "__main__":
    sys.exit(main())
