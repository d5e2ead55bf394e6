"""A design search's files: the ranked table, the record, and the figures.

Every column names the model's own parameters: paper B's as ``l_mm`` …
``lc_mm``, another actuator's by its parameter names (whole numbers as
integers, a categorical parameter by its level's name), and the pressure by
its unit (``pressure_mpa``, ``pressure_kpa`` …).
"""

from __future__ import annotations

import csv
import dataclasses
import math
from pathlib import Path
from typing import Any

from softbend.design_search.search import Predictor, SearchResult
from softbend.design_search.space import pressure_key

__all__ = ["FIGURE_CANDIDATES", "FILES", "candidate_rows", "write_search"]

#: The files of one specification's folder.
FILES: tuple[str, ...] = ("candidates.csv", "search.json", "front.png", "curves.png")

#: The best candidates front.png marks one by one (a rank each); the tables list them all.
FIGURE_CANDIDATES = 50


def candidate_rows(result: SearchResult) -> list[dict[str, Any]]:
    """One flat row per candidate, best first: rank, the design by its actuator's columns
    (:meth:`Actuator.design_record <softbend.actuators.Actuator.design_record>`), the
    pressure, angles, miss, objectives."""
    rows = []
    actuator = result.spec.space.actuator
    for rank, c in enumerate(result.candidates, start=1):
        row: dict[str, Any] = {"rank": rank}
        row.update(actuator.design_record(c.design.as_array()))
        row[pressure_key(c.pressure_unit)] = c.pressure_mpa
        row["angle_deg"] = c.angle_deg
        row["error_deg"] = c.error_deg
        row["meets"] = c.meets
        if c.interval_deg is not None:
            row["interval_low_deg"], row["interval_high_deg"] = c.interval_deg
        for name, value in c.objectives.items():
            row[f"objective_{name}"] = value
        if c.fem_meets is not None:
            row["fem_angle_deg"] = c.fem_angle_deg
            row["fem_error_deg"] = c.fem_error_deg
            row["fem_meets"] = c.fem_meets
        row["flags"] = "; ".join(c.flags)
        rows.append(row)
    return rows


def write_search(result: SearchResult, predictor: Predictor, folder: str | Path) -> dict[str, str]:
    """Write :data:`FILES` into ``folder`` (created); returns name → path.

    ``candidates.csv`` and ``search.json`` hold every candidate; ``front.png``
    marks the best :data:`FIGURE_CANDIDATES` (a longer list is no longer
    readable there, and drawing it would take minutes).
    """
    from softbend._io import json_text
    from softbend.reports import design_figures

    out = Path(folder)
    out.mkdir(parents=True, exist_ok=True)
    rows = candidate_rows(result)
    columns: list[str] = []
    for row in rows:
        columns += [k for k in row if k not in columns]
    with open(out / "candidates.csv", "w", encoding="utf-8", newline="") as handle:
        writer = csv.DictWriter(handle, fieldnames=columns or ["rank"])
        writer.writeheader()
        for row in rows:
            writer.writerow(
                {k: ("" if isinstance(v, float) and math.isnan(v) else v) for k, v in row.items()}
            )
    (out / "search.json").write_text(json_text(result.to_dict()) + "\n", encoding="utf-8")
    shown = dataclasses.replace(result, candidates=result.candidates[:FIGURE_CANDIDATES])
    design_figures.front_figure(shown, out / "front.png")
    design_figures.curves_figure(result, predictor, out / "curves.png")
    return {name: str(out / name) for name in FILES}
