"""Save and load identified NARX models as plain JSON, without pickle.

A saved model holds the NARX lag structure and signal scaling, the fitted
generalized-Gaussian SVR (support vectors, dual coefficients, intercept, kernel
σ and shape), a schema version, the softbend version and free metadata (sign,
output, units, training experiments). Floats are written with ``repr``
precision, so a reloaded model predicts bit-identically.
"""

from __future__ import annotations

import json
import math
from collections.abc import Mapping
from pathlib import Path
from typing import Any

import numpy as np
from sklearn.preprocessing import StandardScaler

from softbend import __version__
from softbend._io import json_text, write_text_atomic
from softbend._jsontext import check_nesting
from softbend._validation import check_object_keys, interval_text, must_be
from softbend.errors import InputError, SchemaError
from softbend.identification.kernels import MOMENTS_OF
from softbend.identification.narx import NARXRegressor, _lag_structure, _regressor_names
from softbend.identification.svr import DEFAULT_MAX_WORKING_SET, GeneralizedGaussianSVR
from softbend.limits import check_file_size
from softbend.plausibility import implausible_text

FORMAT = "softbend.narx-gg-svr"
#: 2: the estimator parameters gained ``moments_of`` and ``max_working_set``. Version 1
#: files are read with ``moments_of="components"`` (how their shape was estimated) and
#: the default ``max_working_set``.
SCHEMA_VERSION = 2
_V1_DEFAULTS = {"moments_of": "components", "max_working_set": DEFAULT_MAX_WORKING_SET}


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
        raise InputError(
            "must be a fitted NARXRegressor whose estimator is a GeneralizedGaussianSVR; "
            f"got estimator {type(svr).__name__}",
            key="model",
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
        "estimator": svr_state(svr),
    }


# --- schema ------------------------------------------------------------------------------------
#
# Loading validates the whole document before building anything: the keys of every object
# (an unknown key is refused), the type of every value, the shapes of the arrays (support
# vectors (n_sv, n_features), scaler vectors per signal), finiteness and bounds (kernel width
# and scales > 0), and the lag structure against the NARX parameters. Every check raises a
# SchemaError keyed by the value's place in the document ("narx.params.output_lags") with
# the shared wording of softbend._validation; load_narx adds the file.


def _object(value: object, key: str, keys: tuple[str, ...]) -> Mapping[str, Any]:
    if not isinstance(value, Mapping):
        raise SchemaError(must_be("a JSON object", value), key=key)
    return check_object_keys(value, key, keys, keys, SchemaError)


def _int(value: object, key: str, low: int) -> int:
    if type(value) is not int or value < low:
        raise SchemaError(must_be(f"an integer in [{low}, inf)", value), key=key)
    return value


def _bool(value: object, key: str) -> bool:
    if not isinstance(value, bool):
        raise SchemaError(must_be("true or false", value), key=key)
    return value


def _real(
    value: object,
    key: str,
    *,
    low: float = -math.inf,
    strict: bool = False,
    high: float = math.inf,
) -> float:
    """A finite JSON number in ``[low, high]`` (``(low, high]`` if ``strict``)."""
    if math.isinf(low) and math.isinf(high):
        rule = "a finite number"
    else:
        rule = "a number in " + interval_text(
            low, high, low_inclusive=not strict, high_inclusive=True
        )
    json_number = isinstance(value, int | float) and not isinstance(value, bool)
    number = float(value) if json_number and isinstance(value, int | float) else math.nan
    inside = (number > low if strict else number >= low) and number <= high
    if not (math.isfinite(number) and inside):
        raise SchemaError(must_be(rule, value), key=key)
    return number


def _vector(
    value: object,
    key: str,
    length: int | None = None,
    *,
    low: float = -math.inf,
    strict: bool = False,
) -> np.ndarray:
    if not isinstance(value, list) or (length is not None and len(value) != length):
        size = f"{length} " if length is not None else ""
        raise SchemaError(must_be(f"a list of {size}numbers", value), key=key)
    for i, item in enumerate(value):
        _real(item, f"{key}[{i}]", low=low, strict=strict)
    return np.asarray(value, dtype=float)


def _kernel_width(value: object, key: str) -> float:
    """A kernel width σ: a finite number in the plausible range of kernel widths."""
    width = _real(value, key, low=0.0, strict=True)
    problem = implausible_text(width, "kernel_width")
    if problem is not None:
        raise SchemaError(problem.rstrip("."), key=key)
    return width


def _int_vector(value: object, key: str, length: int | None = None) -> np.ndarray:
    if not isinstance(value, list) or (length is not None and len(value) != length):
        size = f"{length} " if length is not None else ""
        raise SchemaError(must_be(f"a list of {size}integers", value), key=key)
    for i, item in enumerate(value):
        _int(item, f"{key}[{i}]", 0)
    return np.asarray(value, dtype=int)


def _matrix(value: object, key: str, rows: int, columns: int) -> np.ndarray:
    if not isinstance(value, list) or len(value) != rows:
        raise SchemaError(
            must_be(f"a list of {rows} rows (one per dual coefficient)", value), key=key
        )
    for i, row in enumerate(value):
        _vector(row, f"{key}[{i}]", columns)
    return np.asarray(value, dtype=float).reshape(rows, columns)


_SCALER_KEYS = ("mean", "scale", "var", "n_samples_seen")


def _scaler(value: object, key: str, scale: bool, size: int) -> Mapping[str, Any] | None:
    if not scale:
        if value is not None:
            raise SchemaError(must_be("null when 'narx.params.scale' is false", value), key=key)
        return None
    state = _object(value, key, _SCALER_KEYS)
    _vector(state["mean"], f"{key}.mean", size)
    _vector(state["scale"], f"{key}.scale", size, low=0.0, strict=True)
    _vector(state["var"], f"{key}.var", size, low=0.0)
    _int(state["n_samples_seen"], f"{key}.n_samples_seen", 1)
    return state


_TOP_KEYS = ("format", "schema_version", "softbend_version", "metadata", "narx", "estimator")
_NARX_KEYS = (
    "params",
    "n_inputs",
    "max_lag",
    "output_offsets",
    "input_offsets",
    "n_train_rows",
    "n_experiments",
    "y_scaler",
    "u_scaler",
)
_NARX_PARAMS = ("output_lags", "input_lags", "include_current_input", "scale")
_ESTIMATOR_KEYS = (
    "class",
    "params",
    "n_features_in",
    "sigma",
    "shape",
    "kernel_scale",
    "intercept",
    "n_iter",
    "dual_coef",
    "support_vectors",
)


def _svr_params(value: object) -> Mapping[str, Any]:
    where = "estimator.params"
    params = _object(value, where, tuple(GeneralizedGaussianSVR._get_param_names()))
    for key in ("C", "tol", "cache_size"):
        _real(params[key], f"{where}.{key}", low=0.0, strict=True)
    _real(params["epsilon"], f"{where}.epsilon", low=0.0)
    if params["sigma"] is not None:
        _kernel_width(params["sigma"], f"{where}.sigma")
    if params["shape"] is not None:
        _real(params["shape"], f"{where}.shape", low=0.0, strict=True, high=2.0)
    _bool(params["normalize"], f"{where}.normalize")
    _int(params["max_iter"], f"{where}.max_iter", -1)
    _int(params["max_working_set"], f"{where}.max_working_set", 8)
    if params["moments_of"] not in MOMENTS_OF:
        raise SchemaError(
            must_be(f"one of {', '.join(map(repr, MOMENTS_OF))}", params["moments_of"]),
            key=f"{where}.moments_of",
        )
    return params


def _check_document(data: dict[str, Any]) -> None:
    """Raise :class:`SchemaError` (keyed) unless ``data`` holds a complete, consistent model."""
    _object(data, "(top level)", _TOP_KEYS)
    if not isinstance(data["softbend_version"], str):
        raise SchemaError(must_be("a string", data["softbend_version"]), key="softbend_version")
    if not isinstance(data["metadata"], dict):
        raise SchemaError(must_be("a JSON object", data["metadata"]), key="metadata")

    narx = _object(data["narx"], "narx", _NARX_KEYS)
    params = _object(narx["params"], "narx.params", _NARX_PARAMS)
    na = _int(params["output_lags"], "narx.params.output_lags", 1)
    nb = _int(params["input_lags"], "narx.params.input_lags", 1)
    current = _bool(params["include_current_input"], "narx.params.include_current_input")
    scale = _bool(params["scale"], "narx.params.scale")
    n_inputs = _int(narx["n_inputs"], "narx.n_inputs", 1)
    # The offsets are lists in the file: their lengths bound the lags before any array is made.
    _int_vector(narx["output_offsets"], "narx.output_offsets", na)
    _int_vector(narx["input_offsets"], "narx.input_offsets", nb)
    structure = _lag_structure(na, nb, current)
    for key, expected in (
        ("max_lag", structure.max_lag),
        ("output_offsets", structure.output_offsets.tolist()),
        ("input_offsets", structure.input_offsets.tolist()),
    ):
        found = narx[key]
        if isinstance(expected, int):
            _int(found, f"narx.{key}", 0)
        else:
            _int_vector(found, f"narx.{key}")
        if found != expected:
            raise SchemaError(
                must_be(
                    f"{expected} for output_lags={na}, input_lags={nb}, "
                    f"include_current_input={str(current).lower()}",
                    found,
                ),
                key=f"narx.{key}",
            )
    _int(narx["n_train_rows"], "narx.n_train_rows", 0)
    _int(narx["n_experiments"], "narx.n_experiments", 0)
    _scaler(narx["y_scaler"], "narx.y_scaler", scale, 1)
    _scaler(narx["u_scaler"], "narx.u_scaler", scale, n_inputs)

    estimator = _object(data["estimator"], "estimator", _ESTIMATOR_KEYS)
    if estimator["class"] != "GeneralizedGaussianSVR":
        raise SchemaError(
            must_be("'GeneralizedGaussianSVR'", estimator["class"]), key="estimator.class"
        )
    _svr_params(estimator["params"])
    n_features = na + n_inputs * nb
    if estimator["n_features_in"] != n_features or type(estimator["n_features_in"]) is not int:
        raise SchemaError(
            must_be(
                f"{n_features} (output_lags + n_inputs x input_lags)", estimator["n_features_in"]
            ),
            key="estimator.n_features_in",
        )
    _kernel_width(estimator["sigma"], "estimator.sigma")
    _real(estimator["shape"], "estimator.shape", low=0.0, strict=True, high=2.0)
    _real(estimator["kernel_scale"], "estimator.kernel_scale", low=0.0, strict=True)
    _real(estimator["intercept"], "estimator.intercept")
    _int(estimator["n_iter"], "estimator.n_iter", 0)
    dual_coef = _vector(estimator["dual_coef"], "estimator.dual_coef")
    _matrix(estimator["support_vectors"], "estimator.support_vectors", dual_coef.size, n_features)


def svr_state(svr: GeneralizedGaussianSVR) -> dict[str, Any]:
    """A fitted GG-SVR's parameters and solution as JSON-ready data (:func:`svr_from_state`)."""
    return {
        "class": "GeneralizedGaussianSVR",
        "params": dict(svr.get_params()),
        "n_features_in": int(svr.n_features_in_),
        "sigma": svr.sigma_,
        "shape": svr.shape_,
        "kernel_scale": svr.kernel_scale_,
        "intercept": svr.intercept_,
        "n_iter": int(svr.n_iter_),
        "dual_coef": svr.dual_coef_.tolist(),
        "support_vectors": svr.support_vectors_.tolist(),
    }


def svr_from_state(state: Mapping[str, Any]) -> GeneralizedGaussianSVR:
    """The fitted GG-SVR of :func:`svr_state` data (checked by the caller), predicting bit for
    bit as the one saved."""
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
    svr.shape_estimate_ = None  # the moment diagnostics are not stored
    svr._precompute()
    return svr


def narx_from_dict(data: object) -> NARXRegressor:
    """Rebuild a fitted NARX model from :func:`narx_to_dict` data.

    Every key and value is checked first (see the schema above); a
    :class:`SchemaError` is keyed by the place of the value at fault.
    """
    if not isinstance(data, dict) or data.get("format") != FORMAT:
        found = data.get("format") if isinstance(data, dict) else type(data).__name__
        raise SchemaError(
            f"must be {FORMAT!r}: not a saved softbend NARX model; got {found!r}", key="format"
        )
    version = data.get("schema_version")
    if isinstance(version, bool) or not isinstance(version, int) or version < 1:
        raise SchemaError(
            must_be(f"an integer in [1, {SCHEMA_VERSION}]", version), key="schema_version"
        )
    if version > SCHEMA_VERSION:
        raise SchemaError(
            f"must be at most {SCHEMA_VERSION}, the newest this softbend ({__version__}) "
            f"reads; got schema version {version}: upgrade softbend to load it",
            key="schema_version",
        )
    estimator = data.get("estimator")
    if version == 1 and isinstance(estimator, dict) and isinstance(estimator.get("params"), dict):
        data = {**data, "estimator": {**estimator}}  # the caller's dict stays as it was
        data["estimator"]["params"] = {**_V1_DEFAULTS, **estimator["params"]}
    _check_document(data)

    state = data["estimator"]
    svr = svr_from_state(state)

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
    """Write a fitted NARX/GG-SVR model to ``path`` (strict JSON, atomic) and return the path.

    The JSON is strict (:func:`softbend._io.json_text`): a NaN or infinite value
    in ``metadata`` is written as null. The model's own numbers are finite.
    """
    text = json_text(narx_to_dict(model, metadata), indent=1)
    return write_text_atomic(Path(path), text + "\n")


def load_narx(path: str | Path) -> tuple[NARXRegressor, dict[str, Any]]:
    """Load a model written by :func:`save_narx`; returns ``(model, metadata)``.

    Raises
    ------
    FileNotFoundError
        If ``path`` is not a file.
    softbend.errors.SchemaError
        If the file is not JSON, is nested deeper than the ``nesting`` limit of
        :mod:`softbend.limits` (checked before parsing), is not a saved NARX
        model, has a newer schema, an unknown or missing key, or a value of the
        wrong type or shape, non-finite or out of bounds (a kernel width outside
        the plausible range of :mod:`softbend.plausibility` included); the
        one-line message names the file and the key.
    softbend.errors.LimitError
        If the file is larger than the ``file_mib`` limit of :mod:`softbend.limits`.
    """
    path = Path(path)
    if not path.is_file():
        raise FileNotFoundError(f"No saved model at {path}.")
    check_file_size(path)
    try:
        text = path.read_text(encoding="utf-8")
        check_nesting(text, str(path), SchemaError)
        data = json.loads(text)
    except (json.JSONDecodeError, UnicodeDecodeError) as err:
        raise SchemaError(f"is not valid JSON: {err}", file=str(path)) from None
    except RecursionError:
        raise SchemaError("is nested too deeply to read", file=str(path)) from None
    try:
        model = narx_from_dict(data)
    except SchemaError as error:
        error.file = str(path)
        raise
    return model, dict(data["metadata"])
