"""Hyperelastic and linear elastic material models and the presets of paper B.

``models`` holds the incompressible ``W(I1)`` laws (neo-Hookean, Yeoh,
Arruda–Boyce) and their registry; ``presets`` the materials of paper B §3.1 with
their sources.
"""

from softbend.materials.models import (
    MODELS,
    ArrudaBoyce,
    HyperelasticModel,
    NeoHookean,
    Yeoh,
    get_model_class,
    model_from_dict,
)
from softbend.materials.presets import (
    DRAGON_SKIN_30,
    FIBERGLASS_LAYER,
    KEVLAR_FIBER,
    KEVLAR_MODELLED_RADIUS_MM,
    PRESETS,
    LinearElastic,
    Material,
    get_preset,
)

__all__ = [
    "DRAGON_SKIN_30",
    "FIBERGLASS_LAYER",
    "KEVLAR_FIBER",
    "KEVLAR_MODELLED_RADIUS_MM",
    "MODELS",
    "PRESETS",
    "ArrudaBoyce",
    "HyperelasticModel",
    "LinearElastic",
    "Material",
    "NeoHookean",
    "Yeoh",
    "get_model_class",
    "get_preset",
    "model_from_dict",
]
