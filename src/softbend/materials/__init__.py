"""Hyperelastic and linear elastic material models and the presets of paper B.

``models`` holds the incompressible ``W(I1)`` laws (neo-Hookean, Yeoh,
Arruda–Boyce) and their registry; ``presets`` the materials of paper B §3.1 with
their sources; ``tensile`` reads uniaxial tensile tests (five real ones ship with
softbend, Marechal et al. 2021, ODbL 1.0); ``fit`` fits the models to them.
"""

from softbend.materials.fit import DEFAULT_MODELS, FitResult, fit_model, fit_models
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
from softbend.materials.tensile import (
    SHIPPED_ATTRIBUTION,
    TensileTest,
    load_shipped,
    load_tensile_csv,
    shipped_tensile_tests,
)

__all__ = [
    "DEFAULT_MODELS",
    "DRAGON_SKIN_30",
    "FIBERGLASS_LAYER",
    "KEVLAR_FIBER",
    "KEVLAR_MODELLED_RADIUS_MM",
    "MODELS",
    "PRESETS",
    "SHIPPED_ATTRIBUTION",
    "ArrudaBoyce",
    "FitResult",
    "HyperelasticModel",
    "LinearElastic",
    "Material",
    "NeoHookean",
    "TensileTest",
    "Yeoh",
    "fit_model",
    "fit_models",
    "get_model_class",
    "get_preset",
    "load_shipped",
    "load_tensile_csv",
    "model_from_dict",
    "shipped_tensile_tests",
]
