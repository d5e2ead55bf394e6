"""Save and load identified NARX models as plain JSON, without pickle.

A saved model holds the NARX lag structure and signal scaling, the fitted
generalized-Gaussian SVR (support vectors, dual coefficients, intercept, kernel
σ and shape), a schema version, the softbend version and free metadata (sign,
output, units, training experiments). Floats are written with ``repr``
precision, so a reloaded model predicts bit-identically.
"""

from __future__ import annotations

import json
from pathlib import Path
from typing import Any

import numpy as np
from sklearn.preprocessing import StandardScaler

from softbend import __version__
from softbend._io import write_text_atomic
from softbend.errors import SchemaError
from softbend.identification.narx import NARXRegressor, _regressor_names
from softbend.identification.svr import GeneralizedGaussianSVR

FORMAT = "softbend.narx-gg-svr"
SCHEMA_VERSION = 1


def _scaler_state(scaler: StandardScaler | None) -> dict[str, list[float]] | None:
    if scaler is None:
        return None
    return {
        "mean": scaler.mean_.tolist(),
        "scale": scaler.scale_.tolist(),
        "var": scaler.var_.tolist(),
        "n_samples_seen": int(np.asarray(scaler.n_samples_seen_).ravel()[0]),
    }


def _scaler_from_state(state: dict[str, Any] | None) -> StandardScaler | None:
    if state is None:
        return None
    scaler = StandardScaler()
    scaler.mean_ = np.asarray(state["mean"], dtype=float)
    scaler.scale_ = np.asarray(state["scale"], dtype=float)
    scaler.var_ = np.asarray(state["var"], dtype=float)
    scaler.n_samples_seen_ = np.int64(state["n_samples_seen"])
    scaler.n_features_in_ = scaler.mean_.size
    return scaler


def narx_to_dict(model: NARXRegressor, metadata: dict[str, Any] | None = None) -> dict[str, Any]:
    """The state of a fitted NARX model with a GG-SVR inside, as JSON-ready data."""
    svr = getattr(model, "estimator_", None)
    if not isinstance(svr, GeneralizedGaussianSVR):
        raise ValueError(
            "The 'model' of narx_to_dict must be a fitted NARXRegressor whose estimator is a "
            f"GeneralizedGaussianSVR. Got estimator {type(svr).__name__} instead."
        )
    return {
        "format": FORMAT,
        "schema_version": SCHEMA_VERSION,
        "softbend_version": __version__,
        "metadata": dict(metadata or {}),
        "narx": {
            "params": {
                "output_lags": int(model.output_lags),
                "input_lags": int(model.input_lags),
                "include_current_input": bool(model.include_current_input),
                "scale": bool(model.scale),
            },
            "n_inputs": int(model.n_inputs_),
            "max_lag": int(model.max_lag_),
            "output_offsets": model.output_offsets_.tolist(),
            "input_offsets": model.input_offsets_.tolist(),
            "n_train_rows": int(model.n_train_rows_),
            "n_experiments": int(model.n_experiments_),
            "y_scaler": _scaler_state(model.y_scaler_),
            "u_scaler": _scaler_state(model.u_scaler_),
        },
        "estimator": {
            "class": "GeneralizedGaussianSVR",
            "params": {k: v for k, v in svr.get_params().items()},
            "n_features_in": int(svr.n_features_in_),
            "sigma": svr.sigma_,
            "shape": svr.shape_,
            "kernel_scale": svr.kernel_scale_,
            "intercept": svr.intercept_,
            "n_iter": int(svr.n_iter_),
            "dual_coef": svr.dual_coef_.tolist(),
            "support_vectors": svr.support_vectors_.tolist(),
        },
    }


def narx_from_dict(data: dict[str, Any]) -> NARXRegressor:
    """Rebuild a fitted NARX model from :func:`narx_to_dict` data."""
    if data.get("format") != FORMAT:
        raise SchemaError(
            f"Not a saved softbend NARX model: format {data.get('format')!r}, expected {FORMAT!r}."
        )
    version = data.get("schema_version")
    if not isinstance(version, int) or version > SCHEMA_VERSION:
        raise SchemaError(
            f"The saved model has schema version {version!r}; this softbend ({__version__}) "
            f"reads versions up to {SCHEMA_VERSION}. Upgrade softbend to load it."
        )
    state = data["estimator"]
    svr = GeneralizedGaussianSVR(**state["params"])
    svr.n_features_in_ = int(state["n_features_in"])
    svr.sigma_ = float(state["sigma"])
    svr.shape_ = float(state["shape"])
    svr.kernel_scale_ = float(state["kernel_scale"])
    svr.intercept_ = float(state["intercept"])
    svr.n_iter_ = int(state["n_iter"])
    svr.dual_coef_ = np.asarray(state["dual_coef"], dtype=float)
    svr.support_vectors_ = np.ascontiguousarray(
        np.asarray(state["support_vectors"], dtype=float).reshape(-1, svr.n_features_in_)
    )
    svr.n_support_ = int(svr.dual_coef_.size)
    svr._precompute()

    narx_state = data["narx"]
    model = NARXRegressor(
        estimator=GeneralizedGaussianSVR(**state["params"]), **narx_state["params"]
    )
    model.estimator_ = svr
    model.n_inputs_ = int(narx_state["n_inputs"])
    model.n_features_in_ = model.n_inputs_
    model.max_lag_ = int(narx_state["max_lag"])
    model.output_offsets_ = np.asarray(narx_state["output_offsets"], dtype=int)
    model.input_offsets_ = np.asarray(narx_state["input_offsets"], dtype=int)
    model.n_train_rows_ = int(narx_state["n_train_rows"])
    model.n_experiments_ = int(narx_state["n_experiments"])
    model.y_scaler_ = _scaler_from_state(narx_state["y_scaler"])
    model.u_scaler_ = _scaler_from_state(narx_state["u_scaler"])
    model.regressor_names_ = _regressor_names(model._fitted_structure(), model.n_inputs_)
    return model


def save_narx(
    model: NARXRegressor, path: str | Path, *, metadata: dict[str, Any] | None = None
) -> Path:
    """Write a fitted NARX/GG-SVR model to ``path`` (JSON, atomic) and return the path."""
    text = json.dumps(narx_to_dict(model, metadata), indent=1)
    return write_text_atomic(Path(path), text + "\n")


def load_narx(path: str | Path) -> tuple[NARXRegressor, dict[str, Any]]:
    """Load a model written by :func:`save_narx`; returns ``(model, metadata)``."""
    path = Path(path)
    if not path.is_file():
        raise FileNotFoundError(f"No saved model at {path}.")
    try:
        data = json.loads(path.read_text(encoding="utf-8"))
    except json.JSONDecodeError as err:
        raise SchemaError(f"{path} is not valid JSON: {err}.") from None
    return narx_from_dict(data), dict(data.get("metadata", {}))
