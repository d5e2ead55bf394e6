"""Options of ``softbend design find``, and its help text."""

from __future__ import annotations

import typer

OUT = typer.Option(..., "--out", "-o", help="Folder for the tables and figures.")
MODEL = typer.Option(
    None,
    help="Saved surrogate to search (default: the shipped FEM-trained MLP); its actuator's "
    "parameters are the names of --fix, --range, --resolution and --minimize.",
)
SPEC_FILE = typer.Option(
    None, help="A TOML file of [[spec]] tables, one folder of results per spec."
)
ANGLE = typer.Option(None, help="Target angle, deg (with --at or --max-pressure).")
AT = typer.Option(
    None,
    help="Pressure the target angle is read at: a number in the model's pressure unit "
    "(MPa for paper B's actuator) or with a unit (20psi, 138kPa, 0.1MPa, 1.5bar).",
)
MAX_PRESSURE = typer.Option(
    None,
    help="Reach --angle at no more than this pressure, as --at (then --minimize pressure).",
)
MAX_ANGLE_AT = typer.Option(None, help="Bend as far as possible at this pressure, as --at.")
CURVE = typer.Option(
    None,
    help="Follow the points P:ANGLE, comma-separated (pressure in the model's unit:deg), "
    "e.g. 0.05:40,0.1:95.",
)
TOLERANCE = typer.Option(3.0, help="How far the angle may miss, deg, in (0, 90].")
MARGIN = typer.Option(
    0.0, help="Degrees of the tolerance kept back on the surrogate (its own error)."
)
MINIMIZE = typer.Option(
    None,
    help="Objectives to minimise: a design parameter (l, r, t, b, phi, lc of paper B's "
    "actuator), pressure, volume (paper B's), sensitivity, angle, error (comma-separated "
    "or repeated; default error).",
)
MAXIMIZE = typer.Option(None, help="Objectives to maximise (as --minimize).")
FIX = typer.Option(
    None, help="Fix a parameter, NAME=VALUE (repeatable; a categorical one by level name)."
)
RANGE = typer.Option(
    None,
    "--range",
    help="Range of a parameter, NAME=LOW:HIGH (repeatable; whole ends for an integer one, "
    "none for a categorical one, whose levels are all searched unless fixed).",
)
RESOLUTION = typer.Option(
    None,
    help="Mould resolution: a number for every parameter or NAME=STEP (repeatable); "
    "0 searches continuously. Default 0.5 mm and 1° of phi; for another actuator each "
    "continuous parameter's declared resolution (else a round step, about 1/100 of its "
    "range), integers by 1.",
)
TOP = typer.Option(10, help="Candidates listed, 1 to 1000 (to 25 with a continuous parameter).")
NEIGHBOURS = typer.Option(
    False, "--neighbours", help="Also list designs one step from a better one."
)
VERIFY = typer.Option(
    0,
    help="Sweep the best N (at most 100) with --backend and compare (paper B's actuator, "
    "or another with the FEM of the family its description names; one that names none "
    "is not verified, and the output says so).",
)
BACKEND = typer.Option("fem", help="Backend of the verification: fem or analytical.")
WORKERS = typer.Option(None, help="Processes of the verification, 1 to 4096 (default: all cores).")
MATERIAL = typer.Option(None, help="Elastomer of the verification (as fem run).")
REPLACE_STOPPED = typer.Option(
    False,
    "--replace-stopped",
    help="Replace a verified candidate whose FEM sweep stops before the pressure "
    "(chamber walls touch, no convergence) by the next listed one, until N reach it "
    "or the --top list ends.",
)
REFINE_ROUNDS = typer.Option(
    0,
    "--refine-rounds",
    help="While the FEM puts every verified candidate outside the tolerance, refine the "
    "surrogate on the FEM curves swept so far (residual-gp) and search again, at most this "
    "many times, 0 to 20 (default 0: verify once). The refined surrogates are saved in "
    "--out/rounds/.",
)
ALLOW_EXTRAPOLATION = typer.Option(
    False, "--allow-extrapolation", help="Search outside the training data, answers flagged."
)
JSON = typer.Option(False, "--json", help="Print the results as JSON.")

#: The help of ``design find``.
FIND_HELP = """Find the designs that meet a target bending.

    Every design of the grid of manufacturable values (--resolution) within the
    model's training ranges (or --range, --fix) is scored on the surrogate;
    those that meet the target within --tolerance are ranked by the
    objectives (several: the Pareto front), each listed design more than one
    step from a better one (--neighbours lists them all). Answers outside the model's
    training data are passed over unless --allow-extrapolation (which lists them
    with a "no" in the table's "trained there" column, "supported": false in the
    JSON and a warning on stderr, as softbend predict does). With --verify N
    the best N are swept by the FEM and set beside the surrogate.

    Every input is checked before a design is scored: each number against its
    range, the size of each grid (at most 20 million designs), the material,
    and every [[spec]] of --spec (a name is a plain folder name of --out; the
    target, range and objective options are the file's, not given beside it).
    The results are built beside --out and swapped in when complete; a run
    killed during the verification leaves a hidden .OUT.PID-*.new folder that
    the next run into --out removes. The verification's sweeps are kept beside
    --out (.OUT.verify-KEY.duckdb) until the command ends: after Ctrl-C or a
    kill the same command sweeps only the designs not yet swept.

    The names are the model's own: paper B's l, r, t, b, phi, lc (mm, deg;
    pressures in MPa), or the parameters of the actuator another model was
    trained on, searched within its training ranges and its description's
    (integers on whole numbers, a categorical parameter on every level unless
    --fix names one, a continuous one on its declared resolution, else on a
    round step of about a hundredth of its range), designs breaking the
    description's constraints left out, pressures in the model's unit.
    --verify sweeps another actuator with the FEM of the family its description
    names (such as pneunet; --backend fem); a sweep that stops before the
    pressure checked (chamber walls touching, no convergence) is "stopped", with
    the FEM's reason, not an angle; --replace-stopped then verifies the next
    listed design instead, until N reach the pressure. --refine-rounds R closes
    the loop: while no verified design is within the tolerance, the surrogate
    is refined on every FEM curve swept so far (a Gaussian process on its
    residuals, residual-gp), saved as --out/rounds/round-K.json, and searched
    again for designs not yet swept, at most R times. An actuator that names
    no FEM family is not verified, and the output says so (a warning, and
    "verify_skipped" in search.json).

    Example:

    \b
        softbend design find --angle 90 --at 0.08 --minimize l --fix phi=10 \\
            --range t=3:4 --verify 5 --out design
        softbend design find --model pneunet.json --angle 90 --at 30 \\
            --minimize n_chambers --fix layer=paper --range wall_mm=1:2 --out design
    """
