"""Sweep backends: what computes the angle–pressure curve of one design.

A backend turns one :class:`~softbend.design.SFRBADesign` and a pressure grid into a
:class:`SweepResult`. The campaign runner only knows the :class:`Backend` protocol,
so the analytical model (SPEC §4.3), the finite-element model (SPEC §4.2) and any
later model plug in through the same registry::

    backend = get_backend("analytical")
    result = backend.sweep(design, default_pressures_mpa())

Sweep semantics (shared by every backend): the pressures are applied in increasing
order from the first; the sweep ends at the first pressure that does not converge,
and that pressure is kept with ``converged=False`` (its angle and tip are NaN) so
the database records where the actuator stopped. A sweep that raises an exception
is a *failed* design, not a truncated one.

Backends are sent to worker processes (pickled), so they must be plain picklable
objects and must not hold open resources; they are built once in the coordinating
process, which validates their options before any work starts.
"""

from __future__ import annotations

import inspect
import logging
import os
import time
import warnings
from collections.abc import Callable, Mapping
from dataclasses import dataclass, field
from typing import Any, Protocol, runtime_checkable

import numpy as np
from numpy.typing import ArrayLike

from softbend._validation import check_choice, check_range
from softbend.design import SFRBADesign
from softbend.errors import ConvergenceError, SoftbendError

__all__ = [
    "AnalyticalBackend",
    "Backend",
    "FEMBackend",
    "FaultInjectionBackend",
    "SweepResult",
    "available_backends",
    "check_pressures_mpa",
    "default_pressures_mpa",
    "get_backend",
    "register_backend",
]

logger = logging.getLogger(__name__)

#: Pressure grid of paper B: 0 to 0.5 MPa in steps of 0.005 MPa.
DEFAULT_PMAX_MPA = 0.5
DEFAULT_PSTEP_MPA = 0.005


def default_pressures_mpa(
    pmax_mpa: float = DEFAULT_PMAX_MPA, step_mpa: float = DEFAULT_PSTEP_MPA
) -> np.ndarray:
    """Uniform gauge-pressure grid ``0, step, 2·step, ..., pmax`` in MPa.

    The values are built from integer step counts (``i·step`` rounded to 12
    decimals), so they are the doubles closest to the decimal grid values and
    ``0.015`` in a query matches the third step exactly. The default is paper B's
    grid, 0–0.5 MPa in 0.005 MPa steps: 101 pressures.

    Parameters
    ----------
    pmax_mpa : float
        Largest pressure, MPa, in (0, 100]; must be a whole number of steps
        (to 1e-9 relative).
    step_mpa : float
        Step, MPa, in (0, pmax_mpa].

    Returns
    -------
    numpy.ndarray
        ``round(pmax/step) + 1`` increasing pressures starting at 0.
    """
    owner = "default_pressures_mpa"
    pmax = check_range(pmax_mpa, "pmax_mpa", owner, low=0.0, high=100.0, high_inclusive=True)
    step = check_range(step_mpa, "step_mpa", owner, low=0.0, high=pmax, high_inclusive=True)
    n_steps = round(pmax / step)
    if abs(n_steps * step - pmax) > 1e-9 * pmax:
        raise ValueError(
            f"The 'pmax_mpa' of {owner} must be a whole number of steps of {step:g} MPa. "
            f"Got {pmax:g} MPa ({pmax / step:.6g} steps) instead."
        )
    if n_steps > 100_000:
        raise ValueError(
            f"The pressure grid of {owner} must have at most 100001 values. "
            f"Got {n_steps + 1} ({pmax:g} MPa in steps of {step:g} MPa) instead."
        )
    return np.round(np.arange(n_steps + 1) * step, 12)


def check_pressures_mpa(
    pressures_mpa: ArrayLike, owner: str, name: str = "pressures_mpa"
) -> np.ndarray:
    """Validate a sweep grid: 1-D, finite, >= 0 MPa and strictly increasing.

    Returns the grid as a new read-only float array; raises ``ValueError`` naming
    the field, the rule and the first offending value.
    """
    try:
        grid = np.array(pressures_mpa, dtype=float)
    except (TypeError, ValueError):
        raise ValueError(
            f"The '{name}' of {owner} must be a 1-D sequence of numbers. "
            f"Got {pressures_mpa!r} instead."
        ) from None
    if grid.ndim != 1 or grid.size == 0:
        raise ValueError(
            f"The '{name}' of {owner} must be a non-empty 1-D sequence. "
            f"Got shape {grid.shape} instead."
        )
    bad = ~np.isfinite(grid) | (grid < 0.0)
    if bad.any():
        i = int(np.flatnonzero(bad)[0])
        raise ValueError(
            f"The '{name}' of {owner} must be finite and in [0, inf) MPa. "
            f"Got {float(grid[i])!r} at position {i} instead."
        )
    steps = np.diff(grid)
    if (steps <= 0.0).any():
        i = int(np.flatnonzero(steps <= 0.0)[0]) + 1
        raise ValueError(
            f"The '{name}' of {owner} must be strictly increasing. "
            f"Got {float(grid[i])!r} after {float(grid[i - 1])!r} at position {i} instead."
        )
    grid.setflags(write=False)
    return grid


def _as_vector(values: ArrayLike, dtype: type, name: str) -> np.ndarray:
    array = np.array(values, dtype=dtype)
    if array.ndim != 1:
        raise ValueError(
            f"The '{name}' of SweepResult must be 1-D. Got shape {array.shape} instead."
        )
    array.setflags(write=False)
    return array


@dataclass(frozen=True, eq=False)
class SweepResult:
    """The pressure sweep of one design.

    All arrays have one entry per applied pressure, in the order applied. The
    sweep is truncated at the first pressure that did not converge: every entry
    before it has ``converged=True``; that last entry has ``converged=False`` and
    NaN angle and tip (use :meth:`from_angles` to build a result with this rule
    applied).

    Parameters
    ----------
    design : SFRBADesign
        The design swept.
    pressure_mpa : array_like
        Gauge pressures applied, MPa, strictly increasing.
    angle_deg : array_like
        Bending angle, degrees.
    tip_x_mm, tip_z_mm : array_like
        Tip position in the bending plane, mm (frame of
        :func:`softbend.analytical.tip_position_mm`: ``x`` along the undeformed
        axis from the base, ``z`` towards the bending side).
    converged : array_like of bool
        Whether the solver converged at that pressure.
    newton_iterations : array_like of int
        Newton iterations spent on that pressure (0 for closed-form backends).
    wall_time_s : float
        Wall-clock time of the whole sweep, s.
    mesh_size : int or None
        Number of elements (or degrees of freedom, as the backend documents) of a
        discretised model; None for the analytical model.
    stats : dict
        Backend-specific, JSON-serialisable details (solver settings, warnings).

    Raises
    ------
    ValueError
        If the arrays differ in length, the pressures are not increasing, or a
        non-converged entry is not the last one.
    """

    design: SFRBADesign
    pressure_mpa: np.ndarray
    angle_deg: np.ndarray
    tip_x_mm: np.ndarray
    tip_z_mm: np.ndarray
    converged: np.ndarray
    newton_iterations: np.ndarray
    wall_time_s: float
    mesh_size: int | None = None
    stats: dict[str, Any] = field(default_factory=dict)

    def __post_init__(self) -> None:
        if not isinstance(self.design, SFRBADesign):
            raise ValueError(
                f"The 'design' of SweepResult must be an SFRBADesign. Got {self.design!r} instead."
            )
        arrays = {
            "pressure_mpa": float,
            "angle_deg": float,
            "tip_x_mm": float,
            "tip_z_mm": float,
            "converged": bool,
            "newton_iterations": np.int64,
        }
        for name, dtype in arrays.items():
            object.__setattr__(self, name, _as_vector(getattr(self, name), dtype, name))
        lengths = {name: len(getattr(self, name)) for name in arrays}
        if len(set(lengths.values())) != 1:
            raise ValueError(
                f"The arrays of SweepResult must have equal lengths. Got {lengths} instead."
            )
        if len(self.pressure_mpa):
            check_pressures_mpa(self.pressure_mpa, "SweepResult", "pressure_mpa")
        failed = np.flatnonzero(~self.converged)
        if failed.size and failed[0] != len(self.converged) - 1:
            raise ValueError(
                "The 'converged' of SweepResult must be True everywhere but possibly at the "
                f"last pressure (the sweep ends at the first failure). Got False at position "
                f"{int(failed[0])} of {len(self.converged)} instead."
            )
        wall = check_range(
            self.wall_time_s, "wall_time_s", "SweepResult", low=0.0, low_inclusive=True
        )
        object.__setattr__(self, "wall_time_s", wall)
        if self.mesh_size is not None:
            object.__setattr__(
                self,
                "mesh_size",
                int(check_range(self.mesh_size, "mesh_size", "SweepResult", low=0.0)),
            )
        object.__setattr__(self, "stats", dict(self.stats))

    @classmethod
    def from_angles(
        cls,
        design: SFRBADesign,
        pressure_mpa: ArrayLike,
        angle_deg: ArrayLike,
        tip_x_mm: ArrayLike,
        tip_z_mm: ArrayLike,
        *,
        newton_iterations: ArrayLike | None = None,
        wall_time_s: float,
        mesh_size: int | None = None,
        stats: Mapping[str, Any] | None = None,
    ) -> SweepResult:
        """Build a result from a full-grid solve, ending the sweep at the first NaN angle.

        A pressure whose angle is not finite is the first that did not converge:
        it is kept with ``converged=False`` and NaN angle and tip, and every later
        pressure is dropped.
        """
        angle = np.asarray(angle_deg, dtype=float)
        pressures = np.asarray(pressure_mpa, dtype=float)
        iterations = (
            np.zeros(pressures.shape, dtype=np.int64)
            if newton_iterations is None
            else np.asarray(newton_iterations)
        )
        bad = np.flatnonzero(~np.isfinite(angle))
        end = int(bad[0]) + 1 if bad.size else len(angle)
        converged = np.ones(end, dtype=bool)
        tip_x = np.array(tip_x_mm, dtype=float)[:end]
        tip_z = np.array(tip_z_mm, dtype=float)[:end]
        angle = angle[:end].copy()
        if bad.size:
            converged[-1] = False
            angle[-1] = tip_x[-1] = tip_z[-1] = np.nan
        return cls(
            design=design,
            pressure_mpa=pressures[:end],
            angle_deg=angle,
            tip_x_mm=tip_x,
            tip_z_mm=tip_z,
            converged=converged,
            newton_iterations=iterations[:end],
            wall_time_s=wall_time_s,
            mesh_size=mesh_size,
            stats=dict(stats or {}),
        )

    @property
    def n_converged(self) -> int:
        """Number of pressures at which the solver converged."""
        return int(self.converged.sum())

    @property
    def max_pressure_mpa(self) -> float:
        """Largest converged pressure, MPa (NaN if none converged)."""
        ok = self.pressure_mpa[self.converged]
        return float(ok[-1]) if ok.size else float("nan")

    @property
    def max_angle_deg(self) -> float:
        """Largest converged bending angle, degrees (NaN if none converged)."""
        ok = self.angle_deg[self.converged]
        return float(ok.max()) if ok.size else float("nan")


@runtime_checkable
class Backend(Protocol):
    """What the campaign runner needs from a model.

    Attributes
    ----------
    name : str
        Registry name, stored with every design in the database.

    Optional attribute ``preferred_chunk_size`` (int): how many designs one worker
    task should sweep. Cheap models leave it out and the runner batches designs to
    keep its overhead low; expensive ones (FEM) set 1 for load balancing.
    """

    name: str

    def sweep(self, design: SFRBADesign, pressures_mpa: np.ndarray) -> SweepResult:
        """Sweep ``design`` over the increasing gauge pressures ``pressures_mpa`` (MPa)."""
        ...


@dataclass(frozen=True)
class AnalyticalBackend:
    """The quasi-static moment balance of Polygerinos et al. (SPEC §4.3).

    Calls :func:`softbend.analytical.bending_angle_deg` on the whole grid and
    :func:`softbend.analytical.tip_position_mm` for the tip; the sweep ends at the
    first pressure where the walls cannot balance the pressure (the root finder
    finds no angle), which is kept with ``converged=False``. No gravity and no
    Newton iterations (``newton_iterations`` is 0); ``mesh_size`` is None. The
    model's own warnings (non-convergence, limit points) are not re-emitted in the
    workers but stored in ``stats["warnings"]``.

    Parameters
    ----------
    material : Material, HyperelasticModel or str, optional
        Elastomer of the walls: a material, a hyperelastic law, or the name of a
        preset of :mod:`softbend.materials.presets` (``"dragon-skin-30"``); default
        Dragon Skin 30 (Yeoh, paper B).
    max_angle_deg : float, optional
        Largest bending angle searched, degrees, in (0, 3600]; default that of
        :mod:`softbend.analytical` (720).
    """

    material: Any = None
    max_angle_deg: float | None = None
    name: str = field(default="analytical", init=False)

    def __post_init__(self) -> None:
        from softbend.materials.models import HyperelasticModel
        from softbend.materials.presets import Material, get_preset

        material = self.material
        if isinstance(material, str):
            material = get_preset(material)
        model = material.model if isinstance(material, Material) else material
        if material is not None and not isinstance(model, HyperelasticModel):
            raise ValueError(
                "The 'material' of AnalyticalBackend must be a hyperelastic model, a Material "
                f"holding one, or a preset name. Got {self.material!r} instead."
            )
        object.__setattr__(self, "material", material)
        if self.max_angle_deg is not None:
            limit = check_range(
                self.max_angle_deg,
                "max_angle_deg",
                "AnalyticalBackend",
                low=0.0,
                high=3600.0,
                high_inclusive=True,
            )
            object.__setattr__(self, "max_angle_deg", limit)

    def sweep(self, design: SFRBADesign, pressures_mpa: np.ndarray) -> SweepResult:
        """Solve the moment balance at every pressure of the grid, in MPa."""
        from softbend import analytical

        start = time.perf_counter()
        options = {} if self.max_angle_deg is None else {"max_angle_deg": self.max_angle_deg}
        with warnings.catch_warnings(record=True) as caught:
            warnings.simplefilter("always")
            angle = analytical.bending_angle_deg(design, pressures_mpa, self.material, **options)
        tip_x, tip_z = analytical.tip_position_mm(design, angle)
        stats: dict[str, Any] = {
            "model": "Polygerinos et al. 2015, quasi-static",
            "material": _describe_material(self.material),
        }
        if caught:
            stats["warnings"] = [str(w.message) for w in caught]
        return SweepResult.from_angles(
            design,
            pressures_mpa,
            angle,
            tip_x,
            tip_z,
            wall_time_s=time.perf_counter() - start,
            stats=stats,
        )


def _describe_material(material: Any) -> str:
    from softbend.materials.presets import DRAGON_SKIN_30, Material

    if material is None:
        material = DRAGON_SKIN_30
    if isinstance(material, Material):
        return f"{material.name}: {material.model!r}"
    return repr(material)


@dataclass(frozen=True)
class FEMBackend:
    """The 3D nonlinear finite-element model (SPEC §4.2), via ``softbend.fem.simulate``.

    Parameters
    ----------
    options : Any
        Passed unchanged as the third argument of ``softbend.fem.simulate(design,
        pressures_mpa, options)``; None for its defaults.
    """

    options: Any = None
    name: str = field(default="fem", init=False)
    #: One design per task: an FEM sweep takes minutes, so batching hurts balance.
    preferred_chunk_size: int = field(default=1, init=False)

    def sweep(self, design: SFRBADesign, pressures_mpa: np.ndarray) -> SweepResult:
        """Run the FEM load-stepping sweep of ``design`` over ``pressures_mpa`` (MPa)."""
        fem = _import_fem()
        result = fem.simulate(design, pressures_mpa, self.options)
        if not isinstance(result, SweepResult):
            raise SoftbendError(
                f"softbend.fem.simulate must return a SweepResult. Got {type(result).__name__}."
            )
        return result


def _import_fem() -> Any:
    try:
        from softbend import fem
    except ImportError as exc:
        raise SoftbendError(
            "the FEM backend needs softbend.fem (not available in this installation)"
        ) from exc
    return fem


def _make_fem(options: Any = None, **fem_options: Any) -> FEMBackend:
    fem = _import_fem()
    if fem_options:
        if options is not None:
            raise ValueError(
                "The options of the 'fem' backend must be given either as 'options' or as "
                f"keywords, not both. Got options={options!r} and {sorted(fem_options)}."
            )
        make_options = getattr(fem, "FEMOptions", None)
        if make_options is None:
            raise ValueError(
                "The 'fem' backend takes its settings as options=<object>; this softbend.fem "
                f"has no FEMOptions to build them from keywords {sorted(fem_options)}."
            )
        options = make_options(**fem_options)
    return FEMBackend(options=options)


@dataclass(frozen=True)
class FaultInjectionBackend:
    """Diagnostic wrapper: another backend, slowed down and failing for chosen designs.

    It exercises the campaign machinery with a real model behind it: resuming
    after the coordinating process is killed (``delay_s`` leaves time to kill it
    mid-run), recording failed designs (``fail_design_ids``), surviving a worker
    process that dies (``crash_design_ids``, as a solver that segfaults) and
    checking that a Dask cluster's workers can import softbend. It is registered
    as ``"fault-injection"``; options: ``inner`` (backend name, default
    ``"analytical"``), ``inner_options`` (dict), ``delay_s``, ``fail_design_ids``,
    ``crash_design_ids``.

    Parameters
    ----------
    inner : Backend
        The backend that does the work.
    delay_s : float
        Sleep before each sweep, s, in [0, 3600].
    fail_design_ids : frozenset of str
        Designs (by :attr:`SFRBADesign.design_id`) whose sweep raises
        :class:`~softbend.errors.ConvergenceError` instead of running.
    crash_design_ids : frozenset of str
        Designs whose sweep ends the process running it at once (``os._exit``),
        without cleanup. Only meaningful in worker processes: in a serial campaign
        it ends the coordinating process itself.
    """

    inner: Backend
    delay_s: float = 0.0
    fail_design_ids: frozenset[str] = frozenset()
    crash_design_ids: frozenset[str] = frozenset()
    name: str = field(default="fault-injection", init=False)

    def sweep(self, design: SFRBADesign, pressures_mpa: np.ndarray) -> SweepResult:
        """Sleep ``delay_s``, then fail or delegate to the inner backend."""
        start = time.perf_counter()
        if self.delay_s:
            time.sleep(self.delay_s)
        if design.design_id in self.crash_design_ids:
            os._exit(70)
        if design.design_id in self.fail_design_ids:
            raise ConvergenceError(
                f"injected failure for design {design}", pressure_mpa=float(pressures_mpa[0])
            )
        result = self.inner.sweep(design, pressures_mpa)
        stats = {**result.stats, "inner_backend": self.inner.name, "delay_s": self.delay_s}
        return SweepResult(
            design=result.design,
            pressure_mpa=result.pressure_mpa,
            angle_deg=result.angle_deg,
            tip_x_mm=result.tip_x_mm,
            tip_z_mm=result.tip_z_mm,
            converged=result.converged,
            newton_iterations=result.newton_iterations,
            wall_time_s=time.perf_counter() - start,
            mesh_size=result.mesh_size,
            stats=stats,
        )


def _make_fault_injection(
    inner: str = "analytical",
    inner_options: Mapping[str, Any] | None = None,
    delay_s: float = 0.0,
    fail_design_ids: Any = (),
    crash_design_ids: Any = (),
) -> FaultInjectionBackend:
    if inner == "fault-injection":
        raise ValueError(
            "The 'inner' of the 'fault-injection' backend must be another backend. "
            "Got 'fault-injection' instead."
        )
    delay = check_range(
        delay_s,
        "delay_s",
        "FaultInjectionBackend",
        low=0.0,
        high=3600.0,
        low_inclusive=True,
        high_inclusive=True,
    )
    return FaultInjectionBackend(
        inner=get_backend(inner, **dict(inner_options or {})),
        delay_s=delay,
        fail_design_ids=_id_set(fail_design_ids),
        crash_design_ids=_id_set(crash_design_ids),
    )


def _id_set(ids: Any) -> frozenset[str]:
    if isinstance(ids, str):
        ids = [ids]
    return frozenset(str(i) for i in ids)


_REGISTRY: dict[str, Callable[..., Backend]] = {
    "analytical": AnalyticalBackend,
    "fem": _make_fem,
    "fault-injection": _make_fault_injection,
}


def register_backend(name: str, factory: Callable[..., Backend], *, replace: bool = False) -> None:
    """Make ``factory(**options)`` available as ``get_backend(name, **options)``.

    Parameters
    ----------
    name : str
        Registry name (non-empty).
    factory : callable
        Returns an object satisfying :class:`Backend`. It runs in the coordinating
        process; the backend it returns is pickled to the workers.
    replace : bool
        Allow replacing an existing registration.
    """
    if not isinstance(name, str) or not name.strip():
        raise ValueError(
            f"The 'name' of register_backend must be a non-empty string. Got {name!r}."
        )
    if not callable(factory):
        raise ValueError(f"The 'factory' of register_backend must be callable. Got {factory!r}.")
    if name in _REGISTRY and not replace:
        raise ValueError(
            f"The 'name' of register_backend must be new (or pass replace=True). "
            f"Got {name!r}, already registered."
        )
    _REGISTRY[name] = factory


def available_backends() -> tuple[str, ...]:
    """Names accepted by :func:`get_backend`."""
    return tuple(_REGISTRY)


def get_backend(name: str, **options: Any) -> Backend:
    """Build the backend registered as ``name`` with ``options``.

    Raises
    ------
    ValueError
        For an unknown name (listing the registered ones) or an option the backend
        does not take.
    SoftbendError
        If the backend's implementation is not installed (``"fem"`` without
        ``softbend.fem``).
    """
    check_choice(name, "backend", "get_backend", available_backends())
    factory = _REGISTRY[name]
    try:
        inspect.signature(factory).bind(**options)
    except TypeError as exc:
        raise ValueError(f"The options of backend {name!r} are invalid: {exc}.") from None
    backend = factory(**options)
    if not isinstance(backend, Backend):
        raise SoftbendError(
            f"The factory of backend {name!r} returned {type(backend).__name__}, "
            "which has no 'name' and 'sweep'."
        )
    return backend
