"""Paper B §5 as a study: controllers × references on the simulated rig, with model mismatch.

:func:`control_study` runs each controller on each reference (paper B: a square
wave and a 0.2 Hz triangle, plus a step) on the simulated rig of one design and
scores every run with :func:`~softbend.control.experiments.run_metrics`. The
controllers' model is a surrogate (default: the shipped FEM-trained MLP, as the
virtual angle sensor of paper B); the actuator is that same model, or another
θ(p) (``plant_table``: the design's FEM sweep, or its lab readings, where the
controllers meet the reality gap). The report's control section and the
benchmark are thin layers over it.
"""

from __future__ import annotations

from collections.abc import Callable, Sequence
from dataclasses import dataclass, field
from typing import Any

import pandas as pd

from softbend.control.controllers import mlp_virtual_sensor
from softbend.control.experiments import ControlRun, run_metrics, simulate
from softbend.control.factory import make_controller
from softbend.control.rig import AngleTable, RigParams, SimulatedRig
from softbend.design import SFRBADesign

__all__ = [
    "PAPER_B_CONTROL",
    "STUDY_CONTROLLERS",
    "STUDY_REFERENCES",
    "ControlStudy",
    "control_study",
]

#: Paper B §5 (Fig. 9), its deadzone bang-bang on its rig.
PAPER_B_CONTROL: dict[str, dict[str, float]] = {
    "square": {"mape_pct": 5.5, "settling_s": 0.7, "rise_s": 0.104},
    "triangle": {"mape_pct": 5.3, "delay_s": 0.0875},
}

#: The references of the study: a step, paper B's square wave and 0.2 Hz triangle.
STUDY_REFERENCES: tuple[str, ...] = ("step:90", "square:90:4", "triangle:0.2:90:20")

#: Paper B's controller and the two best alternatives.
STUDY_CONTROLLERS: tuple[str, ...] = ("bang-bang", "pressure-relay", "predictive")


@dataclass
class ControlStudy:
    """The runs of :func:`control_study` and their metrics.

    Attributes
    ----------
    metrics : pandas.DataFrame
        One row per (controller, reference): the metrics of
        :func:`~softbend.control.experiments.run_metrics`.
    runs : dict
        ``{(controller, reference): ControlRun}``.
    settings : dict
        Design, duration, seed, plant, rig parameters.
    """

    metrics: pd.DataFrame
    runs: dict[tuple[str, str], ControlRun] = field(repr=False)
    settings: dict[str, Any]

    def metric(self, controller: str, reference: str, name: str) -> float:
        """One metric of one run."""
        rows = self.metrics
        row = rows[(rows["controller"] == controller) & (rows["reference"] == reference)]
        return float(row[name].iloc[0])


def control_study(
    model: Any,
    design: SFRBADesign,
    *,
    plant_table: AngleTable | None = None,
    plant: str = "surrogate",
    controllers: Sequence[str] = STUDY_CONTROLLERS,
    references: Sequence[str] = STUDY_REFERENCES,
    duration_s: float = 10.0,
    seed: int = 0,
    params: RigParams | None = None,
    progress: Callable[[int, int], None] | None = None,
) -> ControlStudy:
    """Run every controller on every reference on the simulated rig of ``design``.

    Parameters
    ----------
    model : surrogate
        The controllers' model (``.predict`` on feature rows; an MLP with
        ``.predictor()`` is also the bang-bang's virtual sensor).
    design : SFRBADesign
    plant_table : AngleTable, optional
        θ(p) of the actuator (default: ``model``'s, no mismatch).
    plant : str
        Name of the plant, for the settings (e.g. ``"lab"``).
    controllers, references : sequences of str
        Names in :data:`~softbend.control.controllers.CONTROLLERS`; reference specs.
    duration_s : float, default 10
    seed : int, default 0
        Seed of the sensor and camera noise (the same for every run).
    params : RigParams, optional
        Default: :meth:`RigParams.for_design` of ``design``.
    progress : callable, optional
        ``progress(done_runs, total_runs)``.
    """
    params = RigParams.for_design(design) if params is None else params
    table = AngleTable.from_surrogate(model, design)
    sensor = mlp_virtual_sensor(model, design) if hasattr(model, "predictor") else table
    actuator = table if plant_table is None else plant_table
    rows, runs = [], {}
    total = len(controllers) * len(references)
    for name in controllers:
        for spec in references:
            controller = make_controller(name, table, sensor, params)
            run = simulate(SimulatedRig(actuator, params, seed=seed), controller, spec, duration_s)
            runs[(name, spec)] = run
            rows.append({"controller": name, "reference": spec, **run_metrics(run)})
            if progress is not None:
                progress(len(rows), total)
    settings = {
        "design": str(design),
        "duration_s": duration_s,
        "seed": seed,
        "plant": plant if plant_table is not None else "surrogate",
        "rig": params.as_dict(),
    }
    return ControlStudy(metrics=pd.DataFrame(rows), runs=runs, settings=settings)
