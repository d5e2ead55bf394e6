"""The seam between bending models and everything that uses them.

A *bending model* turns one :class:`~softbend.actuators.Design` and an
increasing grid of gauge pressures into a :class:`SweepResult`: the angle and tip
of the actuator at every pressure, and where the sweep stopped. The analytical
model (:class:`softbend.analytical.AnalyticalModel`), the finite-element model
(:class:`softbend.fem.FEMModel`) and a trained surrogate
(:class:`softbend.surrogates.SurrogateModel`) all answer the :class:`BendingModel`
protocol, so campaigns, transfer learning and control take any of them::

    result = model.sweep(design, default_pressures_mpa())

Sweep semantics (shared by every model): the pressures are applied in increasing
order from the first; the sweep ends at the first pressure that does not converge,
and that pressure is kept with ``converged=False`` (its angle and tip are NaN) so
a database records where the actuator stopped. A sweep that raises an exception
is a *failed* design, not a truncated one.

This module sits just above :mod:`softbend.design` and imports nothing else of
softbend's but its validation helpers and errors.
"""

from __future__ import annotations

from collections.abc import Mapping
from dataclasses import dataclass, field
from typing import Any, Protocol, runtime_checkable

import numpy as np
from numpy.typing import ArrayLike

from softbend._validation import check_range, must_be
from softbend.actuators import Design
from softbend.errors import InputError

__all__ = [
    "DEFAULT_PMAX_MPA",
    "DEFAULT_PSTEP_MPA",
    "BendingModel",
    "SweepResult",
    "check_pressures_mpa",
    "default_pressures_mpa",
]

#: Pressure grid of paper B: 0 to 0.5 MPa in steps of 0.005 MPa.
DEFAULT_PMAX_MPA = 0.5
DEFAULT_PSTEP_MPA = 0.005


def default_pressures_mpa(
    pmax_mpa: float = DEFAULT_PMAX_MPA,
    step_mpa: float = DEFAULT_PSTEP_MPA,
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

    Raises
    ------
    InputError
        Keyed ``pmax_mpa`` or ``step_mpa``.
    """
    pmax = check_range(pmax_mpa, "pmax_mpa", low=0.0, high=100.0, high_inclusive=True)
    step = check_range(step_mpa, "step_mpa", low=0.0, high=pmax, high_inclusive=True)
    n_steps = round(pmax / step)
    if abs(n_steps * step - pmax) > 1e-9 * pmax:
        raise InputError(
            must_be(f"a whole number of steps of {step:g} MPa", pmax)
            + f" ({pmax / step:.6g} steps)",
            key="pmax_mpa",
        )
    if n_steps > 100_000:
        raise InputError(
            f"must give a grid of at most 100001 pressures in steps of {step:g} MPa; "
            f"got {n_steps + 1} pressures up to {pmax:g} MPa",
            key="pmax_mpa",
        )
    return np.round(np.arange(n_steps + 1) * step, 12)


def check_pressures_mpa(
    pressures_mpa: ArrayLike,
    key: str = "pressures_mpa",
) -> np.ndarray:
    """Validate a sweep grid: 1-D, finite, >= 0 MPa and strictly increasing.

    Returns the grid as a new read-only float array; raises :class:`InputError`
    keyed ``key`` that names the rule and the first offending value.
    """
    try:
        grid = np.array(pressures_mpa, dtype=float)
    except (TypeError, ValueError):
        raise InputError(must_be("a 1-D sequence of numbers", pressures_mpa), key=key) from None
    if grid.ndim != 1 or grid.size == 0:
        raise InputError(f"must be a non-empty 1-D sequence; got shape {grid.shape}", key=key)
    bad = ~np.isfinite(grid) | (grid < 0.0)
    if bad.any():
        i = int(np.flatnonzero(bad)[0])
        raise InputError(
            f"must be finite and in [0, inf) MPa; got {float(grid[i])!r} at position {i}",
            key=key,
        )
    steps = np.diff(grid)
    if (steps <= 0.0).any():
        i = int(np.flatnonzero(steps <= 0.0)[0]) + 1
        raise InputError(
            f"must be strictly increasing; got {float(grid[i])!r} after "
            f"{float(grid[i - 1])!r} at position {i}",
            key=key,
        )
    grid.setflags(write=False)
    return grid


def _as_vector(values: ArrayLike, dtype: type, key: str) -> np.ndarray:
    array: np.ndarray = np.array(values, dtype=dtype)
    if array.ndim != 1:
        raise InputError(f"must be 1-D; got shape {array.shape}", key=key)
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
    design : Design
        The design swept (paper B's actuator, or a design of another FEM
        family, :class:`~softbend.actuators.Design`).
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

    design: Design
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

        if not isinstance(self.design, Design):
            raise InputError(must_be("a Design", self.design), key="design")
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
            odd = next(name for name in arrays if lengths[name] != lengths["pressure_mpa"])
            raise InputError(
                f"must have the length of 'pressure_mpa' like every array of the sweep; "
                f"got lengths {lengths}",
                key=odd,
            )
        if len(self.pressure_mpa):
            check_pressures_mpa(self.pressure_mpa, key="pressure_mpa")
        failed = np.flatnonzero(~self.converged)
        if failed.size and failed[0] != len(self.converged) - 1:
            raise InputError(
                "must be True everywhere but possibly at the last pressure (the sweep ends "
                f"at the first failure); got False at position {int(failed[0])} of "
                f"{len(self.converged)}",
                key="converged",
            )
        wall = check_range(self.wall_time_s, "wall_time_s", low=0.0, low_inclusive=True)
        object.__setattr__(self, "wall_time_s", wall)
        if self.mesh_size is not None:
            object.__setattr__(
                self,
                "mesh_size",
                int(check_range(self.mesh_size, "mesh_size", low=0.0)),
            )
        object.__setattr__(self, "stats", dict(self.stats))

    @classmethod
    def from_angles(
        cls,
        design: Design,
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
class BendingModel(Protocol):
    """What every bending model answers: a name and a pressure sweep of one design.

    Attributes
    ----------
    name : str
        Short name (a campaign stores it with every design: ``"analytical"``,
        ``"fem"``, ``"surrogate"``); read-only, so a frozen dataclass's field or a
        class attribute answers it.

    Optional attribute ``preferred_chunk_size`` (int): how many designs one worker
    task should sweep. Cheap models leave it out and the runner batches designs to
    keep its overhead low; expensive ones (FEM) set 1 for load balancing.
    """

    @property
    def name(self) -> str:
        """Short name of the model, stored with every design of a campaign."""
        ...

    def sweep(self, design: Design, pressures_mpa: np.ndarray) -> SweepResult:
        """Sweep ``design`` over the increasing gauge pressures ``pressures_mpa`` (MPa)."""
        ...
