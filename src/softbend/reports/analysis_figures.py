"""Figures of the preliminary campaign analysis (paper B Fig. 4).

* :func:`correlation_heatmap` — Pearson correlation matrix (Fig. 4a);
* :func:`loadings_bar` — standardized regression coefficients with
  significance stars (Fig. 4b);
* :func:`parity_plot` — angle fitted by the linear model against the observed
  angle (Fig. 4c);
* :func:`campaign_analysis_figures` — the three of a
  :class:`~softbend.analysis.CampaignAnalysis` into one folder.

Each function draws on a matplotlib ``Figure`` with the Agg canvas (matplotlib
imported inside the functions, pyplot's global figure registry never touched),
writes one PNG at 150 dpi, creates the parent folder if needed and returns the
path written.
"""

from __future__ import annotations

import math
from pathlib import Path
from typing import TYPE_CHECKING

import numpy as np

from softbend.errors import InputError

if TYPE_CHECKING:
    import pandas as pd

    from softbend.analysis import CampaignAnalysis, RegressionReport

__all__ = [
    "campaign_analysis_figures",
    "column_label",
    "correlation_heatmap",
    "loadings_bar",
    "parity_plot",
]

_DPI = 150

#: Axis labels with units for the campaign columns.
_LABELS: dict[str, str] = {
    "l_mm": "l (mm)",
    "r_mm": "r (mm)",
    "t_mm": "t (mm)",
    "b_mm": "b (mm)",
    "phi_deg": "φ (°)",
    "lc_mm": "lc (mm)",
    "pressure_mpa": "P_act (MPa)",
    "angle_deg": "θ (°)",
    "tip_x_mm": "tip x (mm)",
    "tip_z_mm": "tip z (mm)",
}

#: Short symbols (no unit) for bar labels.
_SYMBOLS: dict[str, str] = {
    "l_mm": "l",
    "r_mm": "r",
    "t_mm": "t",
    "b_mm": "b",
    "phi_deg": "φ",
    "lc_mm": "lc",
    "pressure_mpa": "P_act",
    "angle_deg": "θ",
}


def column_label(name: str) -> str:
    """Readable axis label with unit for a campaign column (``"t_mm"`` → ``"t (mm)"``)."""
    return _LABELS.get(name, name)


def _figure(figsize: tuple[float, float]):
    """A figure drawn by the Agg canvas, outside pyplot's global state."""
    from matplotlib.backends.backend_agg import FigureCanvasAgg
    from matplotlib.figure import Figure

    fig = Figure(figsize=figsize)
    FigureCanvasAgg(fig)
    return fig, fig.subplots()


def _save(fig, path: str | Path) -> Path:
    out = Path(path)
    out.parent.mkdir(parents=True, exist_ok=True)
    fig.savefig(out, dpi=_DPI, bbox_inches="tight", format="png")
    return out


def correlation_heatmap(corr: pd.DataFrame, path: str | Path, *, title: str | None = None) -> Path:
    """Draw an annotated Pearson correlation matrix (paper B Fig. 4a).

    Parameters
    ----------
    corr : pandas.DataFrame
        Square correlation matrix, e.g. from
        :func:`softbend.analysis.correlation_matrix`. NaN cells (a constant
        column) are drawn grey and marked "n/a".
    path : str or pathlib.Path
        PNG file to write.
    title : str, optional
        Figure title; default "Pearson correlation".

    Returns
    -------
    pathlib.Path
        The file written.
    """
    values = np.asarray(corr.to_numpy(), dtype=float)
    if values.ndim != 2 or values.shape[0] != values.shape[1]:
        raise InputError(f"must be a square matrix; got shape {values.shape}", key="corr")
    rows = [column_label(str(c)) for c in corr.index]
    cols = [column_label(str(c)) for c in corr.columns]
    k = len(cols)
    size = max(4.5, 0.75 * k + 2.0)
    import matplotlib

    fig, ax = _figure((size + 1.0, size))
    cmap = matplotlib.colormaps["RdBu_r"].with_extremes(bad="0.85")
    image = ax.imshow(np.ma.masked_invalid(values), cmap=cmap, vmin=-1.0, vmax=1.0)
    colorbar = fig.colorbar(image, ax=ax, fraction=0.046, pad=0.04)
    colorbar.set_label("Pearson r")
    ax.set_xticks(range(k), labels=cols, rotation=45, ha="right", rotation_mode="anchor")
    ax.set_yticks(range(k), labels=rows)
    fontsize = 9 if k <= 10 else 7
    for i in range(k):
        for j in range(k):
            v = values[i, j]
            text = "n/a" if math.isnan(v) else f"{v:.2f}"
            color = "white" if (not math.isnan(v) and abs(v) > 0.6) else "black"
            ax.text(j, i, text, ha="center", va="center", color=color, fontsize=fontsize)
    ax.set_xticks(np.arange(-0.5, k, 1.0), minor=True)
    ax.set_yticks(np.arange(-0.5, k, 1.0), minor=True)
    ax.grid(which="minor", color="white", linewidth=1.0)
    ax.tick_params(which="minor", length=0)
    ax.set_title(title or "Pearson correlation")
    return _save(fig, path)


def loadings_bar(report: RegressionReport, path: str | Path, *, sort: bool = False) -> Path:
    """Draw the standardized regression coefficients with significance stars (Fig. 4b).

    Parameters
    ----------
    report : RegressionReport
        From :func:`softbend.analysis.standardized_regression`.
    path : str or pathlib.Path
        PNG file to write.
    sort : bool, default False
        Order the bars by decreasing absolute loading instead of feature order.

    Returns
    -------
    pathlib.Path
        The file written.

    Notes
    -----
    Stars: ``***`` p ≤ 0.001, ``**`` p ≤ 0.01, ``*`` p ≤ 0.05 (two-sided
    t-test of a zero coefficient).
    """
    table = report.coefficients
    if sort:
        table = table.reindex(table["loading"].abs().sort_values(ascending=False).index)
    names = [_SYMBOLS.get(str(f), str(f)) for f in table.index]
    loadings = table["loading"].to_numpy(dtype=float)
    stars = [str(s) for s in table["stars"]]
    colors = ["#b2182b" if v >= 0 else "#2166ac" for v in loadings]
    fig, ax = _figure((max(5.0, 0.8 * len(names) + 2.0), 4.2))
    x = np.arange(len(names))
    ax.bar(x, loadings, color=colors, edgecolor="black", linewidth=0.6, width=0.65)
    ax.axhline(0.0, color="black", linewidth=0.8)
    span = max(float(np.nanmax(np.abs(loadings))), 1e-3)
    offset = 0.03 * span
    for xi, v, s in zip(x, loadings, stars, strict=True):
        label = f"{v:.3f}{s}"
        if v >= 0:
            ax.text(xi, v + offset, label, ha="center", va="bottom", fontsize=9)
        else:
            ax.text(xi, v - offset, label, ha="center", va="top", fontsize=9)
    low = min(0.0, float(np.nanmin(loadings))) - 0.2 * span
    high = max(0.0, float(np.nanmax(loadings))) + 0.2 * span
    ax.set_ylim(low, high)
    ax.set_xticks(x, labels=names)
    ax.set_xlabel("Input variable")
    symbol = _SYMBOLS.get(report.target, report.target)
    ax.set_ylabel(f"Standardized coefficient on {symbol} (dimensionless)")
    ax.set_title(
        f"Standardized regression loadings (n = {report.n_samples})\n"
        "* p ≤ 0.05, ** p ≤ 0.01, *** p ≤ 0.001",
        fontsize=10,
    )
    ax.grid(axis="y", alpha=0.3)
    ax.set_axisbelow(True)
    return _save(fig, path)


def parity_plot(report: RegressionReport, path: str | Path) -> Path:
    """Draw the fitted against the observed target with the y = x line (Fig. 4c).

    Parameters
    ----------
    report : RegressionReport
        From :func:`softbend.analysis.standardized_regression`.
    path : str or pathlib.Path
        PNG file to write.

    Returns
    -------
    pathlib.Path
        The file written.
    """
    observed = np.asarray(report.observed, dtype=float)
    fitted = np.asarray(report.fitted, dtype=float)
    label = column_label(report.target)
    symbol = _SYMBOLS.get(report.target, report.target)
    unit = " °" if report.target.endswith("_deg") else ""
    fig, ax = _figure((5.2, 5.0))
    n = observed.size
    marker_size = 14.0 if n <= 500 else (6.0 if n <= 5000 else 2.0)
    mape = "n/a" if math.isnan(report.mape_pct) else f"{report.mape_pct:.1f} %"
    ax.scatter(
        observed,
        fitted,
        s=marker_size,
        alpha=0.6 if n <= 5000 else 0.3,
        color="#2166ac",
        edgecolors="none",
        rasterized=n > 2000,
        label=(
            f"linear fit, n = {n}\nR² = {report.r2:.4f}, MAPE = {mape}\n"
            f"(MAPE over |{symbol}| ≥ {report.mape_threshold:g}{unit})"
        ),
    )
    both = np.concatenate([observed, fitted])
    low, high = float(both.min()), float(both.max())
    pad = 0.05 * max(high - low, 1e-9)
    lims = (low - pad, high + pad)
    ax.plot(lims, lims, color="black", linewidth=1.0, linestyle="--", label="y = x")
    ax.set_xlim(lims)
    ax.set_ylim(lims)
    ax.set_aspect("equal")
    ax.set_xlabel(f"Observed {label}")
    ax.set_ylabel(f"Fitted {label}")
    ax.set_title(f"Multiple linear regression: R² = {report.r2:.4f}, F = {report.f_value:.4g}")
    markerscale = max(1.0, 12.0 / marker_size)
    if ax.get_legend_handles_labels()[0]:  # no legend without a label
        ax.legend(loc="upper left", fontsize=8, framealpha=0.9, markerscale=markerscale)
    ax.grid(alpha=0.3)
    return _save(fig, path)


def campaign_analysis_figures(
    analysis: CampaignAnalysis,
    folder: str | Path,
    *,
    correlation_png: str = "correlation.png",
    loadings_png: str = "loadings.png",
    parity_png: str = "parity.png",
) -> dict[str, Path]:
    """Draw the three figures of paper B Fig. 4 of a campaign analysis into ``folder``.

    Parameters
    ----------
    analysis : CampaignAnalysis
        From :func:`softbend.analysis.analyze_samples`.
    folder : str or pathlib.Path
        Folder for the PNG files (created if missing).
    correlation_png, loadings_png, parity_png : str
        File names of :func:`correlation_heatmap`, :func:`loadings_bar` and
        :func:`parity_plot`, drawn in this order.

    Returns
    -------
    dict of str to pathlib.Path
        The files written, under the keys ``"correlation"``, ``"loadings"`` and
        ``"parity"``.
    """
    folder = Path(folder)
    return {
        "correlation": correlation_heatmap(analysis.correlation, folder / correlation_png),
        "loadings": loadings_bar(analysis.regression, folder / loadings_png),
        "parity": parity_plot(analysis.regression, folder / parity_png),
    }
