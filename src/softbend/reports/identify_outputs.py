"""The files of ``softbend identify``: the selection, the model, the held-out free runs."""

from __future__ import annotations

import csv
from pathlib import Path
from typing import TYPE_CHECKING, Any

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
    each held-out experiment (:attr:`Selection.holdout_outputs`). ``model.json``'s
    metadata records the time column, its median sampling interval and unit, and
    the model's step readings (gain, time constant, delay per input and output),
    which :func:`softbend.identification.dynamics.load_identified` reads back.
    """
    from softbend._io import json_text
    from softbend.identification.multi import save_multi_narx
    from softbend.reports import identify_figures

    out = Path(folder)
    out.mkdir(parents=True, exist_ok=True)
    selection.table.to_csv(out / "selection.csv", index=False)
    record = selection.to_dict()
    (out / "selection.json").write_text(json_text(record) + "\n", encoding="utf-8")
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
        },
    )
    held = selection.holdout_outputs
    names = [e.name for e in data.experiments if e.name in held]
    heldout = data.subset(names)
    with open(out / "holdout_freerun.csv", "w", encoding="utf-8", newline="") as handle:
        writer = csv.writer(handle)
        header = ["experiment", data.time_name]
        for name in data.output_names:
            header += [f"{name}_measured", f"{name}_simulated"]
        writer.writerow(header)
        for e in heldout.experiments:
            simulated = held[e.name]
            for t in range(e.n_samples):
                row: list[Any] = [e.name, repr(float(e.time[t]))]
                for j in range(len(data.output_names)):
                    row += [repr(float(e.outputs[t, j])), repr(float(simulated[t, j]))]
                writer.writerow(row)
    identify_figures.selection_figure(selection, out / "selection.png")
    kind = "validation experiments" if selection.validation else "cross-validation folds"
    identify_figures.freerun_overlays(
        heldout,
        held,
        out / "freerun.png",
        title=f"{selection.best}: free run on held-out {kind}",
    )
    return {name: str(out / name) for name in FILES}
