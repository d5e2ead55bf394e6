"""Surrogate models of the bending angle: (l, r, t, b, φ, lc, P) → θ (paper B §4.1).

Polynomial regression, XGBoost and the normalized MLP as scikit-learn
estimators; a design-grouped cross-validated grid search; metrics and
inference timing; persistence with metadata; ONNX export; single-sample fast
paths for control loops. Names are imported lazily so that
``import softbend.surrogates`` does not import PyTorch or XGBoost.
"""

from __future__ import annotations

import importlib
from typing import Any

_EXPORTS = {
    "FEATURES": "features",
    "UNITS": "features",
    "TrainingData": "features",
    "training_data": "features",
    "PolynomialRegressor": "polynomial",
    "NormalizedMLPRegressor": "mlp",
    "train_mlp_grid": "batched",
    "accuracy": "metrics",
    "inference_time": "metrics",
    "search": "search",
    "grid": "search",
    "grouped_splits": "search",
    "SearchResult": "search",
    "train_surrogates": "workflow",
    "SurrogateModel": "model",
    "predict_angles": "predict",
    "Prediction": "predict",
    "save_surrogate": "persistence",
    "load_surrogate": "persistence",
    "to_onnx": "onnx_export",
    "onnx_predict": "onnx_export",
}

__all__ = sorted(_EXPORTS)


def __getattr__(name: str) -> Any:
    if name in _EXPORTS:
        module = importlib.import_module(f"softbend.surrogates.{_EXPORTS[name]}")
        return getattr(module, name)
    raise AttributeError(f"module 'softbend.surrogates' has no attribute {name!r}")


def __dir__() -> list[str]:
    return __all__
