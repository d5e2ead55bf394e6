"""Benchmark: choosing the base for transfer on a small table (every base × strategy).

A lab with its own simulator usually has tens of designs. This script cuts the shipped
PneuNet example (``examples/pneunet``) to its first ``--designs`` design_ids (30: the
stand-in for a small table), trains the default families on it with ``softbend train``
(under 100 designs plr, xgb, mlp and table; the default grid, ``small``), then scores every
family's model as a base with ``softbend transfer loco --base plr.json,xgb.json,...``
on the example's measurements (no learning curve), with every default strategy that applies
to each base but the two ``softbend train --measurements`` leaves out as well
(:data:`softbend.transfer.base_choice.CHEAP_EXCLUDED`: ``experimental`` learns from the
measurements alone, the same for every base, with 15000 epochs; ``refined-ensemble`` is
``refined`` five times over; ``analytical`` models paper B's actuator only). It prints
each base × strategy's mean leave-one-actuator-out RMSE, the pair named, the family grouped
cross-validation selected, and the wall time of each step::

    PYTHONPATH=src .venv/bin/python benchmarks/bench_base_choice.py
"""

from __future__ import annotations

import argparse
import json
import tempfile
import time
from pathlib import Path

import pandas as pd
from _record import record

from softbend.cli import main as softbend
from softbend.transfer.base_choice import CHEAP_EXCLUDED
from softbend.transfer.loco import DEFAULT_STRATEGIES

EXAMPLE = Path(__file__).resolve().parents[1] / "examples" / "pneunet"


def _cut(designs: int, folder: Path) -> Path:
    """The example's simulation table cut to its first ``designs`` design_ids."""
    table = pd.read_csv(EXAMPLE / "simulations.csv")
    keep = list(dict.fromkeys(table["design_id"]))[:designs]
    path = folder / f"simulations_{designs}.csv"
    table[table["design_id"].isin(keep)].to_csv(path, index=False)
    return path


def _run(*args: object) -> float:
    """Run one softbend command; its wall time in seconds."""
    start = time.perf_counter()
    code = softbend([str(a) for a in args])
    if code != 0:
        raise SystemExit(f"softbend {' '.join(map(str, args[:2]))} exited {code}")
    return time.perf_counter() - start


def main(argv: list[str] | None = None) -> int:
    parser = argparse.ArgumentParser(description=__doc__.split("\n")[0])
    parser.add_argument("--designs", type=int, default=30, help="First design_ids kept.")
    parser.add_argument(
        "--families", default=None, help="Families trained (default: train's own default)."
    )
    parser.add_argument("--seed", type=int, default=0)
    parser.add_argument(
        "--strategies",
        default=",".join(n for n in DEFAULT_STRATEGIES if n not in (*CHEAP_EXCLUDED, "analytical")),
        help="Strategies scored (each base runs those that apply to it).",
    )
    args = parser.parse_args(argv)

    with tempfile.TemporaryDirectory() as tmp:
        folder = Path(tmp)
        table = _cut(args.designs, folder)
        trained = folder / "train"
        families = () if args.families is None else ("--models", args.families)
        train_s = _run("train", table, "--actuator", EXAMPLE / "actuator.json", *families,
                       "--device", "cpu", "--no-onnx", "--seed", args.seed,
                       "-o", trained)  # fmt: skip
        names = list(pd.read_csv(trained / "summary.csv")["model"])  # every family trained
        bases = ",".join(str(trained / "models" / f"{n}.json") for n in names)
        out = folder / "loco"
        loco_s = _run("transfer", "loco", EXAMPLE / "measurements.csv", "--base", bases,
                      "--strategies", args.strategies, "--no-learning-curve", "--seed", args.seed,
                      "-o", out)  # fmt: skip
        summary = pd.read_csv(trained / "summary.csv")
        choice = json.loads((out / "loco.json").read_text(encoding="utf-8"))
    by_cv = str(summary.loc[summary["rmse_deg"].idxmin(), "model"])
    table_rows = pd.DataFrame(choice["table"])
    print()
    print(f"{args.designs} designs; grouped-CV RMSE per family (°):")
    for _, r in summary.iterrows():
        print(f"  {r['model']:>4}  {r['rmse_deg']:.2f}")
    print("mean leave-one-actuator-out RMSE per base x strategy (°):")
    figures: dict[str, object] = {}
    units: dict[str, str] = {}
    for _, r in table_rows.iterrows():
        value = r["rmse_deg"]
        rank = "-" if r["rank"] != r["rank"] else str(int(r["rank"]))  # NaN: no candidate
        print(f"  {r['base']:>4} x {r['strategy']:<20} {value:.2f}   rank {rank}")
        key = f"{r['base']} x {r['strategy']}: mean LOCO RMSE"
        figures[key], units[key] = round(float(value), 3), "°"
    best = choice["best"]
    print(f"chosen pair: base {best['base']} with {best['strategy']}, {best['rmse_deg']:.2f}°")
    print(f"family grouped CV selects: {by_cv}")
    print(f"wall time: train {train_s:.0f} s, transfer loco with every base {loco_s:.0f} s")
    for _, r in summary.iterrows():
        key = f"{r['model']}: grouped-CV RMSE"
        figures[key], units[key] = round(float(r["rmse_deg"]), 3), "°"
    figures["chosen pair"] = f"{best['base']} x {best['strategy']}"
    figures["chosen pair: mean LOCO RMSE"] = round(float(best["rmse_deg"]), 3)
    figures["family selected by grouped CV"] = by_cv
    figures["train wall time"] = round(train_s, 1)
    figures["transfer loco (every base) wall time"] = round(loco_s, 1)
    units.update(
        {
            "chosen pair: mean LOCO RMSE": "°",
            "train wall time": "s",
            "transfer loco (every base) wall time": "s",
        }
    )
    record(
        "base_choice",
        figures,
        units=units,
        notes=f"examples/pneunet cut to its first {args.designs} designs; families "
        f"{','.join(names)} (default grid); loco on its 6 measured actuators, strategies "
        f"{args.strategies} (those that apply to each base), no learning curve",
    )
    return 0


if __name__ == "__main__":
    raise SystemExit(main())
