"""Paper B's material presets: the constants of §3.1 and the checks of Material."""

from __future__ import annotations

import pytest

from softbend.materials.models import Yeoh
from softbend.materials.presets import (
    DRAGON_SKIN_30,
    FIBERGLASS_LAYER,
    KEVLAR_FIBER,
    PRESETS,
    LinearElastic,
    Material,
    get_preset,
)


def test_the_presets_hold_paper_b_constants():
    assert DRAGON_SKIN_30.model == Yeoh(c10_mpa=0.11, c20_mpa=0.003, c30_mpa=0.0)
    assert DRAGON_SKIN_30.density_t_per_mm3 == pytest.approx(1.08e-9)
    assert FIBERGLASS_LAYER.model == Yeoh(c10_mpa=7.9, c20_mpa=0.0, c30_mpa=0.0)
    assert FIBERGLASS_LAYER.density_t_per_mm3 == pytest.approx(2.40e-9)
    assert KEVLAR_FIBER.model == LinearElastic(e_mpa=31076.0, nu=0.36)
    assert KEVLAR_FIBER.density_t_per_mm3 == pytest.approx(1.67e-9)
    for material in dict(PRESETS.items()).values():
        assert "Ye et al." in material.source


def test_linear_elastic_moduli_follow_the_isotropic_relations():
    fiber = KEVLAR_FIBER.model
    assert fiber.shear_modulus_mpa == pytest.approx(31076.0 / 2.72)
    assert fiber.bulk_modulus_mpa == pytest.approx(31076.0 / (3 * 0.28))
    # E = 9KG / (3K + G) closes the loop.
    k, g = fiber.bulk_modulus_mpa, fiber.shear_modulus_mpa
    assert 9 * k * g / (3 * k + g) == pytest.approx(fiber.e_mpa)
    assert LinearElastic.from_dict(fiber.to_dict()) == fiber
    for material in dict(PRESETS.items()).values():
        assert Material.from_dict(material.to_dict()) == material
    # The Yeoh law's small-strain shear modulus is 2·C10.
    assert DRAGON_SKIN_30.model.initial_shear_modulus_mpa == pytest.approx(0.22)


def test_get_preset_and_bad_materials_name_the_field():
    assert get_preset("dragon-skin-30") is DRAGON_SKIN_30
    with pytest.raises(
        ValueError, match=r"^name: Unknown material preset 'ecoflex'; known: dragon"
    ):
        get_preset("ecoflex")
    with pytest.raises(ValueError, match=r"^nu: must be a number in"):
        LinearElastic(e_mpa=1.0, nu=0.5)
    with pytest.raises(ValueError, match=r"^e_mpa: must be a number in"):
        LinearElastic(e_mpa=-1.0, nu=0.3)
    with pytest.raises(ValueError, match=r"^name: must be a non-empty string"):
        Material(name=" ", model=DRAGON_SKIN_30.model, density_t_per_mm3=1e-9)
    with pytest.raises(ValueError, match=r"^model: must be a HyperelasticModel"):
        Material(name="x", model=3.0, density_t_per_mm3=1e-9)
    with pytest.raises(ValueError, match=r"^density_t_per_mm3: must be a number in"):
        Material(name="x", model=DRAGON_SKIN_30.model, density_t_per_mm3=0.0)
    with pytest.raises(ValueError, match=r"^model: must be one of 'linear-elastic'"):
        LinearElastic.from_dict({"model": "yeoh", "e_mpa": 1.0, "nu": 0.3})
