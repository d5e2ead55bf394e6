"""Paper B Figs. 6 and 7: transfer learning on the shipped virtual lab (no FEM is rerun).

:func:`run_transfer` reads the shipped virtual-lab measurements
(:func:`softbend.transfer.lab.shipped_measurements`, labelled synthetic) and the
shipped FEM-trained MLP (:func:`softbend.transfer.base.load_base`) and runs the
leave-one-configuration-out evaluation of every strategy.
"""

from __future__ import annotations

import time
from collections.abc import Sequence
from dataclasses import dataclass
from pathlib import Path
from typing import TYPE_CHECKING, Any

from softbend.pipeline import Progress

if TYPE_CHECKING:  # pragma: no cover
    from softbend.transfer.loco import LocoResult
    from softbend.transfer.measurements import Measurements

__all__ = ["Transfer", "run_transfer"]


@dataclass(frozen=True)
class Transfer:
    """What :func:`run_transfer` measured.

    Attributes
    ----------
    measurements : Measurements
        The shipped virtual lab's readings (synthetic).
    result : LocoResult
        Leave one configuration out, every strategy.
    files : dict
        ``{name: path}`` of the tables written (CSV, ``loco.json``).
    summary : dict
        Headline figures: wall time, readings, best strategy, per strategy its
        mean RMSE, MAPE, max error and interval coverage (None without one).
    """

    measurements: Measurements
    result: LocoResult
    files: dict[str, str]
    summary: dict[str, Any]


def run_transfer(
    out_dir: Path,
    seed: int = 0,
    progress: Progress | None = None,
    *,
    options: dict[str, dict[str, Any]] | None = None,
    strategies: Sequence[str] | None = None,
) -> Transfer:
    """Leave one configuration out on the shipped virtual lab; write its tables.

    Parameters
    ----------
    out_dir : path
        The report's folder; tables go to ``out_dir/transfer``.
    seed : int
        Seed of the strategies and the learning curve.
    progress : callable, optional
        ``progress(phase, done, total)`` in strategies.
    options : dict, optional
        Constructor options per strategy (e.g. fewer epochs for a quick run);
        default paper B's settings.
    strategies : sequence of str, optional
        Default: every strategy
        (:data:`softbend.transfer.loco.DEFAULT_STRATEGIES`).
    """
    from softbend.transfer.base import load_base
    from softbend.transfer.lab import shipped_measurements
    from softbend.transfer.loco import DEFAULT_STRATEGIES, leave_one_configuration_out

    start = time.perf_counter()
    folder = Path(out_dir) / "transfer"
    measurements = shipped_measurements()
    base = load_base()

    def on_progress(done: int, total: int, name: str) -> None:
        if progress is not None:
            progress("transfer: leave one configuration out", done, total)

    result = leave_one_configuration_out(
        measurements,
        base,
        DEFAULT_STRATEGIES if strategies is None else strategies,
        seed=seed,
        options=options,
        progress=on_progress,
    )
    files = result.write(folder)
    summary = {
        "seconds": time.perf_counter() - start,
        "n_measurements": len(measurements),
        "best": result.best(),
        "summary": {
            str(r["strategy"]): {
                k: (None if r[k] != r[k] else float(r[k]))
                for k in ("rmse_deg", "mape_pct", "max_error_deg", "coverage")
            }
            for _, r in result.summary.iterrows()
        },
        "files": files,
    }
    return Transfer(measurements=measurements, result=result, files=files, summary=summary)
