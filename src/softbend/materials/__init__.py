"""Hyperelastic and linear elastic material models and the presets of paper B.

``models`` holds the incompressible ``W(I1)`` laws (neo-Hookean, Yeoh,
Arruda–Boyce) and their registry (:data:`MODELS`); ``presets`` the materials of
paper B §3.1 with their sources (:data:`PRESETS`); ``tensile`` reads uniaxial
tensile tests (five real ones ship with softbend, Marechal et al. 2021, ODbL
1.0); ``fit`` fits the models to them.

Names are imported on first use: ``import softbend.materials`` imports no
submodule (the fits need SciPy).
"""

from __future__ import annotations

from typing import Any

from softbend._lazy import export as _export

_EXPORTS = {
    "DEFAULT_MODELS": "fit",
    "FitResult": "fit",
    "fit_model": "fit",
    "fit_models": "fit",
    "MODELS": "models",
    "ArrudaBoyce": "models",
    "HyperelasticModel": "models",
    "NeoHookean": "models",
    "Yeoh": "models",
    "get_model_class": "models",
    "model_from_dict": "models",
    "DRAGON_SKIN_30": "presets",
    "FIBERGLASS_LAYER": "presets",
    "KEVLAR_FIBER": "presets",
    "KEVLAR_MODELLED_RADIUS_MM": "presets",
    "PRESETS": "presets",
    "LinearElastic": "presets",
    "Material": "presets",
    "get_preset": "presets",
    "material_from_spec": "choice",
    "SHIPPED_ATTRIBUTION": "tensile",
    "TensileTest": "tensile",
    "load_shipped": "tensile",
    "load_tensile_csv": "tensile",
    "shipped_tensile_tests": "tensile",
}

__all__ = sorted(_EXPORTS)


def __getattr__(name: str) -> Any:
    return _export(__name__, _EXPORTS, name)


def __dir__() -> list[str]:
    return list(__all__)
