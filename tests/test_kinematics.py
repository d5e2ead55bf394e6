import math
import warnings

import numpy as np
import pytest

from softbend.errors import DatasetError
from softbend.kinematics import (
    CURLING_REST_LENGTH_MM,
    ArcFit,
    bending_from_tip,
    fit_arc,
    tip_displacement,
    tip_position,
)

L0 = CURLING_REST_LENGTH_MM


def _arc_points(angle_deg, radius_mm, n=40, center=(3.0, -2.0), start_rad=0.7, noise=0.0, seed=0):
    """Points on a circle from base to tip, turning counter-clockwise for positive angles."""
    t = np.linspace(0.0, 1.0, n)
    polar = start_rad + math.radians(angle_deg) * t
    points = np.asarray(center) + radius_mm * np.column_stack([np.cos(polar), np.sin(polar)])
    if noise:
        points = points + np.random.default_rng(seed).normal(0.0, noise, points.shape)
    return points


# --------------------------------------------------------------------------- tip_position


def test_rest_length_matches_paper_a():
    assert CURLING_REST_LENGTH_MM == 15.25


def test_round_trip_is_exact_over_signed_bending_and_lengths():
    rng = np.random.default_rng(20240611)
    rho = rng.uniform(-0.99, 0.99, 10_000)
    length = rng.uniform(0.3 * L0, 2.0 * L0, 10_000)
    x, y = tip_position(rho, length)
    rho_back, length_back = bending_from_tip(x, y)
    np.testing.assert_allclose(rho_back, rho, rtol=0, atol=1e-9)
    np.testing.assert_allclose(length_back, length, rtol=0, atol=1e-9)


def test_round_trip_holds_close_to_a_full_turn_and_for_other_rest_lengths():
    rho = np.array([-0.999, -0.75, 0.5 + 1e-13, 0.75, 0.999])
    length = np.array([40.0, 3.0, 120.0, 0.5, 300.0])
    x, y = tip_position(rho, length, rest_length_mm=120.0)
    rho_back, length_back = bending_from_tip(x, y, rest_length_mm=120.0)
    np.testing.assert_allclose(rho_back, rho, rtol=0, atol=1e-12)
    np.testing.assert_allclose(length_back, length, rtol=1e-12)


@pytest.mark.parametrize("rho", [0.0, 1e-12, -1e-9])
def test_straight_limit_has_no_nan_and_matches_the_series(rho):
    length = 13.0
    with warnings.catch_warnings():
        warnings.simplefilter("error")
        x, y = tip_position(rho, length)
        rho_back, length_back = bending_from_tip(x, y)
    assert np.isfinite([x, y, rho_back, length_back]).all()
    # First order in theta: x = L theta / 2 = L pi rho, L0 - y = L (1 - theta^2 / 6).
    assert x == pytest.approx(length * math.pi * rho, rel=1e-12, abs=1e-300)
    assert y == pytest.approx(L0 - length, rel=1e-12)
    assert np.sign(x) == np.sign(rho)
    assert rho_back == pytest.approx(rho, rel=1e-9, abs=1e-300)
    assert length_back == pytest.approx(length, rel=1e-12)


def test_half_and_quarter_circle_closed_forms():
    # rho = 1/2: half circle of radius R = L / pi, tip level with the base, x = 2R.
    x, y = tip_position(0.5, 10.0)
    assert x == pytest.approx(2.0 * 10.0 / math.pi, rel=1e-14)
    assert y == pytest.approx(L0, abs=1e-13)
    # rho = 1/4: quarter circle of radius R = 2L / pi, x = R, y = L0 - R.
    x, y = tip_position(0.25, 10.0)
    radius = 2.0 * 10.0 / math.pi
    assert x == pytest.approx(radius, rel=1e-14)
    assert y == pytest.approx(L0 - radius, rel=1e-14)
    # rho = 1: full circle, the tip is back at the base.
    x, y = tip_position(1.0, 10.0)
    assert x == pytest.approx(0.0, abs=1e-14)
    assert y == pytest.approx(L0, abs=1e-14)


def test_negative_bending_mirrors_x_and_keeps_y():
    rho = np.linspace(0.0, 0.99, 101)
    length = np.linspace(5.0, 25.0, 101)
    x_pos, y_pos = tip_position(rho, length)
    x_neg, y_neg = tip_position(-rho, length)
    np.testing.assert_allclose(x_neg, -x_pos, rtol=0, atol=1e-15)
    np.testing.assert_allclose(y_neg, y_pos, rtol=0, atol=1e-15)
    assert (x_neg[1:] < 0).all() and (x_pos[1:] > 0).all()


def test_tip_lies_on_the_circle_through_the_base_with_the_right_radius():
    rho = np.array([0.1, 0.3, -0.6, 0.9])
    length = np.array([10.0, 15.0, 20.0, 8.0])
    x, y = tip_position(rho, length)
    radius = length / (2.0 * np.pi * rho)  # signed; centre at (R, L0) on the base normal
    np.testing.assert_allclose(np.hypot(x - radius, y - L0), np.abs(radius), rtol=1e-13)


def test_scalars_give_scalars_and_arrays_broadcast():
    x, y = tip_position(0.2, 12.0)
    assert np.ndim(x) == 0 and np.ndim(y) == 0
    assert isinstance(float(x), float)
    rho, length = bending_from_tip(1.0, 2.0)
    assert np.ndim(rho) == 0 and np.ndim(length) == 0
    x, y = tip_position(np.array([[0.1], [0.2], [0.3]]), np.array([10.0, 12.0, 14.0, 16.0]))
    assert x.shape == y.shape == (3, 4)
    assert tip_displacement([0.1, 0.2], 12.0).shape == (2,)


# ------------------------------------------------------------------------ bending_from_tip


def test_inverse_on_the_rest_axis_gives_straight_arc():
    y = np.array([-5.0, 0.0, 3.0, L0 - 1e-9])
    rho, length = bending_from_tip(np.zeros_like(y), y)
    np.testing.assert_array_equal(rho, 0.0)
    np.testing.assert_allclose(length, L0 - y, rtol=1e-15)


def test_inverse_matches_paper_formulas_away_from_the_axis():
    x = np.array([0.5, 3.0, -4.0, 8.0])
    y = np.array([1.0, 6.0, 10.0, 18.0])
    u = L0 - y
    s2 = x**2 + u**2
    rho_paper = np.arccos(u / np.sqrt(s2)) / np.pi
    length_paper = s2 * np.arccos(u / np.sqrt(s2)) / np.abs(x)
    rho, length = bending_from_tip(x, y)
    np.testing.assert_allclose(rho, np.sign(x) * rho_paper, rtol=1e-12)
    np.testing.assert_allclose(length, length_paper, rtol=1e-12)


def test_tip_above_the_base_bends_more_than_half_a_turn():
    rho, length = bending_from_tip(np.array([2.0, -2.0]), np.array([L0 + 1.0, L0 + 1.0]))
    assert (np.abs(rho) > 0.5).all() and (np.abs(rho) < 1.0).all()
    assert rho[0] == -rho[1] and length[0] == length[1]


@pytest.mark.parametrize(
    ("args", "field"),
    [
        ((np.nan, 1.0), "x_mm"),
        ((1.0, np.inf), "y_mm"),
        ((0.0, L0), "y_mm"),
        ((0.0, L0 + 2.0), "y_mm"),
        ((np.zeros(3), np.zeros(2)), "x_mm"),
    ],
)
def test_inverse_rejects_bad_tips(args, field):
    with pytest.raises(DatasetError, match=rf"^{field}: must") as info:
        bending_from_tip(*args)
    assert info.value.key == field


@pytest.mark.parametrize("rest", [0.0, -1.0, np.nan, np.inf, "abc"])
def test_rest_length_must_be_a_positive_number(rest):
    with pytest.raises(ValueError, match=r"^rest_length_mm: must be a number in \(0, inf\)"):
        bending_from_tip(1.0, 1.0, rest_length_mm=rest)
    with pytest.raises(ValueError, match=r"^rest_length_mm: must be a number in \(0, inf\)"):
        tip_position(0.1, 1.0, rest_length_mm=rest)


@pytest.mark.parametrize(
    ("rho", "length", "field"),
    [
        (np.nan, 1.0, "rho"),
        ([0.1, np.inf], 1.0, "rho"),
        (0.1, np.nan, "length_mm"),
        (0.1, 0.0, "length_mm"),
        (0.1, [1.0, -2.0], "length_mm"),
    ],
)
def test_forward_rejects_bad_inputs(rho, length, field):
    with pytest.raises(DatasetError, match=rf"^{field}: must") as info:
        tip_position(rho, length)
    assert info.value.key == field
    assert "; got" in str(info.value)


# ------------------------------------------------------------------------ tip_displacement


def test_displacement_is_the_distance_from_the_rest_tip():
    rng = np.random.default_rng(3)
    rho = rng.uniform(-0.99, 0.99, 200)
    length = rng.uniform(5.0, 30.0, 200)
    x, y = tip_position(rho, length)
    d = tip_displacement(rho, length)
    np.testing.assert_allclose(d, np.hypot(x, y), rtol=1e-15)
    np.testing.assert_allclose(d, tip_displacement(-rho, length), rtol=1e-14)
    # Straight: pure elongation/contraction; full turn: tip back at the base.
    assert tip_displacement(0.0, 18.25) == pytest.approx(3.0, rel=1e-14)
    assert tip_displacement(0.0, 9.25) == pytest.approx(6.0, rel=1e-14)
    assert tip_displacement(1.0, 9.25) == pytest.approx(L0, rel=1e-14)


# --------------------------------------------------------------------------------- fit_arc


@pytest.mark.parametrize("angle_deg", [10.0, 90.0, 270.0, -120.0, 355.0])
def test_fit_recovers_noiseless_arcs(angle_deg):
    radius = 7.3
    fit = fit_arc(_arc_points(angle_deg, radius))
    assert isinstance(fit, ArcFit)
    assert fit.angle_deg == pytest.approx(angle_deg, abs=1e-6)
    assert fit.radius_mm == pytest.approx(radius, rel=1e-6)
    assert fit.arc_length_mm == pytest.approx(radius * math.radians(abs(angle_deg)), rel=1e-6)
    assert fit.center_mm == pytest.approx((3.0, -2.0), abs=1e-6)
    assert fit.rms_residual_mm < 1e-9
    assert fit.curvature_per_mm == pytest.approx(math.copysign(1 / radius, angle_deg), rel=1e-6)


@pytest.mark.parametrize("angle_deg", [10.0, 90.0, 270.0, -120.0])
def test_fit_recovers_noisy_arcs_within_one_percent(angle_deg):
    # Actuator-sized backbones (120 mm) sampled at 100 points, camera noise 0.01 mm.
    radius = 120.0 / math.radians(abs(angle_deg))
    fit = fit_arc(_arc_points(angle_deg, radius, n=100, noise=0.01, seed=7))
    assert fit.angle_deg == pytest.approx(angle_deg, rel=0.01)
    assert fit.radius_mm == pytest.approx(radius, rel=0.01)
    assert fit.arc_length_mm == pytest.approx(120.0, rel=0.01)
    assert 0.005 < fit.rms_residual_mm < 0.015


def test_fit_sign_follows_the_kinematic_convention():
    # The backbone of tip_position: points at arc length s have rho_s = rho * s / L.
    for rho in (0.3, -0.45, 0.8):
        length = 14.0
        s = np.linspace(0.0, length, 60)[1:]
        x, y = tip_position(rho * s / length, s)
        points = np.vstack([[0.0, L0], np.column_stack([x, y])])
        fit = fit_arc(points)
        assert fit.angle_deg == pytest.approx(360.0 * rho, rel=1e-9)
        assert fit.arc_length_mm == pytest.approx(length, rel=1e-9)
        assert fit.radius_mm == pytest.approx(length / (2 * math.pi * abs(rho)), rel=1e-9)


def test_fit_is_invariant_to_rigid_motion_and_reverses_sign_with_direction():
    points = _arc_points(200.0, 4.0, n=30)
    rot = np.array([[math.cos(1.1), -math.sin(1.1)], [math.sin(1.1), math.cos(1.1)]])
    moved = points @ rot.T + np.array([100.0, -50.0])
    assert fit_arc(moved).angle_deg == pytest.approx(200.0, abs=1e-8)
    assert fit_arc(points[::-1]).angle_deg == pytest.approx(-200.0, abs=1e-8)
    mirrored = points * np.array([-1.0, 1.0])
    assert fit_arc(mirrored).angle_deg == pytest.approx(-200.0, abs=1e-8)


@pytest.mark.parametrize(
    "points",
    [
        np.column_stack([np.linspace(0, 1, 7) * math.pi, np.linspace(0, 1, 7) * math.e]),
        np.column_stack([np.zeros(5), np.linspace(10.0, -40.0, 5)]),
        np.column_stack([np.linspace(0, 120, 50), 0.3 * np.linspace(0, 120, 50) + 1e-3]),
    ],
)
def test_straight_backbone_gives_zero_angle_without_nan_or_warning(points):
    with warnings.catch_warnings():
        warnings.simplefilter("error")
        fit = fit_arc(points)
    assert fit.angle_deg == 0.0
    assert fit.radius_mm == math.inf
    assert fit.center_mm is None
    assert fit.curvature_per_mm == 0.0
    assert fit.arc_length_mm == pytest.approx(np.hypot(*(points[-1] - points[0])), rel=1e-12)
    assert fit.rms_residual_mm < 1e-12


def test_noisy_nearly_straight_backbone_gives_a_small_angle():
    points = _arc_points(0.5, 120.0 / math.radians(0.5), n=100, noise=0.01, seed=1)
    fit = fit_arc(points)
    assert abs(fit.angle_deg - 0.5) < 0.1
    assert np.isfinite(fit.radius_mm)


def test_three_points_define_the_circle():
    fit = fit_arc(np.array([[1.0, 0.0], [0.0, 1.0], [-1.0, 0.0]]))
    assert fit.angle_deg == pytest.approx(180.0, abs=1e-10)
    assert fit.radius_mm == pytest.approx(1.0, rel=1e-12)


@pytest.mark.parametrize(
    ("points", "message"),
    [
        (np.zeros((5, 3)), r"^points_mm: must be an array of shape \(n, 2\)"),
        (np.zeros(6), r"^points_mm: .*got shape \(6,\)"),
        (np.array([[0.0, 0.0], [1.0, 1.0]]), r"^points_mm: .*n >= 3"),
        ([[0.0, 0.0], [1.0, np.nan], [2.0, 1.0]], "^points_mm: must be finite"),
        (np.ones((6, 2)), "^points_mm: must contain at least 3 distinct points"),
        (np.array([[0.0, 0.0], [1.0, 1.0]] * 3), "at least 3 distinct points; got 2"),
    ],
)
def test_fit_rejects_bad_polylines(points, message):
    with pytest.raises(DatasetError, match=message):
        fit_arc(points)


@pytest.mark.parametrize("tolerance", [-1.0, 1.0, np.nan])
def test_fit_rejects_bad_straight_tolerance(tolerance):
    with pytest.raises(ValueError, match=r"^straight_tolerance_rad: must be a number in \[0, 1\)"):
        fit_arc(_arc_points(30.0, 5.0), straight_tolerance_rad=tolerance)


def test_arc_fit_is_frozen():
    fit = fit_arc(_arc_points(30.0, 5.0))
    with pytest.raises(AttributeError):
        fit.angle_deg = 1.0  # type: ignore[misc]


def test_the_arc_refinement_jacobian_matches_central_differences():
    from softbend.kinematics import (
        _coefficients,
        _geometric_residuals,
        _pratt_fit,
        _residual_jacobian,
    )

    rng = np.random.default_rng(3)
    for angle_deg in (1.0, 90.0, 250.0, 350.0):
        theta = np.radians(np.linspace(0.0, angle_deg, 41))
        radius = 1.0 / np.radians(angle_deg)  # unit arc length, as fit_arc scales
        q = np.column_stack([radius * np.sin(theta), radius * (1 - np.cos(theta))])
        q = q - q[20] + 1e-3 * rng.normal(size=q.shape)
        a, b, c, d = _pratt_fit(q)
        # Near the fit, where the refinement works, and a little off it.
        params = np.array([a, d, np.arctan2(c, b)]) + 1e-2 * rng.normal(size=3)
        numeric = np.empty((41, 3))
        for k in range(3):
            step = np.zeros(3)
            step[k] = 1e-6
            plus = _geometric_residuals(_coefficients(params + step), q)
            minus = _geometric_residuals(_coefficients(params - step), q)
            numeric[:, k] = (plus - minus) / 2e-6
        np.testing.assert_allclose(_residual_jacobian(params, q), numeric, atol=1e-7)
