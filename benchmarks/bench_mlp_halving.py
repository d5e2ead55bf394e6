"""Benchmark: successive halving against the exhaustive MLP grid search.

Both run the same design-grouped five-fold search of
:func:`softbend.surrogates.search.search` over a subset of paper B's grid (two
tanh layers of 55–65 units), on the shipped FEM dataset
(:func:`softbend.datasets.table1_fem`) or a campaign database (``--db``):

* exhaustive: every configuration trains all the epochs;
* successive halving (``--eta``, default 3): every configuration trains a
  fraction of the epochs, the best third goes on, … until the survivors train
  all of them (:func:`softbend.surrogates.search.halving_rungs`).

Printed: wall time of each, the configuration each picks and its cross-validated
RMSE and MAPE, the rank of the halving's pick among all configurations of the
exhaustive search, and the projected wall time of the whole paper grid (121
configurations × 1000 epochs) both ways from the measured cost per model-epoch::

    .venv/bin/python benchmarks/bench_mlp_halving.py --configs 12 --epochs 100
    .venv/bin/python benchmarks/bench_mlp_halving.py --configs 12 --epochs 100 \\
        --rungs 3 --paper-rungs 5    # one rung more than the default rule, both ways
"""

from __future__ import annotations

import argparse
import json
import time

from _record import record

from softbend.references import SURROGATE_TRAINING
from softbend.surrogates.features import training_data
from softbend.surrogates.search import grid, halving_rungs, search

# Paper B §4.1: 11 x 11 hidden-layer sizes (55-65 each), 1000 epochs.
_UNITS_LOW, _UNITS_HIGH = SURROGATE_TRAINING["mlp_hidden_units"].value
PAPER_CONFIGS = (_UNITS_HIGH - _UNITS_LOW + 1) ** 2
PAPER_EPOCHS: int = SURROGATE_TRAINING["mlp_epochs"].value


def _model_epochs(n_configs: int, epochs: int, eta: int | None, rungs: int | None = None) -> int:
    if eta is None:
        return n_configs * epochs
    return sum(n * e for n, e in halving_rungs(n_configs, epochs, eta, rungs))


def main(argv: list[str] | None = None) -> int:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--db", default=None, help="Campaign database (default: shipped FEM data).")
    parser.add_argument("--configs", type=int, default=12, help="Configurations of the subset.")
    parser.add_argument("--epochs", type=int, default=100)
    parser.add_argument("--eta", type=int, default=3)
    parser.add_argument(
        "--rungs", type=int, default=None, help="Rungs of the halving (default: its own rule)."
    )
    parser.add_argument(
        "--paper-rungs",
        type=int,
        default=None,
        help="Rungs assumed for the paper-grid projection (default: the halving's own rule).",
    )
    parser.add_argument("--seed", type=int, default=0)
    parser.add_argument("--json", action="store_true")
    args = parser.parse_args(argv)

    if args.db is None:
        from softbend.datasets import table1_fem

        samples = table1_fem()
    else:
        from softbend.campaign import load_samples

        samples = load_samples(args.db)
    data = training_data(samples)
    paper = grid("paper", "mlp")
    step = max(1, len(paper) // args.configs)
    subset = paper[::step][: args.configs]
    common = {
        "models": ["mlp"],
        "param_grid": {"mlp": subset},
        "epochs": args.epochs,
        "seed": args.seed,
        "device": "cpu",
    }
    runs = {}
    for label, eta in (("exhaustive", None), (f"halving eta={args.eta}", args.eta)):
        start = time.perf_counter()
        result = search(data, halving=eta, halving_rungs=args.rungs if eta else None, **common)
        seconds = time.perf_counter() - start
        fam = result.families["mlp"]
        runs[label] = {
            "seconds": seconds,
            "model_epochs": _model_epochs(len(subset), args.epochs, eta, args.rungs),
            "pick": str(fam.params["hidden_sizes"]),
            "rmse_deg": fam.cv["rmse_deg"],
            "mape_pct": fam.cv["mape_pct"],
            "cv": result.cv_results,
        }
    exhaustive = runs["exhaustive"]["cv"].sort_values("rmse_fold_mean").reset_index(drop=True)
    pick = runs[f"halving eta={args.eta}"]["pick"]
    rank = 1 + int(exhaustive.index[exhaustive["params"] == f"hidden_sizes={pick}"][0])
    per_model_epoch = runs["exhaustive"]["seconds"] / runs["exhaustive"]["model_epochs"]
    projection = {
        label: per_model_epoch
        * _model_epochs(PAPER_CONFIGS, PAPER_EPOCHS, eta, args.paper_rungs)
        / 3600.0
        for label, eta in (("exhaustive", None), ("halving", args.eta))
    }
    out = {
        "samples": data.n_samples,
        "designs": data.n_groups,
        "configs": len(subset),
        "epochs": args.epochs,
        "folds": 5,
        **{label: {k: v for k, v in run.items() if k != "cv"} for label, run in runs.items()},
        "halving_pick_rank_in_exhaustive": rank,
        "paper_grid_projected_hours": projection,
    }
    figures: dict = {}
    units: dict = {}
    for label, run in runs.items():
        for key, value, unit in (
            ("wall time", round(run["seconds"], 1), "s"),
            ("pick", run["pick"], ""),
            ("CV RMSE", round(run["rmse_deg"], 3), "°"),
            ("CV MAPE", round(run["mape_pct"], 3), "%"),
        ):
            figures[f"{label}: {key}"], units[f"{label}: {key}"] = value, unit
    figures["halving's pick: rank in the exhaustive search"] = f"{rank} of {len(subset)}"
    for label, hours in projection.items():
        figures[f"paper grid projected: {label}"] = round(hours, 2)
        units[f"paper grid projected: {label}"] = "h"
    record(
        "mlp_halving",
        figures,
        units=units,
        notes=f"{len(subset)} configurations, {args.epochs} epochs, 5 grouped folds, "
        f"{data.n_samples} samples of {data.n_groups} designs",
    )
    if args.json:
        print(json.dumps(out, indent=2))
        return 0
    print(
        f"{data.n_samples} samples of {data.n_groups} designs; {len(subset)} configurations, "
        f"{args.epochs} epochs, 5 grouped folds"
    )
    for label, run in runs.items():
        print(
            f"  {label:<16} {run['seconds']:8.1f} s  {run['model_epochs']:6d} config-epochs  "
            f"pick {run['pick']}: RMSE {run['rmse_deg']:.3f} deg, MAPE {run['mape_pct']:.3f} %"
        )
    print(f"  the halving's pick ranks {rank} of {len(subset)} in the exhaustive search")
    print(
        f"  paper grid (121 x 1000 epochs) projected: exhaustive {projection['exhaustive']:.1f} h, "
        f"halving {projection['halving']:.2f} h"
    )
    return 0


if __name__ == "__main__":
    raise SystemExit(main())
