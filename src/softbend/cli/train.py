"""``softbend train`` and ``softbend predict``: surrogate models of a campaign (paper B §4.1)."""

from __future__ import annotations

from pathlib import Path

import typer

from softbend.cli import _common


def _floats(text: str, name: str) -> list[float]:
    try:
        values = [float(v) for v in text.split(",") if v.strip()]
    except ValueError:
        raise ValueError(
            f"The '{name}' must be comma-separated numbers, e.g. 0.05,0.1. Got {text!r} instead."
        ) from None
    if not values:
        raise ValueError(f"The '{name}' must hold at least one number. Got {text!r} instead.")
    return values


def train(
    db: Path = typer.Argument(..., help="Campaign database (DuckDB) to learn from."),
    out: Path = typer.Option(..., "--out", help="Folder for models, tables and figures."),
    models: str = typer.Option("plr,xgb,mlp", help="Comma-separated families: plr, xgb, mlp."),
    grid: str = typer.Option("quick", help="Hyperparameter grid: quick or paper."),
    folds: int = typer.Option(5, help="Design-grouped cross-validation folds."),
    seed: int = typer.Option(0, help="Seed of the folds, XGBoost and the MLP."),
    device: str = typer.Option("auto", help="MLP device: auto, cpu or cuda."),
    tf32: bool = typer.Option(
        False, "--tf32", help="On a CUDA device, TF32 matrix products for the MLP (faster)."
    ),
    epochs: int | None = typer.Option(
        None, help="MLP epochs (default: 200 quick grid, 1000 paper grid as paper B)."
    ),
    jobs: int | None = typer.Option(None, "--jobs", help="XGBoost threads, >= 1 (default: all)."),
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
    as_json: bool = typer.Option(False, "--json", help="Print the results as JSON."),
) -> None:
    """Grid-search the surrogates with grouped K-fold CV, refit the best, save and plot.

    Every finished configuration-fold is saved in ``.OUT.train-checkpoint.jsonl``
    beside ``--out``; the same command run again after an interruption resumes
    from it (a checkpoint of other settings is discarded with a warning). It is
    removed when the new ``--out`` is in place.
    """
    from softbend._io import staged_dir
    from softbend._validation import check_int
    from softbend.limits import check_limit
    from softbend.reports.surrogate_figures import training_figures
    from softbend.surrogates.checkpoint import SearchCheckpoint, checkpoint_path
    from softbend.surrogates.workflow import train_surrogates

    if jobs is not None:
        check_int(jobs, "--jobs", "softbend train", low=1)
    if halving_rungs is not None:
        check_int(halving_rungs, "--halving-rungs", "softbend train", low=1)
    if plr_patience is not None:
        check_int(plr_patience, "--plr-patience", "softbend train", low=1)
    if epochs is not None:
        check_limit("epochs", epochs, "--epochs")
    _common.check_output_dir(out, "--out", inputs=(db,))
    # the folder is swapped whole: nothing but an earlier result of this command may be lost
    _common.check_replaceable_dir(
        out, "--out", "softbend train", inputs=(db,), marker="cv_results.csv"
    )
    names = [m.strip() for m in models.split(",") if m.strip()]

    def resuming(line: str) -> None:
        _common.err_console.print(line, highlight=False, soft_wrap=True)

    checkpoint = SearchCheckpoint(
        checkpoint_path(out),
        on_resume=None if as_json else resuming,
        on_discard=_common.warning_line,
    )
    # Built beside --out and swapped in at the end: an interrupted search leaves the
    # previous folder as it was, never old models beside new ones, and its finished
    # configuration-folds in the checkpoint for the next run.
    with _common.output_errors(out, "--out"), checkpoint:
        with staged_dir(out) as stage, _common.phase_progress(enabled=not as_json) as progress:
            result, summary = train_surrogates(
                db,
                stage,
                models=names,
                grid_name=grid,
                folds=folds,
                seed=seed,
                device=device,
                n_jobs=jobs,
                epochs=epochs,
                export_onnx=not no_onnx,
                progress=progress,
                cv=cv,
                halving=halving,
                halving_rungs=halving_rungs,
                plr_patience=plr_patience,
                checkpoint=checkpoint,
                tf32=tf32,
            )
            summary["files"].update(training_figures(result, stage))
        checkpoint.remove()  # the new folder is in place
    summary["files"] = {
        key: str(Path(out) / Path(value).relative_to(stage))
        if str(value).startswith(str(stage))
        else value
        for key, value in summary["files"].items()
    }
    if as_json:
        _common.print_json(summary)
        return
    print_summary(summary)
    _common.console.print(f"models, tables and figures written to {out}")


def print_summary(summary: dict) -> None:
    """The per-family table beside paper B's figures (used by reproduce too)."""
    rows = []
    for name, m in summary["models"].items():
        paper = m["paper_b"]
        rows.append(
            [
                name,
                m["params"],
                f"{m['r2']:.6f}",
                f"{m['rmse_deg']:.3f}",
                f"{m['mape_pct']:.3f}",
                f"{m['max_abs_error_deg']:.2f}",
                f"{m['inference_single_us']:.1f}",
                f"{m['inference_batch_ms']:.2f}",
                f"{paper['r2']} / {paper['mape_pct']} % / {paper['inference_ms']} ms",
            ]
        )
    _common.print_table(
        "Surrogates: grouped cross-validation (held-out designs) and inference",
        [
            "model",
            "best configuration",
            "R²",
            "RMSE °",
            "MAPE %",
            "max |e| °",
            "1 sample µs",
            "10k batch ms",
            "paper B R² / MAPE / IT",
        ],
        rows,
    )


def predict(
    model: Path = typer.Argument(..., help="A model saved by 'softbend train' (models/*.json)."),
    design: str = typer.Option(..., help="l,r,t,b,phi,lc in mm and degrees, e.g. 100,6,2,2,5,8."),
    pressure: str = typer.Option(..., help="Pressures in MPa, comma-separated, e.g. 0.05,0.1."),
    strict: bool = typer.Option(
        False, "--strict", help="Refuse a design or pressure outside the model's training data."
    ),
    as_json: bool = typer.Option(False, "--json", help="Print the predictions as JSON."),
) -> None:
    """Predict the bending angle of a design at the given pressures.

    A design or pressure outside the ranges the model was trained on (recorded in
    the model file) is a warning on stderr, or with ``--strict`` an error: a
    surrogate extrapolates without knowing it.
    """
    from softbend.design import SFRBADesign
    from softbend.surrogates.predict import INTERVAL_LEVEL, predict_angles

    values = _floats(design, "design")
    if len(values) != 6:
        raise ValueError(
            "The 'design' must be 6 numbers l,r,t,b,phi,lc (mm, mm, mm, mm, deg, mm). "
            f"Got {len(values)}: {design!r}."
        )
    checked = SFRBADesign(*values)  # validates the ranges, names the parameter
    result = predict_angles(model, checked, _floats(pressure, "pressure"), strict=strict)
    pressures, angles, outside = (
        result.pressure_mpa,
        result.angle_deg,
        result.outside_training_ranges,
    )
    if outside:
        _common.warning_line(
            f"{model} was not trained there: {'; '.join(outside)}; the prediction is an "
            "extrapolation (--strict refuses)."
        )
    interval = result.interval_deg
    if as_json:
        payload = {
            "model": str(model),
            "kind": result.kind,
            "design": checked.as_dict(),
            "pressure_mpa": pressures.tolist(),
            "angle_deg": angles.tolist(),
            "outside_training_ranges": outside,
        }
        if interval is not None:
            payload["interval_level"] = INTERVAL_LEVEL
            payload["interval_low_deg"] = interval[0].tolist()
            payload["interval_high_deg"] = interval[1].tolist()
        _common.print_json(payload)
        return
    columns = ["pressure (MPa)", "angle (°)"]
    rows = [[f"{p:g}", f"{a:.2f}"] for p, a in zip(pressures, angles, strict=True)]
    if interval is not None:
        columns.append(f"{INTERVAL_LEVEL:.0%} interval (°)")
        for row, low, high in zip(rows, *interval, strict=True):
            row.append(f"{low:.2f} to {high:.2f}")
    _common.print_table(f"{result.kind} surrogate, design {checked.design_id}", columns, rows)
