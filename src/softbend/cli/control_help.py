"""The help texts of ``softbend control simulate`` and ``run`` (what ``--help`` prints)."""

SIMULATE = """\
Run a controller on the simulated rig and score it.

Scores the run as paper B, Figure 9 (synthetic data). metrics.json records
the controller and the rig, with every one of their parameters as used, and
the controller's model. That model (θ(p) and virtual angle sensor) is
--model, else the --plant when it is a saved surrogate (a refined model is
its own soft sensor, as in paper B), else the shipped FEM-trained MLP;
--model with another --plant .json is a deliberate mismatch, and the table
names both. A model of any actuator may be used: --design names its
parameters (NAME=VALUE pairs), its pressures are converted from the rig's MPa
(a bare --supply is in the model's pressure unit, a --rig-param pressure in
MPa as its name says, both take a unit such as 20psi; the scores stay in
MPa), and the chamber is its
description's (else --rig-param volume_mm3). A design outside the model's
training ranges is a warning naming the parameter, and the table's row
"design in the model's training data" and design_supported in metrics.json
say so; --strict refuses it. A model of 'softbend identify' (one pressure
input, an angle output, a time column in s or ms) may play the plant: its
dynamics replace θ(p) and the angle lag, and without --model its
steady-state θ(p) is the controller's (such a plant has no --design).
--rig-from such a model sets the rig's angle_time_constant_s and
valve_delay_s from its step reading; --rig-param values win.
A score the run does not define (an angle that did not settle within the
run, a run without a rising edge) is null in metrics.json and --json, with
the reason under undefined_metrics, and 'null (the reason)' in the table;
never NaN. Every --set and --rig-param value is held to its declared range
and the run to the memory it needs, before it starts. The results are
written beside --out and swapped in at the end: an error, Ctrl-C or kill
leaves the previous results (or none).

Example:

\b
    softbend control simulate --out bb --set deadzone=0.02 --rig-param valve_delay_s=0.02
"""

RUN = """\
Run a controller in the fixed-period loop on a rig.

The loop keeps the rig's safety limits and a log of every tick. It calls the same
controller object as 'softbend control simulate' every tick (1 ms) with the latest
pressure reading (read every 10 ms: paper B's 100 Hz). The controller and its
parameters come from --controller and --set, else the config's [controller] table
(--set overrides its values); run.json records them. A simulated rig takes the
config's [simulation] table and --rig-param (which overrides it). Over-pressure, missed or stale
readings vent the actuator and stop the run; so do Ctrl-C and SIGTERM. Exit 0 when
the run completed and the rig was vented, 1 when a fault stopped it or the final
vent did not reach the rig (the log keeps every tick up to the fault; the one error
line says whether the rig was vented), 130 on Ctrl-C.

Every --set and --rig-param value is held to its declared range and the run to
the memory it needs, before it starts. A score the run does not define (an angle
that did not settle within the run, a rig without an angle sensor) is null in
run.json and --json, with the reason under undefined_metrics, and 'null (the
reason)' in the table; never NaN. The results are built beside --out and swapped
in once written: a kill -9 leaves the previous results whole (the ticks of the
killed run stay in the hidden folder .OUT.PID-*.new/ticks.csv.partial beside it
until the next run into --out).

Example:

\b
    softbend control run --out loop --config rig.toml --set deadzone=0.02
"""

__all__ = ["RUN", "SIMULATE"]
