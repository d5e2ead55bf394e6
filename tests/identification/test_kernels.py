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
    generalized_gaussian_kernel,
    gg_kurtosis,
    gg_normalization,
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
    with pytest.raises(ValueError, match="'shape'"):
        gg_scale(bad)
    with pytest.raises(ValueError, match="'shape'"):
        gg_kurtosis(bad)
    with pytest.raises(ValueError, match="'sigma'"):
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
    with pytest.raises(ValueError, match=r"'sigma' of generalized_gaussian_kernel .*\(0, inf\)"):
        generalized_gaussian_kernel(points, sigma=0.0, shape=2.0)
    with pytest.raises(ValueError, match=r"'shape' of generalized_gaussian_kernel .*\(0, 2\]"):
        generalized_gaussian_kernel(points, sigma=1.0, shape=2.5)
    bad = points.copy()
    bad[3, 1] = np.nan
    with pytest.raises(ValueError, match="'X'"):
        generalized_gaussian_kernel(bad, sigma=1.0, shape=2.0)
    with pytest.raises(ValueError, match=r"'Z'.*3 features"):
        generalized_gaussian_kernel(points, points[:, :2], sigma=1.0, shape=2.0)
    with pytest.raises(ValueError, match="1-D or 2-D"):
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
        (np.ones(10), "must not be constant"),
        (np.array([1.0, 2.0, 3.0]), "n_samples = 3"),
        (np.array([1.0, np.nan, 2.0, 3.0, 4.0]), "'samples' of estimate_gg_shape must be finite"),
        (np.zeros((4, 2, 2)), "1-D or 2-D"),
    ],
)
def test_estimate_rejects_unusable_samples(samples, match):
    with pytest.raises(ValueError, match=match):
        estimate_gg_shape(samples)


def test_estimate_rejects_bad_weights():
    samples = np.arange(10.0)
    with pytest.raises(ValueError, match=r"'sample_weight'.*non-negative"):
        estimate_gg_shape(samples, sample_weight=-np.ones(10))
    with pytest.raises(ValueError, match=r"'sample_weight'.*shape \(10,\)"):
        estimate_gg_shape(samples, sample_weight=np.ones(9))
    with pytest.raises(ValueError, match="n_samples = 2"):
        estimate_gg_shape(samples, sample_weight=np.r_[1.0, 1.0, np.zeros(8)])
