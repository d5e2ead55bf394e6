"""Synthetic PneuNet example: a simulation table and six "measured" actuators.

Writes ``simulations.csv`` (about 150 designs, each swept over 11 pressures) and
``measurements.csv`` (six built actuators, ``A1`` to ``A6``) next to this file, or
to ``--out DIR``. Everything comes from the lumped physical model below; nothing
is measured. The output is deterministic for a given ``--seed`` (default 0).

Run: ``python examples/pneunet/generate.py [--seed 0] [--out DIR]``

The actuator
------------
A PneuNet: a row of ``n_chambers`` identical chambers cast in silicone on a base
of elastomer (thickness ``b``) that holds ``n_layers`` plies of strain-limiting
fabric. Each chamber has inner height ``h`` (``height_mm``), inner width ``W``
and inner length ``L``, and walls of thickness ``t`` (``wall_mm``); neighbouring
chambers are separated by a gap ``g`` and joined only through the base. Under a
pressure ``p`` the end walls of neighbouring chambers bulge into the gap and push
each other apart above the fabric, which does not stretch: the actuator bends
towards the fabric.

The model (per chamber)
-----------------------
1. **End wall.** Each end wall (span ``h`` < ``W``) is taken as a clamped
   circular plate of radius ``a = h/2`` and thickness ``t``, of an incompressible
   elastomer (Young's modulus ``E``, ``ν = 0.5``, shear modulus ``G = E/3``).
   Its centre deflection ``w₀`` under a net pressure ``q`` follows the one-term
   energy solution of the large-deflection clamped plate (Timoshenko &
   Woinowsky-Krieger, *Theory of Plates and Shells*, 1959, §97), with the
   transverse-shear (Mindlin) compliance of a thick plate added to the linear
   term, since here ``t/a`` reaches 0.75::

       q = k₁·w₀ + k₃·w₀³
       1/k₁ = a⁴/(64·D) + a²/(4·κ·G·t),   D = E·t³/(12·(1 − ν²)),  κ = 5/6
       k₃ = 64·β·D/(a⁴·t²),               β = 0.488

   ``k₁`` is bending (and shear), ``k₃`` membrane stretching: the wall stiffens
   as it bulges. β is the value given for ν = 0.3, kept for ν = 0.5.
2. **Wall to rotation.** The deflected wall has the shape
   ``w₀·(1 − r²/a²)²``, of mean deflection ``w₀/3``. The two end walls lengthen
   the chamber by ``2·w₀/3`` at the height of the wall centres,
   ``y_c = n_layers·t_f/2 + b + h/2`` above the neutral axis (the mid-plane of
   the fabric stack), so the chamber turns by ``θ_c = (2/3)·w₀/y_c``.
3. **Backbone.** The base and fabric resist the bending with the moment
   ``M = (EI/s)·θ_c`` per chamber of pitch ``s = L + 2·t + g``, where
   ``EI = E·W·b³/3 + E_f·W·(n_layers·t_f)³/12`` (bonded plies of thickness
   ``t_f``, flexural modulus ``E_f``). The walls carry ``M`` as a contact force
   at ``y_c``, spread over the wall area ``π·a²``: the net pressure on each wall
   is ``q = p − M/(π·a²·y_c)``.
4. **Actuator.** The chambers act in series: ``θ = n_chambers·θ_c``.

Steps 1 to 3 give ``p = (k₁ + K)·w₀ + k₃·w₀³`` with
``K = (2/3)·EI/(s·π·a²·y_c²)``, a cubic with one positive root, solved in
closed form. The angle is exactly 0° at 0 kPa, grows monotonically with pressure
and its slope falls as the walls stiffen; it grows with chamber height and the
number of chambers and falls with wall thickness and with the number of fabric
plies.

Pressure range of a design: its walls' mean membrane strain,
``(64/105)·(w₀/a)²`` for the deflected shape above, may reach ``EPS_LIMIT``; the
sweep runs from 0 to that pressure rounded down to 5 kPa, within
``[P_FLOOR_KPA, P_CEIL_KPA]``.

The built actuators
-------------------
``measurements.csv`` plays back the same model with what a lab builds rather than
what its simulation assumes (see :data:`AS_BUILT` and README.md): walls cast
thicker than nominal, a cast silicone stiffer than the datasheet modulus and
strain-stiffening at large stretch, end chambers that push on one neighbour only,
a small residual curvature and the scatter of a camera-based angle reading.

Units: lengths mm, moduli MPa (N/mm²), pressures kPa at the interface and MPa
inside, angles in degrees at the interface and radians inside.
"""

from __future__ import annotations

import argparse
import math
from collections.abc import Sequence
from dataclasses import dataclass, replace
from pathlib import Path

import numpy as np
import pandas as pd
from numpy.typing import ArrayLike

HERE = Path(__file__).resolve().parent

#: Design parameters: name -> (low, high, kind, resolution), in the table's units.
PARAMETERS: dict[str, tuple[float, float, str, float]] = {
    "n_chambers": (6, 14, "integer", 1),
    "n_layers": (1, 3, "integer", 1),
    "wall_mm": (1.0, 3.0, "continuous", 0.1),
    "height_mm": (8.0, 16.0, "continuous", 0.5),
}
DESIGN_COLUMNS: tuple[str, ...] = tuple(PARAMETERS)
SIMULATION_COLUMNS: tuple[str, ...] = ("design_id", *DESIGN_COLUMNS, "p_kpa", "angle_deg")
MEASUREMENT_COLUMNS: tuple[str, ...] = ("actuator", *DESIGN_COLUMNS, "p_kpa", "angle_deg")

N_DESIGNS = 150  #: Designs in the simulation table.
N_PRESSURES = 11  #: Pressures per simulated design, 0 to its maximum.
EPS_LIMIT = 0.2  #: Mean membrane strain of an end wall at a design's maximum pressure.
P_STEP_KPA = 5.0  #: A design's maximum pressure is a multiple of this, in kPa.
P_FLOOR_KPA = 20.0  #: Lowest maximum pressure of a sweep, in kPa.
P_CEIL_KPA = 80.0  #: Highest maximum pressure of a sweep, in kPa.

NU = 0.5  #: Poisson's ratio of the elastomer (incompressible).
KAPPA = 5.0 / 6.0  #: Shear correction factor of the thick-plate term.
BETA = 0.488  #: Membrane coefficient of the clamped-plate energy solution.
STRAIN_PER_DEFLECTION2 = 64.0 / 105.0  #: Mean membrane strain / (w₀/a)² of the wall shape.

#: Built actuators: name -> (n_chambers, n_layers, wall_mm, height_mm).
BUILT_DESIGNS: dict[str, tuple[int, int, float, float]] = {
    "A1": (8, 1, 1.5, 10.0),
    "A2": (12, 2, 2.0, 14.0),
    "A3": (7, 3, 2.5, 12.0),
    "A4": (10, 1, 1.2, 15.5),
    "A5": (13, 3, 2.8, 9.0),
    "A6": (9, 2, 1.8, 12.5),
}


@dataclass(frozen=True)
class Build:
    """Material, fixed geometry and build deviations the model is evaluated with.

    Parameters
    ----------
    modulus_mpa : float
        Young's modulus ``E`` of the elastomer at small strain, in MPa.
    fabric_modulus_mpa : float
        Flexural modulus ``E_f`` of one silicone-impregnated fabric ply, in MPa.
    ply_mm : float
        Thickness ``t_f`` of one fabric ply, in mm.
    base_mm : float
        Elastomer ``b`` between the chamber floor and the fabric, in mm.
    width_mm : float
        Inner chamber width ``W``, in mm (wider than the tallest chamber).
    length_mm : float
        Inner chamber length ``L`` along the actuator, in mm.
    gap_mm : float
        Gap ``g`` between neighbouring chambers, in mm.
    wall_extra_mm : float
        Added to every nominal wall thickness (casting excess), in mm.
    membrane_stiffening : float
        Factor on the membrane term ``k₃`` (1: the linear material of the simulation;
        more for an elastomer that stiffens as it stretches).
    end_walls_idle : bool
        Whether the outer walls of the first and last chamber bulge into free space
        (or a cap) without pushing a neighbour, so only ``2·n − 2`` walls bend the
        actuator. False: every chamber is a copy of a periodic cell.
    """

    modulus_mpa: float = 0.3
    fabric_modulus_mpa: float = 250.0
    ply_mm: float = 0.3
    base_mm: float = 2.0
    width_mm: float = 20.0
    length_mm: float = 6.0
    gap_mm: float = 1.0
    wall_extra_mm: float = 0.0
    membrane_stiffening: float = 1.0
    end_walls_idle: bool = False


#: What the simulation table assumes: nominal walls, a periodic cell, a linear material.
SIMULATED = Build()

#: How the built actuators differ from :data:`SIMULATED` (before per-actuator scatter).
AS_BUILT = replace(
    SIMULATED,
    modulus_mpa=1.08 * SIMULATED.modulus_mpa,
    wall_extra_mm=0.1,
    membrane_stiffening=1.5,
    end_walls_idle=True,
)
WALL_EXTRA_SD_MM = 0.03  #: Scatter of the casting excess between actuators, in mm.
PRECURVATURE_SD_DEG = 1.0  #: Scatter of the residual curvature at 0 kPa, in degrees.
ANGLE_NOISE_SD_DEG = 1.0  #: Scatter of one angle reading, in degrees.
PRESSURE_NOISE_SD_KPA = 0.2  #: Scatter of the logged pressure about its set point, in kPa.


@dataclass(frozen=True)
class _Cubic:
    """``p = k_lin·w₀ + k_cub·w₀³`` of one design and the factors to an angle."""

    k_lin: np.ndarray  # MPa/mm
    k_cub: np.ndarray  # MPa/mm³
    radius: np.ndarray  # mm
    rad_per_mm: np.ndarray  # actuator angle per unit of w₀, rad/mm


def _cubic(
    n_chambers: ArrayLike,
    n_layers: ArrayLike,
    wall_mm: ArrayLike,
    height_mm: ArrayLike,
    build: Build,
) -> _Cubic:
    n = np.asarray(n_chambers, dtype=float)
    plies = np.asarray(n_layers, dtype=float)
    t = np.asarray(wall_mm, dtype=float) + build.wall_extra_mm
    a = np.asarray(height_mm, dtype=float) / 2.0
    E = build.modulus_mpa
    D = E * t**3 / (12.0 * (1.0 - NU**2))
    G = E / (2.0 * (1.0 + NU))
    k_plate = 1.0 / (a**4 / (64.0 * D) + a**2 / (4.0 * KAPPA * G * t))
    k_cub = build.membrane_stiffening * 64.0 * BETA * D / (a**4 * t**2)
    y_c = plies * build.ply_mm / 2.0 + build.base_mm + a
    pitch = build.length_mm + 2.0 * t + build.gap_mm
    EI = (
        E * build.width_mm * build.base_mm**3 / 3.0
        + build.fabric_modulus_mpa * build.width_mm * (plies * build.ply_mm) ** 3 / 12.0
    )
    k_backbone = (2.0 / 3.0) * EI / (pitch * math.pi * a**2 * y_c**2)
    walls = 2.0 * n - 2.0 if build.end_walls_idle else 2.0 * n
    return _Cubic(
        k_lin=k_plate + k_backbone,
        k_cub=k_cub,
        radius=a,
        rad_per_mm=walls / (3.0 * y_c),
    )


def _deflection_mm(p_mpa: np.ndarray, cubic: _Cubic) -> np.ndarray:
    """The real root ``w₀ ≥ 0`` of ``k_cub·w₀³ + k_lin·w₀ = p`` (hyperbolic form, exact at 0)."""
    P = cubic.k_lin / cubic.k_cub
    scale = 2.0 * np.sqrt(P / 3.0)
    return scale * np.sinh(np.arcsinh(1.5 * p_mpa / cubic.k_cub / P * np.sqrt(3.0 / P)) / 3.0)


def bending_angle_deg(
    p_kpa: ArrayLike,
    n_chambers: ArrayLike,
    n_layers: ArrayLike,
    wall_mm: ArrayLike,
    height_mm: ArrayLike,
    build: Build = SIMULATED,
) -> np.ndarray:
    """Bending angle of a PneuNet at a pressure (the model of the module docstring).

    Parameters
    ----------
    p_kpa : array_like
        Gauge pressure, in kPa (≥ 0).
    n_chambers, n_layers : array_like
        Number of chambers and of strain-limiting fabric plies.
    wall_mm, height_mm : array_like
        Nominal wall thickness and inner chamber height, in mm.
    build : Build
        Material, fixed geometry and build deviations (default: the simulation's).

    Returns
    -------
    numpy.ndarray
        Bending angle in degrees, broadcast over the inputs.
    """
    p_mpa = np.asarray(p_kpa, dtype=float) * 1e-3
    if np.any(p_mpa < 0):
        raise ValueError("The pressure must be >= 0 kPa.")
    cubic = _cubic(n_chambers, n_layers, wall_mm, height_mm, build)
    return np.degrees(cubic.rad_per_mm * _deflection_mm(p_mpa, cubic))


def max_pressure_kpa(
    n_chambers: ArrayLike,
    n_layers: ArrayLike,
    wall_mm: ArrayLike,
    height_mm: ArrayLike,
    build: Build = SIMULATED,
) -> np.ndarray:
    """Top pressure of a design's sweep, in kPa.

    The pressure at which the end walls' mean membrane strain reaches
    :data:`EPS_LIMIT`, rounded down to :data:`P_STEP_KPA` and kept within
    [:data:`P_FLOOR_KPA`, :data:`P_CEIL_KPA`].
    """
    cubic = _cubic(n_chambers, n_layers, wall_mm, height_mm, build)
    w_lim = cubic.radius * math.sqrt(EPS_LIMIT / STRAIN_PER_DEFLECTION2)
    p_lim_kpa = 1e3 * (cubic.k_lin * w_lim + cubic.k_cub * w_lim**3)
    stepped = np.floor(p_lim_kpa / P_STEP_KPA + 1e-9) * P_STEP_KPA
    return np.clip(stepped, P_FLOOR_KPA, P_CEIL_KPA)


def latin_hypercube_designs(n: int, rng: np.random.Generator) -> pd.DataFrame:
    """``n`` space-filling designs over :data:`PARAMETERS`, snapped to their resolution.

    One Latin hypercube sample (one point per stratum of each parameter, strata
    paired at random); an integer parameter takes the level of its stratum's
    share of the ``high − low + 1`` levels, a continuous one is rounded to its
    resolution.
    """
    columns: dict[str, np.ndarray] = {}
    for name, (low, high, kind, resolution) in PARAMETERS.items():
        u = (rng.permutation(n) + rng.random(n)) / n
        if kind == "integer":
            columns[name] = (low + np.floor(u * (high - low + 1))).astype(int)
        else:
            steps = round((high - low) / resolution)
            columns[name] = np.round(low + np.round(u * steps) * resolution, 6)
    return pd.DataFrame(columns)


def simulation_table(seed: int = 0, n_designs: int = N_DESIGNS) -> pd.DataFrame:
    """The simulation table: each design swept over :data:`N_PRESSURES` pressures."""
    rng = np.random.default_rng([seed, 1])
    designs = latin_hypercube_designs(n_designs, rng)
    p_top = max_pressure_kpa(*(designs[c].to_numpy() for c in DESIGN_COLUMNS))
    rows = []
    for i, design in enumerate(designs.itertuples(index=False)):
        p = np.round(np.linspace(0.0, p_top[i], N_PRESSURES), 3)
        angle = bending_angle_deg(p, *design)
        rows.append(
            pd.DataFrame(
                {"design_id": f"d{i:03d}", **design._asdict(), "p_kpa": p, "angle_deg": angle}
            )
        )
    table = pd.concat(rows, ignore_index=True)
    table["angle_deg"] = table["angle_deg"].round(3)
    return table[list(SIMULATION_COLUMNS)]


def measurement_table(seed: int = 0) -> pd.DataFrame:
    """The six built actuators, each read at 8 to 12 pressures from 0 to its top pressure."""
    rng = np.random.default_rng([seed, 2])
    rows = []
    for name, design in BUILT_DESIGNS.items():
        build = replace(
            AS_BUILT, wall_extra_mm=AS_BUILT.wall_extra_mm + WALL_EXTRA_SD_MM * rng.normal()
        )
        precurvature = PRECURVATURE_SD_DEG * rng.normal()
        n_points = int(rng.integers(8, 13))
        p_set = np.linspace(0.0, float(max_pressure_kpa(*design)[()]), n_points)
        p_read = p_set + PRESSURE_NOISE_SD_KPA * rng.normal(size=n_points) * (p_set > 0)
        p_read = np.round(np.clip(p_read, 0.0, p_set[-1]), 1)
        angle = (
            bending_angle_deg(p_read, *design, build=build)
            + precurvature
            + ANGLE_NOISE_SD_DEG * rng.normal(size=n_points)
        )
        rows.append(
            pd.DataFrame(
                {
                    "actuator": name,
                    **dict(zip(DESIGN_COLUMNS, design, strict=True)),
                    "p_kpa": p_read,
                    "angle_deg": np.round(angle, 2),
                }
            )
        )
    return pd.concat(rows, ignore_index=True)[list(MEASUREMENT_COLUMNS)]


def main(seed: int = 0, out: str | Path | None = None) -> dict[str, Path]:
    """Write ``simulations.csv`` and ``measurements.csv`` to ``out`` (default: next to this file).

    Returns
    -------
    dict
        ``{"simulations": path, "measurements": path}``.
    """
    folder = Path(out) if out is not None else HERE
    folder.mkdir(parents=True, exist_ok=True)
    paths = {"simulations": folder / "simulations.csv", "measurements": folder / "measurements.csv"}
    simulation_table(seed).to_csv(paths["simulations"], index=False, lineterminator="\n")
    measurement_table(seed).to_csv(paths["measurements"], index=False, lineterminator="\n")
    return paths


def _cli(argv: Sequence[str] | None = None) -> None:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--seed", type=int, default=0, help="random seed (default 0)")
    parser.add_argument("--out", type=Path, default=None, help="output folder (default: here)")
    parser.add_argument(
        "--angle",
        metavar="N_CHAMBERS,N_LAYERS,WALL_MM,HEIGHT_MM",
        help="print one design's simulated and as-built angle at --at instead of writing files",
    )
    parser.add_argument("--at", type=float, default=40.0, help="pressure for --angle, kPa")
    args = parser.parse_args(argv)
    if args.angle:
        n, layers, wall, height = (float(v) for v in args.angle.split(","))
        design = (int(n), int(layers), wall, height)
        simulated = bending_angle_deg(args.at, *design)
        built = bending_angle_deg(args.at, *design, build=AS_BUILT)
        print(f"at {args.at:g} kPa: simulated {simulated:.1f} deg, as built {built:.1f} deg")
        return
    for path in main(args.seed, args.out).values():
        print(path)


if __name__ == "__main__":
    _cli()
