"""Benchmark: closed-loop control on the simulated rig (paper B §5, Fig. 9).

For each controller, on the (100,6,2,2,5,8) actuator with the shipped FEM-trained
MLP as θ(p) (plant table and, for bang-bang, the virtual sensor), prints the
metrics of a ``step:90``, a ``square:90:4`` and a 0.2 Hz triangle
(``triangle:0.2:90:20``) run of 10 s, the real-time factor (simulated s per
wall s, one core) and the latency of one controller decision (p50/p99 in µs,
over calls at fresh samples: the costly ones). ``--plant lab`` makes the
actuator the virtual lab's measured one (model mismatch); ``--model`` gives the
controllers another surrogate (e.g. one refined on the lab's readings).
Paper B, bang-bang (§5, Fig. 9; :data:`softbend.references.CONTROL_RESULTS`): squares MAPE
5.5 %, convergence 0.7 s, rise 0.104 s; triangle MAPE 5.3 %, delay 0.0875 s. Run::

    .venv/bin/python benchmarks/bench_control.py [--duration 10] [--plant lab] [--model M] [--json]
"""

from __future__ import annotations

import argparse
import json
import time

import numpy as np
from _record import record, variant_name

from softbend.control import CONTROLLERS
from softbend.control.controllers import mlp_virtual_sensor
from softbend.control.experiments import run_metrics, simulate
from softbend.control.factory import make_controller
from softbend.control.plants import PLANTS, plant_table
from softbend.control.rig import AngleTable, RigParams, SimulatedRig
from softbend.design import sfrba_design
from softbend.transfer.base import load_base

REFERENCES = ("step:90", "square:90:4", "triangle:0.2:90:20")


def _latency_us(controller, samples: int = 5000) -> tuple[float, float]:
    rng = np.random.default_rng(0)
    readings = rng.uniform(0.0, 0.2, samples).tolist()
    controller.reset()
    times = []
    for i, p in enumerate(readings):
        t = i * 0.01  # every call a new sample
        start = time.perf_counter_ns()
        controller.step(p, 90.0, t)
        times.append(time.perf_counter_ns() - start)
    us = np.array(times) / 1000.0
    return float(np.percentile(us, 50)), float(np.percentile(us, 99))


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--duration", type=float, default=10.0)
    parser.add_argument("--json", action="store_true")
    parser.add_argument(
        "--plant",
        choices=PLANTS,
        default="surrogate",
        help="θ(p) of the actuator: the controllers' model, the FEM sweep, or the lab readings",
    )
    parser.add_argument("--model", default=None, help="the controllers' surrogate (JSON)")
    args = parser.parse_args()
    design = sfrba_design(100, 6, 2, 2, 5, 8)
    model = load_base(args.model)
    table = AngleTable.from_surrogate(model, design)
    sensor = mlp_virtual_sensor(model, design)
    params = RigParams.for_design(design)
    controllers = {
        name: (lambda name=name: make_controller(name, table, sensor, params))
        for name in CONTROLLERS
    }
    plant = plant_table(args.plant, design, table)
    rig = SimulatedRig(plant, params, seed=0)
    results = []
    for name, make in controllers.items():
        p50, p99 = _latency_us(make())
        for spec in REFERENCES:
            m = run_metrics(simulate(rig, make(), spec, args.duration, seed=0))
            results.append(
                {"controller": name, "reference": spec, **m, "step_p50_us": p50, "step_p99_us": p99}
            )
    figures: dict = {}
    units: dict = {}
    for r in results:
        key = f"{r['controller']}, {r['reference']}"
        figures[f"{key}: MAPE"], units[f"{key}: MAPE"] = round(r["mape_pct"], 2), "%"
        figures[f"{key}: real-time factor"] = round(r["realtime_factor"], 1)
        figures[f"{r['controller']}: decision p99"] = round(r["step_p99_us"], 1)
        units[f"{r['controller']}: decision p99"] = "µs"
    record(
        variant_name("control", None if args.plant == "surrogate" else args.plant),
        figures,
        units=units,
        notes=f"{args.duration:g} s runs on (100,6,2,2,5,8), plant {args.plant}, "
        f"model {args.model or 'shipped FEM-trained MLP'}",
    )
    if args.json:
        print(json.dumps(results, indent=2))
        return
    head = (
        "controller",
        "reference",
        "MAPE%",
        "rise s",
        "settle s",
        "delay s",
        "switches",
        "air mg",
        "RTF",
        "p50 µs",
        "p99 µs",
    )
    print(("{:<17}{:<20}" + "{:>9}" * 9).format(*head))
    for r in results:
        print(
            ("{:<17}{:<20}" + "{:>9.3g}" * 9).format(
                r["controller"],
                r["reference"],
                r["mape_pct"],
                r.get("rise_s", float("nan")),
                r.get("settling_s", float("nan")),
                r.get("delay_s", float("nan")),
                float(r["switches"]),
                r["air_used_kg"] * 1e6,
                r["realtime_factor"],
                r["step_p50_us"],
                r["step_p99_us"],
            )
        )


if __name__ == "__main__":
    main()
