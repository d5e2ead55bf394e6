"""Least-squares fits of the hyperelastic models to uniaxial tension (paper B §3.1)."""

import json
import math

import numpy as np
import pytest

from softbend.errors import ConvergenceError, DatasetError
from softbend.materials import (
    DEFAULT_MODELS,
    ArrudaBoyce,
    FitResult,
    NeoHookean,
    TensileTest,
    Yeoh,
    fit_model,
    fit_models,
    load_shipped,
)
from softbend.materials import fit as fit_module

STRETCH = np.linspace(1.02, 6.0, 60)
TRUE_MODELS = [
    NeoHookean(c10_mpa=0.15),
    Yeoh(c10_mpa=0.11, c20_mpa=0.003, c30_mpa=-2e-5),
    ArrudaBoyce(mu_mpa=0.3, lambda_m=4.0),
    ArrudaBoyce(mu_mpa=0.2, lambda_m=1.5),
]


def _g(lam):
    return 2.0 * (lam - lam**-2)


def _noisy(model, seed=0, sigma=0.01):
    rng = np.random.default_rng(seed)
    return model.uniaxial_nominal_stress_mpa(STRETCH) + rng.normal(0.0, sigma, STRETCH.size)


@pytest.fixture(scope="module")
def ds30_fits():
    return fit_models(load_shipped("dragon-skin-30"))


@pytest.mark.parametrize("true", TRUE_MODELS, ids=lambda m: f"{m.name}-{m}")
def test_exact_recovery_from_synthetic_data(true):
    stress = true.uniaxial_nominal_stress_mpa(STRETCH)
    result = fit_model(true.name, STRETCH, stress)
    assert type(result.model) is type(true)
    expected = true.to_dict()
    for key, value in result.model.to_dict().items():
        if key != "model":
            assert value == pytest.approx(expected[key], rel=1e-7), key
    assert result.r2 == pytest.approx(1.0, abs=1e-12)
    assert result.rmse_mpa < 1e-9
    assert result.n_points == STRETCH.size
    assert result.stretch_range == (STRETCH[0], STRETCH[-1])
    assert result.at_bound == ()


def test_fit_models_on_a_tensile_test_recovers_yeoh():
    true = Yeoh(c10_mpa=0.09, c20_mpa=0.01, c30_mpa=-3e-4)
    strain = STRETCH - 1.0
    test = TensileTest("syn", "synthetic", strain, true.uniaxial_nominal_stress_mpa(STRETCH))
    results = fit_models(test)
    assert list(results) == list(DEFAULT_MODELS)
    assert results["yeoh"].model.c20_mpa == pytest.approx(0.01, rel=1e-7)
    assert results["yeoh"].r2 > results["arruda-boyce"].r2
    assert results["yeoh"].r2 > results["neo-hookean"].r2
    # A (stretch, stress) pair gives the same fits as the test.
    pair = fit_models((test.stretch, test.engineering_stress_mpa), "yeoh")
    assert list(pair) == ["yeoh"]
    assert pair["yeoh"].model == results["yeoh"].model


def test_neo_hookean_equals_closed_form_least_squares():
    stress = _noisy(NeoHookean(c10_mpa=0.15), seed=1, sigma=0.05)
    g = _g(STRETCH)
    c10 = float(g @ stress / (g @ g))  # argmin Σ (C10·g − P)²
    result = fit_model("neo-hookean", STRETCH, stress)
    assert result.model.c10_mpa == pytest.approx(c10, rel=1e-10)
    assert result.r2 < 1.0


def test_yeoh_equals_linear_least_squares_on_noisy_data():
    stress = _noisy(Yeoh(c10_mpa=0.11, c20_mpa=0.003, c30_mpa=0.0), seed=2)
    g = _g(STRETCH)
    d = STRETCH**2 + 2.0 / STRETCH - 3.0
    A = np.column_stack([g, 2 * g * d, 3 * g * d**2])
    expected = np.linalg.solve(A.T @ A, A.T @ stress)  # normal equations
    result = fit_model("yeoh", STRETCH, stress)
    got = [result.model.c10_mpa, result.model.c20_mpa, result.model.c30_mpa]
    np.testing.assert_allclose(got, expected, rtol=1e-6, atol=1e-12)


def test_r2_and_rmse_by_hand():
    stretch = [1.1, 1.5, 2.0, 2.5, 3.0, 4.0]
    stress = [0.05, 0.22, 0.36, 0.51, 0.60, 0.82]
    result = fit_model("neo-hookean", stretch, stress)
    c10 = result.model.c10_mpa
    predicted = [2 * c10 * (lam - 1 / lam**2) for lam in stretch]
    mean = sum(stress) / len(stress)
    ss_res = sum((p - y) ** 2 for p, y in zip(predicted, stress, strict=True))
    ss_tot = sum((y - mean) ** 2 for y in stress)
    assert result.r2 == pytest.approx(1 - ss_res / ss_tot, rel=1e-12)
    assert result.rmse_mpa == pytest.approx(math.sqrt(ss_res / len(stress)), rel=1e-12)
    np.testing.assert_allclose(result.predict(stretch), predicted, rtol=1e-12)


def test_arruda_boyce_tends_to_neo_hookean():
    neo = NeoHookean(c10_mpa=0.15)
    # The model: λm → ∞ gives neo-Hookean with C10 = μ/2, the gap shrinking like 1/λm².
    gaps = []
    for lambda_m in (10.0, 100.0, 1000.0):
        ab = ArrudaBoyce(mu_mpa=0.3, lambda_m=lambda_m)
        diff = ab.uniaxial_nominal_stress_mpa(STRETCH) - neo.uniaxial_nominal_stress_mpa(STRETCH)
        gaps.append(float(np.max(np.abs(diff))))
    assert gaps[2] < 1e-4 * np.max(neo.uniaxial_nominal_stress_mpa(STRETCH))
    assert gaps[1] / gaps[2] == pytest.approx(100.0, rel=0.05)
    # The fit: neo-Hookean data drive λm to its upper bound and μ to 2·C10.
    result = fit_model("arruda-boyce", STRETCH, neo.uniaxial_nominal_stress_mpa(STRETCH))
    assert result.model.lambda_m > 100.0
    assert result.at_bound == ("lambda_m",)
    assert result.model.mu_mpa == pytest.approx(2 * neo.c10_mpa, rel=1e-4)
    assert result.r2 > 1 - 1e-8


def test_bound_on_c10_holds_when_the_unconstrained_optimum_is_negative():
    g = _g(STRETCH)
    d = STRETCH**2 + 2.0 / STRETCH - 3.0
    stress = -0.05 * g + 0.02 * g * d + 0.003 * g * d**2  # linear solve gives C10 = -0.05
    result = fit_model("yeoh", STRETCH, stress)
    assert 0.0 < result.model.c10_mpa < 1e-9
    assert result.at_bound == ("c10_mpa",)
    assert 0.9 < result.r2 < 1.0


def test_dragon_skin_30_yeoh_is_best(ds30_fits):
    nh, yeoh, ab = (ds30_fits[name] for name in ("neo-hookean", "yeoh", "arruda-boyce"))
    # What the shipped data give over the full range to failure (strain 7.09).
    assert yeoh.r2 > ab.r2 > nh.r2
    assert yeoh.rmse_mpa < ab.rmse_mpa < nh.rmse_mpa
    assert yeoh.r2 > 0.995 and yeoh.rmse_mpa < 0.1
    assert 0.9 < nh.r2 < 0.97
    assert 0.05 < yeoh.model.c10_mpa < 0.3 and yeoh.model.c20_mpa > 0.0
    assert 2.0 < ab.model.lambda_m < 20.0
    for result in ds30_fits.values():
        assert result.n_points == 311
        assert result.stretch_range == pytest.approx((1.0446, 8.09091))
        assert result.at_bound == ()


def test_max_stretch_restricts_the_fit():
    test = load_shipped("dragon-skin-30")
    results = fit_models(test, ("neo-hookean", "yeoh"), max_stretch=5.0)
    for result in results.values():
        assert result.stretch_range[1] <= 5.0
        assert result.n_points == int(np.sum(test.stretch <= 5.0))
    # Over λ ≤ 5 the Yeoh constants come near paper B's C10 = 0.11, C20 = 0.003 MPa.
    yeoh = results["yeoh"].model
    assert 0.08 < yeoh.c10_mpa < 0.14 and 0.001 < yeoh.c20_mpa < 0.01


def test_unknown_model_lists_allowed_names():
    with pytest.raises(ValueError, match="Unknown material model 'mooney-rivlin'") as info:
        fit_model("mooney-rivlin", STRETCH, STRETCH - 1.0)
    assert f"known: {', '.join(DEFAULT_MODELS)}." in str(info.value)
    with pytest.raises(ValueError, match=r"^models: Unknown material model 'mooney'"):
        fit_models((STRETCH, STRETCH - 1.0), ["yeoh", "mooney"])


def test_bad_model_lists():
    data = (STRETCH, 0.3 * (STRETCH - 1.0))
    with pytest.raises(ValueError, match=r"^models: must be at least one of"):
        fit_models(data, [])
    with pytest.raises(ValueError, match=r"^models: must be distinct"):
        fit_models(data, ["yeoh", "yeoh"])
    with pytest.raises(ValueError, match=r"^data: must be a TensileTest or a"):
        fit_models(STRETCH)


def test_bad_data():
    stress = 0.3 * (STRETCH - 1.0)
    with pytest.raises(DatasetError, match=r"^nominal_stress_mpa: must be finite"):
        fit_model("yeoh", STRETCH, np.where(STRETCH > 3, np.nan, stress))
    with pytest.raises(DatasetError, match=r"^stretch: must be in \(0, inf\)"):
        fit_model("yeoh", STRETCH - 2.0, stress)
    with pytest.raises(DatasetError, match=r"^nominal_stress_mpa: .* the length of 'stretch'"):
        fit_model("yeoh", STRETCH, stress[:-1])
    with pytest.raises(DatasetError, match=r"^stretch: must be at least 5 points; got 4"):
        fit_model("yeoh", STRETCH[:4], stress[:4])
    with pytest.raises(ValueError, match=r"^max_stretch: must be a number in \(1"):
        fit_model("yeoh", STRETCH, stress, max_stretch=0.9)
    with pytest.raises(
        ValueError, match=r"^max_stretch: must keep at least 5 points.*got 1.2 \(3 points\)"
    ):
        fit_model("yeoh", STRETCH, stress, max_stretch=1.2)


def test_solver_failure_is_raised(monkeypatch):
    class Stopped:
        status = 0
        message = "The maximum number of function evaluations is exceeded."
        x = np.array([0.3, 4.0])
        active_mask = np.zeros(2)

    monkeypatch.setattr(fit_module, "least_squares", lambda *args, **kwargs: Stopped())
    stress = ArrudaBoyce(mu_mpa=0.3, lambda_m=4.0).uniaxial_nominal_stress_mpa(STRETCH)
    with pytest.raises(ConvergenceError, match=r"arruda-boyce.*status 0"):
        fit_model("arruda-boyce", STRETCH, stress)


def test_fit_result_dict_is_json(ds30_fits):
    payload = ds30_fits["arruda-boyce"].to_dict()
    assert json.loads(json.dumps(payload)) == payload
    assert payload["model"] == "arruda-boyce"
    assert set(payload["parameters"]) == {"mu_mpa", "lambda_m"}
    assert payload["initial_shear_modulus_mpa"] > payload["parameters"]["mu_mpa"]
    with pytest.raises(ValueError, match=r"^model: must be a HyperelasticModel"):
        FitResult(model="yeoh", r2=1.0, rmse_mpa=0.0, n_points=5, stretch_range=(1.0, 2.0))
