#!/usr/bin/env bash
# A lab's own actuator, end to end from the command line.
#
# A lab has built (130, 7, 2.5, 3, 10, 9) -- not one of Table 1's levels nor one of
# paper B's seven measured actuators -- from its own silicone, and read it on two
# days. This script:
#   1. fits the lab's silicone to its tensile test (here the shipped Dragon Skin 30
#      test, to stretch 3: the walls' working range);
#   2. sweeps the design with the FEM in that material;
#   3. measures the actuator (the virtual lab plays the bench: the FEM with the same
#      material and a fabrication error) and splits the readings into two files,
#      one per day;
#   4. refines the shipped FEM-trained MLP on paper B's seven actuators and the two
#      new files, with a 90 % interval calibrated over the eight actuators;
#   5. scores the calibrated interval leave-one-actuator-out, on the seven and on
#      the eight (softbend transfer loco --calibrate);
#   6. predicts the new actuator and runs the refined model as the plant of a
#      simulated control loop.
#
# Usage: examples/lab_own_actuator.sh [OUT] [--quick]
#   --quick: the analytical model as the bench and the sweep, 30 epochs, two
#            strategies: the same steps in about a minute (what the test runs).

set -euo pipefail
OUT=${1:-results/lab_own_actuator}
QUICK=${2:-}
DESIGN=130,7,2.5,3,10,9
SOFTBEND=${SOFTBEND:-softbend}
PYTHON=${PYTHON:-python3}
LAB=$("$PYTHON" -c "from softbend.transfer.lab import shipped_measurements_path as p; print(p())")
BASE=$("$PYTHON" -c "from softbend.transfer.base import shipped_base_path as p; print(p())")
mkdir -p "$OUT"

if [[ "$QUICK" == "--quick" ]]; then
    PLANT=analytical; EPOCHS=(--set epochs=30); LOCO=(--strategies refined,scale-offset --set refined.epochs=30)
else
    PLANT=fem; EPOCHS=(); LOCO=(--strategies refined)
fi

# 1. The lab's silicone.
"$SOFTBEND" materials fit dragon-skin-30 --models yeoh,neo-hookean --max-stretch 3 -o "$OUT/material"
MATERIAL="$OUT/material/fit.json"

# 2. The design swept by the FEM in that silicone (quick: skipped, the FEM takes minutes).
if [[ "$PLANT" == fem ]]; then
    "$SOFTBEND" fem run --design "$DESIGN" --material "$MATERIAL" --pmax 0.25 -o "$OUT/fem"
fi

# 3. Two days of readings of the built actuator (two inflation cycles, one per file).
"$SOFTBEND" lab measure --design "$DESIGN" --material "$MATERIAL" --plant "$PLANT" \
    --cycles 2 --seed 8 -o "$OUT/own_both.csv"
"$PYTHON" - "$OUT" <<'PY'
import csv
import sys
from pathlib import Path

out = Path(sys.argv[1])
lines = (out / "own_both.csv").read_text(encoding="utf-8").splitlines(keepends=True)
header = [line for line in lines if line.startswith("#")]
table = [line for line in lines if not line.startswith("#")]
cycle = next(csv.reader(table[:1])).index("cycle")
for day, date in ((1, "2026-11-23"), (2, "2026-11-24")):
    mine = [row for row in table[1:] if next(csv.reader([row]))[cycle] == str(day)]
    text = "".join(header) + f"# date: {date}\n" + table[0] + "".join(mine)
    (out / f"own_day{day}.csv").write_text(text, encoding="utf-8")
PY

# 4. Refined on the seven and the two new files; the interval calibrated over eight actuators.
"$SOFTBEND" transfer refine "$BASE" "$LAB" "$OUT/own_day1.csv" "$OUT/own_day2.csv" "${EPOCHS[@]}" -o "$OUT/refined.json"

# 5. Leave-one-actuator-out coverage of the calibrated interval: the seven, then the eight.
"$SOFTBEND" transfer loco "$LAB" "${LOCO[@]}" --calibrate --no-learning-curve --json \
    -o "$OUT/loco7" > "$OUT/loco7.json"
"$SOFTBEND" transfer loco "$LAB" "$OUT/own_day1.csv" "$OUT/own_day2.csv" "${LOCO[@]}" \
    --calibrate --no-learning-curve --json -o "$OUT/loco8" > "$OUT/loco8.json"

# 6. The new actuator predicted, then played as the plant of a control loop.
"$SOFTBEND" predict "$OUT/refined.json" --design "$DESIGN" --pressures 0.05,0.1,0.15 --json \
    > "$OUT/predict.json"
"$SOFTBEND" control simulate --design "$DESIGN" --plant "$OUT/refined.json" \
    --reference step:90 --duration 5 -o "$OUT/control"
