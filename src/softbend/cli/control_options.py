"""Options of ``softbend control simulate``, ``run`` and ``serve``."""

from __future__ import annotations

import typer

REFERENCE = typer.Option(
    "step:90",
    help="step:AMP[:T0_S], square:AMP:PERIOD_S[:LOW], triangle:FREQ_HZ:AMP[:LOW] or "
    "sine:AMP:PERIOD_S[:OFFSET] (angles in degrees, times in s): the square, triangle and sine "
    "swing between LOW or OFFSET (default 0) at t = 0 and AMP.",
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
DESIGN = typer.Option(
    None,
    metavar="DESIGN",
    help="The actuator's design, read by the actuator of the controller's model: paper B's "
    "l,r,t,b,phi,lc in mm and degrees (default 100,6,2,2,5,8), or NAME=VALUE pairs by the "
    "parameters of another model's actuator, in its units (e.g. "
    "n_chambers=10,wall_mm=2,layer=paper; required for such a model).",
)
MODEL = typer.Option(
    None,
    "--model",
    help="Saved surrogate (of any actuator) the controller uses: θ(p) and virtual angle sensor "
    "(default: the --plant when it is a saved surrogate, else the shipped FEM-trained MLP); "
    "with another --plant .json, a deliberate model mismatch.",
)
PLANT = typer.Option(
    "surrogate",
    help="θ(p) of the actuator: surrogate (the controller's own model), fem (the design's "
    "FEM sweep), lab (its virtual-lab readings: model mismatch), or a file of your own "
    "actuator: a saved surrogate .json (e.g. from 'softbend transfer refine'; also the "
    "controller's model unless --model is given) or a measurements .csv (its loading "
    "readings, smoothed), or a model of 'softbend identify' (DIR/model.json: one pressure "
    "input, an angle output; its dynamics replace θ(p) and the angle lag). fem, lab and .csv "
    "are paper B's actuator's only.",
)
RIG_PARAM = typer.Option(
    None,
    "--rig-param",
    metavar="NAME=VALUE",
    help="A parameter of the simulated rig NAME=VALUE, repeatable: valves "
    "(inlet_conductance_m3_s_pa, outlet_conductance_m3_s_pa, critical_ratio, valve_delay_s), "
    "tubing_mm3, supply_gauge_mpa, sensor (sensor_noise_mpa, sensor_bits, sensor_range_mpa), "
    "camera_noise_deg and more (the command 'control rig-parameters' lists them all). A "
    "pressure (a name ending in _mpa) is a bare number in MPa, as its name says, or takes a "
    "unit: supply_gauge_mpa=20psi, sensor_noise_mpa=0.5kPa. The "
    "chamber is paper B's design's cavity plus tubing_mm3; another actuator's is its "
    "description's chamber_volume_mm3 plus tubing_mm3, growing by its "
    "volume_growth_mm3_per_mpa (else rigid, with a warning): without a described volume, "
    "give volume_mm3 (measured, tubing included) or the run is refused.",
)
RIG_FROM = typer.Option(
    None,
    "--rig-from",
    help="A model of 'softbend identify' (DIR/model.json: a pressure input, an angle output) "
    "whose step reading sets the simulated rig's angle_time_constant_s (its time constant) "
    "and valve_delay_s (its delay); --rig-param values win.",
)
SUPPLY = typer.Option(
    None,
    "--supply",
    help="Supply pressure of the simulated rig, gauge: a number with a unit (20psi, 138kPa, "
    "0.2MPa, 2bar), or a bare number in the pressure unit of the plant when it is a saved "
    "model (else of --model; else MPa, as paper B's) (default 0.2 MPa; the same as "
    "--rig-param supply_gauge_mpa).",
)
STRICT = typer.Option(
    False,
    "--strict",
    help="Refuse a design outside the training ranges of the controller's model, and a "
    "controller model or plant surrogate whose θ(p) of the design, up to the supply, leaves "
    "its training data (a pressure past what the designs nearest to it were swept to, an "
    "angle past the largest trained on); without it, each is a warning.",
)
RUN_OUT = typer.Option(
    ...,
    "--out",
    "-o",
    help="Folder for ticks.csv|parquet, run.json and run.png (replaced as a whole: a new "
    "or empty folder, or an earlier result of this command).",
)
RIG = typer.Option(
    "sim",
    help="A registered rig: sim (simulated time), sim-realtime (simulated, on the wall "
    "clock) or modbus.",
)
CONFIG = typer.Option(
    None,
    "--config",
    help="Rig TOML: connection, register map, scaling, safety, period, [controller], "
    "[simulation] (required for --rig modbus; its [safety] and [loop] apply to every rig).",
)
RUN_DURATION = typer.Option(
    10.0,
    "--duration",
    help="Run time, s: in (0, 86400] and at most SOFTBEND_MAX_LOOP_TICKS ticks (default "
    "10 000 000: 10 000 s at the default 1 ms tick), each logged in memory.",
)
PERIOD = typer.Option(
    None,
    "--period",
    help="Loop tick (controller, valves), s (default: the config's period_s, 0.001).",
)
SENSOR_PERIOD = typer.Option(
    None,
    "--sensor-period",
    help="Pressure reading period, s (default: the config's sensor_period_s, 0.01: 100 Hz).",
)
LOG_FORMAT = typer.Option("csv", help="Tick log format: csv (streamed) or parquet.")
