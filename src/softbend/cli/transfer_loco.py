"""``softbend transfer loco``: every strategy scored on every held-out actuator."""

from __future__ import annotations

from pathlib import Path
from typing import TYPE_CHECKING, Any

import typer

from softbend.cli import _common

if TYPE_CHECKING:
    from softbend.surrogates.persistence import SavedSurrogate
    from softbend.transfer.loco import LocoResult

#: The files 'transfer loco' writes into its '--out' folder (with one --base; with several,
#: each base's folder holds them and the folder itself :data:`CHOICE_FILES`).
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

#: The files 'transfer loco' with several bases writes into its '--out' folder, beside a
#: folder of :data:`LOCO_FILES` per base.
CHOICE_FILES: tuple[str, ...] = ("summary.csv", "loco.json")


MEASUREMENTS_ARGUMENT = typer.Argument(
    ...,
    metavar="MEASUREMENTS",
    help="Measurements CSV file(s) (see 'softbend lab measure'); several are joined, "
    "each keeping its provenance.",
)
OUT_OPTION = typer.Option(..., "--out", "-o", help="Folder for tables and figures.")
BASE_OPTION = typer.Option(
    None,
    metavar="<path>",
    help="Saved surrogate to start from (default: the shipped FEM-trained MLP), or several "
    "separated by commas (a.json,b.json): every base x strategy is scored and the best pair "
    "named.",
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
    True,
    "--learning-curve/--no-learning-curve",
    help="Also fit on fewer actuators: 1..n-2, at most 6 sizes spaced geometrically.",
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
    base: str | None = BASE_OPTION,
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

    Several bases (--base a.json,b.json) are each scored in turn, with the
    strategies that apply to each: --out then holds one folder per base (its
    file's stem) with that base's tables and figures, a summary.csv of every
    base x strategy, and a loco.json recording all of it and the pair of the
    lowest mean RMSE (a pair with failed fits competes only when every pair has
    some; ties go to the base listed first). A base whose every fit fails is a
    row of the table with its reason; the others go on.

    Example:

    \b
        softbend transfer loco lab.csv --out loco \\
            --strategies refined,scale-offset --set epochs=500
        softbend transfer loco lab.csv bench.csv --out loco
        softbend transfer loco lab.csv --base plr.json,xgb.json,mlp.json --out loco
    """
    from softbend.transfer.against_base import load_for_base
    from softbend.transfer.base import load_base_saved
    from softbend.transfer.base_choice import parse_bases
    from softbend.transfer.loco import leave_one_configuration_out
    from softbend.transfer.measurements import files_record

    bases = parse_bases(base)
    if bases is not None and len(bases) > 1:
        _loco_bases(measurements, out, bases, strategies=strategies, settings=settings,
                   level=level, learning_curve=learning_curve, calibrate=calibrate, seed=seed,
                   as_json=as_json, force=force)  # fmt: skip
        return
    base_file = None if bases is None else bases[0]
    inputs = tuple(measurements) if base_file is None else (*measurements, base_file)
    _common.check_output_dir(out, "--out", inputs=inputs, files=LOCO_FILES)
    _common.check_replaceable_dir(out, "--out", inputs=inputs)
    saved = load_base_saved(base_file)
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


def _loco_bases(
    measurements: list[Path],
    out: Path,
    bases: list[Path],
    *,
    strategies: str,
    settings: list[str] | None,
    level: float,
    learning_curve: bool,
    calibrate: bool,
    seed: int,
    as_json: bool,
    force: bool,
) -> None:
    """'transfer loco' with several bases: each scored in turn, then one table of every
    base x strategy and the pair chosen (:mod:`softbend.transfer.base_choice`)."""
    from softbend.errors import InputError, SoftbendError, keyed
    from softbend.transfer.against_base import load_for_base
    from softbend.transfer.base import load_base_saved
    from softbend.transfer.base_choice import (
        Candidate,
        base_labels,
        check_same_actuator,
        score_bases,
    )
    from softbend.transfer.measurements import files_record

    labels = base_labels(bases)
    inputs = (*measurements, *bases)
    _common.check_output_dir(out, "--out", inputs=inputs, files=CHOICE_FILES)
    _common.check_replaceable_dir(out, "--out", inputs=inputs)
    saved = []
    for path in bases:
        with keyed("base"):
            saved.append(load_base_saved(path))
    check_same_actuator([(str(p), s.actuator) for p, s in zip(bases, saved, strict=True)])
    chosen = _chosen_for_bases(strategies, settings, saved)
    candidates, records = [], {}
    for label, path, model, (names, left_out, options) in zip(
        labels, bases, saved, chosen, strict=True
    ):
        try:
            with _common.library_progress(enabled=not as_json):
                data, forced = load_for_base(measurements, model, force=force)  # before any fit
        except SoftbendError as error:  # the one line names the base it was read for
            raise InputError(
                f"{path} (a model of {model.actuator.name}): {' '.join(str(error).split())}",
                key="base",
            ) from None
        candidates.append(Candidate(label, str(path), model.model, data, names, options))
        records[label] = (files_record(measurements, data), forced, left_out)  # type: ignore[arg-type]
    with _common.library_progress(enabled=not as_json) as progress:
        choice = score_bases(
            candidates,
            level=level,
            learning_curve=learning_curve,
            calibrated=calibrate,
            seed=seed,
            progress=lambda label, done, total: progress(
                f"fitting strategies on {label}", done, total
            ),
        )
    for label, result in choice.results.items():
        files, forced, left_out = records[label]
        result.settings["measurement_files"] = files
        result.settings.update({"forced": forced} if forced else {}, left_out=left_out)
    synthetic = bool(candidates[0].measurements.synthetic.any())
    run_settings = {  # the run's own inputs; each base's are in its record
        "measurement_files": records[labels[0]][0],
        "strategies": strategies,
        "set": list(settings or ()),
        "level": level,
        "learning_curve": learning_curve,
        "calibrated": calibrate,
        "seed": seed,
        "force": force,
    }
    written = _write_choice(
        choice, out, synthetic=synthetic, learning_curve=learning_curve, settings=run_settings
    )
    _print_choice(choice, out, written, as_json=as_json, synthetic=synthetic)


def _chosen_for_bases(
    strategies: str, settings: list[str] | None, saved: list[SavedSurrogate]
) -> list[tuple[list[str], dict[str, str], dict[str, dict[str, object]]]]:
    """Each base's strategies, left-out strategies and options. Named strategies that do
    not apply to a base are left out for it (with why); one that applies to none is refused."""
    from softbend.transfer.loco import strategy_options
    from softbend.transfer.strategies import applicable_strategies, check_applicable

    if strategies.strip() == "all":
        return [_chosen_strategies(strategies, settings, one) for one in saved]
    named = [n.strip() for n in strategies.split(",") if n.strip()]
    strategy_options(named, _common.parse_assignments(settings or ()))  # names, values checked
    chosen = []
    for one in saved:
        names, left_out = applicable_strategies(named, one.model, one.actuator)
        options = strategy_options(named, _common.parse_assignments(settings or ()))
        chosen.append((names, left_out, {k: v for k, v in options.items() if k in names}))
    everywhere = set(named).intersection(*(set(left) for _, left, _ in chosen))
    if everywhere:  # applies to no base: the first base's refusal, one line
        check_applicable(sorted(everywhere), saved[0].model, saved[0].actuator, key="strategies")
    return chosen


def _write_choice(
    choice: Any, out: Path, *, synthetic: bool, learning_curve: bool, settings: dict[str, Any]
) -> dict[str, str]:
    """Write each base's results into its folder, then the table of every base x strategy
    (summary.csv) and loco.json, as a whole (staged, then swapped in)."""
    from softbend._io import json_text, write_text_atomic
    from softbend._outdir import staged_dir

    with (
        _common.output_errors(out, "--out"),
        staged_dir(out) as stage,
        _common.as_written(stage, out),
    ):
        for label, result in choice.results.items():
            write_loco_files(
                result, stage / label, synthetic=synthetic, learning_curve=learning_curve
            )
        write_text_atomic(stage / "summary.csv", choice.table.to_csv(index=False))
        record = {**choice.to_dict(), "settings": settings, "synthetic": synthetic}
        write_text_atomic(stage / "loco.json", json_text(record) + "\n")
    written = {"summary": str(out / "summary.csv"), "json": str(out / "loco.json")}
    written.update({label: str(out / label) for label in choice.results})
    return written


def _print_choice(
    choice: Any, out: Path, files: dict[str, str], *, as_json: bool, synthetic: bool
) -> None:
    """The warnings of each base (strategies left out, fits that failed, a base that
    failed), then the results as JSON or as the table of every base x strategy."""
    import math

    for label, result in choice.results.items():
        left_out = result.settings.get("left_out") or {}
        if left_out:
            _common.warning_line(f"base {label}: " + left_out_line(left_out))
        failed = result.settings.get("failed", [])
        others = result.settings.get("failed_other_fits", 0)
        if failed or others:
            _common.warning_line(f"base {label}: " + failed_line(failed, others))
    for label, error in choice.errors.items():
        _common.warning_line(f"base {label}: every fit failed, left out of the choice: {error}")
    if as_json:
        _common.print_json({**choice.to_dict(), "files": files, "synthetic": synthetic})
        return

    def cell(value: object, form: str = ".3g") -> str:
        if value is None or (isinstance(value, float) and not math.isfinite(value)):
            return "—"
        return format(value, form) if isinstance(value, float) else str(value)

    rows = [
        [
            str(r["base"]),
            cell(r["strategy"]),
            cell(r["rmse_deg"], ".4g"),
            cell(r["mape_pct"], ".4g"),
            cell(r["max_error_deg"], ".4g"),
            "—" if r["rank"] != r["rank"] else str(int(r["rank"])),
            str(r["status"]) if r["error"] is None else f"{r['status']}: {r['error']}",
        ]
        for _, r in choice.table.iterrows()
    ]
    _common.print_table(
        f"Leave one configuration out, every base x strategy ({len(choice.files)} bases)",
        ["base", "strategy", "mean RMSE °", "mean MAPE %", "max |e| °", "rank", "status"],
        rows,
    )
    best = choice.best
    if best is None:
        _common.warning_line("no base x strategy pair has a finite mean RMSE; none is named")
    else:
        ties = f" (tied with {', '.join(best['tied_with'])})" if best["tied_with"] else ""
        _common.console.print(
            f"best pair by mean leave-one-actuator-out RMSE: base {best['base']} "
            f"({best['base_file']}) with {best['strategy']}, {best['rmse_deg']:.3g}°{ties}",
            highlight=False,
        )
    _common.console.print(f"tables and figures written to {out}")


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

    with (
        _common.output_errors(out, "--out"),
        staged_dir(out) as stage,
        _common.as_written(stage, out),
    ):
        written = write_loco_files(
            result, stage, synthetic=synthetic, learning_curve=learning_curve
        )
    return {key: str(out / Path(value).name) for key, value in written.items()}


def write_loco_files(
    result: LocoResult, folder: Path, *, synthetic: bool, learning_curve: bool
) -> dict[str, str]:
    """Write loco's tables (:meth:`LocoResult.write`) and figures into ``folder``; the files
    written, by key."""
    from softbend.reports import transfer_figures

    written = result.write(folder)
    written["fig6"] = str(transfer_figures.loss_curves(result, folder / "fig6_loss_curves.png"))
    written["fig7"] = str(
        transfer_figures.actuator_panels(result, folder / "fig7_actuators.png", synthetic=synthetic)
    )
    if learning_curve:
        written["learning_curve_figure"] = str(
            transfer_figures.learning_curve(result, folder / "learning_curve.png")
        )
    return written


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
