"""Figures of the material fits (paper B Fig. 2a).

* :func:`fit_figure` — measured nominal stress of a uniaxial tensile test with the
  curve of each fitted hyperelastic model, R² and RMSE in the legend.

The figure is drawn on a matplotlib ``Figure`` with the Agg canvas (matplotlib
imported inside the functions, pyplot's global figure registry never touched),
written as one PNG at 150 dpi into a folder created if needed; the function
returns the path written.
"""

from __future__ import annotations

from collections.abc import Mapping, Sequence
from pathlib import Path
from typing import TYPE_CHECKING

import numpy as np

from softbend._validation import check_choice
from softbend.errors import InputError
from softbend.reports.analysis_figures import _figure, _save

if TYPE_CHECKING:
    from softbend.materials.fit import FitResult
    from softbend.materials.tensile import TensileTest

__all__ = ["MODEL_LABELS", "fit_figure"]


#: Legend names of the hyperelastic models.
MODEL_LABELS: dict[str, str] = {
    "neo-hookean": "Neo-Hookean",
    "yeoh": "Yeoh",
    "arruda-boyce": "Arruda–Boyce",
}
_COLORS: dict[str, str] = {
    "neo-hookean": "#1b9e77",
    "yeoh": "#d95f02",
    "arruda-boyce": "#7570b3",
}
_STYLES: dict[str, str] = {"neo-hookean": "--", "yeoh": "-", "arruda-boyce": "-."}


def _source_line(test: TensileTest) -> str:
    """``data: <attribution>`` for shipped data, else the file name."""
    if test.attribution:
        return f"data: {test.attribution}"
    if test.source is not None:
        return f"data: {test.source.name}"
    return f"data: {test.name}"


def fit_figure(
    test: TensileTest,
    results: Mapping[str, FitResult] | Sequence[FitResult],
    path: str | Path,
    *,
    x_axis: str = "stretch",
) -> Path:
    """Draw measured nominal stress and the fitted model curves (paper B Fig. 2a).

    Parameters
    ----------
    test : TensileTest
        The measured test (engineering strain, engineering stress in MPa).
    results : mapping of str to FitResult, or sequence of FitResult
        Fits to draw, e.g. from :func:`softbend.materials.fit_models`. Each curve
        is solid over the stretch range its fit used and dotted beyond it.
    path : str or pathlib.Path
        PNG file to write.
    x_axis : {"stretch", "strain"}, default "stretch"
        Abscissa: stretch ``λ`` or engineering strain ``λ − 1`` (both dimensionless).

    Returns
    -------
    pathlib.Path
        The file written.

    Raises
    ------
    ValueError
        If ``x_axis`` is not ``"stretch"`` or ``"strain"``, or ``results`` is empty.
    """
    check_choice(x_axis, "x_axis", ("stretch", "strain"))
    fits = list(results.values()) if isinstance(results, Mapping) else list(results)
    if not fits:
        raise InputError("must hold at least one fit; got none", key="results")
    shift = 1.0 if x_axis == "stretch" else 0.0
    stretch = test.stretch
    stress = test.engineering_stress_mpa

    fig, ax = _figure((6.4, 4.8))
    n = stretch.size
    step = max(1, n // 120)  # at most ~120 markers: the curves stay visible
    ax.plot(
        stretch[::step] - 1.0 + shift,
        stress[::step],
        linestyle="none",
        marker="o",
        markersize=4.0,
        markerfacecolor="none",
        markeredgecolor="0.25",
        markeredgewidth=0.8,
        label=f"measured ({n} points" + (f", 1 in {step} shown)" if step > 1 else ")"),
    )
    grid = np.linspace(1.0, float(stretch.max()), 400)
    limits: set[float] = set()
    top = float(stress.max())
    for fit in fits:
        high = fit.stretch_range[1]
        color = _COLORS.get(fit.name)
        label = (
            f"{MODEL_LABELS.get(fit.name, fit.name)}: R² = {fit.r2:.4f}, "
            f"RMSE = {fit.rmse_mpa:.4f} MPa"
        )
        inside = grid[grid <= high]
        top = max(top, float(fit.predict(inside).max()))
        (line,) = ax.plot(
            inside - 1.0 + shift,
            fit.predict(inside),
            color=color,
            linestyle=_STYLES.get(fit.name, "-"),
            linewidth=1.8,
            label=label,
        )
        beyond = grid[grid >= high]
        if beyond.size > 1:
            ax.plot(
                beyond - 1.0 + shift,
                fit.predict(beyond),
                color=line.get_color(),
                linestyle=":",
                linewidth=1.2,
            )
            limits.add(high)
    for high in sorted(limits):
        ax.axvline(high - 1.0 + shift, color="0.5", linewidth=0.8, linestyle=":")
    if limits:
        ax.plot([], [], color="0.35", linestyle=":", linewidth=1.2, label="beyond the fitted range")
    ax.set_xlabel("Stretch λ (–)" if x_axis == "stretch" else "Engineering strain (–)")
    ax.set_ylabel("Nominal stress (MPa)")
    ax.set_xlim(left=shift)
    # Extrapolated curves can run far off; the axis follows the data and fitted ranges.
    ax.set_ylim(min(0.0, float(stress.min())), 1.08 * top)
    ax.set_title(
        f"{test.material}: uniaxial tension, hyperelastic fits\n{_source_line(test)}",
        fontsize=10,
    )
    if ax.get_legend_handles_labels()[0]:  # no legend without a label
        ax.legend(loc="upper left", fontsize=8, framealpha=0.9)
    ax.grid(alpha=0.3)
    return _save(fig, path)
