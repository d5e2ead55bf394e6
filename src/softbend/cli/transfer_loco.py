"""``softbend transfer loco``: every strategy scored on every held-out actuator."""

from __future__ import annotations

from pathlib import Path
from typing import TYPE_CHECKING

import typer

from softbend.cli import _common

if TYPE_CHECKING:
    from softbend.surrogates.persistence import SavedSurrogate
    from softbend.transfer.loco import LocoResult

#: The files 'transfer loco' writes into its '--out' folder.
LOCO_FILES: tuple[str, ...] = (
    "summary.csv",
    "per_actuator.csv",
    "predictions.csv",
    "learning_curve.csv",
    "loss_curves_deg2.csv",
    "loco.json",
    "fig6_loss_curves.png",
    "fig7_actuators.png",
    "learning_curve.png",
)


MEASUREMENTS_ARGUMENT = typer.Argument(
    ...,
    metavar="MEASUREMENTS",
    help="Measurements CSV file(s) (see 'softbend lab measure'); several are joined, "
    "each keeping its provenance.",
)
OUT_OPTION = typer.Option(..., "--out", "-o", help="Folder for tables and figures.")
BASE_OPTION = typer.Option(
    None, help="Saved surrogate to start from (default: the shipped FEM-trained MLP)."
)
STRATEGIES_OPTION = typer.Option(
    "all",
    help="Comma-separated strategies, or 'all': softbend's own "
    "(see 'softbend transfer strategies').",
)
SETTINGS_OPTION = typer.Option(
    None,
    "--set",
    help="A strategy parameter, STRATEGY.NAME=VALUE, or NAME=VALUE for every strategy "
    "that takes it (repeatable; recorded in loco.json).",
)
LEVEL_OPTION = typer.Option(0.9, help="Probability of the prediction intervals.")
LEARNING_CURVE_OPTION = typer.Option(
    True, "--learning-curve/--no-learning-curve", help="Also fit on 1..n-2 actuators."
)
CALIBRATE_OPTION = typer.Option(
    False,
    "--calibrate",
    help="Also score the calibrated 90 % interval on each held-out actuator, calibrated "
    "without it (n-1 more fits per actuator: several times the run time; at least 3 "
    "actuators).",
)
SEED_OPTION = typer.Option(0, help="Seed of the strategies and the learning curve.")
AS_JSON_OPTION = typer.Option(False, "--json", help="Print the results as JSON.")
FORCE_OPTION = typer.Option(
    False,
    "--force",
    help="Use pressures past the base model's range (1.5x its top) and angles that look "
    "like radians next to its prediction as given (with a warning; recorded in loco.json).",
)


def loco(
    measurements: list[Path] = MEASUREMENTS_ARGUMENT,
    out: Path = OUT_OPTION,
    base: Path | None = BASE_OPTION,
    strategies: str = STRATEGIES_OPTION,
    settings: list[str] | None = SETTINGS_OPTION,
    level: float = LEVEL_OPTION,
    learning_curve: bool = LEARNING_CURVE_OPTION,
    calibrate: bool = CALIBRATE_OPTION,
    seed: int = SEED_OPTION,
    as_json: bool = AS_JSON_OPTION,
    force: bool = FORCE_OPTION,
) -> None:
    """Score every strategy on held-out actuators.

    Leave one configuration out: each strategy is fitted on all actuators but one and
    scored on the one held out, in turn (paper B, Figure 7). The folder --out is written
    as a whole: built beside it and swapped in when every table and figure is complete,
    so a run that fails leaves the previous results as they were. An existing --out may
    hold only what this command writes. loco.json records every parameter of every
    strategy as used, and each MEASUREMENTS file (one or more, joined) with its SHA-256.

    Example:

    \b
        softbend transfer loco lab.csv --out loco \\
            --strategies refined,scale-offset --set epochs=500
        softbend transfer loco lab.csv bench.csv --out loco
    """
    from softbend.transfer.against_base import load_for_base
    from softbend.transfer.base import load_base_saved
    from softbend.transfer.loco import leave_one_configuration_out
    from softbend.transfer.measurements import files_record

    inputs = tuple(measurements) if base is None else (*measurements, base)
    _common.check_output_dir(out, "--out", inputs=inputs, files=LOCO_FILES)
    _common.check_replaceable_dir(out, "--out", inputs=inputs)
    saved = load_base_saved(base)
    names, left_out, options = _chosen_strategies(strategies, settings, saved)
    with _common.library_progress(enabled=not as_json):  # a large file's read, from its start
        data, forced = load_for_base(measurements, saved, force=force)  # before any fit
    with _common.library_progress(enabled=not as_json) as progress:
        result = leave_one_configuration_out(
            data,
            saved.model,
            names,
            level=level,
            learning_curve=learning_curve,
            calibrated=calibrate,
            seed=seed,
            options=options,
            progress=lambda done, total, name: progress("fitting strategies", done, total),
        )
    result.settings["measurement_files"] = files_record(measurements, data)  # type: ignore[arg-type]
    result.settings.update({"forced": forced} if forced else {}, left_out=left_out)
    synthetic = bool(data.synthetic.any())  # the figure flags any synthetic reading
    files = _write_loco(result, out, synthetic=synthetic, learning_curve=learning_curve)
    _print_loco(result, out, files, left_out, synthetic=synthetic, as_json=as_json)


def _chosen_strategies(
    strategies: str, settings: list[str] | None, saved: SavedSurrogate
) -> tuple[list[str], dict[str, str], dict[str, dict[str, object]]]:
    """The strategies named by ``--strategies`` (``all``: those that apply to the base, the
    others left out with why) and their ``--set`` options, checked before any work."""
    from softbend.transfer.loco import DEFAULT_STRATEGIES, strategy_options
    from softbend.transfer.strategies import applicable_strategies, check_applicable

    left_out: dict[str, str] = {}
    if strategies.strip() == "all":  # those that apply to the base, the others said
        names, left_out = applicable_strategies(DEFAULT_STRATEGIES, saved.model, saved.actuator)
    else:
        names = [n.strip() for n in strategies.split(",") if n.strip()]
    options = strategy_options(names, _common.parse_assignments(settings or ()))
    check_applicable(names, saved.model, saved.actuator, key="strategies")
    return names, left_out, options


def _print_loco(
    result: LocoResult,
    out: Path,
    files: dict[str, str],
    left_out: dict[str, str],
    *,
    synthetic: bool,
    as_json: bool,
) -> None:
    """The warnings of a finished run (strategies left out, fits that failed), then the
    results as JSON or as the summary table."""
    if left_out:  # said once the run has succeeded: an error stays the one line
        _common.warning_line(left_out_line(left_out))
    failed, others = result.settings.get("failed", []), result.settings.get("failed_other_fits", 0)
    if failed or others:
        _common.warning_line(failed_line(failed, others))  # type: ignore[arg-type]
    if as_json:
        _common.print_json({**result.to_dict(), "files": files, "synthetic": synthetic})
        return
    print_loco_summary(result)
    _common.console.print(f"tables and figures written to {out}")


def _write_loco(
    result: LocoResult, out: Path, *, synthetic: bool, learning_curve: bool
) -> dict[str, str]:
    """Write loco's tables and figures into ``out`` as a whole (staged, then swapped in);
    the files written, by key."""
    from softbend._outdir import staged_dir
    from softbend.reports import transfer_figures

    with (
        _common.output_errors(out, "--out"),
        staged_dir(out) as stage,
        _common.as_written(stage, out),
    ):
        written = result.write(stage)
        written["fig6"] = str(transfer_figures.loss_curves(result, stage / "fig6_loss_curves.png"))
        written["fig7"] = str(
            transfer_figures.actuator_panels(
                result, stage / "fig7_actuators.png", synthetic=synthetic
            )
        )
        if learning_curve:
            written["learning_curve_figure"] = str(
                transfer_figures.learning_curve(result, stage / "learning_curve.png")
            )
    return {key: str(out / Path(value).name) for key, value in written.items()}


def left_out_line(left_out: dict[str, str]) -> str:
    """The one line saying which strategies of 'all' were left out for the base, and why."""
    reasons: dict[str, list[str]] = {}
    for name, reason in left_out.items():
        reasons.setdefault(reason, []).append(name)
    parts = [f"{', '.join(names)} ({reason})" for reason, names in reasons.items()]
    return (
        "--strategies all runs the strategies that apply to the base; left out: "
        + "; ".join(parts)
        + " (recorded in loco.json, settings.left_out)"
    )


def failed_line(failed: list[dict[str, str]], others: int = 0) -> str:
    """The one line listing the (strategy, held-out actuator) fits that failed.

    ``others``: how many fits of the learning curve and the nested calibration failed.
    """
    pairs = ", ".join(f"{f['strategy']} on held-out {f['actuator_id']}" for f in failed)
    parts = []
    if failed:
        parts.append(
            f"{len(failed)} fit(s) failed and are left out of the means: {pairs}; each reason "
            "is in per_actuator.csv (column 'error') and loco.json"
        )
    if others:
        parts.append(
            f"{others} fit(s) of the learning curve or the calibration failed (learning_curve.csv, "
            "column 'error'; loco.json, settings.failed_other_fits)"
        )
    return "; ".join(parts)


def print_loco_summary(result: LocoResult) -> None:
    """The per-strategy table beside paper B's refined MLP (paper B §4.3, Fig. 7).

    A strategy that could not be fitted without some held-out actuators says
    how many ("pressure-scale (1 failed)"): its means are over the others. The
    "vs baseline" column is each strategy's mean RMSE relative to the
    baseline's (:data:`~softbend.transfer.loco.BASELINE_STRATEGY`, the base plus
    the mean residual against pressure): −23 % is 23 % lower. A dash when the
    baseline is not in the run.
    """
    import pandas as pd

    from softbend.references import TRANSFER_RESULTS, values
    from softbend.transfer.loco import BASELINE_STRATEGY

    paper = values(TRANSFER_RESULTS)

    def _calibrated_cell(r: pd.Series) -> str:
        """Coverage of the calibrated interval and its mean width, or a dash."""
        coverage = float(r.get("calibrated_coverage", float("nan")))
        if coverage != coverage:
            return "—"
        return f"{100 * coverage:.1f} % ({float(r['calibrated_width_deg']):.1f})"

    def _baseline_cell(r: pd.Series) -> str:
        """The mean RMSE relative to the baseline's, e.g. "−23 %", or a dash."""
        if r["strategy"] == BASELINE_STRATEGY:
            return "(baseline)"
        change = float(r.get("rmse_vs_baseline_pct", float("nan")))
        if change != change:
            return "—"
        return f"{change:+.0f} %".replace("-", "\u2212")

    def _strategy_cell(r: pd.Series) -> str:
        """The strategy, and how many held-out actuators it could not be fitted without."""
        failed = int(r.get("n_failed", 0))
        return f"{r['strategy']} ({failed} failed)" if failed else str(r["strategy"])

    def _mape_cell(r: pd.Series) -> str | float:
        """The mean MAPE, or a dash where no held-out reading reached the floor."""
        mape = float(r["mape_pct"])
        return "—" if mape != mape else mape

    floor = float(result.settings.get("mape_floor_deg", 0.0))
    # paper B's MAPE (only exact zeros left out) for its actuator; else the floor's
    mape_title = "mean MAPE %" if floor == 0 else f"mean MAPE % (|θ| ≥ {floor:.3g}°)"
    rows = []
    for _, r in result.summary.iterrows():
        rows.append(
            [
                _strategy_cell(r),
                float(r["rmse_deg"]),
                _baseline_cell(r),
                _mape_cell(r),
                float(r["max_error_deg"]),
                "—" if r["coverage"] != r["coverage"] else f"{100 * r['coverage']:.1f} %",
                _calibrated_cell(r),
                f"{r['worst_actuator']} ({r['worst_rmse_deg']:.1f}°)",
            ]
        )
    if "actuator" not in result.settings:  # paper B's figure, for paper B's actuator only
        rows.append(
            [
                "paper B refined MLP",
                paper["rmse_deg"],
                "—",
                paper["mape_pct"],
                "—",
                "—",
                "—",
                f"{paper['worst']} ({paper['worst_rmse_deg']:.2f}°)",
            ]
        )
    _common.print_table(
        f"Leave one configuration out ({len(result.settings['actuators'])} actuators, "
        f"{result.settings['n_measurements']} readings; intervals {result.level:.0%})",
        [
            "strategy",
            "mean RMSE °",
            "vs baseline",
            mape_title,
            "max |e| °",
            "coverage",
            "calibrated coverage (mean width °)",
            "worst actuator",
        ],
        rows,
    )
    for name, cal in result.calibrations.items():
        if not cal.get("guaranteed", True):
            _common.warning_line(
                f"{name}: {cal['n_actuators']} actuators are too few for a guaranteed "
                f"{result.level:.0%} interval (the rule needs {cal['min_actuators']}); "
                f"its calibrated half-width is the {result.level:.0%} quantile of the "
                "leave-one-actuator-out errors, without a guarantee."
            )
