import math
import warnings

import numpy as np
import pytest
from scipy import integrate, stats

from softbend.identification.kernels import (
    SHAPE_BOUNDS,
    ShapeClippedWarning,
    _shape_from_kurtosis,
    estimate_gg_shape,
    estimate_kernel_shape,
    generalized_gaussian_kernel,
    gg_kurtosis,
    gg_normalization,
    gg_radial_kurtosis,
    gg_scale,
)

SHAPES = (0.5, 1.0, 1.5, 2.0)


# --- closed forms of the generalized Gaussian -------------------------------------------


def test_gg_scale_reference_values():
    assert gg_scale(2.0) == pytest.approx(1.0 / math.sqrt(2.0), rel=1e-14)
    assert gg_scale(1.0) == pytest.approx(math.sqrt(2.0), rel=1e-14)
    # gamma -> inf: uniform on (-sqrt(3) sigma, sqrt(3) sigma), g -> 1/sqrt(3)
    assert gg_scale(1e5) == pytest.approx(1.0 / math.sqrt(3.0), rel=1e-4)


def test_gg_normalization_reference_values():
    sigma = 0.7
    assert gg_normalization(sigma, 2.0) == pytest.approx(
        1.0 / (sigma * math.sqrt(2 * math.pi)), rel=1e-14
    )
    assert gg_normalization(sigma, 1.0) == pytest.approx(1.0 / (sigma * math.sqrt(2)), rel=1e-14)


@pytest.mark.parametrize("shape", SHAPES)
def test_normalized_kernel_in_1d_is_the_generalized_normal_pdf_with_std_sigma(shape):
    sigma = 1.3
    origin = np.zeros((1, 1))

    def pdf(x: float) -> float:
        return float(
            generalized_gaussian_kernel(np.array([[x]]), origin, sigma=sigma, shape=shape)[0, 0]
        )

    # Even function with a cusp at 0 for shape <= 1: integrate the half line twice.
    mass = 2.0 * integrate.quad(pdf, 0.0, np.inf)[0]
    variance = 2.0 * integrate.quad(lambda x: x * x * pdf(x), 0.0, np.inf)[0]
    assert mass == pytest.approx(1.0, rel=1e-8)
    assert variance == pytest.approx(sigma**2, rel=1e-8)
    x = np.linspace(-4.0, 4.0, 17)[:, None]
    reference = stats.gennorm.pdf(x[:, 0], shape, scale=sigma / gg_scale(shape))
    np.testing.assert_allclose(
        generalized_gaussian_kernel(x, origin, sigma=sigma, shape=shape)[:, 0],
        reference,
        rtol=1e-12,
    )


def test_gg_kurtosis_reference_values_and_limit():
    assert gg_kurtosis(1.0) == pytest.approx(6.0, rel=1e-13)
    assert gg_kurtosis(2.0) == pytest.approx(3.0, rel=1e-13)
    assert gg_kurtosis(1e4) == pytest.approx(1.8, rel=1e-3)


def test_gg_kurtosis_matches_scipy_and_decreases_monotonically():
    shapes = np.geomspace(0.1, 50.0, 200)
    kurtosis = gg_kurtosis(shapes)
    assert np.all(np.diff(kurtosis) < 0.0)
    assert np.all(kurtosis > 1.8)
    excess = np.array([stats.gennorm.stats(b, moments="k") for b in shapes[::20]], dtype=float)
    np.testing.assert_allclose(kurtosis[::20], excess + 3.0, rtol=1e-10)


@pytest.mark.parametrize("bad", [0.0, -1.0, np.nan])
def test_gg_functions_reject_non_positive_shape(bad):
    with pytest.raises(ValueError, match=r"^shape: must be"):
        gg_scale(bad)
    with pytest.raises(ValueError, match=r"^shape: must be"):
        gg_kurtosis(bad)
    with pytest.raises(ValueError, match=r"^sigma: must be"):
        gg_normalization(bad, 2.0)


# --- Gram matrix ------------------------------------------------------------------------


@pytest.fixture
def points():
    return np.random.default_rng(7).normal(size=(60, 3))


def test_gaussian_shape_unnormalized_is_the_rbf_kernel(points):
    sigma = 0.8
    diff = points[:, None, :] - points[None, :, :]
    expected = np.exp(-np.sum(diff**2, axis=-1) / (2 * sigma**2))
    gram = generalized_gaussian_kernel(points, sigma=sigma, shape=2.0, normalize=False)
    np.testing.assert_allclose(gram, expected, rtol=1e-13, atol=1e-15)


def test_shape_one_is_the_laplacian_kernel(points):
    sigma = 1.7
    other = points[:11] + 0.3
    distance = np.linalg.norm(points[:, None, :] - other[None, :, :], axis=-1)
    expected = np.exp(-math.sqrt(2.0) * distance / sigma)
    gram = generalized_gaussian_kernel(points, other, sigma=sigma, shape=1.0, normalize=False)
    np.testing.assert_allclose(gram, expected, rtol=1e-13, atol=1e-15)


@pytest.mark.parametrize("shape", SHAPES)
def test_gram_is_symmetric_psd_with_peak_on_the_diagonal(points, shape):
    sigma = 1.1
    gram = generalized_gaussian_kernel(points, sigma=sigma, shape=shape)
    np.testing.assert_array_equal(gram, gram.T)
    np.testing.assert_allclose(np.diag(gram), gg_normalization(sigma, shape), rtol=1e-14)
    assert gram.max() == pytest.approx(gg_normalization(sigma, shape), rel=1e-14)
    assert np.linalg.eigvalsh(gram).min() >= -1e-10
    # The two-argument form gives the same matrix.
    np.testing.assert_allclose(
        generalized_gaussian_kernel(points, points, sigma=sigma, shape=shape),
        gram,
        rtol=1e-12,
        atol=1e-15,
    )


def test_kernel_decreases_with_distance_and_is_translation_invariant():
    offsets = np.linspace(0.0, 5.0, 21)[:, None] * np.array([[0.6, 0.8]])
    row = generalized_gaussian_kernel(np.zeros((1, 2)), offsets, sigma=1.0, shape=1.5)[0]
    assert np.all(np.diff(row) < 0.0)
    shifted = generalized_gaussian_kernel(
        np.full((1, 2), 3.0), offsets + 3.0, sigma=1.0, shape=1.5
    )[0]
    np.testing.assert_allclose(shifted, row, rtol=1e-12)


def test_kernel_rejects_bad_input(points):
    with pytest.raises(ValueError, match=r"^sigma: must be a number in \(0, inf\)"):
        generalized_gaussian_kernel(points, sigma=0.0, shape=2.0)
    with pytest.raises(ValueError, match=r"^shape: must be a number in \(0, 2\]"):
        generalized_gaussian_kernel(points, sigma=1.0, shape=2.5)
    bad = points.copy()
    bad[3, 1] = np.nan
    with pytest.raises(ValueError, match=r"^X: must be finite"):
        generalized_gaussian_kernel(bad, sigma=1.0, shape=2.0)
    with pytest.raises(ValueError, match=r"^Z: must have 3 features"):
        generalized_gaussian_kernel(points, points[:, :2], sigma=1.0, shape=2.0)
    with pytest.raises(ValueError, match=r"^X: must be a 1-D or 2-D"):
        generalized_gaussian_kernel(points[None], sigma=1.0, shape=2.0)


# --- shape estimation -------------------------------------------------------------------


@pytest.mark.parametrize("beta", [1.0, 1.5, 2.0])
def test_estimate_recovers_shape_and_std_of_generalized_normal_samples(beta):
    samples = stats.gennorm.rvs(beta, scale=2.5, size=100_000, random_state=12345)
    true_std = stats.gennorm.std(beta, scale=2.5)
    with warnings.catch_warnings():
        # At beta = 2 the sample kurtosis may fall just below 3 and be clipped to 2.
        warnings.simplefilter("ignore", ShapeClippedWarning)
        sigma, shape = estimate_gg_shape(samples)
    assert shape == pytest.approx(beta, rel=0.05)
    assert sigma == pytest.approx(true_std, rel=0.02)


@pytest.mark.parametrize("shape", [0.1, 0.4, 1.0, 1.37, 1.999, 2.0])
def test_shape_from_kurtosis_inverts_gg_kurtosis(shape):
    assert _shape_from_kurtosis(gg_kurtosis(shape)) == pytest.approx(shape, rel=1e-10)


def test_uniform_samples_are_clipped_to_the_gaussian_with_a_warning():
    samples = np.random.default_rng(3).uniform(-1.0, 1.0, size=20_000)
    with pytest.warns(ShapeClippedWarning, match="clipped to 2"):
        sigma, shape = estimate_gg_shape(samples)
    assert shape == 2.0
    assert sigma == pytest.approx(1.0 / math.sqrt(3.0), rel=0.02)


def test_extreme_kurtosis_is_clipped_to_the_lower_bound_with_a_warning():
    with pytest.warns(ShapeClippedWarning, match="clipped to 0.05"):
        assert _shape_from_kurtosis(1e15) == SHAPE_BOUNDS[0]


def test_estimate_is_scale_and_shift_equivariant():
    samples = stats.gennorm.rvs(1.2, size=5_000, random_state=5)
    sigma, shape = estimate_gg_shape(samples)
    sigma_scaled, shape_scaled = estimate_gg_shape(-40.0 * samples + 7.0)
    assert shape_scaled == pytest.approx(shape, rel=1e-9)
    assert sigma_scaled == pytest.approx(40.0 * sigma, rel=1e-12)


def test_two_dimensional_width_is_the_mean_variance_and_shape_is_scale_free():
    rng = np.random.default_rng(11)
    laplace = rng.laplace(size=(50_000, 2))
    regressors = laplace * np.array([1.0, 100.0]) + np.array([5.0, -3.0])
    regressors = np.column_stack([regressors, np.full(50_000, 4.2)])  # constant: ignored
    sigma, shape = estimate_gg_shape(regressors)
    variances = regressors[:, :2].var(axis=0)
    assert sigma == pytest.approx(math.sqrt(variances.mean()), rel=1e-12)
    assert shape == pytest.approx(1.0, rel=0.05)
    # The shape does not depend on the column scales.
    _, shape_standardized = estimate_gg_shape(laplace / laplace.std(axis=0))
    assert shape == pytest.approx(shape_standardized, rel=1e-9)


def test_integer_weights_equal_repeated_samples_and_zero_weights_drop_samples():
    rng = np.random.default_rng(2)
    samples = rng.laplace(size=(40, 3))
    weights = rng.integers(0, 4, size=40)
    weighted = estimate_gg_shape(samples, sample_weight=weights)
    repeated = estimate_gg_shape(np.repeat(samples, weights, axis=0))
    np.testing.assert_allclose(weighted, repeated, rtol=1e-12)


@pytest.mark.parametrize(
    ("samples", "match"),
    [
        (np.ones(10), "^samples: must not be constant"),
        (np.array([1.0, 2.0, 3.0]), "^samples: .*n_samples = 3"),
        (np.array([1.0, np.nan, 2.0, 3.0, 4.0]), "^samples: must be finite"),
        (np.zeros((4, 2, 2)), "^samples: must be a 1-D or 2-D"),
    ],
)
def test_estimate_rejects_unusable_samples(samples, match):
    with pytest.raises(ValueError, match=match):
        estimate_gg_shape(samples)


def test_estimate_rejects_bad_weights():
    samples = np.arange(10.0)
    with pytest.raises(ValueError, match=r"^sample_weight: must be non-negative"):
        estimate_gg_shape(samples, sample_weight=-np.ones(10))
    with pytest.raises(ValueError, match=r"^sample_weight: must have shape \(10,\)"):
        estimate_gg_shape(samples, sample_weight=np.ones(9))
    with pytest.raises(ValueError, match="n_samples = 2"):
        estimate_gg_shape(samples, sample_weight=np.r_[1.0, 1.0, np.zeros(8)])


# --- the kernel's argument: radial fourth moments (estimate_kernel_shape) ---------------


def _elliptical_gg(n, dim, shape, rng, mixing=None):
    """Samples of the d-dimensional generalized Gaussian exp(-|x|^shape), mixed linearly.

    The radius R has density ∝ r^(d-1) exp(-r^shape): R^shape ~ Gamma(d/shape).
    """
    radius = rng.gamma(dim / shape, size=n) ** (1.0 / shape)
    direction = rng.normal(size=(n, dim))
    direction /= np.linalg.norm(direction, axis=1)[:, None]
    samples = radius[:, None] * direction
    return samples if mixing is None else samples @ mixing.T


MIXING = np.array([[1.0, 0.5, 0.0], [0.0, 2.0, 0.3], [0.2, 0.0, 0.5]])


@pytest.mark.parametrize("dim", [1.0, 2.0, 4.0, 7.5])
def test_radial_kurtosis_reduces_to_eq_24_and_has_the_gaussian_and_uniform_limits(dim):
    assert gg_radial_kurtosis(2.0, dim) == pytest.approx((dim + 2) / dim, rel=1e-12)
    assert gg_radial_kurtosis(1e5, dim) == pytest.approx(
        (dim + 2) ** 2 / (dim * (dim + 4)), rel=1e-3
    )
    shapes = np.geomspace(0.1, 50.0, 100)
    assert np.all(np.diff(gg_radial_kurtosis(shapes, dim)) < 0.0)
    np.testing.assert_allclose(gg_radial_kurtosis(shapes, 1.0), gg_kurtosis(shapes), rtol=1e-12)


@pytest.mark.parametrize("shape", [0.7, 1.0, 1.5])
def test_radial_kurtosis_is_the_moment_ratio_of_the_radius(shape):
    dim = 3.0

    def moment(k):  # of the radius, density ∝ r^(d-1) exp(-r^shape)
        return integrate.quad(lambda r: r ** (dim - 1 + k) * math.exp(-(r**shape)), 0, np.inf)[0]

    ratio = moment(4) * moment(0) / moment(2) ** 2
    assert gg_radial_kurtosis(shape, dim) == pytest.approx(ratio, rel=1e-8)


@pytest.mark.parametrize("dim", [1, 3])
@pytest.mark.parametrize("shape", [0.7, 1.0, 1.5])
def test_moments_of_regressors_recover_the_shape_of_an_elliptical_generalized_gaussian(dim, shape):
    rng = np.random.default_rng(20 + dim)
    mixing = None if dim == 1 else MIXING
    samples = _elliptical_gg(200_000, dim, shape, rng, mixing) + 3.0  # shift: centred inside
    estimate = estimate_kernel_shape(samples, moments_of="regressors")
    assert estimate.shape == pytest.approx(shape, rel=0.05)
    assert not estimate.clipped
    assert estimate.relative_kurtosis > 1.0 and "heavier tails" in estimate.reason


def test_moments_of_differences_match_their_closed_form_for_iid_rows():
    # For i.i.d. rows the ratio of x - z is the mean of the rows' ratio and the
    # Gaussian one (1 + 2/d for isotropic rows): the differences are closer to Gaussian.
    dim, shape = 3, 1.0
    samples = _elliptical_gg(200_000, dim, shape, np.random.default_rng(4))
    estimate = estimate_kernel_shape(samples, moments_of="differences")
    expected = 0.5 * (gg_radial_kurtosis(shape, dim) + (dim + 2) / dim)
    assert estimate.kurtosis == pytest.approx(expected, rel=0.03)
    assert estimate.gaussian_kurtosis == pytest.approx((dim + 2) / dim, rel=0.01)
    assert shape < estimate.shape < 2.0


def test_moments_of_differences_equal_the_brute_force_over_all_pairs():
    rng = np.random.default_rng(6)
    X = rng.laplace(size=(40, 3)) * np.array([1.0, 3.0, 0.5])
    weight = rng.integers(1, 4, size=40).astype(float)
    estimate = estimate_kernel_shape(X, sample_weight=weight, moments_of="differences")
    diff = X[:, None, :] - X[None, :, :]
    pair_weight = (weight[:, None] * weight[None, :]).ravel()
    squared = np.sum(diff**2, axis=-1).ravel()
    ratio = (
        np.average(squared**2, weights=pair_weight) / np.average(squared, weights=pair_weight) ** 2
    )
    assert estimate.kurtosis == pytest.approx(ratio, rel=1e-12)
    # d_eff from the covariance of the differences (twice that of the rows)
    covariance = np.cov(X.T, aweights=weight, bias=True)
    d_eff = np.trace(covariance) ** 2 / np.sum(covariance**2)
    assert estimate.effective_dimension == pytest.approx(d_eff, rel=1e-12)
    assert estimate.sigma == pytest.approx(estimate_gg_shape(X, sample_weight=weight)[0], rel=1e-12)


@pytest.mark.parametrize("moments_of", ["differences", "regressors"])
def test_gaussian_rows_of_any_covariance_give_shape_two(moments_of):
    rng = np.random.default_rng(9)
    rows = rng.normal(size=(200_000, 3)) @ MIXING.T
    with warnings.catch_warnings():
        warnings.simplefilter("ignore", ShapeClippedWarning)  # may fall just above 2
        estimate = estimate_kernel_shape(rows, moments_of=moments_of)
    assert estimate.relative_kurtosis == pytest.approx(1.0, abs=0.02)
    assert estimate.shape == pytest.approx(2.0, abs=0.1)


@pytest.mark.parametrize("moments_of", ["differences", "regressors", "components"])
def test_light_tailed_rows_are_clipped_to_two_with_the_reason(moments_of):
    rows = np.random.default_rng(1).uniform(-1.0, 1.0, size=(20_000, 4))
    with pytest.warns(ShapeClippedWarning, match="clipped to 2"):
        estimate = estimate_kernel_shape(rows, moments_of=moments_of)
    assert estimate.shape == 2.0 and estimate.clipped
    assert estimate.unclipped_shape > 2.0
    assert estimate.relative_kurtosis < 1.0
    assert "lighter tails" in estimate.reason and "clipped to 2" in estimate.reason


def test_components_reading_is_the_pooled_estimator_of_paper_a():
    rows = np.random.default_rng(3).laplace(size=(5_000, 3))
    estimate = estimate_kernel_shape(rows, moments_of="components")
    assert (estimate.sigma, estimate.shape) == pytest.approx(estimate_gg_shape(rows), rel=1e-12)
    assert estimate.gaussian_kurtosis == 3.0 and estimate.dimension == 1


@pytest.mark.parametrize("moments_of", ["differences", "regressors"])
def test_radial_integer_weights_equal_repeated_rows(moments_of):
    rng = np.random.default_rng(2)
    rows = rng.laplace(size=(40, 3))
    weights = rng.integers(0, 4, size=40)
    weighted = estimate_kernel_shape(rows, sample_weight=weights, moments_of=moments_of)
    repeated = estimate_kernel_shape(np.repeat(rows, weights, axis=0), moments_of=moments_of)
    assert weighted.kurtosis == pytest.approx(repeated.kurtosis, rel=1e-12)
    assert weighted.shape == pytest.approx(repeated.shape, rel=1e-10)


def test_estimate_kernel_shape_rejects_an_unknown_reading():
    with pytest.raises(ValueError, match=r"^moments_of: must be one of"):
        estimate_kernel_shape(np.arange(10.0), moments_of="pairs")
    with pytest.raises(ValueError, match=r"^dim: must be a number"):
        gg_radial_kurtosis(1.0, 0.0)
