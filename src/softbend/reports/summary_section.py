"""The report's first screen: every headline figure of softbend beside the papers'.

:func:`add_summary` puts one table before every other section: each row a
figure softbend measured in this run, the paper's figure beside it (from
:mod:`softbend.references`, with its table, figure or section) and a link to the
section that shows it. A figure this run could not compute says why instead of
a number; a run made with reduced settings (fewer designs, fewer epochs, a
stand-in dataset, as the tests make) says so at the top.
"""

from __future__ import annotations

import math
from collections.abc import Callable, Mapping
from typing import Any

from softbend.references import (
    CONTROL_RESULTS,
    LINEAR_MODEL,
    SURROGATES,
    TRANSFER_RESULTS,
    Reference,
)
from softbend.reports.html import Link, Report, Section

__all__ = ["add_summary", "headline_rows", "validation_markdown"]

#: Section titles (their start) that the summary links to, by key.
_SECTIONS = {
    "paper_a": "Paper A",
    "paper_b": "Paper B — design space",
    "fem_data": "Paper B — Figs. 4 and 5 on softbend's FEM data",
    "transfer": "Paper B — transfer learning",
    "control": "Paper B — closed-loop control",
    "design": "Design to a specification",
    "pneunet": "A second actuator: the PneuNet",
}


def _get(summary: Mapping[str, Any], *path: str) -> Any:
    value: Any = summary
    for key in path:
        if not isinstance(value, Mapping) or key not in value:
            return None
        value = value[key]
    return value


def _number(value: float | str | None, fmt: Callable[[float], str]) -> str:
    """``fmt(value)``, or why there is no number (never "nan")."""
    if value is None:
        return "not computed in this run"
    try:
        number = float(value)
    except (TypeError, ValueError):
        return str(value)
    if not math.isfinite(number):
        return "undefined (no finite value in this run)"
    return fmt(number)


def _paper(ref: Reference | None, fmt: Callable[[float], str]) -> str:
    """The paper's value as the paper gives it (every digit), its unit and its source."""
    if ref is None:
        return "—"
    unit = {"deg": "°", "%": " %"}.get(ref.unit, f" {ref.unit}" if ref.unit else "")
    return f"{float(ref.value):g}{unit} ({ref.source})"


def _pct(v: float) -> str:
    return f"{v:.2f} %"


def _deg(v: float) -> str:
    return f"{v:.2f}°"


def _sizes(sizes: list[float]) -> str:
    return f"{sizes[0]:g} mm" if sizes else "? mm"


def _kpa(v: float) -> str:
    return f"{v * 1e3:g} kPa"


def _f_value(v: float) -> str:
    return f"{v:.1f}"


def _r2(v: float) -> str:
    return f"{v:.5f}"


def headline_rows(summary: Mapping[str, Any]) -> list[tuple[str, str, str, str]]:
    """``(figure, softbend, paper, section key)`` rows of a run's summary."""
    rows: list[tuple[str, str, str, str]] = []
    worst = _get(summary, "paper_a", "free_run_nrmse_worst") or {}
    if worst:
        rows.append(
            (
                "Paper A: worst held-out free-run NRMSE of ρ and L (paper A's setting)",
                _number(max(worst.values()), lambda v: f"{100 * v:.2f} %"),
                "— (paper A gives figures, not this number)",
                "paper_a",
            )
        )
    for sign, chosen in (_get(summary, "paper_a", "selection") or {}).items():
        rows.append(
            (
                f"Paper A, {sign} pressure: model chosen by free run ({chosen.get('best')}), "
                "cross-validated free-run NRMSE",
                _number(chosen.get("cv_freerun_nrmse"), lambda v: f"{100 * v:.2f} %")
                + _number(
                    chosen.get("best_arx_cv_freerun_nrmse"),
                    lambda v: f" (best linear ARX {100 * v:.2f} %)",
                ),
                _number(
                    chosen.get("paper_a_cv_freerun_nrmse"),
                    lambda v: f"paper A's setting here: {100 * v:.2f} %",
                ),
                "paper_a",
            )
        )
    for key, label, section in (
        ("paper_b", "analytical model, Table 1", "paper_b"),
        ("paper_b_fem_data", "FEM dataset, Table 1", "fem_data"),
    ):
        for name, fmt, shown in (
            ("r2", _r2, "R²"),
            ("f_value", _f_value, "F"),
            ("mape_pct", _pct, "MAPE"),
        ):
            rows.append(
                (
                    f"Paper B Fig. 4c, linear model on the {label}: {shown}",
                    _number(_get(summary, key, name), fmt),
                    _paper(LINEAR_MODEL.get(name), fmt),
                    section,
                )
            )
    for family in ("plr", "xgb", "mlp"):
        model = _get(summary, "paper_b_fem_data", "surrogates_random", family) or {}
        for name, fmt in (("r2", _r2), ("mape_pct", _pct)):
            rows.append(
                (
                    f"Paper B §4.1, {family} surrogate on the FEM dataset (random 5-fold): "
                    f"{'R²' if name == 'r2' else 'MAPE'}",
                    _number(model.get(name), fmt),
                    _paper(SURROGATES[family].get(name), fmt),
                    "fem_data",
                )
            )
    refined = _get(summary, "transfer", "summary", "refined") or {}
    best = _get(summary, "transfer", "best")
    best_row = _get(summary, "transfer", "summary", best) if best else None
    for name, fmt in (("rmse_deg", _deg), ("mape_pct", _pct)):
        label = "RMSE" if name == "rmse_deg" else "MAPE"
        rows.append(
            (
                f"Paper B Fig. 7, refined MLP, leave one actuator out: mean {label} "
                "(synthetic virtual lab)",
                _number(refined.get(name), fmt),
                _paper(TRANSFER_RESULTS.get(name), fmt),
                "transfer",
            )
        )
        if best_row is not None and best != "refined":
            rows.append(
                (
                    f"  best strategy ({best}): mean {label}",
                    _number(best_row.get(name), fmt),
                    "—",
                    "transfer",
                )
            )
    for run in _get(summary, "control", "rig") or []:
        kind = str(run.get("reference", "")).split(":")[0]
        if run.get("controller") != "bang-bang" or kind not in CONTROL_RESULTS:
            continue
        rows.append(
            (
                f"Paper B Fig. 9, bang-bang on the simulated rig, {run['reference']}: MAPE",
                _number(run.get("mape_pct"), _pct),
                _paper(CONTROL_RESULTS[kind].get("mape_pct"), _pct),
                "control",
            )
        )
    for spec in _get(summary, "design", "specifications") or []:
        best_design = spec.get("best") or {}
        fem = best_design.get("fem_angle_deg")
        rows.append(
            (
                f"Design, {spec.get('name')}: {spec.get('target')}: best design's angle, "
                "surrogate / verification",
                _number(best_design.get("angle_deg"), _deg) + " / " + _number(fem, _deg),
                "— (beyond the papers)",
                "design",
            )
        )
    pneunet = _get(summary, "pneunet") or {}
    if pneunet:
        sizes = pneunet.get("mesh_sizes_mm") or []
        walls = "walls in contact" if pneunet.get("contact") == "on" else "to the walls' touch"
        rows.append(
            (
                f"PneuNet reference ({walls}): angle at "
                f"{_number(pneunet.get('last_pressure_mpa'), _kpa)}",
                _number(pneunet.get("last_angle_deg"), _deg),
                "— (beyond the papers)",
                "pneunet",
            )
        )
        rows.append(
            (
                f"PneuNet reference: angle at {_number(pneunet.get('mesh_pressure_mpa'), _kpa)}, "
                f"change from {_sizes(sizes[:1])} to {_sizes(sizes[-1:])} elements",
                _number(pneunet.get("mesh_change_deg"), _deg),
                "— (beyond the papers)",
                "pneunet",
            )
        )
        best_design = pneunet.get("best") or {}
        rows.append(
            (
                f"PneuNet design find, {pneunet.get('target')}: best design's angle, "
                "surrogate / FEM",
                _number(best_design.get("angle_deg"), _deg)
                + " / "
                + _number(best_design.get("fem_angle_deg"), _deg),
                "— (beyond the papers)",
                "pneunet",
            )
        )
    return rows


def add_summary(report: Report, summary: Mapping[str, Any], *, reduced: str | None) -> Section:
    """Put the summary table before every other section of ``report`` and return it.

    Parameters
    ----------
    report : Report
        With every other section added (the links need their anchors).
    summary : mapping
        The run's headline figures (``summary.json``).
    reduced : str or None
        What was reduced in this run, or None for the built-in defaults.
    """
    anchors = dict(zip((s.title for s in report.sections), report.anchors(), strict=True))

    def link(key: str) -> Any:
        start = _SECTIONS[key]
        for title, anchor in anchors.items():
            if title.startswith(start):
                return Link(title, f"#{anchor}")
        return "—"

    section = Section("Summary: softbend beside the papers")
    if reduced:
        section.text(
            f"REDUCED SETTINGS: this report was made with {reduced}; its figures check that "
            "the pipeline runs, not the papers' numbers. `softbend reproduce` on its "
            "built-in defaults makes the full one.",
            note=True,
        )
    section.text(
        "Every headline figure of this run beside the paper's (its table, figure or section). "
        "Paper A's measurements and paper B's are not public: the data here are softbend's "
        "synthetic actuator, the shipped Table 1 FEM dataset and the virtual lab, as each "
        "section says."
    )
    section.table(
        ["figure", "softbend (this run)", "paper", "section"],
        [[figure, ours, paper, link(key)] for figure, ours, paper, key in headline_rows(summary)],
    )
    report.sections.insert(0, section)
    return section


def validation_markdown(summary: Mapping[str, Any]) -> str:
    """The validation page of the documentation, from a run's ``summary.json``.

    The same rows as the report's summary table, with the run's provenance
    (command, softbend version, machine, date, wall time) above them, so that
    every figure on the page says where it came from.
    """
    provenance = summary.get("provenance") or {}
    lines = [
        "# Validation: softbend beside the papers",
        "",
        "Generated by `make docs` (`python docs/gen_validation.py`) from the `summary.json` "
        "that `softbend reproduce` writes; do not edit by hand. Paper A's measurements and "
        "paper B's are not public: the data are softbend's synthetic curling actuator, the "
        "shipped FEM dataset of Table 1 and the virtual lab, as each section of the report says.",
        "",
    ]
    reduced = summary.get("reduced_settings")
    if reduced:
        lines += [f"**Reduced settings**: {', '.join(reduced)}.", ""]
    if provenance:
        lines += ["| run | |", "|---|---|"]
        lines += [f"| {key} | {value} |" for key, value in provenance.items()]
        lines.append("")
    lines += ["| figure | softbend | paper |", "|---|---|---|"]
    lines += [
        f"| {figure.strip()} | {ours} | {paper} |"
        for figure, ours, paper, _ in headline_rows(summary)
    ]
    return "\n".join(lines) + "\n"
