"""Quasi-static analytical model of the fiber-reinforced bending actuator.

The model of Polygerinos et al. (IEEE Trans. Robot. 31, 2015), which paper B uses
as its baseline (paper B §4.3): the internal pressure ``P`` acting on the distal
cross-section of the chamber (a half disc of radius ``r`` on top of the bottom wall
of thickness ``b``) produces the moment about the strain-limiting layer

    M_p = P·[(2/3)r³ + (π/2)r²b],

which the axially stretched elastomer balances,

    M_e(θ) = ∫ s(λ(y))·y dA,   λ(y) = 1 + θy/l,

over the undeformed cross-section of the walls: the bottom wall ``0 < y < b`` of
width ``2(r + t)`` and the half annulus ``r < ρ < r + t`` centred at height ``b``.
Each material fiber is in the stretch state (axial λ, hoop 1, thickness 1/λ), so
``I1 = λ² + 1 + λ⁻²``, the Cauchy stress is ``σ = 2(λ² − λ⁻²)·∂W/∂I1`` and the
nominal stress ``s = σ/λ``. The bending angle ``θ`` solves ``M_e(θ) = M_p``.

Assumptions
-----------
* Quasi-static, planar bending at constant curvature; plane sections stay plane.
* The bottom (strain-limiting) layer at ``y = 0`` is inextensible and its length
  stays ``l``: it is the neutral axis.
* The fibers prevent any radial and hoop expansion (no radial bulging); the walls
  only stretch axially and thin through their thickness.
* No gravity: the model gives exactly 0° at 0 MPa, while a real or FEM actuator
  already sags under its weight. Paper B (§4.3, Fig. 7) finds it under-predicts
  the measured angles at every pressure for both reasons.
* The caps do not deform and add no stiffness; the fiber winding angle ``φ`` and
  the distal cap length enter only the tip position, not the angle.

Units: lengths mm, pressures MPa, moments N·mm, angles in degrees at the public
interface and radians inside.
"""

from __future__ import annotations

import logging
import math
import time
import warnings
from dataclasses import dataclass, field
from functools import lru_cache
from typing import Any, cast

import numpy as np
from numpy.typing import ArrayLike
from scipy.optimize import brentq

from softbend._validation import check_finite_array, check_range
from softbend.actuators import Design
from softbend.errors import InputError, keyed
from softbend.materials.models import HyperelasticModel
from softbend.materials.presets import DRAGON_SKIN_30, Material
from softbend.models import SweepResult

__all__ = [
    "AnalyticalModel",
    "SectionQuadrature",
    "bending_angle_deg",
    "elastomer_moment_nmm",
    "nominal_axial_stress_mpa",
    "pressure_moment_nmm",
    "section_quadrature",
    "tip_position_mm",
]

logger = logging.getLogger(__name__)

#: Default upper bound of the bending angle searched for a root, degrees.
MAX_ANGLE_DEG = 720.0

# Gauss–Legendre orders. The integrand is analytic in (ρ, α) on the half annulus and in
# y on the bottom wall, so these orders give close to machine precision for the stretch
# range reachable below MAX_ANGLE_DEG (see tests against scipy.integrate.dblquad).
_N_RADIAL = 12
_N_ANGULAR = 24
_N_BOTTOM = 12
# Samples of the angle grid on which the first sign change of M_e - M_p is located.
_N_GRID = 256


def _resolve_model(material: Material | HyperelasticModel | None) -> HyperelasticModel:
    """The hyperelastic law of ``material`` (default Dragon Skin 30); errors keyed ``material``."""
    if material is None:
        model = DRAGON_SKIN_30.model
    elif isinstance(material, Material):
        model = material.model
    else:
        model = material
    if not isinstance(model, HyperelasticModel):
        raise InputError(
            "must be a hyperelastic model (NeoHookean, Yeoh, ArrudaBoyce) or a Material "
            f"holding one; got {material!r}",
            key="material",
        )
    return model


def nominal_axial_stress_mpa(model: HyperelasticModel, stretch: ArrayLike) -> np.ndarray:
    """Nominal axial stress of the wall in the stretch state (λ, 1, 1/λ).

    Parameters
    ----------
    model : HyperelasticModel
        Incompressible ``W(I1)`` law.
    stretch : array_like
        Axial stretch ``λ`` > 0 (not validated here; this is the inner loop).

    Returns
    -------
    numpy.ndarray
        ``s = 2(λ² − λ⁻²)·∂W/∂I1 / λ`` with ``I1 = λ² + 1 + λ⁻²``, MPa: force per
        undeformed area. The hoop stretch 1 is the fiber constraint; the stress
        through the thickness is zero.
    """
    lam = np.asarray(stretch, dtype=float)
    inv2 = lam**-2
    I1 = lam**2 + 1.0 + inv2
    return 2.0 * (lam - inv2 / lam) * model.dW_dI1(I1)


@dataclass(frozen=True, eq=False)
class SectionQuadrature:
    """Quadrature of the wall cross-section of a design about the bottom layer.

    ``Σ weights·f(heights)`` approximates ``∫ f(y) dA`` over the bottom wall and the
    semicircular wall; ``y`` is the height above the strain-limiting layer in mm and
    the weights are areas in mm².
    """

    heights_mm: np.ndarray
    weights_mm2: np.ndarray

    @property
    def area_mm2(self) -> float:
        """Wall cross-section area, mm²."""
        return float(self.weights_mm2.sum())

    @property
    def second_moment_mm4(self) -> float:
        """``∫ y² dA`` about the bottom layer, mm⁴."""
        return float(self.weights_mm2 @ self.heights_mm**2)


@lru_cache(maxsize=256)
def _quadrature_cached(
    r_mm: float, t_mm: float, b_mm: float, n_radial: int, n_angular: int, n_bottom: int
) -> SectionQuadrature:
    outer = r_mm + t_mm
    # Bottom wall: rectangle 0 < y < b of width 2(r + t); Gauss–Legendre in y.
    xb, wb = np.polynomial.legendre.leggauss(n_bottom)
    y_bottom = 0.5 * b_mm * (xb + 1.0)
    w_bottom = 0.5 * b_mm * wb * 2.0 * outer
    # Half annulus in polar coordinates about (0, b): y = b + ρ sin α, dA = ρ dρ dα,
    # α in (0, π/2) counted twice by symmetry about the vertical axis.
    xr, wr = np.polynomial.legendre.leggauss(n_radial)
    xa, wa = np.polynomial.legendre.leggauss(n_angular)
    rho = r_mm + 0.5 * t_mm * (xr + 1.0)
    w_rho = 0.5 * t_mm * wr
    alpha = 0.25 * math.pi * (xa + 1.0)
    w_alpha = 0.25 * math.pi * wa
    y_wall = (b_mm + np.outer(rho, np.sin(alpha))).ravel()
    w_wall = (2.0 * np.outer(w_rho * rho, w_alpha)).ravel()
    heights = np.concatenate([y_bottom, y_wall])
    weights = np.concatenate([w_bottom, w_wall])
    heights.setflags(write=False)
    weights.setflags(write=False)
    return SectionQuadrature(heights_mm=heights, weights_mm2=weights)


def section_quadrature(
    design: Design,
    *,
    n_radial: int = _N_RADIAL,
    n_angular: int = _N_ANGULAR,
    n_bottom: int = _N_BOTTOM,
) -> SectionQuadrature:
    """Gauss–Legendre quadrature of the wall cross-section of ``design``.

    Polar Gauss–Legendre on the half annulus (the integrand is smooth there, unlike
    the chord width in ``y``, which has square-root kinks at ``y = b + r`` and
    ``y = b + r + t``) and Gauss–Legendre in ``y`` on the bottom wall.

    Parameters
    ----------
    design : Design
        Uses ``r_mm``, ``t_mm`` and ``b_mm``.
    n_radial, n_angular, n_bottom : int
        Number of nodes through the wall, along the quarter arc and through the
        bottom wall, each >= 1.
    """
    orders = [
        int(check_range(n, name, low=1, high=1000, low_inclusive=True, high_inclusive=True))
        for n, name in ((n_radial, "n_radial"), (n_angular, "n_angular"), (n_bottom, "n_bottom"))
    ]
    return _quadrature_cached(design.r_mm, design.t_mm, design.b_mm, *orders)


def pressure_moment_nmm(design: Design, pressure_mpa: ArrayLike) -> np.ndarray:
    """Moment of the internal pressure about the bottom layer, ``P·[(2/3)r³ + (π/2)r²b]``.

    The pressure acts on the half disc of radius ``r`` (centroid ``b + 4r/(3π)``
    above the bottom layer) that closes the chamber at the distal cap.

    Parameters
    ----------
    design : Design
        Uses ``r_mm`` and ``b_mm``.
    pressure_mpa : array_like
        Gauge pressure, MPa.

    Returns
    -------
    numpy.ndarray
        Moment in N·mm, the shape of ``pressure_mpa``.
    """
    r, b = design.r_mm, design.b_mm
    arm_mm3 = (2.0 / 3.0) * r**3 + 0.5 * math.pi * r**2 * b
    return np.asarray(pressure_mpa, dtype=float) * arm_mm3


def elastomer_moment_nmm(
    design: Design,
    angle_rad: ArrayLike,
    material: Material | HyperelasticModel | None = None,
) -> np.ndarray:
    """Restoring moment of the stretched walls, ``∫ s(1 + θy/l)·y dA``.

    Parameters
    ----------
    design : Design
        Uses ``l_mm``, ``r_mm``, ``t_mm`` and ``b_mm``.
    angle_rad : array_like
        Bending angle ``θ`` of the chamber in radians, >= 0 (tension everywhere).
    material : Material or HyperelasticModel, optional
        Elastomer; default Dragon Skin 30 (Yeoh, paper B).

    Returns
    -------
    numpy.ndarray
        Moment in N·mm, the shape of ``angle_rad``.
    """
    model = _resolve_model(material)
    theta = np.asarray(angle_rad, dtype=float)
    quad = section_quadrature(design)
    stretch = 1.0 + theta[..., None] * (quad.heights_mm / design.l_mm)
    stress = nominal_axial_stress_mpa(model, stretch)
    return stress @ (quad.weights_mm2 * quad.heights_mm)


def _validate_pressures(pressures_mpa: ArrayLike) -> np.ndarray:
    pressures = check_finite_array(pressures_mpa, "pressures_mpa")
    negative = pressures < 0.0
    if negative.any():
        first = int(np.flatnonzero(negative.ravel())[0])
        raise InputError(
            f"must be in [0, inf); got {float(pressures.ravel()[first])!r} at position {first}",
            key="pressures_mpa",
        )
    return pressures


def bending_angle_deg(
    design: Design,
    pressures_mpa: ArrayLike,
    material: Material | HyperelasticModel | None = None,
    *,
    max_angle_deg: float = MAX_ANGLE_DEG,
) -> np.ndarray:
    """Bending angle of the chamber under pressure from the moment balance.

    Solves ``M_e(θ) = M_p(P)`` for each pressure with Brent's method. ``M_e`` does
    not depend on the pressure, so it is tabulated once on a grid of angles in
    ``[0, max_angle_deg]``; for each pressure the first grid interval where
    ``M_e − M_p`` changes sign brackets the root (the equilibrium reached by loading
    quasi-statically from 0 MPa). For the stable laws of paper B ``M_e`` increases
    with ``θ`` and the root is unique; if the tabulated ``M_e`` is not monotone (a
    softening law with a limit point) a ``RuntimeWarning`` says so.

    Parameters
    ----------
    design : Design
        The actuator; ``φ`` and ``lc`` do not enter the angle.
    pressures_mpa : array_like
        Gauge pressures in MPa, finite and >= 0.
    material : Material or HyperelasticModel, optional
        Elastomer of the walls; default Dragon Skin 30 (Yeoh C10 = 0.11,
        C20 = 0.003 MPa, paper B).
    max_angle_deg : float
        Largest angle searched, degrees, in (0, 3600]; default 720.

    Returns
    -------
    numpy.ndarray
        Bending angle in degrees, the shape of ``pressures_mpa``. Exactly 0 at
        0 MPa. NaN where the walls cannot balance the pressure below
        ``max_angle_deg``: the model does not converge there (a ``RuntimeWarning``
        reports how many).

    Raises
    ------
    ValueError
        If a pressure is negative, ``max_angle_deg`` is out of range or the
        material is not hyperelastic; :class:`softbend.errors.DatasetError` (a
        ``ValueError``) if a pressure is NaN or infinite.
    """
    pressures = _validate_pressures(pressures_mpa)
    theta_max = math.radians(
        check_range(max_angle_deg, "max_angle_deg", low=0.0, high=3600.0, high_inclusive=True)
    )
    model = _resolve_model(material)

    quad = section_quadrature(design)
    moment_weights = quad.weights_mm2 * quad.heights_mm
    height_per_length = quad.heights_mm / design.l_mm

    def elastomer_moment(theta: float) -> float:
        return float(
            nominal_axial_stress_mpa(model, 1.0 + theta * height_per_length) @ moment_weights
        )

    grid = np.linspace(0.0, theta_max, _N_GRID + 1)
    grid_moment = (
        nominal_axial_stress_mpa(model, 1.0 + grid[:, None] * height_per_length) @ moment_weights
    )
    if np.any(np.diff(grid_moment) <= 0.0):
        warnings.warn(
            f"The elastomer moment of {model!r} is not increasing in the bending angle below "
            f"{max_angle_deg:g} deg for design {design}: the actuator has a limit point and "
            "the first equilibrium on the loading path is returned.",
            RuntimeWarning,
            stacklevel=2,
        )

    flat_pressure = pressures.ravel()
    targets = pressure_moment_nmm(design, flat_pressure)
    angles = np.full(flat_pressure.shape, np.nan)
    angles[flat_pressure == 0.0] = 0.0
    reached = np.maximum.accumulate(grid_moment)
    for i in np.flatnonzero(flat_pressure > 0.0):
        target = targets[i]
        k = int(np.searchsorted(reached, target, side="left"))
        if k > _N_GRID:
            continue
        if grid_moment[k] == target:
            angles[i] = grid[k]
            continue
        root = brentq(
            lambda theta, m=target: elastomer_moment(theta) - m,
            grid[k - 1],
            grid[k],
            xtol=1e-14,
            rtol=4 * np.finfo(float).eps,
        )
        angles[i] = root
    failed = np.isnan(angles)
    if failed.any():
        first = float(flat_pressure[np.flatnonzero(failed)[0]])
        message = (
            f"The analytical model does not converge for design {design} at "
            f"{int(failed.sum())} of {flat_pressure.size} pressures (from {first:g} MPa): the "
            f"walls cannot balance the pressure below {max_angle_deg:g} deg. Returned NaN there."
        )
        logger.info(message)
        warnings.warn(message, RuntimeWarning, stacklevel=2)
    return np.degrees(angles).reshape(pressures.shape)


def tip_position_mm(design: Design, angle_deg: ArrayLike) -> tuple[np.ndarray, np.ndarray]:
    """Tip of the actuator bent at constant curvature, in the bending plane.

    Frame: origin at the centre of the fixed base on the strain-limiting layer; ``x``
    along the undeformed actuator axis (towards the tip); ``z`` normal to the
    strain-limiting layer, pointing to the side the actuator bends towards (away
    from the chamber). The strain-limiting layer, of length ``l``, forms a circular
    arc of central angle ``θ``; the distal cap, of length ``lc``, continues it as a
    straight segment tangent to the arc end:

        x = (l/θ) sin θ + lc cos θ,   z = (l/θ)(1 − cos θ) + lc sin θ.

    Parameters
    ----------
    design : Design
        Uses ``l_mm`` and ``lc_mm``.
    angle_deg : array_like
        Bending angle ``θ`` in degrees; negative bends towards ``z < 0``; NaN (an
        angle the analytical model could not find) gives NaN.

    Returns
    -------
    (numpy.ndarray, numpy.ndarray)
        ``x_mm`` and ``z_mm``, the shape of ``angle_deg``. At 0° the tip is at
        ``(l + lc, 0)``; the formulas are evaluated without division by ``θ``.
    """
    theta = np.radians(np.asarray(angle_deg, dtype=float))
    length, cap = design.l_mm, design.lc_mm
    sin_over = np.sinc(theta / math.pi)  # sin θ / θ
    half = 0.5 * theta
    one_minus_cos_over = np.sin(half) * np.sinc(half / math.pi)  # (1 − cos θ) / θ
    x_mm = length * sin_over + cap * np.cos(theta)
    z_mm = length * one_minus_cos_over + cap * np.sin(theta)
    return x_mm, z_mm


@dataclass(frozen=True)
class AnalyticalModel:
    """The quasi-static moment balance of Polygerinos et al. (paper B §4.3).

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

    material: Material | HyperelasticModel | str | None = None
    max_angle_deg: float | None = None
    name: str = field(default="analytical", init=False)

    def __post_init__(self) -> None:
        from softbend.materials.presets import PRESETS

        material = self.material
        if isinstance(material, str):
            with keyed("material"):
                material = PRESETS.get(material)
        model = material.model if isinstance(material, Material) else material
        if material is not None and not isinstance(model, HyperelasticModel):
            raise InputError(
                "must be a hyperelastic model, a Material holding one, or a preset name; "
                f"got {self.material!r}",
                key="material",
            )
        object.__setattr__(self, "material", material)
        if self.max_angle_deg is not None:
            limit = check_range(
                self.max_angle_deg,
                "max_angle_deg",
                low=0.0,
                high=3600.0,
                high_inclusive=True,
            )
            object.__setattr__(self, "max_angle_deg", limit)

    def sweep(self, design: Design, pressures_mpa: ArrayLike) -> SweepResult:
        """Solve the moment balance at every pressure of the grid, in MPa."""
        start = time.perf_counter()
        options = {} if self.max_angle_deg is None else {"max_angle_deg": self.max_angle_deg}
        material = cast("Material | HyperelasticModel | None", self.material)  # no name left
        with warnings.catch_warnings(record=True) as caught:
            warnings.simplefilter("always")
            angle = bending_angle_deg(design, pressures_mpa, material, **options)
        tip_x, tip_z = tip_position_mm(design, angle)
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


def _describe_material(material: Material | HyperelasticModel | str | None) -> str:
    if material is None:
        material = DRAGON_SKIN_30
    if isinstance(material, Material):
        return f"{material.name}: {material.model!r}"
    return repr(material)
