"""``softbend train`` and ``softbend predict``: surrogate models of a campaign (paper B §4.1)."""

from __future__ import annotations

from collections.abc import Callable
from pathlib import Path
from typing import TYPE_CHECKING, Any

import typer

from softbend.cli import _common

if TYPE_CHECKING:
    from softbend.surrogates.features import TrainingData


def train(
    db: Path = typer.Argument(
        ...,
        metavar="TABLE",
        help="What to learn from: a campaign database (DuckDB), a dataset folder of "
        "'softbend campaign dataset' or the name of a shipped one (table1_fem, or a family "
        "such as pneunet), or a simulation table (CSV or Parquet, one row per design and "
        "pressure) described by --design-columns.",
    ),
    out: Path = typer.Option(..., "--out", "-o", help="Folder for models, tables and figures."),
    design_columns: str | None = typer.Option(
        None,
        "--design-columns",
        help="A table's design-parameter columns, comma-separated, in model-input order "
        "(such as n_chambers,wall_mm,height_mm).",
    ),
    pressure_column: str | None = typer.Option(
        None, "--pressure-column", help="A table's gauge-pressure column."
    ),
    pressure_unit: str | None = typer.Option(
        None, "--pressure-unit", help="Unit of the pressure column: kPa, MPa, bar or psi."
    ),
    angle_column: str = typer.Option(
        "angle_deg", "--angle-column", help="A table's bending-angle column, in degrees."
    ),
    actuator: str | None = typer.Option(
        None,
        "--actuator",
        help="The actuator description the table must fit: a registered name (sfrba) or a "
        "JSON file (its columns become the defaults; ranges, kinds, resolutions and "
        "constraints are checked); without it, the description is read off the table.",
    ),
    ranges: list[str] | None = typer.Option(
        None,
        "--range",
        help="A table's design parameter's range, NAME=LOW:HIGH in its unit (repeatable): "
        "recorded in the model's description, so that a design outside it is refused. "
        "Without it, a parameter's range is the span the table sampled: a design outside "
        "is a warning of predict (an error with --strict).",
    ),
    models: str | None = typer.Option(
        None,
        help="Comma-separated surrogate families: plr, xgb, mlp (paper B's), table (the "
        "simulations themselves, a Gaussian process between designs) or any registered "
        "(default: plr,xgb,mlp; below 100 designs also table).",
    ),
    grid: str | None = typer.Option(
        None,
        help="Hyperparameter grid: quick, paper (paper B's) or small (the MLP's small-data "
        "networks; default below 100 designs, quick from 100).",
    ),
    select_by: str = typer.Option(
        "rmse",
        "--select-by",
        help="The cross-validated metric that names the best family: rmse (degrees), mape or r2.",
    ),
    folds: int = typer.Option(5, help="Design-grouped cross-validation folds."),
    seed: int = typer.Option(0, help="Seed of the folds, XGBoost and the MLP."),
    device: str = typer.Option("auto", help="MLP device: auto, cpu or cuda."),
    tf32: bool = typer.Option(
        False, "--tf32", help="On a CUDA device, TF32 matrix products for the MLP (faster)."
    ),
    epochs: int | None = typer.Option(
        None,
        help="MLP epochs (default: 200 quick grid, 1000 paper grid as paper B, 1000 small grid).",
    ),
    workers: int | None = typer.Option(
        None, "--workers", help="XGBoost threads, >= 1 (default: all cores)."
    ),
    halving: int | None = typer.Option(
        None,
        help="Race the MLP configurations by successive halving with this factor (e.g. 3): "
        "a fraction of the exhaustive search's time on the paper grid.",
    ),
    halving_rungs: int | None = typer.Option(
        None,
        help="Rungs of the successive halving (default: at most 4, the first training 1/27 "
        "of the epochs with factor 3; 5 on the paper grid: about half the time).",
    ),
    plr_patience: int | None = typer.Option(
        None,
        help="Stop raising the polynomial's degree once this many in a row did not lower the "
        "best CV RMSE (the paper grid's degrees 8-9 cost 20 min on 2 cores; default: all).",
    ),
    cv: str = typer.Option(
        "grouped", help="Folds: grouped (whole designs) or random (shuffled samples, paper B's)."
    ),
    no_onnx: bool = typer.Option(False, "--no-onnx", help="Skip the ONNX export."),
    interpolation: bool | None = typer.Option(
        None,
        "--interpolation/--no-interpolation",
        help="Score interpolation too (held-out pressures of the simulated designs: one more "
        "fit per family), or skip it (default: scored below 100 designs, skipped from 100).",
        show_default=False,
    ),
    measurements: list[Path] | None = typer.Option(
        None,
        "--measurements",
        metavar="<csv>",
        help="Measurements CSV of built actuators (see 'softbend transfer loco'; repeatable, "
        "joined): the best family is then the one of the lowest leave-one-actuator-out "
        "transfer RMSE, each family's model as the base (the grouped-CV choice recorded "
        "beside).",
    ),
    as_json: bool = typer.Option(False, "--json", help="Print the results as JSON."),
) -> None:
    """Train surrogates of a campaign by cross-validated search.

    Grid-searches each surrogate family with design-grouped K-fold
    cross-validation, refits the best configuration on all designs, then saves
    the models and draws the figures (paper B, Figure 5) into the folder --out.
    The best family is the one of the lowest held-out RMSE (--select-by). MAPE
    leaves out the readings below a floor, max(5°, 5 % of the largest angle)
    (1° for paper B's actuator, as paper B), which the table names. A table of
    fewer than 100 designs is a warning, searches the small-data grids (the
    MLP's small networks, the polynomial's degrees with ridge strengths) unless
    --grid is given, and adds the table base (the simulated curves themselves,
    a Gaussian process between designs) to the default families.

    Below 100 designs, each family's chosen configuration is also scored on
    interpolation: every other interior pressure point of each simulated design
    held out, the rest fitted (the table's "interp." column). From 100 designs
    it is skipped (one more fit per family, long on a large table) unless
    --interpolation asks for it; --no-interpolation skips it on any table.

    With --measurements, the family is selected by how well it transfers, not
    by grouped CV alone: each family's refit model is the base of a
    leave-one-actuator-out evaluation on the measurements (transfer loco's
    default strategies that apply to it, but experimental and
    refined-ensemble; no learning curve), and the family whose best strategy
    has the lowest mean RMSE is named. Both figures per family, and which
    criterion chose, are in the table, summary.csv and the JSON; every
    family x strategy is in transfer_selection.csv.

    TABLE is a softbend campaign (of paper B's actuator or another FEM family),
    a verified dataset (a folder of 'softbend campaign dataset', or the name of
    a shipped one: table1_fem, or a family's name such as pneunet), or any actuator's
    simulation table: a CSV or Parquet file whose columns --design-columns,
    --pressure-column (in --pressure-unit) and --angle-column (degrees) name.
    Integer columns stay integer parameters and text columns categorical ones;
    every saved model records the actuator description it was trained with.
    Without --actuator, each numeric parameter's range is the span the table
    sampled (predict warns outside it, --strict refuses), or the one --range
    declares (a design outside it is refused).

    Every finished configuration-fold is saved in a checkpoint file beside
    --out (.NAME.train-checkpoint.jsonl for an --out named NAME); the same
    command run again after an interruption resumes from it (a checkpoint of
    other settings is discarded with a warning). It is removed when the new
    --out is in place.

    Example:

    \b
        softbend train table1.duckdb --out surrogates --models plr,xgb,mlp
        softbend train sims.csv --design-columns n_chambers,wall_mm \\
            --pressure-column p_kpa --pressure-unit kPa --out pneunet
        softbend train sims.csv --actuator actuator.json --measurements lab.csv \\
            --out pneunet
    """
    from softbend._validation import check_choice, check_int
    from softbend.limits import check_limit
    from softbend.reports.surrogate_figures import training_figures
    from softbend.surrogates.search import SEARCH_GRIDS
    from softbend.surrogates.workflow import SELECT_BY, train_into

    check_choice(select_by, "select_by", tuple(SELECT_BY))
    if grid is not None:
        check_choice(grid, "grid", SEARCH_GRIDS)
    if workers is not None:
        check_int(workers, "workers", low=1)
    if halving_rungs is not None:
        check_int(halving_rungs, "halving_rungs", low=1)
    if plr_patience is not None:
        check_int(plr_patience, "plr_patience", low=1)
    if epochs is not None:
        check_limit("epochs", epochs, "--epochs")
    measured = tuple(measurements or ())
    _common.check_output_dir(out, "--out", inputs=(db, *measured))
    # the folder is swapped whole: nothing but an earlier result of this command may be lost
    _common.check_replaceable_dir(out, "--out", inputs=(db, *measured))
    with _common.library_progress(enabled=not as_json):  # a large table's read, from its start
        source = _training_source(
            db, design_columns, pressure_column, pressure_unit, angle_column, actuator, ranges or []
        )
        if measured:
            _check_measurements(measured, source)

    def resuming(line: str) -> None:
        _common.err_console.print(line, highlight=False, soft_wrap=True)

    with (
        _common.output_errors(out, "--out"),
        _common.library_progress(enabled=not as_json) as progress,
    ):
        _, summary = train_into(
            source,
            out,
            models=models,
            figures=lambda result, stage: _drawn(training_figures, result, stage, progress),
            choose=_by_transfer(measured, seed, progress) if measured else None,
            on_resume=None if as_json else resuming,
            on_discard=_common.warning_line,
            grid_name=grid,
            select_by=select_by,
            advise=_common.warning_line,
            folds=folds,
            seed=seed,
            device=device,
            n_jobs=workers,
            epochs=epochs,
            export_onnx=not no_onnx,
            interpolation=interpolation,
            progress=progress,
            cv=cv,
            halving=halving,
            halving_rungs=halving_rungs,
            plr_patience=plr_patience,
            tf32=tf32,
        )
    if as_json:
        _common.print_json(summary)
        return
    print_summary(summary)
    _common.console.print(f"models, tables and figures written to {out}")


def _drawn(
    draw: Callable[[Any, Path], dict[str, str]],
    result: Any,
    stage: Path,
    progress: Callable[[str, int, int], None],
) -> dict[str, str]:
    """The figures ``draw`` writes, announced as a phase (seconds on a large table)."""
    progress("drawing the figures", 0, 1)
    files = draw(result, stage)
    progress("drawing the figures", 1, 1)
    return files


def _check_measurements(measurements: tuple[Path, ...], source: object) -> None:
    """Read the measurements for the table's actuator before any fit (a campaign's actuator
    is known once it is read: its measurements are read after the search)."""
    from softbend.errors import keyed
    from softbend.surrogates.features import TrainingData
    from softbend.transfer.measurements import read_measurements

    for path in measurements:
        if not path.is_file():
            raise FileNotFoundError(f"--measurements: no file {path}.")
    if isinstance(source, TrainingData) and source.actuator is not None:
        with keyed("measurements"):
            read_measurements(list(measurements), source.actuator)


def _by_transfer(
    measurements: tuple[Path, ...], seed: int, progress: Any
) -> Callable[[Any, Path, dict[str, Any]], None]:
    """The selection step of 'train --measurements': each family's refit model scored as a
    transfer base (:func:`softbend.transfer.base_choice.choose_family`), the tables written."""

    def choose(result: Any, stage: Path, summary: dict[str, Any]) -> None:
        import pandas as pd

        from softbend._io import write_text_atomic
        from softbend.transfer.base_choice import choose_family

        models = {
            name: stage / "models" / f"{name}.json"
            for name in summary["models"]
            if (stage / "models" / f"{name}.json").is_file()
        }
        choice = choose_family(
            summary,
            models,
            measurements,
            seed=seed,
            progress=lambda label, done, total: progress(f"transfer from {label}", done, total),
        )
        table_path = stage / "transfer_selection.csv"
        write_text_atomic(table_path, choice.table.to_csv(index=False))
        summary["files"]["transfer_selection"] = str(table_path)
        table = pd.read_csv(stage / "summary.csv")
        for column in ("transfer_rmse_deg", "transfer_strategy"):
            table[column] = [summary["models"][m].get(column) for m in table["model"]]
        table["selected_by_cv"] = table["model"] == summary.get("best_by_cv")
        table["selected_by_transfer"] = table["model"] == summary["selection"]["by_transfer"]
        write_text_atomic(stage / "summary.csv", table.to_csv(index=False))

    return choose


def _training_source(
    db: Path,
    design_columns: str | None,
    pressure_column: str | None,
    pressure_unit: str | None,
    angle_column: str,
    actuator: str | None,
    ranges: list[str],
) -> Path | TrainingData:
    """The campaign path, or a dataset's or table's training data (checked before anything runs)."""
    from softbend.datasets import is_dataset_name
    from softbend.surrogates.features import dataset_training_data
    from softbend.surrogates.simulation_table import TABLE_SUFFIXES

    described = actuator is not None or bool(ranges)
    table_options = (design_columns, pressure_column, pressure_unit)
    if db.is_dir() or (not db.exists() and is_dataset_name(str(db))):
        if any(v is not None for v in table_options) or described or angle_column != "angle_deg":
            raise typer.BadParameter(
                f"{db} is a dataset (its own columns and actuator); --design-columns, "
                "--pressure-column, --pressure-unit, --angle-column, --actuator and --range "
                "describe a CSV or Parquet table.",
                param_hint="TABLE",
            )
        return dataset_training_data(db)
    if db.suffix.lower() not in TABLE_SUFFIXES:
        if any(v is not None for v in table_options) or described or angle_column != "angle_deg":
            raise typer.BadParameter(
                f"{db} is a campaign database (paper B's actuator, its own columns); "
                "--design-columns, --pressure-column, --pressure-unit, --angle-column, "
                "--actuator and --range describe a CSV or Parquet table.",
                param_hint="TABLE",
            )
        return db
    from softbend.actuators import actuator_from
    from softbend.surrogates.simulation_table import table_training_data

    return table_training_data(
        db,
        design_columns=design_columns,
        pressure_column=pressure_column,
        pressure_unit=pressure_unit,
        angle_column=angle_column,
        actuator=actuator_from(actuator) if actuator is not None else None,
        ranges=ranges,
    )


def _interp_cell(scores: dict | None) -> str:
    """A family's interpolation RMSE (°) as the table shows it: a dash where none was scored."""
    return "—" if not scores else f"{scores['rmse_deg']:.3f}"


def _mape_cell(value: float | None) -> str:
    """A MAPE as the table shows it: a dash where it is undefined (no reading above the floor)."""
    if value is None or value != value:  # None or NaN
        return "—"
    return f"{value:.3f}"


def _transfer_cell(m: dict) -> str:
    """A family's mean leave-one-actuator-out RMSE and its strategy, or a dash."""
    value = m.get("transfer_rmse_deg")
    if value is None or value != value:
        return "—"
    return f"{value:.3f} ({m['transfer_strategy']})"


def print_summary(summary: dict) -> None:
    """The per-family table, beside paper B's figures for paper B's actuator (a dash for a
    family it lacks); another actuator's table names it and leaves paper B out. The MAPE
    column names its floor; a line below names the best family and the metric that chose
    it."""
    from softbend.surrogates.metrics import mape_text

    named = summary.get("actuator")  # an actuator named in its outputs (not paper B's)
    published = any(m.get("paper_b") for m in summary["models"].values())
    floor = summary.get("mape_floor_deg", summary.get("settings", {}).get("mape_threshold_deg"))
    interpolated = any(m.get("interpolation") for m in summary["models"].values())
    rows = []
    for name, m in summary["models"].items():
        paper = m.get("paper_b")
        theirs = (
            f"{paper['r2']} / {paper['mape_pct']} % / {paper['inference_ms']} ms" if paper else "—"
        )
        rows.append(
            [
                name,
                m["params"],
                f"{m['r2']:.6f}",
                f"{m['rmse_deg']:.3f}",
                _mape_cell(m["mape_pct"]),
                f"{m['max_abs_error_deg']:.2f}",
                *([_interp_cell(m.get("interpolation"))] if interpolated else []),
                f"{m['inference_single_us']:.1f}",
                f"{m['inference_batch_ms']:.2f}",
                *([theirs] if published else []),
                *([_transfer_cell(m)] if "selection" in summary else []),
            ]
        )
    title = "Surrogates: grouped cross-validation (held-out designs) and inference"
    if interpolated:
        title = (
            "Surrogates: grouped cross-validation (held-out designs), interpolation "
            "(held-out pressures of simulated designs) and inference"
        )
    if named:
        names = ", ".join(p["name"] for p in named["parameters"])
        title += f"; actuator {named['name']} ({names}; {named['pressure_unit']})"
    _common.print_table(
        title,
        [
            "model",
            "best configuration",
            "R²",
            "RMSE °",
            "MAPE %" if floor is None else mape_text(floor),
            "max |e| °",
            *(["interp. RMSE °"] if interpolated else []),
            "1 sample µs",
            "10k batch ms",
            *(["paper B R² / MAPE / IT"] if published else []),
            *(["transfer RMSE ° (strategy)"] if "selection" in summary else []),
        ],
        rows,
    )
    if interpolated:
        _common.console.print(
            "R², RMSE, MAPE and max |e|: designs held out (grouped folds); interp. RMSE: every "
            "other interior pressure point of each simulated design held out, the rest fitted.",
            highlight=False,
        )
    best = summary.get("best")
    selection = summary.get("selection")
    metric = {"rmse": "RMSE", "mape": "MAPE", "r2": "R²"}
    if selection is not None:
        cv_metric = metric.get(selection["cv_metric"], "")
        if selection["by_transfer"] is None:
            line = f"best by held-out {cv_metric}: {best} (no family could be scored in transfer)"
        else:
            pair = selection["best_pair"]
            line = (
                f"best by leave-one-actuator-out transfer RMSE: {best} ({pair['rmse_deg']:.3g}°, "
                f"{pair['strategy']}); by held-out {cv_metric} (grouped CV): {selection['by_cv']}"
            )
        _common.console.print(line, highlight=False)
    elif best is not None:
        _common.console.print(f"best by held-out {metric.get(summary['selected_by'], '')}: {best}",
                              highlight=False)  # fmt: skip


def predict(
    model: Path = typer.Argument(
        ...,
        help="A model saved by 'softbend train' (models/*.json), or the model.json of "
        "'softbend identify'.",
    ),
    design: str = typer.Option(
        None,
        help="The design by the model's parameter names, NAME=VALUE,... (a categorical "
        "parameter by its level), or the values in the model's column order; for paper B's "
        "actuator l,r,t,b,phi,lc (mm, mm, mm, mm, deg, mm).",
    ),
    pressures: str = typer.Option(
        None,
        help="Comma-separated gauge pressures in the model's pressure unit (MPa for paper "
        "B's actuator; such as 0.05,0.1), or each with a unit (20psi,138kPa).",
    ),
    strict: bool = typer.Option(
        False, "--strict", help="Refuse a design or pressure outside the model's training data."
    ),
    as_json: bool = typer.Option(False, "--json", help="Print the predictions as JSON."),
    series: Path = typer.Option(
        None,
        "--input",
        help="For a model of 'softbend identify': a CSV of its input columns (optionally its "
        "time and output columns: the outputs' first samples then start the run, and its "
        "error is reported); the model runs free on it.",
    ),
    out: Path = typer.Option(
        None,
        "--out",
        "-o",
        help="With --input: a CSV of the time, the inputs and the simulated outputs.",
    ),
) -> None:
    """Predict a design's angles, or an identified model's free run.

    With a surrogate of 'softbend train', --design and --pressures give the
    bending angle of the design at each pressure. With the model.json of
    'softbend identify', --input gives a CSV of its input series: the model runs
    free on it (from the measured outputs' first samples when the CSV has them,
    else from rest), and the outputs are summarized (with their free-run NRMSE
    when measured), written with --out or printed with --json.

    A design or pressure outside the ranges the model was trained on, a pressure
    past what the training designs nearest to this one were swept to, or an angle
    past the largest trained on (all recorded in the model file) is a warning on
    stderr and a "no" in the table's last column, or with --strict an error: a
    surrogate extrapolates without knowing it.

    Example:

    \b
        softbend predict surrogates/models/mlp.json --design 100,6,2,2,5,8 \\
            --pressures 0.05,0.1,0.17
        softbend predict pneunet/models/plr.json \\
            --design n_chambers=10,n_layers=2,wall_mm=2,height_mm=12 --pressures 20,40
        softbend predict arm-model/model.json --input steps.csv --out steps-run.csv
    """
    from softbend.cli.predict_series import is_series_model, predict_series, surrogate_options

    if is_series_model(model):
        predict_series(model, series=series, out=out, as_json=as_json, design=design,
                       pressures=pressures, strict=strict)  # fmt: skip
        return
    design, pressures = surrogate_options(model, design, pressures, series, out)
    from softbend.surrogates.predict import INTERVAL_LEVEL, predict_text

    result = predict_text(model, design, pressures, strict=strict)
    outside = result.pressure_warning()
    if outside is not None:
        _common.warning_line(f"--pressures {outside}.")
    if result.extrapolated:
        _common.warning_line(
            f"{model} was not trained there: {'; '.join(result.extrapolated)}; the "
            "prediction is an extrapolation (--strict refuses)."
        )
    elif result.supported is None:
        _common.warning_line(
            f"{model} records no training support (saved by an older softbend): only its "
            "training ranges were checked."
        )
    if as_json:
        _common.print_json(result.to_dict())
        return
    interval = result.interval_deg
    actuator = result.actuator
    columns = [f"{actuator.pressure_column} ({actuator.pressure_unit})", "angle (°)"]
    rows = [
        [f"{p:g}", f"{a:.2f}"] for p, a in zip(result.pressure_mpa, result.angle_deg, strict=True)
    ]
    if interval is not None:
        columns.append(f"{INTERVAL_LEVEL:.0%} interval (°)")
        for row, low, high in zip(rows, *interval, strict=True):
            row.append(f"{low:.2f} to {high:.2f}")
    if result.supported is not None:
        columns.append("trained there")
        for row, ok in zip(rows, result.supported, strict=True):
            row.append("yes" if ok else "no")
    _common.print_table(f"{result.kind} surrogate, design ({result.design_text})", columns, rows)
