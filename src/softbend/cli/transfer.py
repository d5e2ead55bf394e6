"""``softbend lab`` and ``softbend transfer``: measurements, refinement and its evaluation."""

from __future__ import annotations

import os
from collections.abc import Iterator
from contextlib import contextmanager
from pathlib import Path
from typing import TYPE_CHECKING

import typer

from softbend.cli import _common

if TYPE_CHECKING:
    from softbend.transfer.loco import LocoResult

lab_app = typer.Typer(
    help="The virtual lab: labelled-synthetic measurements of paper B's Fig. 7 actuators.",
    no_args_is_help=True,
)
app = typer.Typer(
    help="Transfer learning (paper B §4.2–4.3): refine a surrogate on measurements.",
    no_args_is_help=True,
)


def _names(text: str) -> list[str]:
    return [n.strip() for n in text.split(",") if n.strip()]


@contextmanager
def _as_written(staged: Path, final: Path) -> Iterator[None]:
    """An OS error about a file under ``staged`` names the file it becomes under ``final``.

    Outputs are written beside their place first (a staging folder, a temporary
    file) and moved there when complete; an error while writing them is about
    the output, and :func:`_common.output_errors` says so with the final name.
    """
    try:
        yield
    except OSError as exc:
        name = exc.filename
        if exc.errno is None or not isinstance(name, str | bytes):
            raise
        found = Path(os.path.abspath(os.fsdecode(name)))
        root = Path(os.path.abspath(staged))
        if found != root and root not in found.parents:
            raise
        renamed = Path(final) / found.relative_to(root) if found != root else Path(final)
        raise OSError(exc.errno, exc.strerror, str(renamed)) from exc


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


@lab_app.command("measure")
def measure(
    out: Path = typer.Option(..., "--out", help="CSV file to write the measurements to."),
    plant: str = typer.Option("fem", help="Model of the actuators as built: fem or analytical."),
    seed: int = typer.Option(0, help="Seed of the fabrication errors and the camera noise."),
    fabrication_error: float = typer.Option(
        0.2, help="Half-width of the uniform error of the wall t and layer b, mm."
    ),
    hysteresis: float = typer.Option(
        0.02, help="Half the largest loading/unloading gap, fraction of the angle."
    ),
    camera_noise: float = typer.Option(1.0, help="Standard deviation of the angle reading, deg."),
    elastomer_max_stretch: float = typer.Option(
        3.0, help="Largest stretch of the shipped Dragon Skin 30 test used by the lab's fit."
    ),
    pmax: float = typer.Option(0.25, help="Highest pressure set, MPa."),
    step: float = typer.Option(0.01, help="Pressure increment, MPa."),
    max_angle: float = typer.Option(270.0, help="Stop raising the pressure past this angle, deg."),
    unloading: bool = typer.Option(False, "--unloading", help="Also read the unloading branch."),
    cycles: int = typer.Option(
        1, help="Inflation cycles per actuator (at most SOFTBEND_MAX_CYCLES, default 1000)."
    ),
    as_json: bool = typer.Option(False, "--json", help="Print a JSON summary."),
) -> None:
    """Measure the 7 actuators of paper B Fig. 7 in the virtual lab (synthetic data).

    Writes the CSV and its figure (the same name with ``.png``) together: a run
    that fails leaves both as they were.
    """
    from softbend._io import atomic_files
    from softbend.limits import check_limit
    from softbend.reports.transfer_figures import lab_measurements
    from softbend.transfer.lab import VirtualLab
    from softbend.transfer.measurements import format_measurements

    check_limit("cycles", cycles, "--cycles")
    out = Path(out)
    figure = out.with_suffix(".png")
    if out.suffix.lower() == ".png":
        raise ValueError(
            f"The '--out' must name the CSV file; its figure is written beside it with "
            f"'.png'. Got {out}, which the figure would replace."
        )
    _common.check_output_file(out, "--out", kind="csv")
    _common.check_output_file(figure, "--out", kind="png")
    lab = VirtualLab(
        plant=plant,
        seed=seed,
        fabrication_error_mm=fabrication_error,
        hysteresis=hysteresis,
        camera_noise_deg=camera_noise,
        elastomer_max_stretch=elastomer_max_stretch,
        pmax_mpa=pmax,
        pressure_step_mpa=step,
        max_angle_deg=max_angle,
        unloading=unloading,
        cycles=cycles,
    )
    total = len(lab.actuators)
    with _common.progress_bar("virtual lab", total, enabled=not as_json) as advance:
        measurements = lab.measure(progress=lambda done, n, name: advance(actuator=name))
    text = format_measurements(measurements)
    with _common.output_errors(out, "--out"), atomic_files(out, figure) as (csv_file, png):
        with (
            _common.output_errors(out, "--out"),
            _as_written(csv_file, out),
            open(csv_file, "w", encoding="utf-8", newline="") as handle,
        ):
            handle.write(text)
        with _common.output_errors(figure, "--out"), _as_written(png, figure):
            lab_measurements(measurements, png)
    path = out
    frame = measurements.frame
    per = frame.groupby("actuator_id", sort=False).agg(
        points=("angle_deg", "size"),
        pmax=("pressure_mpa", "max"),
        angle_max=("angle_deg", "max"),
    )
    if as_json:
        _common.print_json(
            {
                "out": str(path),
                "figure": str(figure),
                "synthetic": True,
                "n_measurements": len(frame),
                "actuators": per.reset_index().to_dict(orient="records"),
                "metadata": dict(measurements.metadata),
            }
        )
        return
    _common.print_table(
        f"Virtual lab (SYNTHETIC, {plant}, seed {seed}): {len(frame)} readings",
        ["actuator (l,r,t,b,φ,lc)", "readings", "top pressure (MPa)", "largest angle (°)"],
        [[str(k), int(r.points), float(r.pmax), float(r.angle_max)] for k, r in per.iterrows()],
    )
    _common.console.print(f"measurements written to {path}, figure {figure}")


@app.command("base")
def base(
    out: Path = typer.Option(..., "--out", help="File for the saved MLP (JSON)."),
    epochs: int = typer.Option(1000, help="Training epochs (paper B: 1000)."),
    seed: int = typer.Option(0, help="Seed of the weights and the batch order."),
) -> None:
    """Train paper B's MLP (63, 65) on the shipped Table 1 FEM dataset and save it."""
    from softbend._io import json_safe
    from softbend.datasets import table1_fem_provenance
    from softbend.limits import check_limit
    from softbend.surrogates.features import training_ranges
    from softbend.surrogates.persistence import save_surrogate
    from softbend.transfer.base import BASE_HIDDEN_SIZES, fem_rows, train_base_mlp

    check_limit("epochs", epochs, "--epochs")
    _common.check_output_file(out, "--out", kind="json")
    with _common.progress_bar("training the FEM MLP (epochs)", epochs) as advance:
        state = {"done": 0}

        def progress(done: int, total: int) -> None:
            advance(done - state["done"])
            state["done"] = done

        model = train_base_mlp(epochs=epochs, seed=seed, progress=progress)
    provenance = table1_fem_provenance()
    metadata = {
        "purpose": "the FEM-trained MLP that transfer learning starts from",
        "trained_on": "softbend.datasets.table1_fem(), converged samples",
        "dataset_samples_sha256": provenance.get("files", {})
        .get("samples.parquet", {})
        .get("sha256"),
        "hidden_sizes": list(BASE_HIDDEN_SIZES),
        "epochs": epochs,
        "seed": seed,
        "command": f"softbend transfer base --out {out.name} --epochs {epochs} --seed {seed}",
        "final_training_mse_deg2": float(model.loss_curve_[-1]) * model.y_scale_**2,
        "training_ranges": training_ranges(fem_rows()),
    }
    with _common.output_errors(out, "--out"):
        path = save_surrogate(model, out, metadata=json_safe(metadata))
    _common.console.print(
        f"FEM MLP {BASE_HIDDEN_SIZES} written to {path} "
        f"(final training MSE {model.loss_curve_[-1] * model.y_scale_**2:.4g} deg²)"
    )


@app.command("loco")
def loco(
    measurements: Path = typer.Argument(..., help="Measurements CSV (see 'softbend lab measure')."),
    out: Path = typer.Option(..., "--out", help="Folder for tables and figures."),
    base: Path | None = typer.Option(
        None, help="Saved surrogate to start from (default: the shipped FEM-trained MLP)."
    ),
    strategies: str = typer.Option(
        "all", help="Comma-separated strategies, or 'all' (see 'softbend transfer strategies')."
    ),
    level: float = typer.Option(0.9, help="Probability of the prediction intervals."),
    learning_curve: bool = typer.Option(
        True, "--learning-curve/--no-learning-curve", help="Also fit on 1..n-2 actuators."
    ),
    seed: int = typer.Option(0, help="Seed of the strategies and the learning curve."),
    as_json: bool = typer.Option(False, "--json", help="Print the results as JSON."),
) -> None:
    """Leave one configuration out: every strategy, every held-out actuator (paper B Fig. 7).

    The folder ``--out`` is written as a whole: built beside it and swapped in
    when every table and figure is complete, so a run that fails leaves the
    previous results as they were. An existing ``--out`` may hold only what this
    command writes.
    """
    from softbend._io import staged_dir
    from softbend.reports import transfer_figures
    from softbend.transfer.base import load_base
    from softbend.transfer.loco import DEFAULT_STRATEGIES, leave_one_configuration_out
    from softbend.transfer.measurements import load_measurements

    out = Path(out)
    inputs = (measurements,) if base is None else (measurements, base)
    _common.check_output_dir(out, "--out", inputs=inputs, files=LOCO_FILES)
    _common.check_replaceable_dir(out, "--out", "transfer loco", inputs=inputs, files=LOCO_FILES)
    data = load_measurements(measurements)
    names = list(DEFAULT_STRATEGIES) if strategies.strip() == "all" else _names(strategies)
    model = load_base(base)
    with _common.phase_progress(enabled=not as_json) as progress:
        result = leave_one_configuration_out(
            data,
            model,
            names,
            level=level,
            learning_curve=learning_curve,
            seed=seed,
            progress=lambda done, total, name: progress("fitting strategies", done, total),
        )
    synthetic = str(data.metadata.get("synthetic", "")).startswith("true")
    with _common.output_errors(out, "--out"), staged_dir(out) as stage, _as_written(stage, out):
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
    files = {key: str(out / Path(value).name) for key, value in written.items()}
    if as_json:
        _common.print_json({**result.to_dict(), "files": files, "synthetic": synthetic})
        return
    print_loco_summary(result)
    _common.console.print(f"tables and figures written to {out}")


def print_loco_summary(result: LocoResult) -> None:
    """The per-strategy table beside paper B's refined MLP (used by reproduce too)."""
    rows = []
    for _, r in result.summary.iterrows():
        rows.append(
            [
                r["strategy"],
                float(r["rmse_deg"]),
                float(r["mape_pct"]),
                float(r["max_error_deg"]),
                "—" if r["coverage"] != r["coverage"] else f"{100 * r['coverage']:.1f} %",
                f"{r['worst_actuator']} ({r['worst_rmse_deg']:.1f}°)",
            ]
        )
    rows.append(["paper B refined MLP", 7.935, 6.45, "—", "—", "120,6,2,2,5,8 (19.58°)"])
    _common.print_table(
        f"Leave one configuration out ({len(result.settings['actuators'])} actuators, "
        f"{result.settings['n_measurements']} readings; intervals {result.level:.0%})",
        ["strategy", "mean RMSE °", "mean MAPE %", "max |e| °", "coverage", "worst actuator"],
        rows,
    )


#: Strategies that ``transfer refine`` fits and saves (the baselines learn nothing).
REFINE_STRATEGIES: tuple[str, ...] = (
    "refined",
    "experimental",
    "scale-offset",
    "pressure-scale",
    "residual-gp",
    "refined-ensemble",
    "scaled-refined",
)


@app.command("refine")
def refine(
    base: Path = typer.Argument(..., help="Saved surrogate to start from (an mlp for 'refined')."),
    measurements: Path = typer.Argument(..., help="Measurements CSV."),
    out: Path = typer.Option(..., "--out", help="File for the refined model (JSON)."),
    strategy: str = typer.Option("refined", help=f"Strategy: {', '.join(REFINE_STRATEGIES)}."),
    epochs: int | None = typer.Option(
        None, help="Epochs of the MLP strategies (default: the strategy's)."
    ),
    seed: int = typer.Option(0, help="Seed of the training."),
) -> None:
    """Fit a strategy on all measurements and save it like the other surrogates.

    The saved model plugs into ``softbend predict``; the strategies with
    intervals (scale-offset, pressure-scale, residual-gp, refined-ensemble) save them too.
    """
    import numpy as np

    from softbend._io import json_safe
    from softbend._validation import check_choice
    from softbend.limits import check_limit
    from softbend.surrogates.persistence import save_surrogate
    from softbend.transfer.measurements import load_measurements
    from softbend.transfer.strategies import NETWORK_STRATEGIES, fit_strategy

    check_choice(strategy, "strategy", "softbend transfer refine", REFINE_STRATEGIES)
    if epochs is not None:
        check_limit("epochs", epochs, "--epochs")
    if epochs is not None and strategy not in NETWORK_STRATEGIES:
        raise ValueError(
            f"The '--epochs' option applies to the MLP strategies "
            f"({', '.join(NETWORK_STRATEGIES)}); {strategy!r} trains no network."
        )
    _common.check_output_file(out, "--out", inputs=(base, measurements), kind="json")
    data = load_measurements(measurements)
    from softbend.surrogates.features import training_ranges
    from softbend.surrogates.persistence import load_surrogate

    start = load_surrogate(base)
    model = fit_strategy(strategy, start.model, data, seed=seed, epochs=epochs)
    ranges = training_ranges(data.features)
    if strategy != "experimental" and isinstance(start.metadata.get("training_ranges"), dict):
        ranges = {  # the base's simulations and the measurements
            k: [
                min(v[0], start.metadata["training_ranges"][k][0]),
                max(v[1], start.metadata["training_ranges"][k][1]),
            ]
            for k, v in ranges.items()
        }
    residual = data.angle_deg - model.predict(data.features)
    metadata = {
        "strategy": strategy,
        "base": str(base),
        "measurements": str(measurements),
        "n_measurements": len(data),
        "actuators": list(data.actuator_ids),
        "synthetic_measurements": str(data.metadata.get("synthetic", "false")),
        "training_rmse_deg": float(np.sqrt(np.mean(residual**2))),
        "training_ranges": ranges,
    }
    if hasattr(model, "loss_curve_"):
        metadata["final_training_mse_deg2"] = float(model.loss_curve_[-1])
    with _common.output_errors(out, "--out"):
        path = save_surrogate(model.model_, out, metadata=json_safe(metadata))
    _common.console.print(
        f"{strategy} model on {len(data)} readings of {len(data.actuator_ids)} actuators "
        f"written to {path} (training RMSE {metadata['training_rmse_deg']:.3g}°); "
        f"use it with 'softbend predict {path}'"
    )
