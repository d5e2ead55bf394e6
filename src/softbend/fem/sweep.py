"""Load stepping: the pressure sweep of one design of any FEM family (``run_model_sweep``).

1. Gravity is applied first, followed in growing fractions of the weight the
   same way as the pressure below; that state is the 0 MPa output.
2. Pressure is raised in adaptive steps. Each step starts from the cubic
   extrapolation of the last two converged states and their tangents ``du/dp``
   (``K du/dp = ∂V/∂u``), so Newton starts close to the solution. A step that
   does not converge is restored and halved. After a converged step, the
   distance between the predicted and the converged state sets the next step:
   the predictor's error grows like ``Δp⁴``, so the step is sized for an error
   of ``predictor_error_mm`` (growing or shrinking by at most 1.5× or 2×),
   between ``min_step_mpa`` and ``max_step_mpa``.
3. At every converged step the angle, the tip and their derivatives with respect
   to pressure are stored; outputs on the requested grid are the cubic Hermite
   interpolants between steps (or, with ``output="solve"``, the steps land on
   every requested pressure).

The sweep ends at the last requested pressure, when the angle passes
``max_angle_deg`` (the actuator has curled round; outputs above it are not
reported), when the model itself says so after a converged step (a model with a
``stop_after_step(pressure)`` method: the PneuNet's neighbouring chamber walls
touching, :class:`~softbend.fem.pneunet.model.PneuNetModel`; outputs stop at the
pressure it names), when the largest stretch in the elastomer passes ``max_stretch``
(outside the material model; outputs stop at the step before), or when a step
shorter than ``min_step_mpa`` still does not converge — then the first requested
pressure beyond the last converged state is reported with ``converged=False``.
That last stop is told apart: where the cavity's stiffness ``dp/dV`` is falling
to zero just ahead (a ballooning part, the inflation instability of rubber: no
equilibrium nearby above a pressure maximum) the reason says so and names the
region; otherwise it is a plain "no convergence". The reason is always in
``stats["stop_reason"]`` (the keys: :class:`~softbend.fem.stats.FEMStats`). A model
that does not even hold its own weight raises
:class:`~softbend.errors.ConvergenceError`.

A model may also act around every step: ``before_step()`` before the solve
(the PneuNet pairs its faces in contact anew), ``reject_step()`` after a
converged step longer than four ``min_step_mpa`` (True: the step is restored
and halved as a failed one is; the PneuNet's walls starting to touch within it)
and ``linear_predictor()`` before the prediction (True: the step starts from
the linear predictor ``u₁ + Δp·u₁'``, not the cubic; the PneuNet while its walls
press on each other).
"""

from __future__ import annotations

import logging
import math
import time
from collections.abc import Callable
from dataclasses import dataclass, field
from typing import TYPE_CHECKING, Any, cast

import numpy as np
from numpy.typing import ArrayLike

from softbend.errors import ConvergenceError
from softbend.fem._ngsolve import require_ngsolve
from softbend.fem.actuator import ActuatorModel
from softbend.fem.options import FEMOptions
from softbend.fem.stats import FEMStats, FEMTimings
from softbend.models import SweepResult, check_pressures_mpa

if TYPE_CHECKING:
    from typing import TypeAlias

    from softbend.fem.pneunet.model import PneuNetModel

    #: A model the load stepping drives (the interface of :class:`ActuatorModel`).
    SweepModel: TypeAlias = ActuatorModel | PneuNetModel

require_ngsolve()  # NGSolve after PyTorch, or one line naming softbend[fem]

__all__ = ["ProgressCallback", "Step", "StepHistory", "run_model_sweep"]

logger = logging.getLogger(__name__)

#: Called after every converged step with (pressure MPa, angle deg, target pressure MPa).
ProgressCallback = Callable[[float, float, float], None]


def _hermite_basis(s: float) -> tuple[float, float, float, float]:
    """Cubic Hermite basis ``h00, h10, h01, h11`` at ``s`` (0 and 1: the two ends)."""
    return (1 + 2 * s) * (1 - s) ** 2, s * (1 - s) ** 2, s * s * (3 - 2 * s), s * s * (s - 1)


@dataclass(frozen=True)
class Step:
    """One converged load step."""

    pressure_mpa: float
    values: np.ndarray  # angle deg, tip x mm, tip z mm
    slopes: np.ndarray  # their derivatives per MPa
    iterations: int
    max_stretch: float = float("nan")
    state: np.ndarray | None = field(default=None, repr=False)
    volume_rate: float = float("nan")  # dV/dp of the cavity, mm³/MPa
    volume_mm3: float = float("nan")  # the cavity's volume (both halves), mm³


@dataclass
class StepHistory:
    """The converged steps of a sweep, in order, and why it stopped."""

    steps: list[Step] = field(default_factory=list)
    stop_reason: str = "reached the last pressure"
    failed_pressure_mpa: float | None = None
    failure: str | None = None
    rejected_steps: int = 0
    #: Outputs are reported up to here (the last step inside the stretch limit).
    valid_up_to_mpa: float | None = None

    @property
    def pressures(self) -> np.ndarray:
        return np.array([s.pressure_mpa for s in self.steps])

    def nearest_steps(self, pressures_mpa: ArrayLike) -> list[Step]:
        """The converged steps nearest to ``pressures_mpa``, each once, in order."""
        p = self.pressures
        picked = {int(np.abs(p - q).argmin()) for q in np.atleast_1d(pressures_mpa)}
        return [self.steps[i] for i in sorted(picked)]

    def interpolate(self, pressures_mpa: np.ndarray) -> np.ndarray:
        """Cubic Hermite values (n, 3) at pressures inside the converged range."""
        p = self.pressures
        values = np.array([s.values for s in self.steps])
        slopes = np.array([s.slopes for s in self.steps])
        out = np.empty((len(pressures_mpa), 3))
        for row, q in enumerate(pressures_mpa):
            k = int(np.searchsorted(p, q, side="left"))
            if k < len(p) and abs(p[k] - q) <= 1e-12:
                out[row] = values[k]
                continue
            k = min(max(k, 1), len(p) - 1)
            h = p[k] - p[k - 1]
            h00, h10, h01, h11 = _hermite_basis((q - p[k - 1]) / h)
            out[row] = (
                h00 * values[k - 1]
                + h10 * h * slopes[k - 1]
                + h01 * values[k]
                + h11 * h * slopes[k]
            )
        return out


def _record(
    model: SweepModel, pressure: float, iterations: int, keep_state: bool
) -> tuple[Step, np.ndarray]:
    """The converged state at ``pressure`` as a :class:`Step`, and its tangent ``du/dp``."""
    values = model.measure().as_array()
    tangent = model.pressure_tangent(refactorize=iterations == 0)
    slopes = model.measure_derivative(tangent)
    stretch, _ = model.max_stretch()
    state = model.state() if keep_state else None
    rate = model.cavity_volume_rate(tangent)
    volume = model.cavity_volume_mm3()
    return Step(pressure, values, slopes, iterations, stretch, state, rate, volume), tangent


def _apply_gravity(model: SweepModel) -> int:
    """Ramp gravity in fractions with extrapolated starts; returns the Newton iterations.

    The weight is followed like the pressure: from 1/4 of it, doubling the
    fraction after a quick solve and halving it after a failed one, each solve
    starting from the cubic extrapolation of the last two states along
    ``du/dg``. A long soft actuator sags tens of degrees; Newton straight from
    the undeformed state to the full weight zigzags through that rotation (51
    iterations for (160, 6, 2, 2, 5, 8) against 17 followed). The early
    give-up rules stay off: the first solve starts a long way off by nature.
    """
    solver = model.solver
    names = ("stall_iteration", "progress_iteration", "first_contraction", "max_iterations")
    saved = [getattr(solver, name) for name in names]
    solver.stall_iteration = solver.progress_iteration = 10**6
    solver.first_contraction = math.inf
    solver.max_iterations = max(30, solver.max_iterations)
    try:
        return _gravity_fractions(model)
    finally:
        for name, value in zip(names, saved, strict=True):
            setattr(solver, name, value)


def _gravity_tangent(model: SweepModel) -> np.ndarray:
    """``du/dg`` at the current state, g the fraction of gravity applied (mm).

    The weight is a dead load ``g·f``, so ``∂r/∂g = −f`` and ``K du/dg = f``.
    """
    solver = model.solver
    out = solver.gfu.vec.CreateVector()
    if not solver.has_factorization:
        solver.factorize()
    solver.solve_tangent(model.weight_vector, out)
    return np.array(out.FV().NumPy(), copy=True)


def _gravity_fractions(model: SweepModel) -> int:
    options = model.options
    solver = model.solver
    if options.gravity == "none" or options.gravity_mm_s2 == 0.0:
        model.set_load(0.0, 0.0)
        return solver.solve(model.force_scale_n(0.0), load=0.0, step=0).iterations
    done, fraction, iterations, step = 0.0, 0.25, 0, 0
    model.set_load(0.0, 0.0)
    tangent = _gravity_tangent(model)
    previous: tuple[float, np.ndarray, np.ndarray] | None = None
    while done < 1.0:
        target = min(1.0, done + fraction)
        start = model.state()
        model.set_state(_predict(start, tangent, done, target, previous))
        model.set_load(0.0, target)
        try:
            report = solver.solve(model.force_scale_n(0.0), load=0.0, step=step)
        except ConvergenceError as exc:
            model.set_state(start)
            model.set_load(0.0, done)
            fraction /= 2.0
            if fraction < 1.0 / 64.0:
                raise ConvergenceError(
                    f"the actuator {model.design} does not hold its own weight: gravity "
                    f"fraction {target:.3g} did not converge",
                    pressure_mpa=0.0,
                    step=step,
                    residual=exc.residual,
                ) from exc
            continue
        iterations += report.iterations
        previous = (done, start, tangent)
        done = target
        step += 1
        if done < 1.0:
            tangent = _gravity_tangent(model)
        if report.iterations <= 6:
            fraction *= 2.0
    return iterations


def _predict(
    state: np.ndarray,
    tangent: np.ndarray,
    pressure: float,
    target: float,
    previous: tuple[float, np.ndarray, np.ndarray] | None,
) -> np.ndarray:
    """Starting guess for the step ``pressure → target``.

    The cubic through the last two converged states and their tangents
    ``(p₀, u₀, u₀'), (p₁, u₁, u₁')``, extrapolated to ``target`` (the first
    step has no earlier state: linear, ``u₁ + Δp·u₁'``). The linear predictor
    misses the curvature of the path, which on a curling actuator is a large
    rotation: its error stretches the stiff fibers and costs Newton iterations
    and rejected steps (reference design: 64 s with it, 21 s with the cubic).
    """
    h = target - pressure
    if previous is None:
        return state + h * tangent
    p0, u0, t0 = previous
    h1 = pressure - p0
    h00, h10, h01, h11 = _hermite_basis(1.0 + h / h1)  # s = 0 at p0, 1 at pressure
    return h00 * u0 + h10 * h1 * t0 + h01 * state + h11 * h1 * tangent


def run_steps(
    model: SweepModel,
    pmax_mpa: float,
    *,
    landing_mpa: np.ndarray | None = None,
    keep_states: bool = False,
    progress: ProgressCallback | None = None,
) -> StepHistory:
    """Gravity, then adaptive pressure steps up to ``pmax_mpa`` (see module docstring).

    ``landing_mpa``: pressures every step must land on (``output="solve"``).
    ``keep_states``: store the displacement of every step (for VTK output).
    """
    options = model.options
    history = StepHistory()
    gravity_iterations = _apply_gravity(model)
    step, tangent = _record(model, 0.0, gravity_iterations, keep_states)
    history.steps.append(step)
    if progress is not None:
        progress(0.0, float(step.values[0]), pmax_mpa)
    pressure, dp = 0.0, options.initial_step_mpa
    previous: tuple[float, np.ndarray, np.ndarray] | None = None
    while pressure < pmax_mpa - 1e-12:
        target = min(pressure + dp, pmax_mpa)
        if landing_mpa is not None:
            ahead = landing_mpa[landing_mpa > pressure + 1e-12]
            if ahead.size:
                target = min(target, float(ahead[0]))
        start = model.state()
        linear = getattr(model, "linear_predictor", None)
        cubic = previous is not None and not (linear is not None and linear())
        predicted = _predict(start, tangent, pressure, target, previous if cubic else None)
        model.set_state(predicted)
        model.set_load(target, 1.0)
        before_step = getattr(model, "before_step", None)
        if before_step is not None:
            before_step()
        try:
            report = model.solver.solve(
                model.force_scale_n(target), load=target, step=len(history.steps)
            )
        except ConvergenceError as exc:
            model.set_state(start)
            model.set_load(pressure, 1.0)
            history.rejected_steps += 1
            dp = 0.5 * (target - pressure)
            if dp < options.min_step_mpa:
                limit = _pressure_maximum(history.steps)
                if limit is None:
                    history.stop_reason = (
                        f"no convergence above {pressure:.6g} MPa (step cut below "
                        f"{options.min_step_mpa:g} MPa)"
                    )
                else:
                    stretch, site = model.stretch_site()
                    history.stop_reason = (
                        f"inflation instability above {pressure:.6g} MPa: the {site} "
                        f"balloons (stretch {stretch:.2f}), dp/dV fell {limit[1]:.1f}-fold "
                        f"over the last 0.05 MPa towards a pressure maximum near "
                        f"{limit[0]:.4g} MPa"
                    )
                history.failed_pressure_mpa = target
                history.failure = str(exc)
                break
            continue
        reject_step = getattr(model, "reject_step", None)
        if (
            reject_step is not None
            and target - pressure > 4.0 * options.min_step_mpa
            and reject_step()
        ):
            logger.debug("step to %.6g MPa cut: contact starts within it", target)
            model.set_state(start)
            model.set_load(pressure, 1.0)
            history.rejected_steps += 1
            dp = 0.5 * (target - pressure)
            continue
        previous = (pressure, start, tangent)
        pressure = target
        logger.debug(
            "step %d at %.6g MPa: %d Newton iterations, residual %.3g N (force scale %.3g N)",
            len(history.steps),
            pressure,
            report.iterations,
            report.residual,
            model.force_scale_n(pressure),
        )
        step, tangent = _record(model, pressure, report.iterations, keep_states)
        history.steps.append(step)
        if progress is not None:
            progress(pressure, float(step.values[0]), pmax_mpa)
        stop_after_step = getattr(model, "stop_after_step", None)
        found = stop_after_step(pressure) if stop_after_step is not None else None
        if found is not None:
            history.stop_reason, history.valid_up_to_mpa = found
            break
        if step.max_stretch > options.max_stretch:
            _, site = model.stretch_site()
            history.stop_reason = (
                f"stretch {step.max_stretch:.2f} above {options.max_stretch:g} in the "
                f"{site} (beyond the material model)"
            )
            history.valid_up_to_mpa = history.steps[-2].pressure_mpa
            break
        if step.values[0] > options.max_angle_deg:
            history.stop_reason = f"bending angle above {options.max_angle_deg:g} deg"
            break
        miss = float(np.abs(model.state() - predicted).max())
        dp = _next_step(dp, miss, options)
    return history


def _pressure_maximum(steps: list[Step], *, within_mpa: float = 0.01) -> tuple[float, float] | None:
    """A pressure maximum just ahead of the last step, from the cavity's stiffness.

    When an unreinforced part of the actuator balloons, the pressure–volume
    curve flattens towards a maximum (the inflation instability of rubber
    membranes): past it no nearby state is in equilibrium under a prescribed
    pressure, so Newton cannot converge however short the step. The signature
    is the stiffness ``dp/dV`` falling towards zero: over the last three steps it
    decreases, and its straight-line extrapolation through the last two reaches
    zero within ``within_mpa`` of the last converged pressure.

    Returns
    -------
    (float, float) or None
        The extrapolated pressure of the maximum (MPa) and the factor by which
        ``dp/dV`` fell over the last 0.05 MPa; None without that signature.
    """
    if len(steps) < 3:
        return None
    p = np.array([s.pressure_mpa for s in steps])
    rate = np.array([s.volume_rate for s in steps])
    if not np.all(np.isfinite(rate[-3:])) or np.any(rate[-3:] <= 0.0):
        return None
    stiffness = 1.0 / rate
    k0, k1, k2 = stiffness[-3:]
    if not k0 > k1 > k2:
        return None
    slope = (k2 - k1) / (p[-1] - p[-2])
    maximum = p[-1] - k2 / slope
    if maximum - p[-1] > within_mpa:
        return None
    earlier = int(np.searchsorted(p, p[-1] - 0.05))
    return float(maximum), float(stiffness[earlier] / k2)


def _next_step(dp: float, miss_mm: float, options: FEMOptions) -> float:
    """The next pressure step from how far the predictor missed the converged state.

    The error of the cubic predictor grows like ``Δp⁴``, so the step that would
    have missed by ``predictor_error_mm`` is ``Δp (target / miss)^¼``; the
    change is held within a factor 0.5–1.5 per step and the step within
    ``[min_step_mpa, max_step_mpa]``.
    """
    factor = (options.predictor_error_mm / max(miss_mm, 1e-12)) ** 0.25
    factor = min(1.5, max(0.5, factor))
    return min(options.max_step_mpa, max(options.min_step_mpa, factor * dp))


def run_model_sweep(
    build: Callable[[Any, FEMOptions], SweepModel],
    design: Any,
    pressures_mpa: ArrayLike,
    options: FEMOptions,
    *,
    progress: ProgressCallback | None = None,
    keep_states: bool = False,
) -> tuple[SweepResult, SweepModel, StepHistory]:
    """The sweep of the model ``build(design, options)`` (any FEM family's model).

    The load stepping above on the model the family builds
    (one with the interface of :class:`ActuatorModel`); ``design`` and
    ``options`` are checked by the caller.
    """
    from ngsolve import SetNumThreads, TaskManager

    grid = check_pressures_mpa(pressures_mpa)
    started = time.perf_counter()
    SetNumThreads(options.threads)
    with TaskManager():
        model = build(design, options)
        built = time.perf_counter()
        landing = grid if options.output == "solve" else None
        history = run_steps(
            model, float(grid[-1]), landing_mpa=landing, progress=progress, keep_states=keep_states
        )
    return _to_result(model, grid, history, started, built), model, history


def _to_result(
    model: SweepModel, grid: np.ndarray, history: StepHistory, started: float, built: float
) -> SweepResult:
    options = model.options
    p_steps = history.pressures
    last = p_steps[-1] if history.valid_up_to_mpa is None else history.valid_up_to_mpa
    reached = grid[grid <= last + 1e-12]
    values = history.interpolate(reached)
    # Drop outputs beyond the angle limit.
    keep = values[:, 0] <= options.max_angle_deg
    if not keep.all():
        cut = int(np.flatnonzero(~keep)[0])
        reached, values = reached[:cut], values[:cut]
    iterations = np.array(
        [
            history.steps[
                min(int(np.searchsorted(p_steps, q - 1e-12)), len(p_steps) - 1)
            ].iterations
            for q in reached
        ],
        dtype=np.int64,
    )
    pressure, angle = list(reached), list(values[:, 0])
    tip_x, tip_z, its = list(values[:, 1]), list(values[:, 2]), list(iterations)
    converged = [True] * len(reached)
    if history.failed_pressure_mpa is not None:
        beyond = grid[grid > p_steps[-1] + 1e-12]
        if beyond.size:
            pressure.append(float(beyond[0]))
            angle.append(np.nan)
            tip_x.append(np.nan)
            tip_z.append(np.nan)
            its.append(options.max_iterations)
            converged.append(False)
    timings = cast(FEMTimings, model.solver.timings.as_dict())
    wall = time.perf_counter() - started
    stats: FEMStats = {
        "model": getattr(model, "description", "3D FEM, NGSolve, half model, quadratic tetrahedra"),
        "stop_reason": history.stop_reason,
        "steps_mpa": [float(s.pressure_mpa) for s in history.steps],
        "step_angles_deg": [float(s.values[0]) for s in history.steps],
        "step_iterations": [int(s.iterations) for s in history.steps],
        "step_max_stretch": [float(s.max_stretch) for s in history.steps],
        "step_volume_rate_mm3_per_mpa": [float(s.volume_rate) for s in history.steps],
        "rejected_steps": history.rejected_steps,
        "ndof": model.ndof,
        "setup_s": built - started,
        "timings": timings,
        "options": options.to_dict(),
        "options_sha256": options.digest(),
        "fiber_spacing_mm": (
            model.fiber_spacing_mm() if isinstance(model, ActuatorModel) else float("nan")
        ),
    }
    if history.failure:
        stats["failure"] = history.failure
    return SweepResult(
        design=model.design,
        pressure_mpa=np.array(pressure, dtype=float),
        angle_deg=np.array(angle, dtype=float),
        tip_x_mm=np.array(tip_x, dtype=float),
        tip_z_mm=np.array(tip_z, dtype=float),
        converged=np.array(converged, dtype=bool),
        newton_iterations=np.array(its, dtype=np.int64),
        wall_time_s=wall,
        mesh_size=model.n_elements,
        stats=dict(stats),
    )
