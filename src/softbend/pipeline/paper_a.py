"""Paper A: the synthetic curling actuator's experiments and their NARX/GG-SVR identification."""

from __future__ import annotations

import time
from dataclasses import dataclass, field
from pathlib import Path
from typing import TYPE_CHECKING, Any

from softbend._io import write_text_atomic
from softbend.pipeline import Progress

if TYPE_CHECKING:  # pragma: no cover
    from softbend.identification.study import IdentificationResult

__all__ = ["PaperA", "run_paper_a", "write_identification_data"]


@dataclass(frozen=True)
class PaperA:
    """What :func:`run_paper_a` computed.

    Attributes
    ----------
    result : IdentificationResult
        The leave-one-experiment-out identification.
    paths : dict
        ``{artefact name: path}`` of the files written (metrics, models).
    summary : dict
        Headline figures: wall time, free-run NRMSE mean and worst per
        ``"sign/output"``, and per sign the model chosen by free-run error.
    selections : dict of str to Selection
        Per pressure sign, the selection by held-out free-run error among linear,
        polynomial and kernel NARX models of ρ and L together
        (:func:`softbend.identification.selection.select_model`), beside paper A's
        setting, which the identification above keeps.
    """

    result: IdentificationResult
    paths: dict[str, Path]
    summary: dict[str, Any]
    selections: dict[str, Any] = field(default_factory=dict)


def write_identification_data(result: IdentificationResult, out_dir: Path) -> dict[str, Path]:
    """Write the metrics (``metrics.csv``, ``summary.csv``) and fitted models (``models/*.json``).

    Returns
    -------
    dict
        ``{artefact name: path}``.
    """
    from softbend.identification.persistence import save_narx

    out_dir = Path(out_dir)
    out_dir.mkdir(parents=True, exist_ok=True)
    paths: dict[str, Path] = {}
    paths["metrics"] = write_text_atomic(
        out_dir / "metrics.csv", result.metrics.to_csv(index=False)
    )
    paths["summary"] = write_text_atomic(
        out_dir / "summary.csv", result.summary().to_csv(index=False)
    )
    synthetic = any(e.synthetic for group in result.experiments.values() for e in group)
    for (sign, output), model in result.models.items():
        names = [e.name for e in result.experiments[sign]]
        metadata = {
            "sign": sign,
            "output": output,
            "input": "pressure_kpa",
            "output_unit": "mm" if output == "length_mm" else "1",
            "trained_on": names,
            "synthetic_data": synthetic,
        }
        paths[f"model_{sign}_{output}"] = save_narx(
            model, out_dir / "models" / f"{sign}_{output}.json", metadata=metadata
        )
    return paths


def run_paper_a(out_dir: Path, *, seed: int = 0, progress: Progress | None = None) -> PaperA:
    """Generate the synthetic experiments, identify them, write data and models.

    Writes ``out_dir/paper_a/data/*.csv`` (the experiments), ``metrics.csv``,
    ``summary.csv`` and ``models/<sign>_<output>.json``.

    Parameters
    ----------
    out_dir : path
        The report's folder; files go to ``out_dir/paper_a``.
    seed : int
        Seed of the synthetic data.
    progress : callable, optional
        ``progress(phase, done, total)``, once per fitted model.
    """
    from softbend.identification.data import save_experiments
    from softbend.identification.study import IdentificationConfig, identify, n_fits
    from softbend.identification.synthetic import synthetic_dataset

    phase = "paper A: identification"
    start = time.perf_counter()
    folder = Path(out_dir) / "paper_a"
    dataset = synthetic_dataset(seed=seed)
    experiments = [e for group in dataset.values() for e in group]
    save_experiments(experiments, folder / "data")
    total = n_fits(experiments)
    done = 0

    def step(_label: str) -> None:
        nonlocal done
        done += 1
        if progress is not None:
            progress(phase, done, total)

    if progress is not None:
        progress(phase, 0, total)
    result = identify(experiments, IdentificationConfig(), progress=step)
    paths = write_identification_data(result, folder)
    selections = _selections(dataset, seed, progress)
    table = result.summary()
    free_run = table[table["mode"] == "free-run"]
    summary = {
        "seconds": time.perf_counter() - start,
        "free_run_nrmse_mean": {
            f"{r.sign}/{r.output}": float(r.nrmse_mean) for r in free_run.itertuples()
        },
        "free_run_nrmse_worst": {
            f"{r.sign}/{r.output}": float(r.nrmse_max) for r in free_run.itertuples()
        },
    }
    summary["selection"] = {
        sign: {
            "best": chosen.best,
            "cv_freerun_nrmse": float(chosen.row(chosen.best)["cv_freerun_nrmse"]),
            "best_arx": (chosen.best_of("arx") or {}).get("candidate"),
            "best_arx_cv_freerun_nrmse": float(
                (chosen.best_of("arx") or {}).get("cv_freerun_nrmse", float("nan"))
            ),
            "paper_a_cv_freerun_nrmse": float(chosen.row("paper-a")["cv_freerun_nrmse"]),
        }
        for sign, chosen in selections.items()
    }
    return PaperA(result=result, paths=paths, summary=summary, selections=selections)


def _selections(
    dataset: dict[str, list[Any]], seed: int, progress: Progress | None
) -> dict[str, Any]:
    """Per pressure sign, the model chosen by held-out free-run error (ρ and L together)."""
    from softbend._progress import listening
    from softbend.identification.selection import select_model
    from softbend.identification.timeseries import from_experiments

    out = {}
    for sign, group in dataset.items():
        if len(group) < 2:
            continue
        phase = f"paper A: model selection ({sign})"

        def tick(done: int, total: int, phase: str = phase) -> None:
            if progress is not None:
                progress(phase, done, total)

        with listening(None):  # the selection's own fits are this phase
            out[sign] = select_model(from_experiments(group), seed=seed, progress=tick)
    return out
