"""The files of ``softbend identify``: the selection, the model, the held-out free runs."""

from __future__ import annotations

import csv
from pathlib import Path
from typing import TYPE_CHECKING, Any

import numpy as np

if TYPE_CHECKING:
    from softbend.identification.selection import Selection
    from softbend.identification.timeseries import TimeSeriesSet

__all__ = ["FILES", "write_identification"]

#: The files of an identification folder.
FILES: tuple[str, ...] = (
    "selection.csv",
    "selection.json",
    "model.json",
    "holdout_freerun.csv",
    "selection.png",
    "freerun.png",
)


def write_identification(
    selection: Selection, data: TimeSeriesSet, folder: str | Path
) -> dict[str, str]:
    """Write :data:`FILES` into ``folder`` (created) and return name → path.

    ``holdout_freerun.csv`` has ``experiment``, the time column and, per output,
    ``<name>_measured`` and ``<name>_simulated``: the selected model run free on
    each held-out experiment (:attr:`Selection.holdout_outputs`), each followed by
    ``<name>_low`` and ``<name>_high``, the 90 % band around the free run from
    the cross-validation residuals (:attr:`Selection.band`, in the output's unit;
    no width over the first ``max_lag`` samples, the run's initial conditions).
    ``freerun.png`` shades that band. ``model.json``'s metadata records the time
    column, its median sampling interval and unit, the model's step readings
    (gain, time constant, delay per input and output), which
    :func:`softbend.identification.dynamics.load_identified` reads back, and the
    band with its coverage on held-out samples (``"band"``, as in
    ``selection.json``).
    """
    from softbend._io import json_text
    from softbend._progress import report
    from softbend.identification.multi import save_multi_narx
    from softbend.reports import identify_figures

    out = Path(folder)
    out.mkdir(parents=True, exist_ok=True)
    phase = "writing the outputs (files)"
    report(phase, 0, len(FILES))
    selection.table.to_csv(out / "selection.csv", index=False)
    record = selection.to_dict()
    (out / "selection.json").write_text(json_text(record) + "\n", encoding="utf-8")
    report(phase, 2, len(FILES))
    save_multi_narx(
        selection.model,
        out / "model.json",
        metadata={
            "inputs": list(selection.input_names),
            "outputs": list(selection.output_names),
            "candidate": selection.best,
            "train": list(selection.train),
            "validation": list(selection.validation),
            "verdict": selection.verdict(),
            "time": selection.time_name,
            "sample_period": selection.sample_period,
            "time_unit_s": selection.time_unit_s,
            "dynamics": record["dynamics"],
            "band": record["band"],
        },
    )
    report(phase, 3, len(FILES))
    held = selection.holdout_outputs
    names = [e.name for e in data.experiments if e.name in held]
    heldout = data.subset(names)
    bands = _bands(selection, held)
    with open(out / "holdout_freerun.csv", "w", encoding="utf-8", newline="") as handle:
        writer = csv.writer(handle)
        header = ["experiment", data.time_name]
        ends = ("measured", "simulated", "low", "high") if bands else ("measured", "simulated")
        header += [f"{name}_{end}" for name in data.output_names for end in ends]
        writer.writerow(header)
        for e in heldout.experiments:
            simulated = held[e.name]
            low, high = bands.get(e.name, (None, None))
            for t in range(e.n_samples):
                row: list[Any] = [e.name, repr(float(e.time[t]))]
                for j in range(len(data.output_names)):
                    row += [repr(float(e.outputs[t, j])), repr(float(simulated[t, j]))]
                    if low is not None and high is not None:
                        row += [repr(float(low[t, j])), repr(float(high[t, j]))]
                writer.writerow(row)
    report(phase, 4, len(FILES))
    identify_figures.selection_figure(selection, out / "selection.png")
    report(phase, 5, len(FILES))
    kind = "validation experiments" if selection.validation else "cross-validation folds"
    identify_figures.freerun_overlays(
        heldout,
        held,
        out / "freerun.png",
        title=f"{selection.best}: free run on held-out {kind}",
        bands=bands,
        band_label=_band_label(selection),
    )
    report(phase, 6, len(FILES))
    return {name: str(out / name) for name in FILES}


def _bands(
    selection: Selection, runs: dict[str, np.ndarray]
) -> dict[str, tuple[np.ndarray, np.ndarray]]:
    """Each held-out run's band, ``(low, high)`` shaped like the run (none without a band)."""
    band = selection.band
    if band is None:
        return {}
    start = selection.model.max_lag
    return {name: band.bounds(run, start=start) for name, run in runs.items()}


def _band_label(selection: Selection) -> str:
    """The band's legend: its level, where it comes from and its held-out coverage."""
    band = selection.band
    if band is None:
        return ""
    label = f"{100 * band.level:.0f} % band (CV residuals)"
    if band.coverage is not None:
        label += f", covers {100 * float(np.mean(band.coverage)):.0f} % held out"
    return label
