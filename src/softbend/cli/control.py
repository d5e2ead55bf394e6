"""``softbend control``: closed-loop control of an actuator on the simulated rig (paper B §5)."""

from __future__ import annotations

from pathlib import Path

import typer

from softbend.cli import _common

app = typer.Typer(
    help="Closed-loop control (paper B §5): valves, pressure sensor, virtual angle sensor.",
    no_args_is_help=True,
)

_FILES = ("run.csv", "metrics.json", "run.png")


def build_controller(name: str, table, sensor):
    """The controller called ``name`` (see :data:`softbend.control.controllers.CONTROLLERS`)."""
    from softbend._validation import check_choice
    from softbend.control.controllers import CONTROLLERS, BangBang, PressurePI, PressureRelay

    check_choice(name, "controller", "softbend control simulate", CONTROLLERS)
    if name == "bang-bang":
        return BangBang(sensor, mode="hold")
    if name == "bang-bang-closed":
        return BangBang(sensor, mode="closed")
    if name == "pressure-pi":
        return PressurePI(table)
    return PressureRelay(table)


def _figure(run, path: Path, title: str) -> Path | None:
    try:
        import matplotlib

        matplotlib.use("Agg")
        import matplotlib.pyplot as plt
    except ImportError:  # pragma: no cover - matplotlib is optional here
        return None
    fig, axes = plt.subplots(3, 1, figsize=(8, 7), sharex=True, height_ratios=(3, 1, 2))
    axes[0].plot(run.t_s, run.reference_deg, "k--", lw=1, label="reference θr")
    axes[0].plot(run.t_s, run.camera_deg, lw=1.2, label="true angle θe (camera)")
    axes[0].plot(run.t_s, run.predicted_deg, lw=0.8, alpha=0.8, label="predicted θp (MLP)")
    axes[0].set_ylabel("angle (°)")
    axes[0].legend(loc="upper right", fontsize=8)
    axes[0].set_title(title, fontsize=9)
    axes[1].step(run.t_s, run.inlet.astype(float) + 1.2, where="post", lw=0.8, label="inlet")
    axes[1].step(run.t_s, run.outlet.astype(float), where="post", lw=0.8, label="outlet")
    axes[1].set_yticks([0, 1, 1.2, 2.2], ["shut", "open", "shut", "open"], fontsize=7)
    axes[1].legend(loc="upper right", fontsize=7)
    axes[2].plot(run.t_s, run.pressure_mpa, lw=1, label="true")
    axes[2].plot(run.t_s, run.measured_mpa, lw=0.6, alpha=0.7, label="sensor")
    axes[2].set_ylabel("pressure (MPa, gauge)")
    axes[2].set_xlabel("time (s)")
    axes[2].legend(loc="upper right", fontsize=8)
    fig.tight_layout()
    fig.savefig(path, dpi=120)
    plt.close(fig)
    return path


@app.command("simulate")
def simulate_cmd(
    out: Path = typer.Option(..., "--out", help="Folder for run.csv, metrics.json and run.png."),
    reference: str = typer.Option(
        "step:90",
        help="step:AMP[:T0_S], square:AMP:PERIOD_S[:LOW] or triangle:FREQ_HZ:AMP[:LOW] (degrees).",
    ),
    controller: str = typer.Option(
        "bang-bang", help="bang-bang, bang-bang-closed, pressure-pi or pressure-relay."
    ),
    design: str = typer.Option("100,6,2,2,5,8", help="Actuator l,r,t,b,phi,lc (mm, deg)."),
    model: Path = typer.Option(
        None, "--model", help="Saved surrogate for θ(p) (default: the shipped FEM-trained MLP)."
    ),
    duration: float = typer.Option(10.0, help="Simulated time, s."),
    supply: float = typer.Option(0.2, help="Supply pressure, MPa gauge."),
    seed: int = typer.Option(0, help="Seed of the sensor and camera noise."),
    as_json: bool = typer.Option(False, "--json", help="Print the metrics as JSON."),
) -> None:
    """Run a controller on the simulated rig and score it as paper B's Fig. 9 (synthetic)."""
    from softbend._validation import check_choice
    from softbend.control.controllers import CONTROLLERS, mlp_virtual_sensor
    from softbend.control.experiments import parse_reference, run_metrics, simulate
    from softbend.control.rig import AngleTable, RigParams, SimulatedRig
    from softbend.design import SFRBADesign
    from softbend.transfer.base import load_base

    check_choice(controller, "controller", "softbend control simulate", CONTROLLERS)
    ref = parse_reference(reference)
    actuator = SFRBADesign.parse(design)
    params = RigParams.for_design(actuator, supply_gauge_mpa=supply)
    _common.check_output_dir(out, "--out", files=_FILES)
    surrogate = load_base(model)
    table = AngleTable.from_surrogate(surrogate, actuator)
    sensor = mlp_virtual_sensor(surrogate, actuator) if hasattr(surrogate, "predictor") else table
    ctrl = build_controller(controller, table, sensor)
    rig = SimulatedRig(table, params, seed=seed)
    run = simulate(rig, ctrl, ref, duration, seed=seed)
    metrics = run_metrics(run)
    payload = {
        "synthetic": True,
        "reference": reference,
        "controller": controller,
        "design": str(actuator),
        "duration_s": duration,
        "seed": seed,
        "rig": params.as_dict(),
        "metrics": metrics,
    }
    with _common.output_errors(out, "--out"):
        out.mkdir(parents=True, exist_ok=True)
        run.frame().to_csv(out / "run.csv", index=False)
        (out / "metrics.json").write_text(_common.json_text(payload) + "\n", encoding="utf-8")
        figure = _figure(
            run, out / "run.png", f"{controller} on {actuator}, {reference} (simulated)"
        )
    payload["files"] = [str(out / "run.csv"), str(out / "metrics.json")] + (
        [str(figure)] if figure else []
    )
    if as_json:
        _common.print_json(payload)
        return
    _common.print_table(
        f"{controller} on {actuator}, {reference}: simulated rig (SYNTHETIC)",
        ["metric", "value"],
        [[k, v] for k, v in metrics.items()],
    )
    _common.console.print(f"run written to {out}")


__all__ = ["app", "build_controller"]
