import math
import warnings

import numpy as np
import pytest
from scipy.integrate import dblquad

from softbend.analytical import (
    AnalyticalModel,
    bending_angle_deg,
    elastomer_moment_nmm,
    nominal_axial_stress_mpa,
    pressure_moment_nmm,
    section_quadrature,
    tip_position_mm,
)
from softbend.design import DesignSpace, sfrba_design
from softbend.errors import DatasetError
from softbend.materials import DRAGON_SKIN_30, KEVLAR_FIBER, NeoHookean, Yeoh

BASE = sfrba_design(100, 6, 2, 2, 5, 8)
PRESSURES = np.linspace(0.0, 0.17, 18)


def _second_moment_mm4(design):
    """∫ y² dA of the bottom wall and the half annulus about the bottom layer, by hand."""
    r, t, b = design.r_mm, design.t_mm, design.b_mm
    R = r + t
    rectangle = 2 * R * b**3 / 3
    # y = b + ρ sin α over r < ρ < R, 0 < α < π, dA = ρ dρ dα.
    annulus = (
        b**2 * math.pi * (R**2 - r**2) / 2
        + 2 * b * 2 * (R**3 - r**3) / 3
        + math.pi * (R**4 - r**4) / 8
    )
    return rectangle + annulus


def _elastomer_moment_dblquad(design, theta, model):
    """Reference M_e by adaptive cubature in Cartesian coordinates (x, y)."""
    r, t, b, length = design.r_mm, design.t_mm, design.b_mm, design.l_mm
    R = r + t

    def integrand(x, y):
        return float(nominal_axial_stress_mpa(model, 1 + theta * y / length)) * y

    opts = {"epsabs": 1e-12, "epsrel": 1e-12}
    rect, _ = dblquad(integrand, 0, b, -R, R, **opts)

    def half_disc(radius):
        # Integrate over 0 < x < sqrt(ρ² − (y − b)²), doubled by symmetry.
        value, _ = dblquad(
            integrand,
            b,
            b + radius,
            0,
            lambda y: math.sqrt(max(radius**2 - (y - b) ** 2, 0.0)),
            **opts,
        )
        return 2 * value

    return rect + half_disc(R) - half_disc(r)


def test_zero_pressure_gives_exactly_zero():
    angles = bending_angle_deg(BASE, [0.0, 0.0])
    assert np.array_equal(angles, [0.0, 0.0])
    assert bending_angle_deg(BASE, 0.0) == 0.0


def test_angle_increases_with_pressure_and_solves_the_moment_balance():
    angles = bending_angle_deg(BASE, PRESSURES)
    assert angles.shape == PRESSURES.shape
    assert np.all(np.diff(angles) > 0)
    theta = np.radians(angles)
    np.testing.assert_allclose(
        elastomer_moment_nmm(BASE, theta), pressure_moment_nmm(BASE, PRESSURES), rtol=1e-10
    )


@pytest.mark.parametrize(
    ("field", "values", "sign"),
    [("t_mm", (2, 3, 4), -1), ("b_mm", (2, 3, 4), -1), ("l_mm", (100, 120, 140, 160), +1)],
)
def test_angle_trends_with_the_geometry(field, values, sign):
    pressures = [0.02, 0.1, 0.17]
    rows = []
    for value in values:
        params = BASE.as_dict() | {field: value}
        rows.append(bending_angle_deg(sfrba_design(**params), pressures))
    differences = np.diff(np.array(rows), axis=0)
    assert np.all(sign * differences > 0)


def test_angle_scales_linearly_with_length():
    # λ depends on θ/l only, so θ/l is a function of P alone: θ ∝ l.
    short = bending_angle_deg(sfrba_design(100, 8, 3, 2, 5, 8), [0.05, 0.15])
    long = bending_angle_deg(sfrba_design(160, 8, 3, 2, 5, 8), [0.05, 0.15])
    np.testing.assert_allclose(long / short, 1.6, rtol=1e-9)


def test_fiber_angle_and_cap_do_not_change_the_angle():
    reference = bending_angle_deg(BASE, PRESSURES)
    for other in (sfrba_design(100, 6, 2, 2, 15, 8), sfrba_design(100, 6, 2, 2, 5, 12)):
        np.testing.assert_array_equal(bending_angle_deg(other, PRESSURES), reference)


@pytest.mark.parametrize("design", [BASE, sfrba_design(140, 10, 4, 3, 10, 12)], ids=str)
def test_small_angle_linearization_closed_form(design):
    # σ = 2(λ² − λ⁻²)C10 and s = σ/λ give ds/dλ = 8 C10 at λ = 1, so
    # M_e ≈ 8 C10 (θ/l) ∫ y² dA and θ ≈ M_p l / (8 C10 I).
    c10 = 0.11
    model = NeoHookean(c10_mpa=c10)
    inertia = _second_moment_mm4(design)
    assert section_quadrature(design).second_moment_mm4 == pytest.approx(inertia, rel=1e-12)
    R = design.r_mm + design.t_mm
    area = 2 * R * design.b_mm + math.pi * (R**2 - design.r_mm**2) / 2
    assert section_quadrature(design).area_mm2 == pytest.approx(area, rel=1e-12)

    for pressure, tolerance in ((1e-3, 1e-2), (1e-6, 1e-5)):
        moment = pressure * (
            (2 / 3) * design.r_mm**3 + (math.pi / 2) * design.r_mm**2 * design.b_mm
        )
        expected = math.degrees(moment * design.l_mm / (8 * c10 * inertia))
        got = bending_angle_deg(design, [pressure], model)[0]
        assert got == pytest.approx(expected, rel=tolerance)
    # At finite angles the neo-Hookean wall softens (s < 8 C10 ε): θ exceeds the linear value.
    pressure = 0.1
    moment = pressure_moment_nmm(design, pressure)
    linear = math.degrees(moment * design.l_mm / (8 * c10 * inertia))
    assert bending_angle_deg(design, pressure, model) > 1.05 * linear


def test_pressure_moment_closed_form():
    # Half disc of radius r, centroid b + 4r/(3π) above the bottom layer.
    r, b = BASE.r_mm, BASE.b_mm
    area = math.pi * r**2 / 2
    expected = 0.1 * area * (b + 4 * r / (3 * math.pi))
    assert pressure_moment_nmm(BASE, 0.1) == pytest.approx(expected, rel=1e-14)


@pytest.mark.parametrize(
    ("design", "theta", "model"),
    [
        (BASE, 1.5, DRAGON_SKIN_30.model),
        (sfrba_design(160, 10, 4, 4, 15, 12), 4.0, DRAGON_SKIN_30.model),
        (sfrba_design(100, 6, 3, 2, 5, 8), 6.0, Yeoh(0.2, 0.05, 0.002)),
    ],
    ids=["base", "largest", "stiff-yeoh"],
)
def test_section_quadrature_matches_adaptive_cubature(design, theta, model):
    reference = _elastomer_moment_dblquad(design, theta, model)
    assert elastomer_moment_nmm(design, theta, model) == pytest.approx(reference, rel=1e-9)


def test_elastomer_moment_is_increasing_for_dragon_skin_on_the_table1_corners():
    theta = np.linspace(0.0, 4 * math.pi, 200)
    for design in DesignSpace.corners():
        moment = elastomer_moment_nmm(design, theta)
        assert moment[0] == 0.0
        assert np.all(np.diff(moment) > 0), str(design)


def test_vectorized_over_pressure_shape():
    pressures = np.array([[0.0, 0.05], [0.1, 0.17]])
    angles = bending_angle_deg(BASE, pressures)
    assert angles.shape == (2, 2)
    for p, a in zip(pressures.ravel(), angles.ravel(), strict=True):
        assert bending_angle_deg(BASE, [p])[0] == pytest.approx(a, rel=1e-12)


def test_accepts_a_material_or_a_bare_model():
    default = bending_angle_deg(BASE, PRESSURES)
    np.testing.assert_array_equal(bending_angle_deg(BASE, PRESSURES, DRAGON_SKIN_30), default)
    np.testing.assert_array_equal(bending_angle_deg(BASE, PRESSURES, DRAGON_SKIN_30.model), default)
    # A stiffer elastomer bends less.
    stiffer = bending_angle_deg(BASE, PRESSURES[1:], Yeoh(0.2, 0.003))
    assert np.all(stiffer < default[1:])


def test_no_root_below_the_angle_bound_gives_nan_and_a_warning():
    with pytest.warns(RuntimeWarning, match="does not converge.*2 of 3 pressures"):
        angles = bending_angle_deg(BASE, [0.01, 0.1, 0.17], max_angle_deg=60.0)
    assert angles[0] > 0
    assert np.isnan(angles[1:]).all()


def test_reference_values_stay_inside_the_default_bound_without_warnings():
    with warnings.catch_warnings():
        warnings.simplefilter("error")
        angles = bending_angle_deg(BASE, [0.05, 0.1, 0.17])
    # Regression values of this implementation (degrees); paper B reports that the
    # analytical model under-predicts the measured angles.
    np.testing.assert_allclose(angles, [43.0379, 93.4201, 177.8707], rtol=1e-5)


def test_softening_law_warns_about_the_limit_point_and_returns_the_first_equilibrium():
    softening = Yeoh(c10_mpa=0.11, c20_mpa=-0.05)
    with pytest.warns(RuntimeWarning, match="not increasing"):
        angle = bending_angle_deg(BASE, [0.01], softening)[0]
    theta = math.radians(angle)
    assert elastomer_moment_nmm(BASE, theta, softening) == pytest.approx(
        pressure_moment_nmm(BASE, 0.01), rel=1e-10
    )
    # The first crossing: M_e is below the target everywhere before it.
    before = elastomer_moment_nmm(BASE, np.linspace(0, theta, 50)[:-1], softening)
    assert np.all(before < pressure_moment_nmm(BASE, 0.01))


@pytest.mark.parametrize("pressures", [[-0.01], [0.1, -1e-9]])
def test_negative_pressure_raises(pressures):
    with pytest.raises(ValueError, match=r"^pressures_mpa: must be in \[0, inf\); got -"):
        bending_angle_deg(BASE, pressures)


@pytest.mark.parametrize("bad", [np.nan, np.inf])
def test_non_finite_pressure_raises(bad):
    with pytest.raises(DatasetError, match=r"^pressures_mpa: must be finite"):
        bending_angle_deg(BASE, [0.1, bad])


def test_bad_options_raise_naming_the_field():
    with pytest.raises(ValueError, match=r"^max_angle_deg: must be a number in"):
        bending_angle_deg(BASE, [0.1], max_angle_deg=0.0)
    with pytest.raises(ValueError, match=r"^material: must be a hyperelastic model"):
        bending_angle_deg(BASE, [0.1], KEVLAR_FIBER)
    with pytest.raises(ValueError, match=r"^material: must be a hyperelastic model"):
        AnalyticalModel(material=KEVLAR_FIBER)
    with pytest.raises(ValueError, match=r"^material: Unknown material"):
        AnalyticalModel(material="no-such-silicone")
    with pytest.raises(ValueError, match=r"^n_radial: must be a number in \[1, 1000\]"):
        section_quadrature(BASE, n_radial=0)


def test_tip_position_limits_and_closed_forms():
    length, lc = BASE.l_mm, BASE.lc_mm
    x, z = tip_position_mm(BASE, [0.0, 90.0, 180.0, 360.0])
    np.testing.assert_allclose(x, [length + lc, 2 * length / math.pi, -lc, lc], atol=1e-9)
    np.testing.assert_allclose(
        z, [0.0, 2 * length / math.pi + lc, 2 * length / math.pi, 0.0], atol=1e-9
    )
    # θ → 0 without division by zero: x ≈ l + lc, z ≈ (l/2 + lc)·θ.
    tiny = 1e-9
    x, z = tip_position_mm(BASE, tiny)
    assert x == pytest.approx(length + lc, rel=1e-15)
    assert z == pytest.approx((length / 2 + lc) * math.radians(tiny), rel=1e-12)


def test_tip_position_geometry_and_symmetry():
    length, lc = BASE.l_mm, BASE.lc_mm
    angles = np.array([5.0, 45.0, 120.0, 250.0])
    x, z = tip_position_mm(BASE, angles)
    theta = np.radians(angles)
    # Arc end = tip minus the cap along the tangent; its distance from the base is the chord.
    xe, ze = x - lc * np.cos(theta), z - lc * np.sin(theta)
    np.testing.assert_allclose(np.hypot(xe, ze), 2 * length / theta * np.sin(theta / 2), rtol=1e-12)
    # Negative angles mirror the shape about the x axis.
    xn, zn = tip_position_mm(BASE, -angles)
    np.testing.assert_allclose(xn, x)
    np.testing.assert_allclose(zn, -z)
    # NaN (no equilibrium) propagates.
    xnan, znan = tip_position_mm(BASE, [np.nan])
    assert np.isnan(xnan).all() and np.isnan(znan).all()
