"""Figures of transfer learning (paper B Figs. 6 and 7) and of the virtual lab.

* :func:`loss_curves` — Fig. 6: training MSE per epoch (deg², log scale) of the
  FEM-trained MLP, the refined MLP and the experimental MLP;
* :func:`actuator_panels` — Fig. 7: for every held-out actuator, the measured
  angle against pressure and each strategy's prediction (intervals shaded);
* :func:`learning_curve` — mean held-out RMSE against the number of measured
  actuators;
* :func:`lab_measurements` — the virtual lab's readings, marked synthetic.

Matplotlib is imported inside the functions (Agg canvas, no pyplot state).
"""

from __future__ import annotations

import math
from pathlib import Path
from typing import TYPE_CHECKING

import numpy as np

from softbend.references import TRANSFER_LOSS, values

if TYPE_CHECKING:
    from softbend.transfer.loco import LocoResult
    from softbend.transfer.measurements import Measurements

_DPI = 150

#: Paper B Fig. 6 final losses (deg²): FEM MLP on FEM data, refined after 1000 epochs
#: (:data:`softbend.references.TRANSFER_LOSS`).
PAPER_B_FINAL_LOSS: dict[str, float] = values(TRANSFER_LOSS)

_STYLE = {
    "fem-only": ("tab:gray", "--"),
    "base-mean-residual": ("tab:pink", ":"),
    "analytical": ("tab:brown", ":"),
    "experimental": ("tab:purple", "-."),
    "refined": ("tab:red", "-"),
    "scale-offset": ("tab:olive", "--"),
    "pressure-scale": ("tab:cyan", "--"),
    "residual-gp": ("tab:blue", "-"),
    "refined-ensemble": ("tab:green", "-"),
    "scaled-refined": ("tab:orange", "-"),
}


def _style(name: str) -> tuple[str, str]:
    return _STYLE.get(name, ("black", "-"))


def loss_curves(result: LocoResult, path: Path) -> Path:
    """Paper B Fig. 6: training loss (MSE, deg²) per epoch, log scale, with paper B's."""
    from matplotlib.figure import Figure

    fig = Figure(figsize=(7, 4.2))
    ax = fig.subplots()
    for name, curve in result.loss_curves.items():
        color, line = _style(name)
        label = "FEM MLP (on FEM data)" if name == "fem-only" else name
        ax.plot(
            np.arange(1, curve.size + 1),
            curve,
            color=color,
            ls=line,
            lw=1.2,
            label=f"{label}: final {curve[-1]:.3g} deg²",
        )
    for name, value in PAPER_B_FINAL_LOSS.items():
        color, _ = _style(name)
        ax.axhline(value, color=color, lw=0.6, alpha=0.6)
        ax.annotate(
            f"paper B {name} {value} deg²", (1, value), fontsize=7, color=color, va="bottom"
        )
    ax.set_xscale("log")
    ax.set_yscale("log")
    ax.set_xlabel("epoch")
    ax.set_ylabel("training MSE (deg²)")
    ax.set_title("Training loss on all measured actuators (cf. paper B Fig. 6)", fontsize=10)
    if ax.get_legend_handles_labels()[0]:
        if ax.get_legend_handles_labels()[0]:  # no legend without a label
            ax.legend(fontsize=7)
    else:  # no strategy of this run trains a network (a base without a loss curve)
        ax.text(
            0.5,
            0.5,
            "no strategy of this run records a training loss",
            ha="center",
            va="center",
            transform=ax.transAxes,
        )
    ax.grid(True, which="both", alpha=0.3)
    fig.tight_layout()
    fig.savefig(path, dpi=_DPI)
    return path


def actuator_panels(result: LocoResult, path: Path, *, synthetic: bool = True) -> Path:
    """Paper B Fig. 7: held-out actuators, measured and predicted angle against pressure."""
    pcol = str(result.settings.get("pressure_column", "pressure_mpa"))
    punit = str(result.settings.get("pressure_unit", "MPa"))
    from matplotlib.figure import Figure

    pred = result.predictions
    ids = list(dict.fromkeys(pred["actuator_id"]))
    names = list(dict.fromkeys(pred["strategy"]))
    ncols = min(4, len(ids))
    nrows = math.ceil(len(ids) / ncols)
    fig = Figure(figsize=(4.0 * ncols, 3.4 * nrows + 0.8))
    axes = np.atleast_1d(fig.subplots(nrows, ncols, squeeze=False)).ravel()
    for ax, actuator in zip(axes, ids, strict=False):
        part = pred[pred["actuator_id"] == actuator]
        first = part[part["strategy"] == names[0]]
        for direction, marker in (("loading", "o"), ("unloading", "v")):
            rows = first[first["direction"] == direction]
            if len(rows):
                ax.plot(
                    rows[pcol],
                    rows["angle_deg"],
                    marker,
                    ms=3.5,
                    mfc="none",
                    color="black",
                    label=f"measured ({direction})",
                )
        for name in names:
            rows = part[part["strategy"] == name].sort_values(pcol)
            rows = rows[rows["direction"] == rows["direction"].iloc[0]]
            color, line = _style(name)
            score = result.per_actuator[
                (result.per_actuator["strategy"] == name)
                & (result.per_actuator["actuator_id"] == actuator)
            ]["rmse_deg"]
            ax.plot(
                rows[pcol],
                rows["predicted_deg"],
                color=color,
                ls=line,
                lw=1.1,
                label=f"{name} ({float(score.iloc[0]):.1f}°)",
            )
            if "lo_deg" in rows and rows["lo_deg"].notna().all():
                ax.fill_between(
                    rows[pcol],
                    rows["lo_deg"],
                    rows["hi_deg"],
                    color=color,
                    alpha=0.12,
                    lw=0,
                )
        ax.set_title(f"held out ({actuator})", fontsize=9)
        ax.set_xlabel(f"pressure ({punit})")
        ax.set_ylabel("bending angle (°)")
        ax.grid(True, alpha=0.3)
        if ax.get_legend_handles_labels()[0]:  # no legend without a label
            ax.legend(fontsize=6, loc="upper left")
    for ax in axes[len(ids) :]:
        ax.set_visible(False)
    kind = "virtual-lab (synthetic) measurements" if synthetic else "measurements"
    fig.suptitle(
        f"Leave one configuration out on {kind}: each actuator predicted by models "
        f"trained on the others (cf. paper B Fig. 7); RMSE in the legend; "
        f"{result.level:.0%} intervals shaded",
        fontsize=10,
    )
    fig.tight_layout()
    fig.savefig(path, dpi=_DPI)
    return path


def learning_curve(result: LocoResult, path: Path) -> Path:
    """Mean held-out RMSE against the number of measured actuators, per strategy."""
    from matplotlib.figure import Figure

    fig = Figure(figsize=(6.5, 4))
    ax = fig.subplots()
    curve = result.learning_curve
    for name, part in curve.groupby("strategy", sort=False):
        stats = part.groupby("n_actuators")["rmse_deg"].mean()
        color, line = _style(str(name))
        ax.plot(stats.index, stats.to_numpy(), marker="o", color=color, ls=line, label=name)
    for name in ("fem-only", "analytical"):
        rows = result.summary[result.summary["strategy"] == name]
        if len(rows):
            color, line = _style(name)
            ax.axhline(
                float(rows["rmse_deg"].iloc[0]),
                color=color,
                ls=line,
                lw=0.8,
                label=f"{name} (no measurements)",
            )
    ax.set_xlabel("measured actuators used for training")
    ax.set_ylabel("mean held-out RMSE (°)")
    ax.set_title("Learning curve: how many prototypes to measure", fontsize=10)
    ax.grid(True, alpha=0.3)
    if ax.get_legend_handles_labels()[0]:  # no legend without a label
        ax.legend(fontsize=7)
    fig.tight_layout()
    fig.savefig(path, dpi=_DPI)
    return path


def lab_measurements(measurements: Measurements, path: Path) -> Path:
    """The readings of every actuator against pressure; the title says when synthetic."""
    from matplotlib.figure import Figure

    frame = measurements.frame
    fig = Figure(figsize=(7, 4.5))
    ax = fig.subplots()
    for actuator, part in frame.groupby("actuator_id", sort=False):
        loading = part[part["direction"] == "loading"]
        line = ax.plot(
            loading["pressure_mpa"], loading["angle_deg"], "o-", ms=3, lw=0.8, label=str(actuator)
        )[0]
        unloading = part[part["direction"] == "unloading"]
        if len(unloading):
            ax.plot(
                unloading["pressure_mpa"],
                unloading["angle_deg"],
                "v--",
                ms=3,
                lw=0.8,
                color=line.get_color(),
            )
    synthetic = str(measurements.metadata.get("synthetic", "")).startswith("true")
    ax.set_xlabel("pressure (MPa)")
    ax.set_ylabel("bending angle (°)")
    ax.set_title(
        ("SYNTHETIC virtual-lab measurements" if synthetic else "Measurements")
        + f" ({len(frame)} readings, {frame['actuator_id'].nunique()} actuators)",
        fontsize=10,
    )
    if synthetic:
        gap = ", ".join(
            f"{k[4:]}={measurements.metadata[k]}"
            for k in (
                "lab.fabrication_error_mm",
                "lab.hysteresis",
                "lab.camera_noise_deg",
                "lab.seed",
                "lab.plant",
            )
            if k in measurements.metadata
        )
        fig.text(0.01, 0.01, f"reality gap: {gap}", fontsize=7)
    ax.grid(True, alpha=0.3)
    if ax.get_legend_handles_labels()[0]:  # no legend without a label
        ax.legend(title="actuator (l,r,t,b,φ,lc)", fontsize=7, title_fontsize=7)
    fig.tight_layout(rect=(0, 0.03, 1, 1))
    fig.savefig(path, dpi=_DPI)
    return path
