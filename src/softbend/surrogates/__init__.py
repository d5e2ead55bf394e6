"""Surrogate models of the bending angle: (design parameters, pressure) → θ (paper B §4.1).

The inputs are the design parameters of the model's actuator in its description's order
(:class:`softbend.actuators.Actuator`), then the pressure in its unit: for paper B's
actuator (l, r, t, b, φ, lc, P) in mm, degrees and MPa, for another its own names, such as
(n_chambers, wall_mm, height_mm, p_kpa). Every saved model records its description.

Polynomial regression, XGBoost, the normalized MLP and the table base (the
simulated curves themselves, a Gaussian process between designs) as scikit-learn
estimators, each a family of :data:`FAMILIES` (``plr``, ``xgb``, ``mlp``,
``table``; more can be registered); a design-grouped cross-validated grid search; metrics and
inference timing; persistence with metadata; ONNX export; single-sample fast
paths for control loops; the :class:`Surrogate` protocol every fitted one
answers. Names are imported lazily so that ``import softbend.surrogates`` does
not import PyTorch or XGBoost. The search itself is
:func:`softbend.surrogates.search.search` (not exported here: the name is its
module's).
"""

from __future__ import annotations

from typing import Any

from softbend._lazy import export as _export

#: Every public name, and the module that defines it.
_EXPORTS = {
    "FAMILIES": "families",
    "GRID_NAMES": "families",
    "MODEL_NAMES": "families",
    "Family": "families",
    "FitSettings": "families",
    "Storage": "families",
    "Surrogate": "protocol",
    "FastSurrogate": "protocol",
    "FEATURES": "features",
    "UNITS": "features",
    "TrainingData": "features",
    "training_data": "features",
    "PolynomialRegressor": "polynomial",
    "NormalizedMLPRegressor": "mlp",
    "TableRegressor": "table",
    "AffineCorrected": "corrected",
    "GPCorrected": "corrected",
    "MeanEnsemble": "corrected",
    "PressureScaled": "corrected",
    "train_mlp_grid": "batched",
    "accuracy": "metrics",
    "inference_time": "metrics",
    "grid": "search",
    "grouped_splits": "search",
    "SearchResult": "search",
    "train_surrogates": "workflow",
    "train_into": "workflow",
    "SurrogateModel": "model",
    "predict_angles": "predict",
    "Prediction": "predict",
    "save_surrogate": "persistence",
    "load_surrogate": "persistence",
    "SavedSurrogate": "persistence",
    "to_onnx": "onnx_export",
    "save_onnx": "onnx_export",
    "onnx_predict": "onnx_export",
}

__all__ = sorted(_EXPORTS)


def __getattr__(name: str) -> Any:
    return _export(__name__, _EXPORTS, name)


def __dir__() -> list[str]:
    return list(__all__)
