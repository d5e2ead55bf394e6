"""``softbend design find``: the designs that meet a specification, verified by the FEM."""

from __future__ import annotations

from pathlib import Path

import typer

from softbend.cli import _common

app = typer.Typer(
    help="Design to a specification.\n\n"
    "Search the design space on a surrogate for the designs that meet a target "
    "bending, and verify the best with the FEM.",
    no_args_is_help=True,
)


@app.command("find")
def find(
    out: Path = typer.Option(..., "--out", "-o", help="Folder for the tables and figures."),
    model: Path = typer.Option(
        None, help="Saved surrogate to search (default: the shipped FEM-trained MLP)."
    ),
    spec: Path = typer.Option(
        None, help="A TOML file of [[spec]] tables, one folder of results per spec."
    ),
    angle: float = typer.Option(None, help="Target angle, deg (with --at or --max-pressure)."),
    at: float = typer.Option(None, help="Pressure the target angle is read at, MPa."),
    max_pressure: float = typer.Option(
        None, help="Reach --angle at no more than this pressure, MPa (then --minimize pressure)."
    ),
    max_angle_at: float = typer.Option(None, help="Bend as far as possible at this pressure, MPa."),
    curve: str = typer.Option(
        None, help="Follow the points P:ANGLE, comma-separated (MPa:deg), e.g. 0.05:40,0.1:95."
    ),
    tolerance: float = typer.Option(3.0, help="How far the angle may miss, deg."),
    margin: float = typer.Option(
        0.0, help="Degrees of the tolerance kept back on the surrogate (its own error)."
    ),
    minimize: list[str] = typer.Option(
        None,
        help="Objectives to minimise: l, r, t, b, phi, lc, pressure, volume, "
        "sensitivity, angle, error (comma-separated or repeated; default error).",
    ),
    maximize: list[str] = typer.Option(None, help="Objectives to maximise (as --minimize)."),
    fix: list[str] = typer.Option(None, help="Fix a parameter, NAME=VALUE (repeatable)."),
    ranges: list[str] = typer.Option(
        None, "--range", help="Range of a parameter, NAME=LOW:HIGH (repeatable)."
    ),
    resolution: list[str] = typer.Option(
        None,
        help="Mould resolution: a number for every parameter or NAME=STEP (repeatable); "
        "0 searches continuously. Default 0.5 mm and 1° of phi.",
    ),
    top: int = typer.Option(10, help="Candidates listed."),
    neighbours: bool = typer.Option(
        False, "--neighbours", help="Also list designs one step from a better one."
    ),
    verify: int = typer.Option(0, help="Sweep the best N with --backend and compare."),
    backend: str = typer.Option("fem", help="Backend of the verification: fem or analytical."),
    workers: int = typer.Option(None, help="Processes of the verification (default: all cores)."),
    material: str = typer.Option(None, help="Elastomer of the verification (as fem run)."),
    allow_extrapolation: bool = typer.Option(
        False, "--allow-extrapolation", help="Search outside the training data, answers flagged."
    ),
    as_json: bool = typer.Option(False, "--json", help="Print the results as JSON."),
) -> None:
    """Find the designs that meet a target bending.

    Every design of the grid of manufacturable values (--resolution) within the
    model's training ranges (or --range, --fix) is scored on the surrogate;
    those that meet the target within --tolerance are ranked by the
    objectives (several: the Pareto front), each listed design more than one
    step from a better one (--neighbours lists them all). Answers outside the model's
    training data are passed over unless --allow-extrapolation. With --verify N
    the best N are swept by the FEM and set beside the surrogate.

    Example:

    \b
        softbend design find --angle 90 --at 0.08 --minimize l --fix phi=10 \\
            --range t=3:4 --verify 5 --out design
    """
    from softbend._io import staged_dir
    from softbend.design_search import spec as specs
    from softbend.design_search.search import find_designs
    from softbend.design_search.verify import verify_candidates
    from softbend.reports.design_outputs import FILES, write_search
    from softbend.surrogates.predict import load_predictor
    from softbend.transfer.base import shipped_base_path

    out = Path(out)
    model_path = shipped_base_path() if model is None else Path(model)
    inputs = tuple(p for p in (model, spec) if p is not None)
    _common.check_output_dir(out, "--out", inputs=inputs)
    _common.check_replaceable_dir(
        out, "--out", "design find", inputs=inputs, files=None, marker="search.json"
    )
    if top < 1:
        raise ValueError(f"The '--top' must be an integer >= 1. Got {top} instead.")
    if verify < 0:
        raise ValueError(f"The '--verify' must be an integer >= 0. Got {verify} instead.")
    if verify:
        from softbend.campaign.backends import public_backends

        if backend not in public_backends():
            raise ValueError(
                f"The '--backend' must be one of {', '.join(public_backends())}. "
                f"Got {backend!r} instead."
            )
    if spec is not None:
        chosen = specs.load_specifications(spec)
    else:
        target = specs.target_from_options(
            angle=angle, at=at, max_pressure=max_pressure, max_angle_at=max_angle_at,
            curve=curve, tolerance=tolerance,
        )  # fmt: skip
        numbers = [s for s in resolution or () if "=" not in s]
        if len(numbers) > 1:
            raise ValueError(
                f"The '--resolution' number is given {len(numbers)} times; give it once."
            )
        try:
            every = float(numbers[0]) if numbers else None
        except ValueError:
            raise ValueError(
                f"The '--resolution' must be a number or NAME=STEP. Got {numbers[0]!r} instead."
            ) from None
        given, steps = specs.build_ranges(
            fix or (), ranges or (), [s for s in resolution or () if "=" in s], step=every
        )
        objectives = specs.parse_objectives(minimize or (), maximize or ())
        chosen = [specs.Specification(target, given, objectives, "spec", steps, margin)]
    predictor, _ = load_predictor(model_path)
    results = []
    with _common.library_progress(enabled=not as_json):
        for one in chosen:
            result = find_designs(
                model_path,
                one,
                top=top,
                allow_extrapolation=allow_extrapolation,
                distinct=not neighbours,
            )
            if verify and result.candidates:
                verify_candidates(
                    result, verify, backend=backend, workers=workers, material=material
                )
            results.append(result)
    payload = [r.to_dict() for r in results]
    with _common.output_errors(out, "--out"), staged_dir(out) as stage:
        for result in results:
            folder = stage / result.spec.name if len(results) > 1 else stage
            write_search(result, predictor, folder)
        if len(results) > 1:  # the record of them all, and the folder's marker
            (stage / "search.json").write_text(
                _common.json_text({"specs": payload}) + "\n", encoding="utf-8"
            )
    for result in results:
        line = result.message()
        if line is not None:
            _common.warning_line(line)
    if as_json:
        _common.print_json(payload[0] if len(payload) == 1 else {"specs": payload})
        return
    for result in results:
        _print_result(result)
    _common.console.print(f"{', '.join(FILES)} written to {out}")


def _print_result(result: object) -> None:
    from softbend.design_search.search import SearchResult

    assert isinstance(result, SearchResult)
    spec = result.spec
    columns = ["#", "l,r,t,b,φ,lc", "θ (°)", "miss (°)"]
    columns += [f"{o.name}" for o in spec.objectives if o.name != "error"]
    verified = any(c.fem_meets is not None for c in result.candidates)
    if verified:
        columns += ["FEM θ (°)", "FEM ok"]
    rows = []
    for rank, c in enumerate(result.candidates, start=1):
        row = [str(rank), str(c.design), f"{c.angle_deg:.2f}", f"{c.error_deg:.2f}"]
        row += [f"{c.objectives[o.name]:.4g}" for o in spec.objectives if o.name != "error"]
        if verified:
            fem = "" if c.fem_angle_deg is None else f"{c.fem_angle_deg:.2f}"
            row += [fem, "" if c.fem_meets is None else ("yes" if c.fem_meets else "NO")]
        rows.append(row)
    title = (
        f"{spec.name}: {spec.target.describe()} — {result.n_meeting:,} of "
        f"{result.n_designs:,} designs meet it ({result.seconds:.1f} s)"
    )
    _common.print_table(title, columns, rows)
