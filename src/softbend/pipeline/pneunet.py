"""The PneuNet section: the second FEM family from its reference to a checked design.

:func:`run_pneunet` computes, for the report,

1. the FEM sweep of the reference PneuNet (:data:`softbend.fem.pneunet.description.REFERENCE`)
   with the family's default options (the facing walls of neighbouring chambers in
   contact): its bending angle, cavity volume, contact force and mean contact
   pressure at every converged step, to 50 kPa or 180°;
2. the mesh convergence of the reference at :data:`MESH_PRESSURES_MPA` (past the
   touch, the walls pressing on each other) on every mesh of :data:`MESH_SIZES_MM`;
3. the main effects of the shipped PneuNet dataset's design space
   (:func:`softbend.analysis.main_effects`) on three responses: the angle at
   :data:`EFFECT_PRESSURE_MPA`, the largest angle before the sweep stopped and
   the pressure it reached (the last pressure, 180°, or where Newton stopped);
4. a design search on a surrogate trained on that dataset (90° at 30 kPa on the
   grid of :data:`SPECIFICATION_STEPS`), its best design swept by the FEM (the
   next one while a sweep stops before the specified pressure) and, while the FEM
   puts it outside the tolerance, the surrogate refined on the FEM curves swept so
   far and searched again (:func:`softbend.design_search.rounds.verify_in_rounds`,
   at most :data:`REFINE_ROUNDS` times).
"""

from __future__ import annotations

import time
from dataclasses import dataclass
from pathlib import Path
from typing import TYPE_CHECKING, Any

import numpy as np

from softbend.pipeline import Progress

if TYPE_CHECKING:
    import pandas as pd

    from softbend.analysis.effects import MainEffects
    from softbend.design_search.rounds import Round
    from softbend.design_search.search import LoadedModel, SearchResult
    from softbend.fem.verification import MeshStudyRow
    from softbend.models import SweepResult

__all__ = [
    "EFFECT_PRESSURE_MPA",
    "MESH_PRESSURES_MPA",
    "MESH_SIZES_MM",
    "SPECIFICATION_STEPS",
    "PneuNetSection",
    "run_pneunet",
]

#: Element sizes of the mesh study, mm (3 mm: the family's default).
MESH_SIZES_MM: tuple[float, ...] = (3.0, 2.5, 2.0)
#: Pressures of the mesh study, MPa: the reference's walls touch at 6–7 kPa and press on
#: each other past it (the study to 50 kPa: ``benchmarks/bench_fem_pneunet.py --contact``).
MESH_PRESSURES_MPA: tuple[float, ...] = (0.004, 0.008, 0.012)
#: Pressure of the main effects' angle, MPa (248 of the 256 shipped designs reach it).
EFFECT_PRESSURE_MPA = 0.02
#: The search's target: 90° at 30 kPa.
TARGET_ANGLE_DEG, TARGET_PRESSURE_MPA = 90.0, 0.03
#: The surrogate of the design search: the MLP (grouped-CV RMSE 7.2° on the dataset with
#: contact, against 12.2° for the polynomial).
SURROGATE = "mlp"
#: Refinements of the surrogate on the FEM sweeps of its own candidates, at most
#: (:func:`softbend.design_search.rounds.verify_in_rounds`).
REFINE_ROUNDS = 3
#: The search grid's step per parameter (803 520 designs over the dataset's ranges).
SPECIFICATION_STEPS: dict[str, float] = {
    "n_chambers": 1.0,
    "chamber_length_mm": 1.0,
    "chamber_width_mm": 2.0,
    "chamber_height_mm": 2.0,
    "wall_mm": 0.5,
    "outer_wall_mm": 0.5,
    "gap_mm": 1.0,
    "base_mm": 1.0,
}


@dataclass(frozen=True)
class PneuNetSection:
    """What :func:`run_pneunet` computed (see the module's list).

    Attributes
    ----------
    design : Design
        The reference PneuNet.
    sweep : SweepResult
        Its FEM sweep.
    step_pressure_mpa, step_angle_deg, step_volume_mm3 : ndarray
        Its converged steps' pressures (MPa), bending angles (degrees) and cavity
        volumes (both halves, mm³). Without contact they end at the first touch of
        neighbouring walls: a step past it is replaced by the values at the touch
        (the angle cubic Hermite between the last two steps, as the sweep's
        outputs; the volume linear).
    step_contact_force_n, step_contact_pressure_kpa : ndarray
        The contact force between the walls of the whole actuator (N) and their
        mean contact pressure (kPa) at the same steps; empty without contact.
    mesh : list of MeshStudyRow
    mesh_pressures_mpa : tuple of float
        The mesh study's pressures, MPa.
    designs : DataFrame
        The shipped dataset's designs (one row each, with the responses).
    effects : MainEffects
    search : SearchResult
        The design search (its last round), its verified candidates carrying the
        FEM's angles.
    model : LoadedModel
        The surrogate that search ran on (``out_dir/pneunet/surrogate/models/mlp.json``,
        or its last refinement, ``surrogate/rounds/round-K.json``).
    training : dict
        The surrogate's cross-validated figures (``model``, ``params``, ``r2``, ``rmse_deg``).
    rounds : list of Round
        The verification's rounds (empty without verification).
    summary : dict
        Headline figures for ``summary.json``.
    """

    design: Any
    sweep: SweepResult
    step_pressure_mpa: np.ndarray
    step_angle_deg: np.ndarray
    step_volume_mm3: np.ndarray
    step_contact_force_n: np.ndarray
    step_contact_pressure_kpa: np.ndarray
    mesh: list[MeshStudyRow]
    mesh_pressures_mpa: tuple[float, ...]
    designs: pd.DataFrame
    effects: MainEffects
    search: SearchResult
    model: LoadedModel
    training: dict[str, Any]
    rounds: list[Round]
    summary: dict[str, Any]


def _reference_sweep(
    progress: Progress | None, pmax_mpa: float | None
) -> tuple[Any, SweepResult, np.ndarray, np.ndarray, np.ndarray, np.ndarray, np.ndarray]:
    """The reference, its sweep and its steps' pressures, angles, volumes, contact forces
    and mean contact pressures (the last two empty without contact)."""
    from softbend.fem.families import get_family

    family = get_family("pneunet")
    design = family.design()
    pmax = family.pmax_mpa if pmax_mpa is None else pmax_mpa
    pressures = np.round(np.arange(0.0, pmax + 1e-12, family.pstep_mpa), 6)
    phase = "PneuNet: FEM sweep of the reference, kPa"

    def told(pressure_mpa: float, angle_deg: float, pmax_mpa: float) -> None:
        if progress is not None:
            progress(phase, round(pressure_mpa * 1e3), round(pmax_mpa * 1e3))

    result, _, history = family.sweep(design, pressures, family.options(), progress=told)
    if progress is not None:  # done, at the last pressure, 180° or the touch
        progress(phase, round(pmax * 1e3), round(pmax * 1e3))
    p = np.array([s.pressure_mpa for s in history.steps])
    a = np.array([s.values[0] for s in history.steps])
    v = np.array(result.stats["step_volume_mm3"])
    contact_n = np.array(result.stats.get("step_contact_force_n", []), dtype=float)
    contact_kpa = np.array(result.stats.get("step_contact_pressure_kpa", []), dtype=float)
    limit = history.valid_up_to_mpa
    if limit is not None and limit < p[-1]:  # without contact, past the touch: cut there
        keep = p < limit - 1e-12
        # the angle as the sweep's own outputs (cubic Hermite), the volume linear
        a = np.append(a[keep], history.interpolate(np.array([limit]))[0, 0])
        v = np.append(v[keep], np.interp(limit, p, v))
        p = np.append(p[keep], limit)
    return design, result, p, a, v, contact_n, contact_kpa


def _effects(designs: pd.DataFrame, samples: pd.DataFrame) -> MainEffects:
    from softbend.actuators import PNEUNET
    from softbend.analysis.effects import angle_at_pressure, main_effects

    angle = angle_at_pressure(samples, EFFECT_PRESSURE_MPA)
    responses = {
        f"angle at {EFFECT_PRESSURE_MPA * 1e3:g} kPa (°)": angle,
        "largest angle (°)": designs["max_angle_deg"],
        "pressure reached (kPa)": designs["max_pressure_mpa"] * 1e3,
    }
    return main_effects(designs, [p.name for p in PNEUNET.parameters], responses)


def _search(
    out_dir: Path, seed: int, verify: int, surrogate: str, progress: Progress | None
) -> tuple[SearchResult, LoadedModel, dict[str, Any], list[Round]]:
    from softbend._progress import listening
    from softbend.actuators import PNEUNET
    from softbend.design_search.rounds import verify_in_rounds
    from softbend.design_search.search import LoadedModel, find_designs
    from softbend.design_search.spec import Specification, Target
    from softbend.surrogates.features import dataset_training_data
    from softbend.surrogates.workflow import train_into

    folder = out_dir / "pneunet" / "surrogate"
    _, summary = train_into(
        dataset_training_data("pneunet"),
        folder,
        models=surrogate,
        seed=seed,
        export_onnx=False,
        plr_patience=1,  # a plr (a quick run's): degree 4 loses to 2, 6 (minutes) not tried
        progress=progress,
    )
    model = LoadedModel.load(folder / "models" / f"{surrogate}.json")
    spec = Specification(
        Target("angle_at", angle_deg=TARGET_ANGLE_DEG, pressure_mpa=TARGET_PRESSURE_MPA),
        name="pneunet-90-at-30kPa",
        steps=SPECIFICATION_STEPS,
        actuator=PNEUNET,
    )
    rounds: list[Round] = []
    with listening(progress):
        result = find_designs(model, spec, top=5)
        if verify and result.candidates:
            result, model, rounds = verify_in_rounds(
                model,
                spec,
                result,
                verify=verify,
                rounds=REFINE_ROUNDS,
                folder=folder / "rounds",
                seed=seed,
                top=5,
                backend="fem",
                workers=1,
                scratch_dir=folder,
                replace_stopped=True,
            )
    cv = summary["models"][surrogate]
    training = {
        "model": surrogate,
        "params": cv["params"],
        "r2": cv["r2"],
        "rmse_deg": cv["rmse_deg"],
    }
    return result, model, training, rounds


def run_pneunet(
    out_dir: Path,
    *,
    seed: int = 0,
    progress: Progress | None = None,
    mesh_sizes_mm: tuple[float, ...] = MESH_SIZES_MM,
    mesh_pressures_mpa: tuple[float, ...] = MESH_PRESSURES_MPA,
    pmax_mpa: float | None = None,
    verify: int = 1,
    surrogate: str = SURROGATE,
) -> PneuNetSection:
    """Compute the PneuNet section of the report (see the module's list).

    Parameters
    ----------
    out_dir : Path
        The report's folder; the surrogate is written into ``out_dir/pneunet/surrogate``.
    seed : int
        Seed of the surrogate's folds.
    progress : callable, optional
        ``progress(phase, done, total)``.
    mesh_sizes_mm : tuple of float
        Element sizes of the mesh study, mm, coarsest first (one size for a quick run).
    mesh_pressures_mpa : tuple of float
        Pressures of the mesh study, MPa, increasing (lower for a quick run).
    pmax_mpa : float, optional
        Last pressure of the reference's sweep, MPa; None: the family's (50 kPa).
    verify : int, default 1
        Designs the FEM verifies per round (0: none, for a quick run); a sweep
        that stops before the target's pressure is replaced by the next design's.
    surrogate : str, default "mlp"
        The surrogate family searched (``"plr"`` trains in seconds, for a quick run).
    """
    from softbend.datasets import family_dataset, family_dataset_designs
    from softbend.design_search.rounds import rounds_summary
    from softbend.fem.verification import mesh_study

    start = time.perf_counter()
    design, sweep, p, a, v, contact_n, contact_kpa = _reference_sweep(progress, pmax_mpa)
    phase = "PneuNet: mesh study of the reference"
    mesh = mesh_study(
        design,
        mesh_sizes_mm,
        mesh_pressures_mpa,
        progress=None if progress is None else lambda d, n: progress(phase, d, n),
    )
    designs = family_dataset_designs("pneunet").set_index("design_id")
    effects = _effects(designs, family_dataset("pneunet"))
    search, model, training, rounds = _search(Path(out_dir), seed, verify, surrogate, progress)
    best = next((c for c in search.candidates if c.fem_angle_deg is not None), None)
    finest = mesh[-1].angles_deg[-1]
    summary = {
        "reference": design.as_text(),
        "stop_reason": sweep.stats["stop_reason"],
        "contact": sweep.stats["options"].get("contact", "off"),
        "last_pressure_mpa": float(p[-1]),
        "last_angle_deg": float(a[-1]),
        "largest_contact_pressure_kpa": float(contact_kpa.max(initial=0.0)),
        "mesh_sizes_mm": list(mesh_sizes_mm),
        "mesh_pressure_mpa": mesh_pressures_mpa[-1],
        "mesh_angles_deg": [r.angles_deg[-1] for r in mesh],
        "mesh_change_deg": float(abs(mesh[0].angles_deg[-1] - finest)),
        "surrogate": training,
        "target": search.spec.target.describe(),
        "designs_searched": search.n_designs,
        "verify": verify,
        "refinements": rounds_summary(rounds) if rounds else None,
        "best": None if best is None else best.to_dict(),
        "seconds": time.perf_counter() - start,
    }
    return PneuNetSection(
        design,
        sweep,
        p,
        a,
        v,
        contact_n,
        contact_kpa,
        mesh,
        tuple(mesh_pressures_mpa),
        designs,
        effects,
        search,
        model,
        training,
        rounds,
        summary,
    )
