"""Paper B Figs. 4 and 5 on the FEM dataset shipped with softbend (no campaign is rerun).

:func:`run_fem_data` reads :func:`softbend.datasets.table1_fem` (verified against
its checksums), fits the standardized regression of paper B §3.3 (Fig. 4) and
searches the three surrogate families with folds of whole designs (the honest
score of an unseen actuator, primary), then scores each family's chosen
configuration with samples shuffled across designs (paper B's protocol, for
comparison; no second grid search, no refit). The FEM-trained models are saved
under ``paper_b_fem/surrogates/models`` for later use (transfer learning,
control).
"""

from __future__ import annotations

import time
from collections.abc import Sequence
from dataclasses import dataclass
from pathlib import Path
from typing import TYPE_CHECKING, Any

from softbend.pipeline import Progress
from softbend.references import FEM_DATASET

if TYPE_CHECKING:  # pragma: no cover
    import pandas as pd

    from softbend.analysis import RegressionReport
    from softbend.surrogates.search import SearchResult

__all__ = ["TABLE1_DESIGNS", "FEMData", "run_fem_data"]

#: Designs of paper B's Table 1 (§3.3).
TABLE1_DESIGNS: int = FEM_DATASET["designs"].value


@dataclass(frozen=True)
class FEMData:
    """What :func:`run_fem_data` read and computed.

    Attributes
    ----------
    samples, designs : pandas.DataFrame
        The dataset's samples and designs tables.
    provenance : dict
        The dataset's provenance (command, CPU time, versions, checksums).
    regression : RegressionReport
        Paper B's standardized linear model of the angle (Fig. 4b, c).
    correlation : pandas.DataFrame
        Pearson correlation of the inputs and the angle (Fig. 4a).
    search : SearchResult
        The grouped surrogate search (out-of-fold predictions, refitted families).
    grouped : dict
        :func:`softbend.surrogates.workflow.train_surrogates`'s summary of it.
    shuffled : dict
        ``settings``, ``seconds`` and per family ``params``, ``r2``,
        ``rmse_deg``, ``mape_pct``, ``max_abs_error_deg`` of the chosen
        configurations under random folds.
    summary : dict
        Headline figures of the section.
    """

    samples: pd.DataFrame
    designs: pd.DataFrame
    provenance: dict[str, Any]
    regression: RegressionReport
    correlation: pd.DataFrame
    search: SearchResult
    grouped: dict[str, Any]
    shuffled: dict[str, Any]
    summary: dict[str, Any]

    @property
    def converged(self) -> pd.DataFrame:
        """The converged samples."""
        return self.samples[self.samples["converged"]]

    @property
    def done(self) -> pd.DataFrame:
        """The designs swept to the end."""
        return self.designs[self.designs["status"] == "done"]


def _surrogates(
    samples: pd.DataFrame,
    folder: Path,
    seed: int,
    progress: Progress | None,
    epochs: int | None,
    models: Sequence[str] | None,
) -> tuple[SearchResult, dict[str, Any], dict[str, Any]]:
    """Grouped search with saved models, then the chosen configurations under random folds."""
    from softbend.surrogates.features import training_data
    from softbend.surrogates.search import MODEL_NAMES, search
    from softbend.surrogates.workflow import SAVING_PHASE, train_surrogates

    families = MODEL_NAMES if models is None else tuple(models)
    # after the last family's refit on all designs: the saved models and their export
    after = "paper B FEM data: surrogates, save and export (stages)"

    def on_progress(protocol: str) -> Progress:
        def forward(phase: str, done: int, total: int) -> None:
            if progress is not None and phase != SAVING_PHASE:  # within ``after``
                progress(f"paper B FEM data: surrogates ({protocol} CV), {phase}", done, total)
                last = (
                    protocol == "grouped"
                    and families
                    and phase.startswith(f"{families[-1]}: refit on all designs")
                )
                if last and done >= total:
                    progress(after, 0, 1)

        return forward

    data = training_data(samples)
    result, grouped = train_surrogates(
        data,
        folder,
        models=families,
        grid_name="quick",
        seed=seed,
        epochs=epochs,
        progress=on_progress("grouped"),
        interpolation=False,  # paper B's figures are the grouped ones; no more fits
    )
    if progress is not None:
        progress(after, 1, 1)
    started = time.perf_counter()
    chosen = {name: [dict(fam.params)] for name, fam in result.families.items()}
    shuffled = search(
        data,
        models=list(chosen),
        grid_name="quick",
        param_grid=chosen,
        seed=seed,
        epochs=epochs,
        cv="random",
        refit=False,
        progress=on_progress("random"),
    )
    random_summary = {
        "settings": shuffled.settings,
        "seconds": time.perf_counter() - started,
        "models": {
            name: {
                "params": row["params"],
                **{k: float(row[k]) for k in ("r2", "rmse_deg", "mape_pct", "max_abs_error_deg")},
            }
            for name, row in shuffled.summary().set_index("model").iterrows()
        },
    }
    return result, grouped, random_summary


def run_fem_data(
    out_dir: Path,
    seed: int = 0,
    progress: Progress | None = None,
    *,
    dataset: str | Path | None = None,
    epochs: int | None = None,
    models: Sequence[str] | None = None,
) -> FEMData:
    """Paper B's regression and surrogate search on the shipped (or given) FEM dataset.

    Parameters
    ----------
    out_dir : path
        The report's folder; models go to ``out_dir/paper_b_fem/surrogates``.
    seed : int
        Seed of the folds and of the models.
    progress : callable, optional
        ``progress(phase, done, total)``.
    dataset : path, optional
        A dataset folder (default: the one shipped in the package).
    epochs : int, optional
        MLP epochs (default: the quick grid's).
    models : sequence of str, optional
        Surrogate families (default: all three of paper B).
    """
    from softbend.analysis import analyze_samples
    from softbend.datasets import table1_fem, table1_fem_designs, table1_fem_provenance

    start = time.perf_counter()
    folder = Path(out_dir) / "paper_b_fem"
    folder.mkdir(parents=True, exist_ok=True)
    samples = table1_fem(dataset)
    designs = table1_fem_designs(dataset)
    provenance = table1_fem_provenance(dataset)
    converged = samples[samples["converged"]]
    done = designs[designs["status"] == "done"]
    analysis = analyze_samples(samples)
    regression, correlation = analysis.regression, analysis.correlation
    result, grouped, shuffled = _surrogates(
        samples, folder / "surrogates", seed, progress, epochs, models
    )
    stops = done["stop_kind"].value_counts()
    summary = {
        "seconds": time.perf_counter() - start,
        "designs_done": len(done),
        "samples_sha256": provenance["files"]["samples.parquet"]["sha256"],
        "samples": len(samples),
        "converged_samples": len(converged),
        "stops": {str(k): int(v) for k, v in stops.items()},
        "cpu_hours": provenance["cpu_time_s"] / 3600.0,
        "r2": regression.r2,
        "f_value": regression.f_value,
        "mape_pct": regression.mape_pct,
        "loadings": {str(k): float(v) for k, v in regression.coefficients["loading"].items()},
        "surrogates_grouped": {
            name: {k: m[k] for k in ("params", "r2", "rmse_deg", "mape_pct", "max_abs_error_deg")}
            for name, m in grouped["models"].items()
        },
        "surrogates_random": shuffled["models"],
    }
    return FEMData(
        samples=samples,
        designs=designs,
        provenance=provenance,
        regression=regression,
        correlation=correlation,
        search=result,
        grouped=grouped,
        shuffled=shuffled,
        summary=summary,
    )
