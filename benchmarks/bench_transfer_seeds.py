"""Benchmark: how much the transfer-learning figures depend on the base MLP's training seed.

Every strategy of ``softbend transfer loco`` starts from one FEM-trained MLP
(paper B's (63, 65), 1000 epochs, trained with seed 0 and shipped). Another seed
gives another network of about the same training error, so the leave-one-configuration-out
figures of the strategies that start from it are one draw each. This script trains
the base again with each ``--seeds`` value on the shipped FEM dataset
(:func:`softbend.transfer.base.train_base_mlp`, one thread per base, ``--jobs``
bases at once), scores ``fem-only``, ``refined`` and ``scaled-refined`` by
leave-one-configuration-out on the lab file (default: the shipped virtual lab)
and prints, per seed and as mean and spread over the seeds, the base's RMSE on
the FEM samples it was trained on, the mean held-out RMSE of each strategy and
their ratio to ``fem-only``. Also
printed: the same figures for the members' mean of each strategy's MLPs of all
seeds (an ensemble over base seeds).

Bases are kept in ``--cache`` (default ``.bench_transfer_seeds/``), so a second
run only refines::

    .venv/bin/python benchmarks/bench_transfer_seeds.py --seeds 0 1 2 3 4 --jobs 2
"""

from __future__ import annotations

import argparse
import time
from concurrent.futures import ProcessPoolExecutor
from pathlib import Path

import numpy as np
from _record import record

from softbend.datasets import table1_fem
from softbend.metrics import rmse
from softbend.surrogates.persistence import load_surrogate, save_surrogate
from softbend.transfer.base import fem_rows, train_base_mlp
from softbend.transfer.measurements import load_measurements
from softbend.transfer.strategies import RefinedMLP, ScaledRefinedMLP

#: The strategies scored for every base, by name.
STRATEGIES = {"refined": RefinedMLP, "scaled-refined": ScaledRefinedMLP}

SHIPPED_LAB = Path(__file__).resolve().parents[1] / "src/softbend/data/transfer/virtual_lab.csv"


def _train(seed: int, path: Path) -> tuple[int, float]:
    start = time.perf_counter()
    save_surrogate(train_base_mlp(seed=seed), path, metadata={"seed": seed})
    return seed, time.perf_counter() - start


def _bases(seeds: list[int], cache: Path, jobs: int) -> dict[int, object]:
    cache.mkdir(parents=True, exist_ok=True)
    paths = {seed: cache / f"base_seed{seed}.json" for seed in seeds}
    missing = [seed for seed in seeds if not paths[seed].is_file()]
    if missing:
        with ProcessPoolExecutor(max_workers=jobs) as pool:
            for seed, seconds in pool.map(_train, missing, [paths[s] for s in missing]):
                print(f"base seed {seed}: trained in {seconds:.0f} s", flush=True)
    return {seed: load_surrogate(paths[seed]).model for seed in seeds}


def main(argv: list[str] | None = None) -> int:
    parser = argparse.ArgumentParser(description=__doc__.split("\n")[0])
    parser.add_argument("--seeds", type=int, nargs="+", default=[0, 1, 2, 3, 4])
    parser.add_argument("--lab", type=Path, default=SHIPPED_LAB, help="Measurement CSV.")
    parser.add_argument("--jobs", type=int, default=2, help="Bases trained at once.")
    parser.add_argument("--cache", type=Path, default=Path(".bench_transfer_seeds"))
    args = parser.parse_args(argv)

    lab = load_measurements(args.lab)
    X, y, groups = lab.features, lab.angle_deg, lab.groups
    ids = list(lab.actuator_ids)
    held_out = [groups == a for a in ids]
    training = [np.flatnonzero(~mask) for mask in held_out]
    bases = _bases(args.seeds, args.cache, args.jobs)

    def mean_rmse(predictions: list[np.ndarray]) -> float:
        return float(np.mean([rmse(y[m], p) for m, p in zip(held_out, predictions, strict=True)]))

    print(f"{len(ids)} actuators, {y.size} readings ({args.lab.name}); refined: 1000 epochs")
    samples = table1_fem()
    samples = samples[samples["converged"].astype(bool)]
    fem_X, fem_y = fem_rows(samples), samples["angle_deg"].to_numpy(dtype=float)
    names = list(STRATEGIES)
    print(
        "seed  FEM-data RMSE  fem-only RMSE  "
        + "  ".join(f"{n + ' RMSE':>19s}" for n in names)
        + "  ratios to fem-only"
    )

    def line(label: str, fit: float, fem: float, held_out: list[float], ratios: list[float]) -> str:
        return (
            f"{label:4s}  {fit:13.2f}  {fem:13.2f}  "
            + "  ".join(f"{v:19.2f}" for v in held_out)
            + "  "
            + ", ".join(f"{r:.3f}" for r in ratios)
        )

    figures: dict = {}
    fit, fem = [], []
    held = {name: [] for name in names}  # per seed: the mean held-out RMSE
    members = {name: [] for name in names}  # per seed: the held-out predictions
    for seed, base in bases.items():
        fit.append(rmse(fem_y, base.predict(fem_X)))
        fem.append(mean_rmse([base.predict(X[m]) for m in held_out]))
        for name, cls in STRATEGIES.items():
            models = cls.fit_batch([cls(base) for _ in ids], X, y, training)
            predictions = [model.predict(X[m]) for model, m in zip(models, held_out, strict=True)]
            members[name].append(predictions)
            held[name].append(mean_rmse(predictions))
        last = [held[n][-1] for n in names]
        print(line(str(seed).rjust(4), fit[-1], fem[-1], last, [v / fem[-1] for v in last]))
        figures[f"seed {seed}: base RMSE on the FEM data"] = round(fit[-1], 3)
        figures[f"seed {seed}: fem-only held-out RMSE"] = round(fem[-1], 3)
        for n in names:
            figures[f"seed {seed}: {n} held-out RMSE"] = round(held[n][-1], 3)
    if len(fem) > 1:
        fem_a = np.array(fem)
        for label, reduce in (("mean", np.mean), ("sd", lambda a: np.std(a, ddof=1))):
            values = [reduce(np.array(held[n])) for n in names]
            ratios = [reduce(np.array(held[n]) / fem_a) for n in names]
            print(line(label, reduce(np.array(fit)), reduce(fem_a), values, ratios))
        for name in names:
            mean_of_members = [
                np.mean([p[k] for p in members[name]], axis=0) for k in range(len(ids))
            ]
            print(
                f"{name} MLPs of all {len(fem)} seeds averaged: mean RMSE "
                f"{mean_rmse(mean_of_members):.2f}"
            )
            figures[f"{name}, MLPs of all seeds averaged: held-out RMSE"] = round(
                mean_rmse(mean_of_members), 3
            )
    record(
        "transfer_seeds",
        figures,
        units=dict.fromkeys(figures, "°"),
        notes=f"{len(ids)} actuators, {y.size} readings ({args.lab.name}); refined: 1000 epochs",
    )
    return 0


if __name__ == "__main__":
    raise SystemExit(main())
