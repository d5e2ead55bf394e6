"""Paper A figures: measured tip positions, ρ and L against pressure, identified vs measured.

Figure numbers follow paper A: Fig. 5 tip positions, Fig. 6 bending grade ρ,
Fig. 7 arc length L (each for positive and negative pressure), Figs. 9–10 the
identified ρ and L against the measured ones. Each function writes one PNG and
returns its path. Every figure of synthetic data says so in its title.
"""

from __future__ import annotations

from collections.abc import Mapping, Sequence
from pathlib import Path
from typing import TYPE_CHECKING

import numpy as np

if TYPE_CHECKING:  # pragma: no cover
    from softbend.identification.data import Experiment
    from softbend.identification.study import IdentificationResult

_LABELS = {"rho": "bending grade ρ (–)", "length_mm": "arc length L (mm)"}
_SIGN_TITLES = {"positive": "positive pressure", "negative": "negative pressure (vacuum)"}


def _pyplot():
    import matplotlib

    matplotlib.use("Agg")
    import matplotlib.pyplot as plt

    return plt


def _suffix(experiments: Mapping[str, Sequence[Experiment]]) -> str:
    synthetic = any(e.synthetic for group in experiments.values() for e in group)
    return " — synthetic data" if synthetic else ""


def _save(fig, path: Path) -> Path:
    path = Path(path)
    path.parent.mkdir(parents=True, exist_ok=True)
    fig.savefig(path, dpi=130, bbox_inches="tight")
    _pyplot().close(fig)
    return path


def tip_positions(experiments: Mapping[str, Sequence[Experiment]], path: Path) -> Path:
    """Paper A Fig. 5: measured tip positions (x, y), coloured by pressure."""
    plt = _pyplot()
    signs = list(experiments)
    fig, axes = plt.subplots(1, len(signs), figsize=(5.2 * len(signs), 4.6), squeeze=False)
    for ax, sign in zip(axes[0], signs, strict=True):
        group = experiments[sign]
        pressure = np.concatenate([e.pressure_kpa for e in group])
        x = np.concatenate([e.x_mm for e in group])
        y = np.concatenate([e.y_mm for e in group])
        points = ax.scatter(x, y, c=pressure, s=4, cmap="viridis")
        rest = group[0].rest_length_mm
        ax.plot([0, 0], [rest, 0], "k--", lw=1, label="actuator at rest")
        ax.plot(0, rest, "ks", ms=6, label="fixed base")
        ax.set_aspect("equal", adjustable="datalim")
        ax.set_xlabel("tip x (mm)")
        ax.set_ylabel("tip y (mm)")
        ax.set_title(_SIGN_TITLES.get(sign, sign))
        if ax.get_legend_handles_labels()[0]:  # no legend without a label
            ax.legend(loc="best", fontsize=8)
        fig.colorbar(points, ax=ax, label="pressure (kPa)")
    fig.suptitle("Measured tip positions (paper A Fig. 5)" + _suffix(experiments))
    return _save(fig, path)


def output_vs_pressure(
    experiments: Mapping[str, Sequence[Experiment]], output: str, path: Path
) -> Path:
    """Paper A Fig. 6 (``output="rho"``) or Fig. 7 (``"length_mm"``) against pressure."""
    plt = _pyplot()
    number = {"rho": 6, "length_mm": 7}[output]
    signs = list(experiments)
    fig, axes = plt.subplots(1, len(signs), figsize=(5.2 * len(signs), 4.0), squeeze=False)
    for ax, sign in zip(axes[0], signs, strict=True):
        for experiment in experiments[sign]:
            ax.plot(
                experiment.pressure_kpa,
                getattr(experiment, output),
                ".",
                ms=2,
                alpha=0.6,
                label=experiment.name,
            )
        ax.set_xlabel("pressure (kPa)")
        ax.set_ylabel(_LABELS[output])
        ax.set_title(_SIGN_TITLES.get(sign, sign))
        ax.grid(alpha=0.3)
        if ax.get_legend_handles_labels()[0]:  # no legend without a label
            ax.legend(fontsize=7, markerscale=4, ncol=2)
    name = "bending grade ρ" if output == "rho" else "arc length L"
    fig.suptitle(
        f"Calculated {name} against pressure (paper A Fig. {number})" + _suffix(experiments)
    )
    return _save(fig, path)


def identified_vs_measured(result: IdentificationResult, output: str, path: Path) -> Path:
    """Paper A Fig. 9 (ρ) or Fig. 10 (L): held-out experiments, measured and identified.

    Each experiment is predicted by the model trained on the others; the panels
    show the experiments one after another on a common time axis.
    """
    plt = _pyplot()
    number = {"rho": 9, "length_mm": 10}[output]
    signs = list(result.experiments)
    fig, axes = plt.subplots(len(signs), 1, figsize=(11, 3.4 * len(signs)), squeeze=False)
    for ax, sign in zip(axes[:, 0], signs, strict=True):
        offset = 0.0
        for i, experiment in enumerate(result.experiments[sign]):
            t = experiment.time_s - experiment.time_s[0] + offset
            pred = result.predictions[(sign, output, experiment.name)]
            first = i == 0
            ax.plot(
                t,
                getattr(experiment, output),
                color="0.3",
                lw=1.0,
                label="measured" if first else None,
            )
            ax.plot(
                t,
                pred["one-step"],
                color="tab:blue",
                lw=0.8,
                ls=":",
                label="one-step ahead" if first else None,
            )
            ax.plot(
                t,
                pred["free-run"],
                color="tab:red",
                lw=1.0,
                label="free-run simulation" if first else None,
            )
            ax.axvline(offset, color="0.8", lw=0.8)
            offset = t[-1] + experiment.dt_s
        rows = result.metrics.query("sign == @sign and output == @output and mode == 'free-run'")
        ax.set_title(
            f"{_SIGN_TITLES.get(sign, sign)}: held-out free-run NRMSE "
            f"{100 * rows['nrmse'].mean():.2f} % (mean), fit {rows['fit_percent'].mean():.1f} %"
        )
        ax.set_xlabel("time, experiments one after another (s)")
        ax.set_ylabel(_LABELS[output])
        ax.grid(alpha=0.3)
        if ax.get_legend_handles_labels()[0]:  # no legend without a label
            ax.legend(loc="upper right", fontsize=8)
    name = "bending grade ρ" if output == "rho" else "arc length L"
    fig.suptitle(
        f"Identified {name}, leave-one-experiment-out (paper A Fig. {number})"
        + _suffix(result.experiments)
    )
    fig.tight_layout()
    return _save(fig, path)


def all_figures(result: IdentificationResult, out_dir: Path) -> dict[str, Path]:
    """Write paper A Figs. 5, 6, 7, 9 and 10 into ``out_dir``; return ``{name: path}``."""
    out_dir = Path(out_dir)
    return {
        "fig5_tip_positions": tip_positions(result.experiments, out_dir / "fig5_tip_positions.png"),
        "fig6_bending_grade": output_vs_pressure(
            result.experiments, "rho", out_dir / "fig6_bending_grade.png"
        ),
        "fig7_arc_length": output_vs_pressure(
            result.experiments, "length_mm", out_dir / "fig7_arc_length.png"
        ),
        "fig9_identified_rho": identified_vs_measured(
            result, "rho", out_dir / "fig9_identified_rho.png"
        ),
        "fig10_identified_length": identified_vs_measured(
            result, "length_mm", out_dir / "fig10_identified_length.png"
        ),
    }
