"""Paper B: the design-space campaign (analytical backend) and the surrogates trained on it."""

from __future__ import annotations

import time
from collections.abc import Sequence
from dataclasses import dataclass
from pathlib import Path
from typing import TYPE_CHECKING, Any

from softbend.design import DesignSpace
from softbend.pipeline import Progress

if TYPE_CHECKING:  # pragma: no cover
    import pandas as pd

    from softbend.analysis import CampaignAnalysis
    from softbend.surrogates.search import SearchResult

__all__ = ["Campaign", "Surrogates", "run_campaign_section", "train_campaign_surrogates"]


@dataclass(frozen=True)
class Campaign:
    """What :func:`run_campaign_section` ran and stored.

    Attributes
    ----------
    samples : pandas.DataFrame
        Every sample of the campaign database.
    database, parquet : Path
        The campaign database (DuckDB) and its Parquet export.
    analysis : CampaignAnalysis
        Paper B's preliminary analysis of the samples (Fig. 4): correlations and
        the standardized regression.
    summary : dict
        ``backend``, ``n_designs``, ``done``, ``failed``, ``n_samples``,
        ``run_now``, ``resumed_done``, ``seconds`` and ``designs_per_s``
        (None when a resumed run had nothing left to do).
    """

    samples: pd.DataFrame
    database: Path
    parquet: Path
    analysis: CampaignAnalysis
    summary: dict[str, Any]


@dataclass(frozen=True)
class Surrogates:
    """What :func:`train_campaign_surrogates` trained.

    Attributes
    ----------
    search : SearchResult
        The grouped search (out-of-fold predictions, refitted families).
    training : dict
        :func:`softbend.surrogates.workflow.train_surrogates`'s summary
        (settings, models, files written).
    summary : dict
        Headline figures: wall time, best family by MAPE, per family its
        configuration, R², RMSE, MAPE and single-sample inference time.
    """

    search: SearchResult
    training: dict[str, Any]
    summary: dict[str, Any]


def run_campaign_section(
    out_dir: Path,
    *,
    space: DesignSpace | None = None,
    workers: int | None = None,
    progress: Progress | None = None,
) -> Campaign:
    """Run (or resume) the campaign over ``space`` with the analytical backend.

    Writes ``out_dir/paper_b/campaign.duckdb`` and its export ``samples.parquet``.

    Parameters
    ----------
    out_dir : path
        The report's folder.
    space : DesignSpace, optional
        Default: paper B's Table 1 (972 designs).
    workers : int, optional
        Local worker processes (default: all cores).
    progress : callable, optional
        ``progress(phase, done, total)`` in designs finished or failed.
    """
    from softbend.analysis import analyze_samples
    from softbend.campaign import run_campaign
    from softbend.campaign.store import CampaignStore

    phase = "paper B: campaign (analytical)"
    folder = Path(out_dir) / "paper_b"
    folder.mkdir(parents=True, exist_ok=True)
    space = DesignSpace.table1() if space is None else space
    database = folder / "campaign.duckdb"

    def on_progress(done: int, failed: int, running: int, total: int) -> None:
        if progress is not None:
            progress(phase, done + failed, total)

    run = run_campaign(database, space, backend="analytical", workers=workers, progress=on_progress)
    with CampaignStore(database, read_only=True) as store:
        samples = store.load_samples()
        status = store.status_summary()
        parquet = store.export(folder / "samples.parquet", format="parquet")
    summary = {
        "backend": run.backend,
        "n_designs": len(space),
        "done": int(status["done"]),
        "failed": int(status["failed"]),
        "n_samples": len(samples),
        "run_now": run.n_run,
        "resumed_done": run.n_skipped_done,
        "seconds": run.wall_time_s,
        # None (not NaN) when a resumed run had nothing left to do: JSON has no NaN.
        "designs_per_s": run.designs_per_s if run.n_run else None,
    }
    return Campaign(
        samples=samples,
        database=database,
        parquet=Path(parquet),
        analysis=analyze_samples(samples),
        summary=summary,
    )


def train_campaign_surrogates(
    out_dir: Path,
    *,
    seed: int = 0,
    progress: Progress | None = None,
    models: Sequence[str] | None = None,
) -> Surrogates:
    """Train the surrogate families on the campaign with the quick grid.

    Reads ``out_dir/paper_b/campaign.duckdb`` (see :func:`run_campaign_section`)
    and writes ``out_dir/paper_b/surrogates`` (models, ONNX, CV tables).
    ``models`` defaults to paper B's three families.
    """
    from softbend.surrogates.search import MODEL_NAMES
    from softbend.surrogates.workflow import SAVING_PHASE, train_surrogates

    folder = Path(out_dir) / "paper_b"
    families = MODEL_NAMES if models is None else tuple(models)
    # after the last family's refit on all designs (each refit is a phase of the search):
    # the saved models and their ONNX export, told as a phase of their own
    after = "paper B: surrogates, save and export (stages)"

    def on_progress(phase: str, done: int, total: int) -> None:
        if progress is not None and phase != SAVING_PHASE:  # within ``after``
            progress(f"paper B: surrogates, {phase}", done, total)
            if (
                families
                and phase.startswith(f"{families[-1]}: refit on all designs")
                and done >= total
            ):
                progress(after, 0, 1)

    start = time.perf_counter()
    result, training = train_surrogates(
        folder / "campaign.duckdb",
        folder / "surrogates",
        models=families,
        grid_name="quick",
        seed=seed,
        progress=on_progress,
        interpolation=False,  # paper B's figures are the grouped ones; no more fits
    )
    if progress is not None:
        progress(after, 1, 1)
    summary = {
        "seconds": time.perf_counter() - start,
        "best_by_mape": training["best_by_mape"],
        "models": {
            name: {
                key: m[key]
                for key in ("params", "r2", "rmse_deg", "mape_pct", "inference_single_us")
            }
            for name, m in training["models"].items()
        },
    }
    return Surrogates(search=result, training=training, summary=summary)
