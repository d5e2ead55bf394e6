"""Paper B §5 (Figs. 8–9): closed-loop control on the simulated rig, with model mismatch.

:func:`run_control` runs :func:`softbend.control.study.control_study` three
times on paper B's (100,6,2,2,5,8) actuator: with the plant equal to the
controllers' model (the shipped FEM-trained MLP), and with the virtual lab's
measured actuator as the plant, once with the FEM-trained MLP and once with that
MLP refined on the lab's readings (paper B's method).
"""

from __future__ import annotations

import time
from collections.abc import Callable
from dataclasses import dataclass
from pathlib import Path
from typing import TYPE_CHECKING, Any

from softbend.design import parse_sfrba
from softbend.pipeline import Progress

if TYPE_CHECKING:  # pragma: no cover
    from softbend.control.study import ControlStudy
    from softbend.surrogates.protocol import Surrogate

__all__ = ["CONTROL_DESIGN", "Control", "run_control"]

#: The actuator of the control experiments: the reference design of paper B Fig. 7b
#: (paper B §5 does not say which actuator it controlled).
CONTROL_DESIGN = "100,6,2,2,5,8"


@dataclass(frozen=True)
class Control:
    """What :func:`run_control` ran.

    Attributes
    ----------
    nominal : ControlStudy
        The simulated rig, plant and model the FEM-trained MLP.
    mismatch : ControlStudy
        The lab actuator as the plant, the FEM-trained MLP as the model.
    refined : ControlStudy
        The lab actuator as the plant, the MLP refined on the lab's readings.
    duration_s : float
        Length of every run, s.
    seed : int
        Seed of the rig's noise and of the refined MLP.
    files : dict
        ``{"rig", "lab_fem_mlp", "lab_refined_mlp"}``: the metrics tables (CSV).
    summary : dict
        Wall time and the three studies' metrics, one record per run.
    """

    nominal: ControlStudy
    mismatch: ControlStudy
    refined: ControlStudy
    duration_s: float
    seed: int
    files: dict[str, Path]
    summary: dict[str, Any]


def _refined(base: Surrogate, seed: int, epochs: int | None) -> Surrogate:
    """The shipped MLP refined on all the shipped lab readings (``transfer refine``)."""
    from softbend.transfer.lab import shipped_measurements
    from softbend.transfer.strategies import fit_strategy

    return fit_strategy("refined", base, shipped_measurements(), seed=seed, epochs=epochs).model_


def run_control(
    out_dir: Path,
    seed: int = 0,
    progress: Progress | None = None,
    *,
    duration_s: float = 10.0,
    refine_epochs: int | None = None,
) -> Control:
    """Run the control studies; write their metrics to ``out_dir/control/metrics_*.csv``.

    Parameters
    ----------
    out_dir : path
        The report's folder.
    seed : int
        Seed of the rig's noise and of the refined MLP.
    progress : callable, optional
        ``progress(phase, done, total)`` in runs.
    duration_s : float, default 10
        Length of every run, s.
    refine_epochs : int, optional
        Epochs of the refined MLP (default: the strategy's; fewer for a quick run).
    """
    from softbend.control.plants import lab_angle_table
    from softbend.control.study import control_study
    from softbend.transfer.base import load_base

    start = time.perf_counter()
    folder = Path(out_dir) / "control"
    folder.mkdir(parents=True, exist_ok=True)
    design = parse_sfrba(CONTROL_DESIGN)
    base = load_base()

    def step(phase: str) -> Callable[[int, int], None]:
        def forward(done: int, total: int) -> None:
            if progress is not None:
                progress(f"control: {phase}", done, total)

        return forward

    nominal = control_study(base, design, duration_s=duration_s, seed=seed, progress=step("rig"))
    lab = lab_angle_table(design)
    mismatch = control_study(
        base, design, plant_table=lab, plant="lab", duration_s=duration_s, seed=seed,
        progress=step("lab, FEM-trained MLP"),
    )  # fmt: skip
    refined = control_study(
        _refined(base, seed, refine_epochs), design, plant_table=lab, plant="lab",
        duration_s=duration_s, seed=seed, progress=step("lab, refined MLP"),
    )  # fmt: skip
    files = {
        "rig": folder / "metrics_rig.csv",
        "lab_fem_mlp": folder / "metrics_lab_fem_mlp.csv",
        "lab_refined_mlp": folder / "metrics_lab_refined_mlp.csv",
    }
    nominal.metrics.to_csv(files["rig"], index=False)
    mismatch.metrics.to_csv(files["lab_fem_mlp"], index=False)
    refined.metrics.to_csv(files["lab_refined_mlp"], index=False)
    summary = {
        "seconds": time.perf_counter() - start,
        "rig": nominal.metrics.to_dict(orient="records"),
        "lab_fem_mlp": mismatch.metrics.to_dict(orient="records"),
        "lab_refined_mlp": refined.metrics.to_dict(orient="records"),
    }
    return Control(nominal, mismatch, refined, duration_s, seed, files, summary)
