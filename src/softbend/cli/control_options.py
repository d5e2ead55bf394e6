"""Options shared by ``softbend control simulate``, ``run`` and ``serve``."""

from __future__ import annotations

import typer

from softbend.cli._common import DESIGN_HELP

REFERENCE = typer.Option(
    "step:90",
    help="step:AMP[:T0_S], square:AMP:PERIOD_S[:LOW] or triangle:FREQ_HZ:AMP[:LOW] (degrees).",
)
CONTROLLER = typer.Option(
    None,
    help="A registered controller: bang-bang (default; paper B), bang-bang-closed, "
    "pressure-pi, pressure-relay, predictive or another ('softbend control controllers' "
    "lists them).",
)
SET = typer.Option(
    None,
    "--set",
    metavar="NAME=VALUE",
    help="A controller parameter NAME=VALUE, repeatable (e.g. --set deadzone=0.02 for "
    "bang-bang; 'softbend control controllers' lists them).",
)
DESIGN = typer.Option("100,6,2,2,5,8", help=DESIGN_HELP)
MODEL = typer.Option(
    None, "--model", help="Saved surrogate for θ(p) (default: the shipped FEM-trained MLP)."
)
PLANT = typer.Option(
    "surrogate",
    help="θ(p) of the actuator: surrogate (the controller's own model), fem (the design's "
    "FEM sweep), lab (its virtual-lab readings: model mismatch), or a file of your own "
    "actuator: a saved surrogate .json (e.g. from 'softbend transfer refine') or a "
    "measurements .csv (its loading readings, smoothed).",
)
RIG_PARAM = typer.Option(
    None,
    "--rig-param",
    metavar="NAME=VALUE",
    help="A parameter of the simulated rig NAME=VALUE, repeatable: valves "
    "(inlet_conductance_m3_s_pa, outlet_conductance_m3_s_pa, critical_ratio, valve_delay_s), "
    "tubing_mm3, supply_gauge_mpa, sensor (sensor_noise_mpa, sensor_bits, sensor_range_mpa), "
    "camera_noise_deg and more (the command 'control rig-parameters' lists them all).",
)
SUPPLY = typer.Option(
    None,
    help="Supply pressure of the simulated rig, MPa gauge (default 0.2; the same as "
    "--rig-param supply_gauge_mpa).",
)
STRICT = typer.Option(
    False,
    "--strict",
    help="Refuse a controller model or plant surrogate whose θ(p) of the design, up to the "
    "supply, leaves its training data (a pressure past what the designs nearest to it were "
    "swept to, an angle past the largest trained on).",
)
