"""``softbend materials``: shipped tensile tests and hyperelastic fits (paper B §3.1, Fig. 2a)."""

from __future__ import annotations

from pathlib import Path
from typing import TYPE_CHECKING, Annotated

import typer

from softbend.cli import _common

if TYPE_CHECKING:
    from softbend.materials.fit import FitResult

app = typer.Typer(
    help="Tensile tests and hyperelastic fits (paper B §3.1).\n\n"
    "The uniaxial tensile tests shipped with softbend, and fits of hyperelastic "
    "models to them or to your own.",
    no_args_is_help=True,
)

#: Files written into ``--out`` by ``fit``.
FIT_PNG = "fit.png"
FIT_JSON = "fit.json"
_SYMBOLS = {
    "c10_mpa": "C10",
    "c20_mpa": "C20",
    "c30_mpa": "C30",
    "mu_mpa": "μ",
    "lambda_m": "λm",
}


def _describe(result: FitResult) -> str:
    return ", ".join(f"{_SYMBOLS.get(k, k)} {v:.4g}" for k, v in result.parameters.items())


@app.command("fit")
def fit(
    csv: Annotated[
        str | None,
        typer.Argument(
            help=(
                "Tensile data file (semicolon-separated, with the columns 'Engineering Strain' "
                "and 'Engineering Stress (MPa)') or the name of a shipped test "
                "(see 'softbend materials list'). Default: the shipped Dragon Skin 30 test."
            ),
            show_default=False,
        ),
    ] = None,
    models: Annotated[
        str,
        typer.Option(
            "--models", help="Comma-separated models among neo-hookean, yeoh, arruda-boyce."
        ),
    ] = "neo-hookean,yeoh,arruda-boyce",
    out: Annotated[
        Path,
        typer.Option("--out", "-o", help="Folder for fit.png and fit.json (created if missing)."),
    ] = Path("results/materials"),
    max_stretch: Annotated[
        float | None,
        typer.Option(
            "--max-stretch",
            help="Fit only the points with stretch ≤ this (> 1). Default: all, to failure.",
            show_default=False,
        ),
    ] = None,
    force: Annotated[
        bool,
        typer.Option(
            "--force",
            help="Read a stress column that looks like kPa (stiffer than 20 MPa) as given.",
        ),
    ] = False,
    json_output: Annotated[bool, typer.Option("--json", help="Print the results as JSON.")] = False,
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
    from softbend._io import atomic_files
    from softbend.materials.fit import fit_file_payload, fit_models
    from softbend.materials.tensile import load_tensile
    from softbend.reports.material_figures import fit_figure

    names = [m.strip() for m in models.split(",") if m.strip()]
    inputs = (Path(csv),) if csv is not None and Path(csv).exists() else ()
    _common.check_output_dir(out, "--out", inputs=inputs, files=(FIT_PNG, FIT_JSON))
    test = load_tensile(csv, force=force)
    results = fit_models(test, names, max_stretch=max_stretch)

    figure = out / FIT_PNG
    payload = fit_file_payload(test, results, max_stretch)
    payload["files"] = {"figure": str(figure), "json": str(out / FIT_JSON)}
    with (
        _common.output_errors(out, "--out"),
        atomic_files(figure, out / FIT_JSON) as (png, summary),  # both new, or both as they were
    ):
        fit_figure(test, results, png)
        summary.write_text(_common.json_text(payload) + "\n", encoding="utf-8")

    if json_output:
        _common.print_json(payload)
        return
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
