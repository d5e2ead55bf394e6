"""Constant-curvature kinematics of a bending actuator (paper A §3, paper B §3.1).

Frame and assumptions
---------------------
The actuator is a planar arc of constant curvature (piecewise-constant-curvature
model with one segment). Its base is clamped at ``(0, L0)`` with the rest axis
pointing along ``-y``, so the tip of the straight actuator at rest length ``L0``
lies at the origin. The bending grade ``rho = theta / (2 pi)`` is signed:
``rho > 0`` (inflation) curls the tip towards ``+x``, ``rho < 0`` (vacuum) towards
``-x``. Seen in the ``(x, y)`` plane, ``rho > 0`` is a counter-clockwise turn of
the backbone tangent, the same sign convention :func:`fit_arc` uses. All lengths
are in mm, angles in radians inside the math.

With ``theta = 2 pi rho``, the half angle ``alpha = theta / 2`` and
``sinc(rho) = sin(pi rho) / (pi rho)`` the tip of an arc of length ``L`` is
(paper A eq. 12, rewritten without the removable singularity at ``theta = 0``)::

    x      = (L / theta)(1 - cos theta) = L sinc(rho) sin(pi rho)
    L0 - y = (L / theta) sin theta      = L sinc(rho) cos(pi rho)

i.e. the chord from base to tip has length ``s = L sinc(rho)`` and leans by the
half angle ``alpha`` from the rest axis. The inverse (paper A eqs. 16-17, made
signed) follows from the same picture.

:func:`fit_arc` fits such an arc to a measured or simulated backbone polyline and
returns the bending angle ``theta = arc length / radius`` (paper B §3.1).
"""

from __future__ import annotations

import logging
import math
from dataclasses import dataclass

import numpy as np
from scipy.optimize import least_squares

from softbend._validation import check_finite_array, check_range
from softbend.errors import DatasetError

__all__ = [
    "CURLING_REST_LENGTH_MM",
    "ArcFit",
    "bending_from_tip",
    "fit_arc",
    "tip_displacement",
    "tip_position",
]

logger = logging.getLogger(__name__)

#: Rest length of paper A's miniature pneumatic curling rubber actuator, mm.
CURLING_REST_LENGTH_MM = 15.25


def _positive_array(values: np.ndarray, key: str) -> None:
    """Raise :class:`DatasetError` keyed ``key`` unless every element of ``values`` is > 0."""
    bad = ~(values > 0)
    if bad.any():
        first = int(np.flatnonzero(bad.ravel())[0])
        raise DatasetError(
            f"must be in (0, inf); got {float(values.ravel()[first])!r} at position {first} "
            f"({int(bad.sum())} values out of range in all)",
            key=key,
        )


def _broadcast(a: np.ndarray, b: np.ndarray, keys: tuple[str, str]) -> tuple[np.ndarray, ...]:
    """``a`` and ``b`` broadcast together; the error is keyed by the second of ``keys``."""
    try:
        return np.broadcast_arrays(a, b)
    except ValueError:
        raise DatasetError(
            f"must have a shape that broadcasts with '{keys[0]}'; got {b.shape} and {a.shape}",
            key=keys[1],
        ) from None


def _out(values: np.ndarray) -> np.ndarray:
    """Return 0-d results as NumPy scalars, arrays unchanged."""
    return values[()] if values.ndim == 0 else values


def tip_position(
    rho: np.ndarray | float,
    length_mm: np.ndarray | float,
    rest_length_mm: float = CURLING_REST_LENGTH_MM,
) -> tuple[np.ndarray, np.ndarray]:
    """Tip position of a constant-curvature arc (paper A eq. 12, signed).

    Parameters
    ----------
    rho : array_like
        Signed bending grade ``theta / (2 pi)``, dimensionless; negative values
        curl the actuator towards ``-x`` (vacuum). Any finite value is accepted,
        but only ``|rho| < 1`` (less than one full turn) is invertible by
        :func:`bending_from_tip`.
    length_mm : array_like
        Current arc length ``L`` of the backbone, mm; must be > 0. Broadcast
        against ``rho``.
    rest_length_mm : float, optional
        Rest length ``L0``, mm; the base is clamped at ``(0, L0)``. Defaults to
        :data:`CURLING_REST_LENGTH_MM`.

    Returns
    -------
    x_mm, y_mm : ndarray
        Tip coordinates, mm, with ``x = (L / theta)(1 - cos theta)`` and
        ``y = L0 - (L / theta) sin theta``. Evaluated as
        ``x = L sinc(rho) sin(pi rho)`` and ``y = L0 - L sinc(rho) cos(pi rho)``,
        which are exact and finite at ``theta = 0`` (``x = 0``, ``y = L0 - L``).
        0-d inputs give NumPy scalars.

    Raises
    ------
    DatasetError
        If ``rho`` or ``length_mm`` holds NaN/inf, ``length_mm`` is not positive,
        or the shapes do not broadcast.
    ValueError
        If ``rest_length_mm`` is not a finite number > 0.
    """
    rest = check_range(rest_length_mm, "rest_length_mm", low=0.0)
    rho_arr = check_finite_array(rho, "rho")
    length = check_finite_array(length_mm, "length_mm")
    _positive_array(length, "length_mm")
    rho_arr, length = _broadcast(rho_arr, length, ("rho", "length_mm"))

    chord = length * np.sinc(rho_arr)  # s = L sin(alpha) / alpha, signed beyond |rho| = 1
    half = np.pi * rho_arr
    x = chord * np.sin(half)
    y = rest - chord * np.cos(half)
    return _out(x), _out(y)


def bending_from_tip(
    x_mm: np.ndarray | float,
    y_mm: np.ndarray | float,
    rest_length_mm: float = CURLING_REST_LENGTH_MM,
) -> tuple[np.ndarray, np.ndarray]:
    """Bending grade and arc length from a measured tip position (paper A eqs. 16-17).

    The chord from the base ``(0, L0)`` to the tip has components ``x`` and
    ``u = L0 - y`` and length ``s = sqrt(x**2 + u**2)``. For a constant-curvature
    arc it leans from the rest axis by half the central angle,
    ``alpha = |theta| / 2 = arctan2(|x|, u)`` in ``[0, pi]`` (the paper's
    ``arccos(u / s)``, but accurate for every ``alpha``), and ``s = L sin(alpha) /
    alpha``. Hence::

        rho = sign(x) * alpha / pi
        L   = s * alpha / sin(alpha)       (= s**2 * alpha / |x|, paper A eq. 17)

    ``alpha / sin(alpha)`` is evaluated as ``1 / sinc(alpha / pi)`` for
    ``alpha < pi / 2`` (no division by ``x``, exact limit ``L = u`` at ``x = 0``)
    and as ``alpha * s / |x|`` above, where ``sin(alpha) = |x| / s`` is exact.

    Parameters
    ----------
    x_mm, y_mm : array_like
        Tip coordinates in the frame of :func:`tip_position`, mm; broadcast
        against each other.
    rest_length_mm : float, optional
        Rest length ``L0``, mm. Defaults to :data:`CURLING_REST_LENGTH_MM`.

    Returns
    -------
    rho : ndarray
        Signed bending grade in ``(-1, 1)``, dimensionless; ``0`` where ``x = 0``.
    length_mm : ndarray
        Arc length ``L`` > 0, mm; ``L0 - y`` where ``x = 0``.

    Raises
    ------
    DatasetError
        If an input holds NaN/inf, the shapes do not broadcast, or a tip is not
        reachable by an arc of positive length with ``|rho| < 1`` (``x = 0`` and
        ``y >= L0``: the tip on or above the base on the rest axis).
    ValueError
        If ``rest_length_mm`` is not a finite number > 0.
    """
    rest = check_range(rest_length_mm, "rest_length_mm", low=0.0)
    x = check_finite_array(x_mm, "x_mm")
    y = check_finite_array(y_mm, "y_mm")
    y, x = _broadcast(y, x, ("y_mm", "x_mm"))

    u = rest - y
    unreachable = (x == 0) & ~(u > 0)
    if unreachable.any():
        first = int(np.flatnonzero(unreachable.ravel())[0])
        raise DatasetError(
            f"must be < rest_length_mm ({rest:g}) where x_mm == 0, since a tip on the rest "
            f"axis lies below the base; got {float(y.ravel()[first])!r} at position {first}",
            key="y_mm",
        )

    abs_x = np.abs(x)
    chord = np.hypot(x, u)
    alpha = np.arctan2(abs_x, u)
    small = alpha < 0.5 * np.pi
    with np.errstate(divide="ignore", invalid="ignore"):
        ratio = np.where(
            small,
            1.0 / np.sinc(np.where(small, alpha, 0.0) / np.pi),
            alpha * chord / np.where(small, 1.0, abs_x),
        )
    length = chord * ratio
    if not np.all(np.isfinite(length)):
        first = int(np.flatnonzero(~np.isfinite(length).ravel())[0])
        raise DatasetError(
            "must not be vanishingly small on the far side of the base (the arc length "
            f"diverges); got {float(x.ravel()[first])!r} at position {first}",
            key="x_mm",
        )
    rho_out = np.sign(x) * alpha / np.pi
    return _out(rho_out), _out(length)


def tip_displacement(
    rho: np.ndarray | float,
    length_mm: np.ndarray | float,
    rest_length_mm: float = CURLING_REST_LENGTH_MM,
) -> np.ndarray:
    """Distance of the tip from its rest position, ``d = sqrt(x**2 + y**2)``, mm.

    Paper A eq. 13 is garbled; this is its stated definition, with ``(x, y)``
    from :func:`tip_position` (the origin is the tip of the straight actuator at
    rest length). Arguments and errors as for :func:`tip_position`.

    Returns
    -------
    ndarray
        Tip displacement, mm; ``|L0 - L|`` when ``rho = 0``, ``L0`` when the tip
        returns to the base (``|rho| = 1``). Even in ``rho``.
    """
    x, y = tip_position(rho, length_mm, rest_length_mm)
    return _out(np.asarray(np.hypot(x, y)))


@dataclass(frozen=True)
class ArcFit:
    """Least-squares constant-curvature arc fitted to a backbone polyline.

    Attributes
    ----------
    angle_deg : float
        Signed bending angle ``theta = arc_length / radius``, degrees; positive
        when the backbone turns counter-clockwise walking from base to tip
        (centre of curvature on the left). ``0`` for a straight backbone.
    radius_mm : float
        Radius of curvature, mm (> 0); ``inf`` for a straight backbone.
    arc_length_mm : float
        Length along the fitted circle (or line) between the projections of the
        first and the last point, mm.
    rms_residual_mm : float
        Root-mean-square geometric distance of the points to the fitted curve, mm.
    center_mm : tuple of float or None
        Centre of curvature ``(x, y)``, mm; ``None`` for a straight backbone.
    """

    angle_deg: float
    radius_mm: float
    arc_length_mm: float
    rms_residual_mm: float
    center_mm: tuple[float, float] | None

    @property
    def curvature_per_mm(self) -> float:
        """Signed curvature ``theta / arc_length``, 1/mm (0 when straight)."""
        if self.center_mm is None:
            return 0.0
        return math.copysign(1.0 / self.radius_mm, self.angle_deg)


# Circle or line as A (x^2 + y^2) + B x + C y + D = 0 with B^2 + C^2 - 4 A D = 1
# (Pratt's normalisation): curvature 2|A|, and A = 0 is a straight line, so one
# parametrisation covers both. ``_PRATT`` is the matrix of that quadratic form.
_PRATT = np.array(
    [[0.0, 0.0, 0.0, -2.0], [0.0, 1.0, 0.0, 0.0], [0.0, 0.0, 1.0, 0.0], [-2.0, 0.0, 0.0, 0.0]]
)
_PRATT_INV = np.linalg.inv(_PRATT)


def _as_polyline(points_mm: object) -> np.ndarray:
    points = check_finite_array(points_mm, "points_mm")
    if points.ndim != 2 or points.shape[1] != 2 or points.shape[0] < 3:
        raise DatasetError(
            "must be an array of shape (n, 2) with n >= 3, ordered from base to tip; "
            f"got shape {points.shape}",
            key="points_mm",
        )
    distinct = np.unique(points, axis=0).shape[0]
    if distinct < 3:
        raise DatasetError(
            "must contain at least 3 distinct points; "
            f"got {distinct} distinct of {points.shape[0]}",
            key="points_mm",
        )
    return points


def _pratt_fit(q: np.ndarray) -> np.ndarray:
    """Pratt's algebraic circle fit, SVD form (Chernov 2010); returns normalised (A, B, C, D)."""
    z = np.einsum("ij,ij->i", q, q)
    design = np.column_stack([z, q[:, 0], q[:, 1], np.ones(len(q))])
    _, sv, vt = np.linalg.svd(design, full_matrices=False)
    if len(q) == 3 or sv[-1] <= 1e-12 * sv[0]:
        coef = vt[-1]  # exact fit (noiseless data, three points or collinear points)
    else:
        root = vt.T @ np.diag(sv) @ vt  # (Z^T Z)^(1/2)
        _, vectors = np.linalg.eigh(root @ _PRATT_INV @ root)
        # One negative eigenvalue, then the smallest positive one is Pratt's solution.
        coef = vt.T @ np.diag(1.0 / sv) @ vt @ vectors[:, 1]
    norm = float(coef @ _PRATT @ coef)
    if not norm > 0:
        raise DatasetError("must not be degenerate: no circle or line fits them", key="points_mm")
    return coef / math.sqrt(norm)


def _geometric_residuals(coef: np.ndarray, q: np.ndarray) -> np.ndarray:
    """Signed distances of ``q`` to the circle/line ``coef`` (exact, smooth through A = 0)."""
    a, b, c, d = coef
    p = a * np.einsum("ij,ij->i", q, q) + b * q[:, 0] + c * q[:, 1] + d
    return 2.0 * p / (1.0 + np.sqrt(np.maximum(1.0 + 4.0 * a * p, 0.0)))


def _coefficients(params: np.ndarray) -> np.ndarray:
    a, d, phi = params
    scale = math.sqrt(max(1.0 + 4.0 * a * d, 0.0))
    return np.array([a, scale * math.cos(phi), scale * math.sin(phi), d])


def _residual_jacobian(params: np.ndarray, q: np.ndarray) -> np.ndarray:
    """Derivatives of :func:`_geometric_residuals` by ``(A, D, phi)``, shape (n, 3).

    With ``P = A|q|² + B x + C y + D``, ``w = √(1 + 4AP)`` and the residual
    ``r = 2P / (1 + w)``: ``∂r/∂P = 1/w`` and ``∂r/∂A = −4P² / (w (1 + w)²)``
    at fixed ``P``; ``B, C = s (cos phi, sin phi)`` with ``s = √(1 + 4AD)``.
    """
    a, d, phi = params
    s = math.sqrt(max(1.0 + 4.0 * a * d, 1e-300))
    cos, sin = math.cos(phi), math.sin(phi)
    x, y = q[:, 0], q[:, 1]
    along = x * cos + y * sin
    squared = np.einsum("ij,ij->i", q, q)
    p = a * squared + s * along + d
    w = np.sqrt(np.maximum(1.0 + 4.0 * a * p, 1e-300))
    dr_dp = 1.0 / w
    dp_da = squared + along * (2.0 * d / s)
    dr_da = dr_dp * dp_da - 4.0 * p * p / (w * (1.0 + w) ** 2)
    dr_dd = dr_dp * (1.0 + along * (2.0 * a / s))
    dr_dphi = dr_dp * s * (y * cos - x * sin)
    return np.column_stack([dr_da, dr_dd, dr_dphi])


def _refine(q: np.ndarray, coef: np.ndarray) -> np.ndarray:
    """Minimise the geometric residuals over (A, D, phi), with B, C on the Pratt constraint."""
    a, b, c, d = coef
    start = np.array([a, d, math.atan2(c, b)])
    initial_cost = float(np.sum(_geometric_residuals(coef, q) ** 2))
    result = least_squares(
        lambda p: _geometric_residuals(_coefficients(p), q),
        start,
        jac=lambda p: _residual_jacobian(p, q),
        xtol=1e-15,
        ftol=1e-15,
        gtol=1e-15,
        max_nfev=200,
    )
    refined = _coefficients(result.x)
    cost = float(np.sum(_geometric_residuals(refined, q) ** 2))
    if not np.all(np.isfinite(refined)) or cost > initial_cost:
        logger.debug("arc refinement did not improve the algebraic fit (%s)", result.message)
        return coef
    return refined


def fit_arc(points_mm: np.ndarray, *, straight_tolerance_rad: float = 1e-9) -> ArcFit:
    """Fit a constant-curvature arc to a backbone polyline (paper B §3.1).

    Pratt's algebraic fit (Chernov, *Circular and Linear Regression*, 2010),
    which treats circles and straight lines alike, is refined by
    :func:`scipy.optimize.least_squares` on the exact geometric distances. The
    fit runs in coordinates centred on the middle point and scaled by the
    polyline length, so it is well conditioned from nearly straight to nearly
    closed arcs. The bending angle is ``theta = arc_length / radius``, signed by
    the direction of travel.

    Parameters
    ----------
    points_mm : array_like, shape (n, 2)
        Backbone points, mm, ordered from the base (first row) to the tip; at
        least 3 distinct points. Consecutive points must be less than 180° apart
        along the fitted circle (any usual sampling): the polar angle about the
        centre is unwrapped point by point, so arcs beyond 180° and up to (and
        past) 360° are measured correctly.
    straight_tolerance_rad : float, optional
        If the fitted curvature times the polyline length (the total turning,
        radians) is below this, the backbone is treated as straight.

    Returns
    -------
    ArcFit
        Angle (degrees, positive counter-clockwise from base to tip), radius,
        arc length between the projections of the first and last points, RMS
        residual and centre. A straight backbone gives ``angle_deg = 0``,
        ``radius_mm = inf``, ``center_mm = None`` and the length of its
        projection on the fitted line (the chord for collinear points).

    Raises
    ------
    DatasetError
        If ``points_mm`` is not an ``(n, 2)`` array with ``n >= 3``, holds NaN or
        inf, or has fewer than 3 distinct points.
    ValueError
        If ``straight_tolerance_rad`` is not a number in ``[0, 1)``.
    """
    tolerance = check_range(
        straight_tolerance_rad,
        "straight_tolerance_rad",
        low=0.0,
        high=1.0,
        low_inclusive=True,
    )
    points = _as_polyline(points_mm)
    steps = np.diff(points, axis=0)
    polyline_length = float(np.hypot(steps[:, 0], steps[:, 1]).sum())
    origin = points[len(points) // 2]
    q = (points - origin) / polyline_length

    coef = _refine(q, _pratt_fit(q))
    a, b, c, _ = coef
    residuals = _geometric_residuals(coef, q) * polyline_length
    rms = float(np.sqrt(np.mean(residuals**2)))

    if 2.0 * abs(a) < tolerance:
        direction = np.array([c, -b]) / math.hypot(b, c)
        length = abs(float((points[-1] - points[0]) @ direction))
        return ArcFit(0.0, math.inf, length, rms, None)

    center = origin + polyline_length * np.array([-b, -c]) / (2.0 * a)
    radius = polyline_length / (2.0 * abs(a))
    polar = np.arctan2(points[:, 1] - center[1], points[:, 0] - center[0])
    turns = np.diff(polar)
    turns = (turns + np.pi) % (2.0 * np.pi) - np.pi
    theta = float(turns.sum())
    return ArcFit(
        angle_deg=math.degrees(theta),
        radius_mm=radius,
        arc_length_mm=radius * abs(theta),
        rms_residual_mm=rms,
        center_mm=(float(center[0]), float(center[1])),
    )
