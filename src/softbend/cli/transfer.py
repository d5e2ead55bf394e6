"""``softbend transfer``: refine a surrogate on measurements, and evaluate the strategies.

``base`` trains the surrogate refinement starts from, ``refine`` fits one
strategy and saves it, ``loco`` (:mod:`~softbend.cli.transfer_loco`) scores every
strategy on held-out actuators, ``strategies`` lists them with their parameters.
The virtual lab (``softbend lab``) is :mod:`~softbend.cli.transfer_lab`.
"""

from __future__ import annotations

from collections.abc import Mapping
from pathlib import Path
from typing import Any

import typer

from softbend.cli import _common
from softbend.cli.transfer_lab import lab_app
from softbend.cli.transfer_loco import LOCO_FILES, loco, print_loco_summary

__all__ = ["LOCO_FILES", "app", "lab_app", "print_loco_summary"]

app = typer.Typer(
    help="Refine a surrogate on measurements (paper B §4.2-4.3).\n\n"
    "Transfer learning: train the base surrogate, refine it on an actuator's "
    "measurements with a strategy, and score the strategies on held-out actuators.",
    no_args_is_help=True,
)
app.command("loco")(loco)


@app.command("base")
def base(
    out: Path = typer.Option(..., "--out", "-o", help="File for the saved MLP (JSON)."),
    epochs: int = typer.Option(1000, help="Training epochs (paper B: 1000)."),
    seed: int = typer.Option(0, help="Seed of the weights and the batch order."),
) -> None:
    """Train paper B's base MLP on the shipped FEM dataset.

    The MLP of paper B (hidden layers 63 and 65), trained on the shipped
    Table 1 FEM dataset and saved as a surrogate: the model the strategies
    refine.

    Example:

    \b
        softbend transfer base --out base.json --epochs 1000
    """
    from softbend._validation import check_int
    from softbend.limits import check_limit

    check_int(epochs, "epochs", low=1)
    check_limit("epochs", epochs, "--epochs")
    _common.check_output_file(out, "--out", kind="model")
    # heavy (PyTorch, scikit-learn: seconds): after the arguments' checks
    from softbend._io import json_safe
    from softbend.surrogates.persistence import save_surrogate
    from softbend.transfer.base import BASE_HIDDEN_SIZES, base_metadata, train_base_mlp

    with _common.progress_bar("training the FEM MLP (epochs)", epochs) as advance:
        state = {"done": 0}

        def progress(done: int, total: int) -> None:
            advance(done - state["done"])
            state["done"] = done

        model = train_base_mlp(epochs=epochs, seed=seed, progress=progress)
    command = f"softbend transfer base --out {out.name} --epochs {epochs} --seed {seed}"
    metadata = base_metadata(model, epochs=epochs, seed=seed, command=command)
    with _common.output_errors(out, "--out"):
        path = save_surrogate(model, out, metadata=json_safe(metadata))
    _common.console.print(
        f"FEM MLP {BASE_HIDDEN_SIZES} written to {path} "
        f"(final training MSE {model.loss_curve_[-1] * model.y_scale_**2:.4g} deg²)"
    )


_BASE = typer.Argument(..., help="Saved surrogate to start from (an mlp for 'refined').")
_MEASUREMENTS = typer.Argument(
    ...,
    metavar="MEASUREMENTS",
    help="Measurements CSV file(s); several are joined, each keeping its provenance.",
)
_OUT = typer.Option(..., "--out", "-o", help="File for the refined model (JSON).")
_STRATEGY = typer.Option(
    None,
    help="A strategy that learns from the measurements (see 'softbend transfer "
    "strategies'). Default: 'refined' for an mlp base, else 'scale-offset'.",
)
_SET = typer.Option(
    None,
    "--set",
    help="A parameter of the strategy, NAME=VALUE (repeatable; recorded in the model file).",
)
_EPOCHS = typer.Option(
    None,
    min=1,
    help="Epochs of the MLP strategies (default: the strategy's); as --set epochs=N.",
)
_SEED = typer.Option(0, min=0, help="Seed of the training.")
_FORCE = typer.Option(
    False,
    "--force",
    help="Use pressures past the base model's range (1.5x its top) and angles that look "
    "like radians next to its prediction as given (with a warning; recorded in the model "
    "file).",
)


@app.command("refine")
def refine(
    base: Path = _BASE,
    measurements: list[Path] = _MEASUREMENTS,
    out: Path = _OUT,
    strategy: str | None = _STRATEGY,
    settings: list[str] | None = _SET,
    epochs: int | None = _EPOCHS,
    seed: int = _SEED,
    force: bool = _FORCE,
) -> None:
    """Fit a strategy on measurements and save it.

    Without --strategy, the base's own default: paper B's refined MLP for an mlp base,
    scale-offset (the base frozen, corrected linearly) for any other, said on stderr. A
    strategy that cannot start from the base is refused before any work, naming those that
    can.

    The strategy learns from all the MEASUREMENTS (one or more CSV files, joined; the
    model file records each file with its SHA-256); the model is saved like the other
    surrogates and plugs into 'softbend predict'; the strategies with intervals
    (scale-offset, pressure-scale, residual-gp, refined-ensemble) save them too. The
    model file records the strategy and every one of its parameters as used.

    Every --set value is held to the range its parameter declares before any work
    ('softbend transfer strategies' lists them); a refit whose predictions or
    figures are not finite is an error, never a saved model.

    Example:

    \b
        softbend transfer refine base.json lab.csv --out refined.json --set epochs=500
        softbend transfer refine base.json lab.csv bench.csv --out refined.json
    """
    values = _strategy_settings(settings, epochs)
    _check_inputs(base, measurements)
    _common.check_output_file(out, "--out", inputs=(base, *measurements), kind="model")
    from softbend.transfer.refine import refine_surrogate  # heavy: after the arguments' checks

    with _common.library_progress():  # the refit's epochs, then the calibration's
        result = refine_surrogate(
            base, measurements, strategy, seed=seed, settings=values, force=force
        )
    with _common.output_errors(out, "--out"):
        path = result.save(out)
    _print_refined(result.metadata, path)


def _strategy_settings(settings: list[str] | None, epochs: int | None) -> dict[str, str]:
    """The ``--set`` values, with ``--epochs`` as ``epochs`` (refused when both give it)."""
    from softbend.limits import check_limit

    values = _common.parse_assignments(settings or ())
    if epochs is not None:
        if "epochs" in values:
            raise ValueError(
                "The epochs are given twice, by '--epochs' and '--set'; give them once."
            )
        check_limit("epochs", epochs, "--epochs")
        values["epochs"] = str(epochs)
    return values


def _print_refined(meta: Mapping[str, Any], path: Path) -> None:
    """The strategy fitted (and any left out for it), its training error and interval."""
    strategy = str(meta["strategy"])
    for name, reason in meta.get("strategy_left_out", {}).items():
        _common.warning_line(
            f"--strategy not given: '{name}' {reason}; fitted '{strategy}' instead "
            "(recorded in the model file, strategy_left_out)"
        )
    interval = meta.get("interval")
    calibration = (
        f"; calibrated {interval['level']:.0%} interval ±{interval['half_width_deg']:.3g}° "
        f"over {interval['n_actuators']} actuators"
        if isinstance(interval, dict)
        else ""
    )
    _common.console.print(
        f"{strategy} model on {meta['n_measurements']} readings of {len(meta['actuators'])} "
        f"actuators written to {path} (training RMSE {meta['training_rmse_deg']:.3g}°"
        f"{calibration}); use it with 'softbend predict {path}'"
    )


def _check_inputs(base: Path, measurements: list[Path]) -> None:
    """Refuse a missing base model or measurements file before the strategies are imported
    (scikit-learn, PyTorch: seconds)."""
    if not base.is_file():
        raise FileNotFoundError(f"No saved surrogate at {base}.")
    for path in measurements:
        if not path.is_file():
            raise FileNotFoundError(f"No measurements file at {path}.")


@app.command("strategies")
def strategies(
    as_json: bool = typer.Option(False, "--json", help="Print the list as JSON."),
) -> None:
    """List the transfer strategies and their parameters.

    What each strategy does, whether it learns (refine) and gives intervals,
    and the parameters --set NAME=VALUE may give it, with the range of each
    number (a value outside is refused before any work).

    Example:

    \b
        softbend transfer strategies --json
    """
    from softbend.transfer.strategies import describe_strategies

    rows = describe_strategies()
    if as_json:
        _common.print_json(rows)
        return

    def shown(value: object) -> str:
        return ",".join(map(str, value)) if isinstance(value, tuple) else str(value)

    _common.print_table(
        "Transfer strategies (softbend transfer loco --strategies, refine --strategy)",
        ["strategy", "what it does", "parameters (--set NAME=VALUE)", "refine", "interval"],
        [
            [
                r["name"],
                r["summary"],
                ", ".join(
                    f"{k}={shown(v)}" + (f" in {r['ranges'][k]}" if k in r["ranges"] else "")
                    for k, v in r["parameters"].items()
                )
                or "—",
                "yes" if r["learns"] else "no (baseline)",
                "yes" if r["interval"] else "no",
            ]
            for r in rows
        ],
    )
