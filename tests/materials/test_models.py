import json

import numpy as np
import pytest

from softbend.materials import (
    DRAGON_SKIN_30,
    FIBERGLASS_LAYER,
    KEVLAR_FIBER,
    KEVLAR_MODELLED_RADIUS_MM,
    MODELS,
    PRESETS,
    ArrudaBoyce,
    HyperelasticModel,
    LinearElastic,
    Material,
    NeoHookean,
    Yeoh,
    get_model_class,
    get_preset,
    model_from_dict,
)

ALL_MODELS = [
    NeoHookean(c10_mpa=0.11),
    Yeoh(c10_mpa=0.11, c20_mpa=0.003, c30_mpa=-0.0001),
    ArrudaBoyce(mu_mpa=0.2, lambda_m=3.0),
]


def _ab_initial_shear_modulus(mu, lambda_m):
    # Closed form of the five-term series (ABAQUS Theory Manual 4.6.1).
    k = 1.0 / lambda_m**2
    return mu * (1 + 3 / 5 * k + 99 / 175 * k**2 + 513 / 875 * k**3 + 42039 / 67375 * k**4)


@pytest.mark.parametrize("model", ALL_MODELS, ids=lambda m: m.name)
def test_undeformed_state_is_stress_and_energy_free(model):
    assert model.uniaxial_nominal_stress_mpa(1.0) == pytest.approx(0.0, abs=1e-15)
    assert model.strain_energy(3.0) == pytest.approx(0.0, abs=1e-15)


@pytest.mark.parametrize("model", ALL_MODELS, ids=lambda m: m.name)
def test_small_strain_slope_is_three_times_the_shear_modulus(model):
    h = 1e-6
    slope = (
        model.uniaxial_nominal_stress_mpa(1 + h) - model.uniaxial_nominal_stress_mpa(1 - h)
    ) / (2 * h)
    assert slope == pytest.approx(3.0 * model.initial_shear_modulus_mpa, rel=1e-8)


def test_initial_shear_moduli_match_closed_forms():
    assert NeoHookean(0.11).initial_shear_modulus_mpa == pytest.approx(0.22)
    assert Yeoh(0.11, 0.5, -0.2).initial_shear_modulus_mpa == pytest.approx(0.22)
    ab = ArrudaBoyce(mu_mpa=0.2, lambda_m=3.0)
    assert ab.initial_shear_modulus_mpa == pytest.approx(_ab_initial_shear_modulus(0.2, 3.0))
    # Uniaxial slope at λ = 1 is 6 C10 for the invariant-polynomial models.
    h = 1e-6
    for model in (NeoHookean(0.11), Yeoh(0.11, 0.003)):
        slope = model.uniaxial_nominal_stress_mpa(1 + h) / h
        assert slope == pytest.approx(6 * 0.11, rel=1e-5)


@pytest.mark.parametrize("model", ALL_MODELS, ids=lambda m: m.name)
def test_derivative_is_consistent_with_the_energy(model):
    I1 = np.linspace(3.0, 12.0, 7)
    h = 1e-6
    numeric = (model.strain_energy(I1 + h) - model.strain_energy(I1 - h)) / (2 * h)
    np.testing.assert_allclose(model.dW_dI1(I1), numeric, rtol=1e-7)


@pytest.mark.parametrize("model", ALL_MODELS, ids=lambda m: m.name)
def test_uniaxial_stress_equals_the_energy_derivative_along_the_path(model):
    # Incompressible uniaxial tension: P = dW(I1(λ))/dλ with I1 = λ² + 2/λ.
    lam = np.linspace(0.6, 4.0, 9)
    h = 1e-6

    def energy(x):
        return model.strain_energy(x**2 + 2 / x)

    numeric = (energy(lam + h) - energy(lam - h)) / (2 * h)
    np.testing.assert_allclose(model.uniaxial_nominal_stress_mpa(lam), numeric, rtol=1e-6)


def test_stress_is_vectorized_and_keeps_the_shape():
    stretch = np.linspace(1.0, 3.0, 12).reshape(3, 4)
    stress = DRAGON_SKIN_30.model.uniaxial_nominal_stress_mpa(stretch)
    assert stress.shape == (3, 4)
    np.testing.assert_allclose(
        stress.ravel(),
        [DRAGON_SKIN_30.model.uniaxial_nominal_stress_mpa(s) for s in stretch.ravel()],
    )


def test_yeoh_with_only_c10_is_neo_hookean():
    lam = np.linspace(0.5, 6.0, 50)
    np.testing.assert_allclose(
        Yeoh(0.2).uniaxial_nominal_stress_mpa(lam),
        NeoHookean(0.2).uniaxial_nominal_stress_mpa(lam),
        rtol=1e-14,
    )
    I1 = np.linspace(3, 20, 5)
    np.testing.assert_allclose(Yeoh(0.2).strain_energy(I1), NeoHookean(0.2).strain_energy(I1))


def test_neo_hookean_uniaxial_closed_form():
    lam = np.array([0.5, 1.0, 2.0, 3.0])
    expected = 2 * 0.1 * (lam - lam**-2)
    np.testing.assert_allclose(NeoHookean(0.1).uniaxial_nominal_stress_mpa(lam), expected)


def test_arruda_boyce_tends_to_neo_hookean_for_large_locking_stretch():
    lam = np.linspace(0.5, 4.0, 30)
    neo = NeoHookean(c10_mpa=0.1).uniaxial_nominal_stress_mpa(lam)
    errors = []
    for lambda_m in (10.0, 100.0, 1000.0):
        ab = ArrudaBoyce(mu_mpa=0.2, lambda_m=lambda_m).uniaxial_nominal_stress_mpa(lam)
        errors.append(np.max(np.abs(ab - neo) / np.maximum(np.abs(neo), 1e-12)))
    assert errors[-1] < 1e-4
    # The gap closes like 1/λm².
    assert errors[0] > errors[1] > errors[2]
    assert errors[1] / errors[2] == pytest.approx(100.0, rel=0.05)


def test_arruda_boyce_stiffens_towards_the_locking_stretch():
    # Stress over initial shear modulus: neo-Hookean gives λ − λ⁻²; short chains stiffen.
    lam = 2.5
    neo = lam - lam**-2
    normalized = []
    for lambda_m in (10.0, 4.0, 2.0):
        model = ArrudaBoyce(mu_mpa=0.2, lambda_m=lambda_m)
        normalized.append(model.uniaxial_nominal_stress_mpa(lam) / model.initial_shear_modulus_mpa)
    assert normalized[0] == pytest.approx(neo, rel=0.02)
    assert normalized[0] < normalized[1] < normalized[2]
    assert normalized[2] > 1.3 * neo


def test_dragon_skin_30_is_monotone_up_to_five_times_its_length():
    lam = np.linspace(1.0, 5.0, 400)
    stress = DRAGON_SKIN_30.model.uniaxial_nominal_stress_mpa(lam)
    assert np.all(np.diff(stress) > 0)
    # In compression the nominal stress is negative and also monotone.
    comp = DRAGON_SKIN_30.model.uniaxial_nominal_stress_mpa(np.linspace(0.3, 1.0, 50))
    assert np.all(np.diff(comp) > 0) and np.all(comp[:-1] < 0)


def test_presets_hold_the_values_of_paper_b():
    ds30 = DRAGON_SKIN_30.model
    assert isinstance(ds30, Yeoh)
    assert (ds30.c10_mpa, ds30.c20_mpa, ds30.c30_mpa) == (0.11, 0.003, 0.0)
    assert DRAGON_SKIN_30.density_t_per_mm3 == pytest.approx(1.08e-9, rel=1e-12)
    assert DRAGON_SKIN_30.density_g_per_cm3 == pytest.approx(1.08)

    glass = FIBERGLASS_LAYER.model
    assert isinstance(glass, Yeoh)
    assert (glass.c10_mpa, glass.c20_mpa, glass.c30_mpa) == (7.9, 0.0, 0.0)
    assert FIBERGLASS_LAYER.density_t_per_mm3 == pytest.approx(2.40e-9, rel=1e-12)

    kevlar = KEVLAR_FIBER.model
    assert isinstance(kevlar, LinearElastic)
    assert (kevlar.e_mpa, kevlar.nu) == (31076.0, 0.36)
    assert kevlar.shear_modulus_mpa == pytest.approx(31076.0 / 2.72)
    assert KEVLAR_FIBER.density_t_per_mm3 == pytest.approx(1.67e-9, rel=1e-12)
    assert KEVLAR_MODELLED_RADIUS_MM == 0.07
    for preset in dict(PRESETS.items()).values():
        assert preset.source
    assert get_preset("dragon-skin-30") is DRAGON_SKIN_30


@pytest.mark.parametrize("model", ALL_MODELS, ids=lambda m: m.name)
def test_models_round_trip_through_json(model):
    data = json.loads(json.dumps(model.to_dict()))
    assert data["model"] == model.name
    assert type(model).from_dict(data) == model
    assert model_from_dict(data) == model
    assert HyperelasticModel.from_dict(data) == model


@pytest.mark.parametrize("material", list(dict(PRESETS.items()).values()), ids=list(PRESETS))
def test_materials_round_trip_through_json(material):
    data = json.loads(json.dumps(material.to_dict()))
    assert Material.from_dict(data) == material


def test_registry_names_and_classes():
    expected = {"neo-hookean": NeoHookean, "yeoh": Yeoh, "arruda-boyce": ArrudaBoyce}
    assert expected == dict(MODELS.items())
    for name, cls in MODELS.items():
        assert get_model_class(name) is cls
        assert cls.name == name


def test_unknown_model_name_lists_the_allowed_names():
    with pytest.raises(
        ValueError,
        match=r"^model: Unknown material model 'mooney'; known: neo-hookean, yeoh, arruda",
    ):
        get_model_class("mooney")
    with pytest.raises(ValueError, match="Unknown material model 'ogden'"):
        model_from_dict({"model": "ogden", "mu_mpa": 1.0})
    with pytest.raises(ValueError, match="Unknown material model None"):
        model_from_dict({"mu_mpa": 1.0})
    with pytest.raises(ValueError, match="'yeoh'"):
        Yeoh.from_dict({"model": "neo-hookean", "c10_mpa": 1.0})
    with pytest.raises(ValueError, match=r"'c20_mpa' in 'neo-hookean'; allowed keys"):
        NeoHookean.from_dict({"model": "neo-hookean", "c10_mpa": 1.0, "c20_mpa": 2.0})
    with pytest.raises(ValueError, match=r"Unknown material preset 'ecoflex'.*dragon-skin-30"):
        get_preset("ecoflex")


@pytest.mark.parametrize(
    ("factory", "field", "value"),
    [
        (lambda v: NeoHookean(c10_mpa=v), "c10_mpa", 0.0),
        (lambda v: NeoHookean(c10_mpa=v), "c10_mpa", float("nan")),
        (lambda v: NeoHookean(c10_mpa=v), "c10_mpa", "soft"),
        (lambda v: Yeoh(c10_mpa=v), "c10_mpa", -0.1),
        (lambda v: Yeoh(c10_mpa=0.1, c20_mpa=v), "c20_mpa", float("inf")),
        (lambda v: Yeoh(c10_mpa=0.1, c30_mpa=v), "c30_mpa", float("nan")),
        (lambda v: ArrudaBoyce(mu_mpa=v, lambda_m=3.0), "mu_mpa", -1.0),
        (lambda v: ArrudaBoyce(mu_mpa=0.2, lambda_m=v), "lambda_m", 1.0),
        (lambda v: ArrudaBoyce(mu_mpa=0.2, lambda_m=v), "lambda_m", 0.5),
        (lambda v: LinearElastic(e_mpa=v, nu=0.3), "e_mpa", 0.0),
        (lambda v: LinearElastic(e_mpa=1.0, nu=v), "nu", 0.5),
        (lambda v: Material("x", Yeoh(0.1), v), "density_t_per_mm3", 0.0),
        (lambda v: Material("x", v, 1e-9), "model", "yeoh"),
        (lambda v: Material(v, Yeoh(0.1), 1e-9), "name", ""),
    ],
)
def test_bad_values_raise_naming_the_field(factory, field, value):
    with pytest.raises(ValueError, match=rf"^{field}: must be") as info:
        factory(value)
    assert info.value.key == field


def test_yeoh_accepts_negative_higher_order_terms():
    model = Yeoh(c10_mpa=0.1, c20_mpa=-0.01, c30_mpa=0.001)
    assert model.c20_mpa == -0.01
    assert model.initial_shear_modulus_mpa == pytest.approx(0.2)


@pytest.mark.parametrize("stretch", [0.0, -1.0, [1.0, np.nan]])
def test_bad_stretch_raises_naming_the_field(stretch):
    with pytest.raises(ValueError, match=r"^stretch: must be"):
        NeoHookean(0.1).uniaxial_nominal_stress_mpa(stretch)


def test_models_are_frozen_and_hashable():
    model = Yeoh(0.11, 0.003)
    with pytest.raises(AttributeError):
        model.c10_mpa = 1.0
    assert hash(model) == hash(Yeoh(0.11, 0.003))
