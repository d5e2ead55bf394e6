"""Coverage of the calibrated 90 % interval, leave one actuator out, on the lab's actuators.

For paper B's `refined` strategy (the shipped FEM-trained MLP refitted on the
readings), each actuator is held out in turn; its interval is calibrated on the
leave-one-out errors of the others only (nested, as a lab without it would
have calibrated it), and the share of its readings inside is counted. Run on

- the shipped virtual lab (paper B's seven actuators, Fig. 7), and
- the same plus an eighth actuator of a design outside Fig. 7,
  (130, 7, 2.5, 3, 10, 9), measured by the virtual lab with the FEM in the
  lab's own silicone (a Yeoh fit of the shipped Dragon Skin 30 test to
  stretch 3), two inflation cycles,

with both half-widths for too few actuators (`quantile`, the default, and
`largest`; `softbend.transfer.conformal`). Prints one line per run and writes
nothing. About ten minutes on two cores (the FEM sweep of the eighth
actuator, then 4 × 7–8 outer and 42–56 nested refits of 1000 epochs).

Usage: python benchmarks/bench_lab_coverage.py
"""

from __future__ import annotations

import tempfile
import time
from pathlib import Path

from _record import record

from softbend.design import sfrba_design
from softbend.transfer.base import load_base
from softbend.transfer.lab import VirtualLab, shipped_measurements, shipped_measurements_path
from softbend.transfer.loco import leave_one_configuration_out
from softbend.transfer.measurements import (
    Measurements,
    load_measurements_files,
    save_measurements,
)

EIGHTH = sfrba_design(130, 7, 2.5, 3, 10, 9)


def eighth_actuator() -> Measurements:
    """The eighth actuator as the virtual lab measures it (FEM, the lab's silicone)."""
    lab = VirtualLab(actuators=(EIGHTH,), plant="fem", cycles=2, seed=8)
    return lab.measure()


def main() -> None:
    base = load_base()
    seven = shipped_measurements()
    start = time.perf_counter()
    with tempfile.TemporaryDirectory() as scratch:
        own = save_measurements(eighth_actuator(), Path(scratch) / "own.csv")
        eight = load_measurements_files([shipped_measurements_path(), own])
    print(f"eighth actuator measured in {time.perf_counter() - start:.0f} s")
    figures = {"eighth actuator measured in": round(time.perf_counter() - start, 1)}
    units = {"eighth actuator measured in": "s"}
    for label, data in (("shipped lab (7)", seven), ("lab + (130,7,2.5,3,10,9) (8)", eight)):
        for fallback in ("quantile", "largest"):
            start = time.perf_counter()
            result = leave_one_configuration_out(
                data,
                base,
                ["refined"],
                learning_curve=False,
                calibrated=True,
                fallback=fallback,
            )
            row = result.summary.set_index("strategy").loc["refined"]
            cal = result.calibrations["refined"]
            print(
                f"{label:32s} {fallback:8s}: calibrated coverage "
                f"{100 * row['calibrated_coverage']:.1f} %, mean width "
                f"{row['calibrated_width_deg']:.1f}°, half-width on all "
                f"{cal['half_width_deg']:.1f}°, held-out RMSE {row['rmse_deg']:.2f}° "
                f"({time.perf_counter() - start:.0f} s)"
            )
            for figure, value, unit in (
                ("calibrated coverage", 100 * row["calibrated_coverage"], "%"),
                ("mean width", row["calibrated_width_deg"], "°"),
                ("half-width on all", cal["half_width_deg"], "°"),
                ("held-out RMSE", row["rmse_deg"], "°"),
                ("wall time", time.perf_counter() - start, "s"),
            ):
                key = f"{label}, {fallback}: {figure}"
                figures[key], units[key] = round(float(value), 3), unit
    record("lab_coverage", figures, units=units, notes="refined strategy, 90 % interval")


if __name__ == "__main__":
    main()
