"""``softbend materials``: shipped tensile tests and hyperelastic fits (paper B §3.1, Fig. 2a)."""

from __future__ import annotations

from pathlib import Path
from typing import TYPE_CHECKING, Annotated, Any

import typer

from softbend.cli import _common

if TYPE_CHECKING:
    from softbend.materials.fit import FitResult
    from softbend.materials.tensile import TensileTest

app = typer.Typer(
    help="Tensile tests and hyperelastic fits (paper B §3.1).\n\n"
    "The uniaxial tensile tests shipped with softbend, and fits of hyperelastic "
    "models to them or to your own.",
    no_args_is_help=True,
)

_SYMBOLS = {
    "c10_mpa": "C10",
    "c20_mpa": "C20",
    "c30_mpa": "C30",
    "mu_mpa": "μ",
    "lambda_m": "λm",
}


def _describe(result: FitResult) -> str:
    return ", ".join(f"{_SYMBOLS.get(k, k)} {v:.4g}" for k, v in result.parameters.items())


_CSV = typer.Argument(
    help=(
        "Tensile data file (semicolon-separated, with the columns 'Engineering Strain' "
        "and 'Engineering Stress (MPa)') or the name of a shipped test "
        "(see 'softbend materials list'). Default: the shipped Dragon Skin 30 test."
    ),
    show_default=False,
)
_MODELS = typer.Option(
    "--models", help="Comma-separated models among neo-hookean, yeoh, arruda-boyce."
)
_OUT = typer.Option("--out", "-o", help="Folder for fit.png and fit.json (created if missing).")
_MAX_STRETCH = typer.Option(
    "--max-stretch",
    help="Fit only the points with stretch ≤ this (> 1). Default: all, to failure.",
    show_default=False,
)
_FORCE = typer.Option(
    "--force",
    help="Read a stress column that looks like kPa (stiffer than 20 MPa) as given.",
)
_JSON = typer.Option("--json", help="Print the results as JSON.")


@app.command("fit")
def fit(
    csv: Annotated[str | None, _CSV] = None,
    models: Annotated[str, _MODELS] = "neo-hookean,yeoh,arruda-boyce",
    out: Annotated[Path, _OUT] = Path("results/materials"),
    max_stretch: Annotated[float | None, _MAX_STRETCH] = None,
    force: Annotated[bool, _FORCE] = False,
    json_output: Annotated[bool, _JSON] = False,
) -> None:
    """Fit hyperelastic models to a uniaxial tensile test.

    As paper B, Figure 2a: least squares of each model's nominal stress in
    incompressible uniaxial tension against the measured engineering stress
    (MPa), with R² and RMSE. Writes fit.png (data and fitted curves) and
    fit.json into the folder --out.

    Example:

    \b
        softbend materials fit dragon-skin-30 --models yeoh --out results/materials
    """
    from softbend.materials.fit import fit_models
    from softbend.materials.tensile import load_tensile
    from softbend.reports.material_outputs import FIT_JSON, FIT_PNG, write_fit

    names = [m.strip() for m in models.split(",") if m.strip()]
    inputs = (Path(csv),) if csv is not None and Path(csv).exists() else ()
    _common.check_output_dir(out, "--out", inputs=inputs, files=(FIT_PNG, FIT_JSON))
    test = load_tensile(csv, force=force)
    results = fit_models(test, names, max_stretch=max_stretch)
    with _common.output_errors(out, "--out"):
        payload = write_fit(test, results, max_stretch, out)
    if json_output:
        _common.print_json(payload)
        return
    _print_fit(test, results, payload, out)


def _print_fit(
    test: TensileTest, results: dict[str, FitResult], payload: dict[str, Any], out: Path
) -> None:
    """The fits as a table, the data's attribution, the best model and where the files are."""
    first, last = next(iter(results.values())).stretch_range
    _common.print_table(
        f"{test.material}: {test.n_points} points, stretch {first:.4g} to {last:.4g} fitted",
        ["model", "parameters (C, μ in MPa)", "R²", "RMSE (MPa)", "points"],
        [
            [r.name, _describe(r), f"{r.r2:.4f}", f"{r.rmse_mpa:.4f}", r.n_points]
            for r in results.values()
        ],
    )
    if test.attribution:
        _common.console.print(f"Data: {test.attribution}", highlight=False)
    if payload["best_model"] is not None:
        _common.console.print(f"Best fit (highest R²): {payload['best_model']}", highlight=False)
    _common.console.print(f"Figure and JSON written to {out}", highlight=False)


@app.command("list")
def list_tests(
    json_output: Annotated[bool, typer.Option("--json", help="Print the list as JSON.")] = False,
) -> None:
    """List the tensile tests shipped with softbend.

    The tests are those of Marechal et al. (Soft Robotics, 2021), pulled to
    failure; the data are under the ODbL 1.0.

    Example:

    \b
        softbend materials list --json
    """
    from softbend.materials.tensile import SHIPPED_ATTRIBUTION, load_shipped, shipped_tensile_tests

    tests = [load_shipped(name) for name in shipped_tensile_tests()]
    rows = [
        [t.name, t.n_points, t.max_strain, float(t.engineering_stress_mpa.max())] for t in tests
    ]
    if json_output:
        _common.print_json(
            {
                "attribution": SHIPPED_ATTRIBUTION,
                "tests": [t.summary() for t in tests],
            }
        )
        return
    _common.print_table(
        "Shipped uniaxial tensile tests (pull to failure)",
        ["name", "points", "max strain", "max stress (MPa)"],
        rows,
    )
    _common.console.print(f"Data: {SHIPPED_ATTRIBUTION}", highlight=False)
