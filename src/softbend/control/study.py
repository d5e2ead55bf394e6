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

from collections.abc import Callable, Mapping, Sequence
from dataclasses import dataclass, field
from typing import TYPE_CHECKING, Any

import pandas as pd

from softbend.actuators import Design
from softbend.control.controllers import ControllerModel
from softbend.control.experiments import ControlRun, run_metrics, simulate
from softbend.control.factory import CONTROLLERS, controller_parameters
from softbend.control.rig import AngleTable, RigParams, SimulatedRig
from softbend.errors import InputError, keyed
from softbend.references import CONTROL_RESULTS, values

if TYPE_CHECKING:
    from softbend.surrogates.protocol import Surrogate

__all__ = [
    "PAPER_B_CONTROL",
    "STUDY_CONTROLLERS",
    "STUDY_REFERENCES",
    "ControlStudy",
    "control_study",
]

#: Paper B §5 (Fig. 9), its deadzone bang-bang on its rig
#: (:data:`softbend.references.CONTROL_RESULTS`).
PAPER_B_CONTROL: dict[str, dict[str, float]] = values(CONTROL_RESULTS)

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
        Design, duration, seed, plant, rig parameters, and ``controllers``: every
        controller's parameters as used (``{name: {parameter: value}}``).
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
    model: Surrogate,
    design: Design,
    *,
    plant_table: AngleTable | None = None,
    plant: str = "surrogate",
    controllers: Sequence[str] = STUDY_CONTROLLERS,
    references: Sequence[str] = STUDY_REFERENCES,
    duration_s: float = 10.0,
    seed: int = 0,
    params: RigParams | None = None,
    progress: Callable[[int, int], None] | None = None,
    controller_params: Mapping[str, Mapping[str, Any]] | None = None,
) -> ControlStudy:
    """Run every controller on every reference on the simulated rig of ``design``.

    Parameters
    ----------
    model : surrogate
        The controllers' model (``.predict`` on feature rows; an MLP with
        ``.predictor()`` is also the bang-bang's virtual sensor).
    design : Design
    plant_table : AngleTable, optional
        θ(p) of the actuator (default: ``model``'s, no mismatch).
    plant : str
        Name of the plant, for the settings (e.g. ``"lab"``).
    controllers, references : sequences of str
        Names in :data:`~softbend.control.factory.CONTROLLERS`; reference specs.
    duration_s : float, default 10
    seed : int, default 0
        Seed of the sensor and camera noise (the same for every run).
    params : RigParams, optional
        Default: :meth:`RigParams.for_design` of ``design``.
    progress : callable, optional
        ``progress(done_runs, total_runs)``.
    controller_params : mapping, optional
        ``{controller: {parameter: value}}``: public parameters of some of the
        ``controllers`` (see their classes, e.g. ``{"bang-bang": {"deadzone": 0.02}}``);
        the others keep their defaults.

    Raises
    ------
    UnknownNameError
        An unknown controller or parameter; the message lists the known names.
    """
    with keyed("controllers"):
        for name in controllers:
            CONTROLLERS.check(name)
    given = dict(controller_params or {})
    for name in given:
        if name not in controllers:
            raise InputError(
                f"name {name!r}, which is not one of the controllers ({', '.join(controllers)})",
                key="controller_params",
            )
    with keyed("controller_params"):
        used = {name: controller_parameters(name, given.get(name)) for name in controllers}
    params = RigParams.for_design(design) if params is None else params
    controller_model = ControllerModel.from_surrogate(model, design, params)
    actuator = controller_model.angle_table if plant_table is None else plant_table
    rows, runs = [], {}
    total = len(controllers) * len(references)
    for name in controllers:
        for spec in references:
            controller = CONTROLLERS.get(name)(controller_model, **used[name])
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
        "controllers": used,
    }
    return ControlStudy(metrics=pd.DataFrame(rows), runs=runs, settings=settings)
