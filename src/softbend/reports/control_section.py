"""Paper B §5 (Figs. 8–9): closed-loop control on the simulated rig, with model mismatch.

:func:`softbend.pipeline.control.run_control` runs the studies on paper B's
(100,6,2,2,5,8) actuator: with the plant equal to the controllers' model (the
shipped FEM-trained MLP), and with the virtual lab's measured actuator as the
plant, once with the FEM-trained MLP and once with that MLP refined on the lab's
readings (paper B's method); :func:`add_section` draws them and reports paper
B's numbers beside.
"""

from __future__ import annotations

import math
import time
from pathlib import Path
from typing import TYPE_CHECKING, Any

from softbend.pipeline import Progress
from softbend.pipeline.control import CONTROL_DESIGN, Control
from softbend.reports.html import Report

if TYPE_CHECKING:
    import pandas as pd

__all__ = ["CONTROL_DESIGN", "add_control", "add_section"]


def _cell(metrics: pd.DataFrame, controller: str, reference: str, name: str) -> float | str:
    rows = metrics[(metrics["controller"] == controller) & (metrics["reference"] == reference)]
    value = float(rows[name].iloc[0]) if len(rows) and name in rows else math.nan
    return "" if value != value else value


def add_section(
    report: Report,
    out_dir: Path,
    seed: int,
    progress: Progress | None = None,
    *,
    duration_s: float = 10.0,
    refine_epochs: int | None = None,
) -> dict[str, Any]:
    """Append the control section to ``report``; return the headline figures.

    Parameters
    ----------
    report : Report
    out_dir : path
        The report's folder; tables and figures go to ``out_dir/control``.
    seed : int
        Seed of the rig's noise and of the refined MLP.
    progress : callable, optional
    duration_s : float, default 10
        Length of every run, s.
    refine_epochs : int, optional
        Epochs of the refined MLP (default: the strategy's; fewer for a quick run).
    """
    from softbend.pipeline.control import run_control

    start = time.perf_counter()
    control = run_control(
        out_dir, seed, progress, duration_s=duration_s, refine_epochs=refine_epochs
    )
    figures = add_control(report, control, out_dir)
    return {
        **control.summary,
        "seconds": time.perf_counter() - start,
        "files": {k: str(v) for k, v in figures.items()},
    }


def add_control(report: Report, control: Control, root: Path) -> dict[str, Path]:
    """Draw Fig. 9 and the mismatch runs into ``root/control``; add the section.

    Returns
    -------
    dict
        ``{"square", "triangle", "lab"}`` paths of the figures.
    """
    from softbend.control.study import PAPER_B_CONTROL, STUDY_REFERENCES
    from softbend.references import CONTROL_RESULTS
    from softbend.reports.control_figures import runs_figure

    folder = root / "control"
    nominal, mismatch, refined = control.nominal, control.mismatch, control.refined
    duration_s, seed = control.duration_s, control.seed
    step_ref, square, triangle = STUDY_REFERENCES
    figures = {
        "square": runs_figure(
            {c: nominal.runs[(c, square)] for c in ("bang-bang", "predictive")},
            folder / "fig9_square.png",
            f"{square}: paper B's bang-bang and the predictive controller (simulated rig)",
        ),
        "triangle": runs_figure(
            {c: nominal.runs[(c, triangle)] for c in ("bang-bang", "predictive")},
            folder / "fig9_triangle.png",
            f"{triangle}: paper B's bang-bang and the predictive controller (simulated rig)",
        ),
        "lab": runs_figure(
            {
                "FEM-trained MLP": mismatch.runs[("predictive", square)],
                "refined MLP": refined.runs[("predictive", square)],
            },
            folder / "lab_square.png",
            f"predictive on the lab actuator, {square}: the model's error is the loop's",
        ),
    }

    section = report.section("Paper B — closed-loop control (Figs. 8 and 9)")
    params = nominal.settings["rig"]
    section.text(
        f"SIMULATED rig: paper B's rig parameters are not given, so these are softbend's stated "
        f"defaults (RigParams): supply {params['supply_gauge_mpa']:g} MPa, ISO 6358 valves "
        f"C = {params['inlet_conductance_m3_s_pa']:g} m³/(s·Pa), b = {params['critical_ratio']:g}, "
        f"{params['valve_delay_s'] * 1e3:g} ms switching delay, a compliant chamber, the angle "
        f"lagging θ(p) by {params['angle_time_constant_s'] * 1e3:g} ms, a 100 Hz pressure sensor "
        f"with {params['sensor_noise_mpa'] * 1e3:g} kPa noise, a {params['camera_fps']:g} fps "
        f"camera for scoring. Actuator ({CONTROL_DESIGN}); θ(p) and the virtual angle sensor "
        f"are the shipped FEM-trained MLP; {duration_s:g} s per run, seed {seed}.",
        note=True,
    )
    rows = []
    for c in nominal.metrics["controller"].unique():
        m = nominal.metrics
        rows.append(
            [
                c,
                _cell(m, c, step_ref, "mape_pct"),
                _cell(m, c, step_ref, "switches"),
                _cell(m, c, square, "mape_pct"),
                _cell(m, c, square, "rise_s"),
                _cell(m, c, square, "settling_s"),
                _cell(m, c, square, "switches"),
                _cell(m, c, triangle, "mape_pct"),
                _cell(m, c, triangle, "delay_s"),
                _cell(m, c, triangle, "switches"),
            ]
        )
    sq, tr = PAPER_B_CONTROL["square"], PAPER_B_CONTROL["triangle"]
    rows.append(
        ["paper B bang-bang (its rig)", "", "", sq["mape_pct"], sq["rise_s"], sq["settling_s"],
         "", tr["mape_pct"], tr["delay_s"], ""]
    )  # fmt: skip
    section.table(
        [
            "controller",
            "step MAPE (%)",
            "step switches",
            "square MAPE (%)",
            "square rise (s)",
            "square settling (s)",
            "square switches",
            "triangle MAPE (%)",
            "triangle delay (s)",
            "triangle switches",
        ],
        rows,
        caption=(
            f"{step_ref}, {square} and {triangle} on the simulated rig; MAPE of the camera "
            "angle where θr ≥ 5°, settling into ±5 %, delay by cross-correlation; paper B's "
            f"row: {CONTROL_RESULTS['square']['mape_pct'].cite()} and "
            f"{CONTROL_RESULTS['triangle']['mape_pct'].source}"
        ),
    )
    bb_sq = nominal.metric("bang-bang", square, "mape_pct")
    best_sq = nominal.metric("predictive", square, "mape_pct")
    section.text(
        f"Paper B's bang-bang here: square MAPE {bb_sq:.2f} % against its {sq['mape_pct']} % "
        f"({CONTROL_RESULTS['square']['mape_pct'].cite()}). The predictive "
        f"controller (the rig model's fill and vent responses, an observer between sensor "
        f"samples, pulses timed to end on the target pressure) gives {best_sq:.2f} % with "
        f"{nominal.metric('predictive', square, 'switches'):.0f} switches against "
        f"{nominal.metric('bang-bang', square, 'switches'):.0f}; on the triangle "
        f"{nominal.metric('predictive', triangle, 'mape_pct'):.2f} % against "
        f"{nominal.metric('bang-bang', triangle, 'mape_pct'):.2f} %. On the square wave each "
        f"0 → 90° edge costs the fill time at full flow, which no controller of these valves "
        f"avoids.",
        note=True,
    )
    section.figure(figures["square"], "Fig. 9 (square wave), simulated rig", root=root)
    section.figure(figures["triangle"], "Fig. 9 (triangle), simulated rig", root=root)
    lab_rows = []
    for c in mismatch.metrics["controller"].unique():
        lab_rows.append(
            [c]
            + [_cell(mismatch.metrics, c, r, "mape_pct") for r in STUDY_REFERENCES]
            + [_cell(refined.metrics, c, r, "mape_pct") for r in STUDY_REFERENCES]
        )
    section.table(
        ["controller"]
        + [f"{r}, FEM-trained MLP (%)" for r in STUDY_REFERENCES]
        + [f"{r}, refined MLP (%)" for r in STUDY_REFERENCES],
        lab_rows,
        caption=(
            "MAPE on the virtual lab's actuator (SYNTHETIC: its smoothed loading readings as "
            "the plant) with the controllers' model the FEM-trained MLP, or that MLP refined "
            "on the lab's readings"
        ),
    )
    section.text(
        "Every controller here trusts its model: with the FEM-trained MLP the actuator bends "
        "more than the model says and the loop's error is the model's; refined on the lab's "
        "readings, the same controllers come back to their nominal figures. This is why paper "
        "B refines its MLP before closing the loop with it.",
        note=True,
    )
    section.figure(figures["lab"], "Model mismatch on the lab actuator", root=root)
    return figures
