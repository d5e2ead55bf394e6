"""Save and load fitted surrogates as one JSON file, without pickle.

A saved surrogate records what it is (``kind``), how it was configured
(``params``, from ``get_params``), what it learned (``state``: the fitted
arrays as nested lists, or the XGBoost booster as JSON text), what it maps
(``features`` and ``units`` of :mod:`softbend.surrogates.features`, ``target``)
and where it came from (``softbend_version``, ``created_utc`` and the caller's
``metadata``, e.g. the training data hash and cross-validated metrics)::

    {"format": "softbend-surrogate", "schema_version": 1, "kind": "polynomial",
     "features": [...], "units": {...}, "target": "angle_deg",
     "softbend_version": "0.1.0", "created_utc": "2025-01-01T00:00:00+00:00",
     "metadata": {...}, "params": {...}, "state": {...}}

Python writes a float with the shortest decimal that reads back to the same
float64 (``repr``), so a reloaded polynomial or MLP predicts bit for bit what
the saved one did; XGBoost restores its own JSON model exactly. The file is
strict JSON (no bare ``NaN`` or ``Infinity``, which most JSON readers refuse):
XGBoost's ``missing`` (NaN by default) is written as ``null`` and read back as
NaN, any other NaN or infinite parameter or fitted value as
``{"__float__": "nan"}`` (``"inf"``, ``"-inf"``), and NaN or infinite numbers in
the caller's ``metadata`` as ``null``. Files of earlier versions, with bare
``NaN``, still load.

Arrays are stored as ``{"__ndarray__": nested list, "dtype": ..., "shape": ...}``,
NumPy scalars as ``{"__scalar__": value, "dtype": ...}`` and tuples as
``{"__tuple__": [...]}``, so dtypes and parameter types come back unchanged.
Fitted attributes that are none of these (a framework object such as a torch
module) are not written; everything ``predict`` needs under the surrogate
contract is.

Loading trusts nothing in the file: each kind has a schema (``SCHEMAS``) listing
its ``params`` and ``state`` keys with a rule for each value (type, dtype,
dimensions, finiteness, bounds such as scales > 0) and rules across keys (the
chained layer shapes of an MLP, a complete exponent table of a polynomial, the
declared sizes against the arrays, plausible parameters of a correction). The
header's ``units`` must be those of this softbend and the ``training_ranges``
in ``metadata`` (if any) one plausible ``[low, high]`` per input. A file nested
deeper than the ``nesting`` limit of :mod:`softbend.limits` is a
:class:`~softbend.errors.LimitError`; a key the schema does not know, or a value
breaking its rule, is a :class:`~softbend.errors.SchemaError` of one line naming
the file, the key and the rule; only validated keys are ever set on the model.
"""

from __future__ import annotations

import importlib
import json
import logging
import math
import sys
import warnings
from dataclasses import dataclass, field
from datetime import UTC, datetime
from pathlib import Path
from typing import Any

import numpy as np
from sklearn.exceptions import NotFittedError

from softbend import __version__
from softbend._extras import require
from softbend._io import json_safe, write_text_atomic
from softbend._validation import short_repr
from softbend.errors import SchemaError
from softbend.limits import check_limit, limit
from softbend.plausibility import RANGES, implausible_index
from softbend.surrogates.features import FEATURES, TARGET, UNITS
from softbend.surrogates.schema import (
    QUANTITIES,
    SCHEMAS,
    Rule,
    RuleError,
    tag_float,
    untag_float,
)

logger = logging.getLogger(__name__)

__all__ = [
    "BASE_KINDS",
    "COMPOSITE_KINDS",
    "FORMAT",
    "KINDS",
    "SCHEMA_VERSION",
    "SavedSurrogate",
    "check_fitted_surrogate",
    "kind_of",
    "load_surrogate",
    "save_surrogate",
]

#: Format tag of a saved surrogate file.
FORMAT = "softbend-surrogate"

#: Newest schema version this softbend writes and reads.
SCHEMA_VERSION = 1

#: Surrogate kinds and the (module, class) each is restored into.
_CLASSES: dict[str, tuple[str, str]] = {
    "polynomial": ("softbend.surrogates.polynomial", "PolynomialRegressor"),
    "mlp": ("softbend.surrogates.mlp", "NormalizedMLPRegressor"),
    "xgboost": ("xgboost", "XGBRegressor"),
    "affine-corrected": ("softbend.surrogates.corrected", "AffineCorrected"),
    "gp-corrected": ("softbend.surrogates.corrected", "GPCorrected"),
    "ensemble": ("softbend.surrogates.corrected", "MeanEnsemble"),
    "pressure-scaled": ("softbend.surrogates.corrected", "PressureScaled"),
}

#: Kinds built on other surrogates (:mod:`softbend.surrogates.corrected`): their
#: ``state`` holds the inner surrogates as whole documents (``base``, ``members``).
COMPOSITE_KINDS: tuple[str, ...] = (
    "affine-corrected",
    "gp-corrected",
    "ensemble",
    "pressure-scaled",
)

#: Inner surrogates nest at most this deep (a corrected ensemble of corrected MLPs).
_MAX_DEPTH = 4

#: Kinds of surrogate that can be saved.
KINDS: tuple[str, ...] = tuple(_CLASSES)

#: Kinds trained on data directly (the three families of paper B).
BASE_KINDS: tuple[str, ...] = tuple(k for k in KINDS if k not in COMPOSITE_KINDS)

#: Fitted attributes that prediction needs (the surrogate contract), per kind.
_REQUIRED_STATE: dict[str, tuple[str, ...]] = {
    "polynomial": (
        "n_features_in_",
        "x_mean_",
        "x_scale_",
        "y_mean_",
        "y_scale_",
        "powers_",
        "coef_",
    ),
    "mlp": (
        "n_features_in_",
        "x_mean_",
        "x_scale_",
        "y_mean_",
        "y_scale_",
        "coefs_",
        "intercepts_",
    ),
    "xgboost": ("booster",),
    "affine-corrected": ("base", "scale_", "offset_", "residual_std_"),
    "gp-corrected": ("base", "z_mean_", "z_scale_", "kernel_theta_", "inputs_", "targets_"),
    "ensemble": ("members", "residual_std_"),
    "pressure-scaled": ("base", "scale_", "residual_std_"),
}

_HEADER_KEYS = (
    "kind",
    "features",
    "units",
    "target",
    "softbend_version",
    "created_utc",
    "metadata",
    "params",
    "state",
)


@dataclass(frozen=True)
class SavedSurrogate:
    """A surrogate read back by :func:`load_surrogate`.

    Attributes
    ----------
    model : estimator
        The fitted surrogate (``PolynomialRegressor``, ``NormalizedMLPRegressor``
        or ``xgboost.XGBRegressor``); it maps inputs :data:`FEATURES` (mm, deg, MPa)
        to the bending angle in degrees.
    kind : str
        One of :data:`KINDS`.
    metadata : dict
        The caller's metadata as given to :func:`save_surrogate` (after a JSON
        round trip: tuples become lists, NumPy numbers Python numbers).
    softbend_version : str
        Version of softbend that wrote the file.
    created_utc : str
        When the file was written, ISO 8601 in UTC.
    """

    model: Any
    kind: str
    metadata: dict[str, Any] = field(default_factory=dict)
    softbend_version: str = ""
    created_utc: str = ""


def _class_of(kind: str) -> type:
    module, name = _CLASSES[kind]
    if module == "xgboost":
        return getattr(require("xgboost", "An XGBoost surrogate"), name)
    return getattr(importlib.import_module(module), name)


def _allowed() -> str:
    return ", ".join(f"{name} ({kind!r})" for kind, (_, name) in _CLASSES.items())


def kind_of(model: Any) -> str:
    """The kind of a surrogate: ``"polynomial"``, ``"mlp"`` or ``"xgboost"``.

    Only the exact classes count (a subclass could change what ``params`` and
    ``state`` mean). No heavy module is imported: a model's class is loaded
    whenever the model exists.

    Parameters
    ----------
    model : estimator
        A ``PolynomialRegressor``, ``NormalizedMLPRegressor`` or ``xgboost.XGBRegressor``.

    Returns
    -------
    str
        One of :data:`KINDS`.

    Raises
    ------
    ValueError
        For any other type, naming the allowed ones.
    """
    for kind, (module, name) in _CLASSES.items():
        cls = getattr(sys.modules.get(module), name, None)
        if cls is not None and type(model) is cls:
            return kind
    raise ValueError(
        f"The 'model' of kind_of must be one of {_allowed()}. Got {type(model).__name__} instead."
    )


def check_fitted_surrogate(model: Any, owner: str) -> str:
    """Return the kind of a fitted surrogate on the 7 inputs, or raise a clear error.

    Parameters
    ----------
    model : estimator
        The surrogate to check.
    owner : str
        Name of the calling function, used in the messages.

    Returns
    -------
    str
        The model's kind.

    Raises
    ------
    ValueError
        Unknown model type, or a model fitted on other than the 7 :data:`FEATURES`.
    sklearn.exceptions.NotFittedError
        If the model is not fitted (a ``ValueError`` too).
    """
    try:
        kind = kind_of(model)
    except ValueError:
        raise ValueError(
            f"The 'model' of {owner} must be one of {_allowed()}. "
            f"Got {type(model).__name__} instead."
        ) from None
    name = type(model).__name__
    if kind == "xgboost":
        fitted = model.__sklearn_is_fitted__()
    elif kind in COMPOSITE_KINDS:
        fitted = True  # built from fitted surrogates, each checked when saved
    else:
        fitted = all(hasattr(model, key) for key in _REQUIRED_STATE[kind])
    if not fitted:
        raise NotFittedError(f"This {name} instance is not fitted yet. Call 'fit' before {owner}.")
    n_features = int(model.n_features_in_)
    if n_features != len(FEATURES):
        raise ValueError(
            f"The 'model' of {owner} must be fitted on the {len(FEATURES)} surrogate inputs "
            f"({', '.join(FEATURES)}). Got a {name} with n_features_in_ = {n_features} instead."
        )
    names = getattr(model, "feature_names_in_", None)
    if names is not None and [str(n) for n in names] != list(FEATURES):
        raise ValueError(
            f"The 'model' of {owner} must be fitted on the columns {', '.join(FEATURES)} in "
            f"this order. Got a {name} fitted on {', '.join(map(str, names))} instead."
        )
    return kind


# --- JSON codec --------------------------------------------------------------------------------


def _tagged(nested: Any) -> Any:
    """A nested list of an array's elements with its NaN and infinities as tags."""
    if isinstance(nested, list):
        return [_tagged(v) for v in nested]
    return tag_float(nested) if isinstance(nested, float) else nested


def _encode(value: Any, where: str) -> Any:
    """Strict-JSON form of ``value`` that :func:`_decode` turns back into an equal object.

    A NaN or infinite float is written as ``{"__float__": "nan" | "inf" | "-inf"}``.
    """
    if isinstance(value, float):  # Python floats and NumPy float64: plain numbers
        return tag_float(value)
    if value is None or isinstance(value, bool | int | str):
        return value
    if isinstance(value, np.generic | np.ndarray):
        array = np.asarray(value)
        if array.dtype.kind in "biuf":
            dtype = array.dtype.name
        elif array.dtype.kind in "OU" and all(isinstance(v, str) for v in array.ravel()):
            dtype = "str"
        else:
            raise TypeError(f"{where}: arrays of dtype {array.dtype} cannot be saved")
        finite = array.dtype.kind != "f" or bool(np.isfinite(array).all())
        if isinstance(value, np.generic):
            item = value.item()
            return {"__scalar__": item if finite else tag_float(item), "dtype": dtype}
        nested = array.tolist() if finite else _tagged(array.tolist())
        return {"__ndarray__": nested, "dtype": dtype, "shape": list(array.shape)}
    if isinstance(value, tuple):
        return {"__tuple__": [_encode(v, where) for v in value]}
    if isinstance(value, list):
        return [_encode(v, where) for v in value]
    if isinstance(value, dict) and all(isinstance(k, str) for k in value):
        return {k: _encode(v, where) for k, v in value.items()}
    raise TypeError(f"{where}: values of type {type(value).__name__} cannot be saved")


def _untagged(nested: Any) -> Any:
    """A nested list of an array's elements with its tags of non-finite floats as floats."""
    if isinstance(nested, list):
        return [_untagged(v) for v in nested]
    return untag_float(nested)


def _dtype(name: Any) -> np.dtype:
    """The NumPy dtype ``name`` of a saved array or scalar: a bool, integer or float one."""
    dtype = np.dtype(name) if isinstance(name, str) else None
    if dtype is None or dtype.kind not in "biuf":
        raise TypeError(f"dtype {short_repr(name)} is none of bool, integer, float or 'str'")
    return dtype


def _decode(value: Any) -> Any:
    """The object :func:`_encode` wrote (raises KeyError, TypeError, ValueError, RuleError)."""
    if isinstance(value, list):
        return [_decode(v) for v in value]
    if not isinstance(value, dict):
        return value
    if "__float__" in value:
        return untag_float(value)
    if "__ndarray__" in value:
        if value["dtype"] == "str":
            array = np.asarray(value["__ndarray__"], dtype=object)
        else:
            array = np.asarray(_untagged(value["__ndarray__"]), dtype=_dtype(value["dtype"]))
        return np.ascontiguousarray(array.reshape(value["shape"]))
    if "__scalar__" in value:
        if value["dtype"] == "str":
            return np.str_(value["__scalar__"])
        return _dtype(value["dtype"]).type(untag_float(value["__scalar__"]))
    if "__tuple__" in value:
        return tuple(_decode(v) for v in value["__tuple__"])
    return {k: _decode(v) for k, v in value.items()}


def _plain_json(value: Any) -> Any:
    """``json.dumps`` fallback for caller metadata: NumPy numbers and arrays as Python ones."""
    if isinstance(value, np.generic | np.ndarray):
        return value.tolist()
    if isinstance(value, Path):
        return str(value)
    raise TypeError(f"values of type {type(value).__name__} are not JSON-serializable")


# --- save --------------------------------------------------------------------------------------


def _params(model: Any, kind: str) -> dict[str, Any]:
    params = {}
    for key, value in model.get_params(deep=False).items():
        try:
            params[key] = _encode(value, key)
        except TypeError:
            raise ValueError(
                f"The parameter '{key}' of {type(model).__name__} must be JSON-serializable to "
                f"save the model (None, numbers, strings, arrays, lists, tuples, dicts). "
                f"Got {type(value).__name__} instead."
            ) from None
    if kind == "xgboost" and params.get("missing") == tag_float(math.nan):
        params["missing"] = None  # XGBoost's default NaN, as strict JSON; read back as NaN
    return params


def _document(model: Any, kind: str, depth: int = 0) -> dict[str, Any]:
    """The saved form of a checked model, without ``metadata``."""
    return {
        "format": FORMAT,
        "schema_version": SCHEMA_VERSION,
        "kind": kind,
        "features": list(FEATURES),
        "units": {name: UNITS[name] for name in (*FEATURES, TARGET)},
        "target": TARGET,
        "softbend_version": __version__,
        "created_utc": datetime.now(UTC).isoformat(timespec="seconds"),
        "params": {} if kind in COMPOSITE_KINDS else _params(model, kind),
        "state": _state(model, kind, depth),
    }


def _inner(model: Any, depth: int) -> dict[str, Any]:
    """An inner surrogate of a composite as a whole document (empty metadata)."""
    if depth >= _MAX_DEPTH:
        raise ValueError(
            f"save_surrogate nests surrogates at most {_MAX_DEPTH} deep; this model nests deeper."
        )
    kind = check_fitted_surrogate(model, "save_surrogate")
    return {**_document(model, kind, depth + 1), "metadata": {}}


def _composite_state(model: Any, kind: str, depth: int) -> dict[str, Any]:
    if kind == "ensemble":
        state = {"members": [_inner(m, depth) for m in model.members_]}
    else:
        state = {"base": _inner(model.base, depth)}
    names = [key for key in _REQUIRED_STATE[kind] if key not in ("base", "members")]
    return state | {key: _encode(getattr(model, key), key) for key in names}


def _state(model: Any, kind: str, depth: int = 0) -> dict[str, Any]:
    if kind in COMPOSITE_KINDS:
        return _composite_state(model, kind, depth)
    if kind == "xgboost":
        return {"booster": bytes(model.get_booster().save_raw("json")).decode("utf-8")}
    state = {}
    fitted = [k for k in vars(model) if k.endswith("_") and not k.startswith("_")]
    for key in fitted:
        try:
            state[key] = _encode(getattr(model, key), key)
        except TypeError as err:
            if key in _REQUIRED_STATE[kind]:
                raise ValueError(
                    f"The fitted attribute '{key}' of {type(model).__name__} cannot be saved: "
                    f"{err}."
                ) from None
            logger.debug("save_surrogate leaves out %s: %s", key, err)
    return state


def save_surrogate(model: Any, path: str | Path, *, metadata: dict[str, Any] | None = None) -> Path:
    """Write a fitted surrogate to one JSON file (atomically) and return its path.

    Parameters
    ----------
    model : estimator
        A fitted ``PolynomialRegressor``, ``NormalizedMLPRegressor`` or
        ``xgboost.XGBRegressor`` on the 7 inputs :data:`FEATURES` (mm, deg, MPa),
        predicting the bending angle in degrees.
    path : str or Path
        File to write; parent folders are created. An existing file is replaced
        only once the new one is complete.
    metadata : dict, optional
        JSON-serializable provenance with string keys, e.g. ``data_hash``,
        ``metrics``, ``cv``; NumPy numbers and arrays are written as Python ones,
        NaN and infinities as ``null`` (the file is strict JSON).

    Returns
    -------
    Path
        The written file.

    Raises
    ------
    ValueError
        Unknown model type (naming the allowed kinds), a model fitted on other than
        7 features, a parameter or ``metadata`` that JSON cannot hold.
    sklearn.exceptions.NotFittedError
        If the model is not fitted.
    """
    kind = check_fitted_surrogate(model, "save_surrogate")
    if metadata is None:
        metadata = {}
    if not isinstance(metadata, dict) or not all(isinstance(k, str) for k in metadata):
        raise ValueError(
            "The 'metadata' of save_surrogate must be a dict with string keys. "
            f"Got {type(metadata).__name__} instead."
        )
    try:  # strict JSON: NaN and infinities become null
        metadata_json = json.dumps(json_safe(metadata), default=_plain_json, allow_nan=False)
    except (TypeError, ValueError, RecursionError) as err:
        raise ValueError(
            f"The 'metadata' of save_surrogate must be JSON-serializable. Got an error: {err}."
        ) from None
    document = _document(model, kind)
    # One top-level key per line: the header stays readable, big arrays stay on one line.
    # Every non-finite float is tagged by _encode, so the text is strict JSON.
    lines = [
        f"{json.dumps(key)}: {json.dumps(value, allow_nan=False)}"
        for key, value in document.items()
    ]
    lines.insert(-2, f'"metadata": {metadata_json}')
    return write_text_atomic(Path(path), "{\n " + ",\n ".join(lines) + "\n}\n")


# --- load --------------------------------------------------------------------------------------


def _depth(value: Any) -> int:
    """How deep JSON objects and arrays nest in ``value`` (a number 0, ``[]`` 1), iteratively."""
    deepest, stack = 0, [(value, 1)] if isinstance(value, dict | list) else []
    while stack:
        item, level = stack.pop()
        children = item.values() if isinstance(item, dict) else item
        deepest = max(deepest, level)
        stack.extend((child, level + 1) for child in children if isinstance(child, dict | list))
    return deepest


def _read_document(path: Path) -> dict[str, Any]:
    if not path.is_file():
        raise FileNotFoundError(f"No saved surrogate at {path}.")
    try:
        document = json.loads(path.read_text(encoding="utf-8"))
    except (ValueError, UnicodeDecodeError) as err:  # JSONDecodeError, a 5000-digit number
        raise SchemaError(f"{path} is not a softbend surrogate: not valid JSON ({err}).") from None
    except RecursionError:  # the parser recurses once per level
        raise SchemaError(
            f"{path} is not a softbend surrogate: its JSON nests too deeply to be read (a "
            f"softbend surrogate nests at most {limit('nesting')} levels, the limit "
            "SOFTBEND_MAX_NESTING)."
        ) from None
    check_limit("nesting", _depth(document), f"The JSON nesting of {path}")
    return _checked_document(document, str(path))


def _checked_document(document: Any, path: str) -> dict[str, Any]:
    """``document`` if its header is that of a softbend surrogate (``path`` names it)."""
    if not isinstance(document, dict) or document.get("format") != FORMAT:
        found = document.get("format") if isinstance(document, dict) else type(document).__name__
        shown = repr(found) if isinstance(found, str | None) else short_repr(found)
        raise SchemaError(
            f"{path} is not a softbend surrogate: format {shown}, expected {FORMAT!r}."
        )
    version = document.get("schema_version")
    if isinstance(version, bool) or not isinstance(version, int) or version < 1:
        shown = repr(version) if isinstance(version, str | None) else short_repr(version)
        raise SchemaError(
            f"{path} has an invalid schema_version {shown}; expected an integer "
            f"from 1 to {SCHEMA_VERSION}."
        )
    if version > SCHEMA_VERSION:
        raise SchemaError(
            f"{path} has schema version {version}, newer than this softbend ({__version__}) "
            f"reads (up to {SCHEMA_VERSION}). Upgrade softbend to load it."
        )
    missing = [key for key in _HEADER_KEYS if key not in document]
    if missing:
        raise SchemaError(
            f"{path} is an incomplete softbend surrogate: key(s) {', '.join(missing)} missing."
        )
    unknown = [key for key in document if key not in ("format", "schema_version", *_HEADER_KEYS)]
    if unknown:
        raise SchemaError(
            f"{path}: unknown key(s) {', '.join(map(repr, unknown))} in a softbend surrogate; "
            f"allowed keys: format, schema_version, {', '.join(_HEADER_KEYS)}."
        )
    kind = document["kind"]
    if not isinstance(kind, str) or kind not in _CLASSES:
        shown = repr(kind) if isinstance(kind, str) else short_repr(kind)
        raise SchemaError(
            f"{path} holds an unknown surrogate kind {shown}; "
            f"expected one of {', '.join(map(repr, KINDS))}."
        )
    if document["features"] != list(FEATURES) or document["target"] != TARGET:
        raise SchemaError(
            f"{path} maps {short_repr(document['features'])} -> {short_repr(document['target'])}"
            f"; this softbend's surrogates map {list(FEATURES)} -> {TARGET!r}."
        )
    for key in ("params", "state", "metadata", "units"):
        if not isinstance(document[key], dict):
            raise SchemaError(f"{path}: '{key}' must be a JSON object.")
    units = {name: UNITS[name] for name in (*FEATURES, TARGET)}
    if document["units"] != units:
        wrong = next(
            (name for name in units if document["units"].get(name) != units[name]),
            next(iter(set(document["units"]) - set(units)), ""),
        )
        got = short_repr(document["units"].get(wrong)) if wrong in document["units"] else "none"
        raise SchemaError(
            f"{path}: 'units' must be {json.dumps(units)} (the units every softbend surrogate "
            f"maps); got {got} for {wrong!r}."
        )
    for key in ("softbend_version", "created_utc"):
        if not isinstance(document[key], str):
            raise SchemaError(f"{path}: '{key}' must be a string; got {short_repr(document[key])}.")
    return document


def _validated(
    values: dict[str, Any], rules: dict[str, Rule], path: Path, kind: str, section: str
) -> dict[str, Any]:
    """``values`` decoded by their rules; a key without a rule or a broken rule raises."""
    unknown = [key for key in values if key not in rules]
    if unknown:
        raise SchemaError(
            f"{path}: unknown {section} key(s) {', '.join(map(repr, unknown))} for the {kind} "
            f"surrogate; allowed keys: {', '.join(rules)}."
        )
    decoded = {}
    for key, value in values.items():
        try:
            decoded[key] = rules[key](value)
        except RuleError as err:
            raise SchemaError(
                f"{path}: {section} key '{key}' of the {kind} surrogate {err}."
            ) from None
    return decoded


def _xgboost_params(params: dict[str, Any], path: Path) -> tuple[dict[str, Any], set[str]]:
    """Decoded XGBoost parameters and the names of the standard ones.

    XGBoost takes extra keyword parameters (passed on to the booster, kept in
    ``kwargs``); such a key is accepted unless it could name an attribute of the
    estimator (a method such as ``predict``, a private name).
    """
    cls = _class_of("xgboost")
    standard = set(cls().get_params(deep=False))
    unknown = [
        key
        for key in params
        if key not in standard
        and (not key.isidentifier() or key.startswith("_") or hasattr(cls, key))
    ]
    if unknown:
        raise SchemaError(
            f"{path}: unknown params key(s) {', '.join(map(repr, unknown))} for the xgboost "
            f"surrogate; allowed keys: {', '.join(sorted(standard))} and XGBoost's extra "
            "booster parameters."
        )
    try:
        decoded = {key: _decode(value) for key, value in params.items()}
    except (KeyError, TypeError, ValueError, AttributeError, RuleError) as err:
        raise SchemaError(
            f"{path}: params of the xgboost surrogate cannot be read ({err})."
        ) from None
    if "missing" in decoded:  # null: XGBoost's default NaN (how save_surrogate writes it)
        missing = decoded["missing"]
        if missing is None:
            decoded["missing"] = math.nan
        elif isinstance(missing, bool | np.bool_) or not isinstance(
            missing, int | float | np.integer | np.floating
        ):
            raise SchemaError(
                f"{path}: params key 'missing' of the xgboost surrogate must be a number or "
                f"null (NaN, XGBoost's default); got {short_repr(params['missing'])}."
            )
    return decoded, standard


def _check_training_ranges(metadata: dict[str, Any], path: Path) -> None:
    """Refuse ``metadata["training_ranges"]`` unless one plausible ``[low, high]`` per input.

    A range that is not two finite numbers (a NaN low end) would silently stop the
    extrapolation check of :func:`softbend.surrogates.predict.predict_angles`.
    """
    if "training_ranges" not in metadata:
        return
    ranges = metadata["training_ranges"]
    where = f"{path}: metadata key 'training_ranges'"
    if not isinstance(ranges, dict):
        raise SchemaError(
            f"{where} must be an object of [low, high] per input ({', '.join(FEATURES)}); "
            f"got {short_repr(ranges)}."
        )
    unknown = [name for name in ranges if name not in FEATURES]
    missing = [name for name in FEATURES if name not in ranges]
    if unknown or missing:
        found = (
            f"unknown input(s) {', '.join(map(repr, unknown))}"
            if unknown
            else f"no range for {', '.join(missing)}"
        )
        raise SchemaError(
            f"{where} must give [low, high] for each input {', '.join(FEATURES)}; got {found}."
        )
    for name, pair in ranges.items():
        bounds = RANGES[QUANTITIES[name]]
        values: list[float] = []
        if isinstance(pair, list) and len(pair) == 2 and all(type(v) in (int, float) for v in pair):
            try:
                values = [float(v) for v in pair]
            except OverflowError:  # an integer beyond float64
                values = []
        if (
            not values
            or not all(math.isfinite(v) for v in values)
            or implausible_index(values, QUANTITIES[name]) is not None
            or values[0] > values[1]
        ):
            raise SchemaError(
                f"{where}, field '{name}' must be [low, high]: two finite numbers with "
                f"low <= high, from {bounds.low:g} to {bounds.high:g} {UNITS[name]} "
                f"(a plausible {bounds.label}); got {short_repr(pair)}."
            )


def _restore_inner(value: Any, path: str, key: str, depth: int) -> Any:
    where = f"{path}, state key '{key}'"
    if depth >= _MAX_DEPTH:
        raise SchemaError(f"{where}: surrogates nest at most {_MAX_DEPTH} deep.")
    return _restore(_checked_document(value, where), where, depth + 1)


def _restore_composite(document: dict[str, Any], path: str, depth: int) -> Any:
    """A composite's inner surrogates restored (and validated) first, then the composite."""
    kind = document["kind"]
    if document["params"]:
        got = short_repr(document["params"])
        raise SchemaError(f"{path}: the {kind} surrogate takes no params; got {got}.")
    state = _validated(document["state"], SCHEMAS[kind].state, path, kind, "state")
    try:
        SCHEMAS[kind].check(state)
    except RuleError as err:
        raise SchemaError(f"{path}: the {kind} surrogate's {err}.") from None
    cls = _class_of(kind)
    if kind == "ensemble":
        members = [
            _restore_inner(m, path, f"members[{i}]", depth) for i, m in enumerate(state["members"])
        ]
        return cls(members, state["residual_std_"])
    base = _restore_inner(state["base"], path, "base", depth)
    if kind == "affine-corrected":
        return cls(base, state["scale_"], state["offset_"], state["residual_std_"])
    if kind == "pressure-scaled":
        return cls(base, state["scale_"], state["residual_std_"])
    try:
        return cls(
            base,
            *(state[k] for k in ("z_mean_", "z_scale_", "kernel_theta_", "inputs_", "targets_")),
        )
    except (ValueError, np.linalg.LinAlgError) as err:  # a kernel matrix that is not positive
        raise SchemaError(f"{path}: cannot rebuild the {kind} surrogate ({err}).") from None


def _restore(document: dict[str, Any], path: Path | str, depth: int = 0) -> Any:
    """The model of a document, every params and state value validated by its kind's schema."""
    kind = document["kind"]
    schema = SCHEMAS[kind]
    state = document["state"]
    missing = [key for key in _REQUIRED_STATE[kind] if key not in state]
    if missing:
        raise SchemaError(
            f"{path} is an incomplete softbend surrogate: state key(s) "
            f"{', '.join(missing)} missing for kind {kind!r}."
        )
    if kind in COMPOSITE_KINDS:
        return _restore_composite(document, str(path), depth)
    state = _validated(state, schema.state, path, kind, "state")
    try:
        schema.check(state)
    except RuleError as err:
        raise SchemaError(f"{path}: the {kind} surrogate's {err}.") from None
    cls = _class_of(kind)
    if kind != "xgboost":
        model = cls(**_validated(document["params"], schema.params or {}, path, kind, "params"))
        try:  # the declared sizes (defaults included) against the arrays
            schema.against(model.get_params(deep=False), state)
        except RuleError as err:
            raise SchemaError(f"{path}: the {kind} surrogate's {err}.") from None
        for key, value in state.items():  # keys of the schema only
            setattr(model, key, value)
        return model
    params, standard = _xgboost_params(document["params"], path)
    try:
        model = cls(**params)
        model.load_model(bytearray(state["booster"].encode("utf-8")))
        # load_model fills base_score, booster, ... from the booster; put back the standard
        # parameters as they were set, so that get_params (and a refit) is unchanged.
        for key in standard & params.keys():
            setattr(model, key, params[key])
        # A parameter XGBoost only reads when predicting (missing, n_jobs, ...) fails here,
        # not in the caller's first prediction.
        with warnings.catch_warnings():
            warnings.simplefilter("ignore")
            probe = np.asarray(model.predict(np.zeros((1, len(FEATURES)))), dtype=np.float64)
    except Exception as err:  # xgboost.core.XGBoostError, a parameter XGBoost refuses, ...
        reason = (str(err).strip().splitlines() or [type(err).__name__])[0]  # no stack trace
        raise SchemaError(f"{path}: cannot rebuild the {kind} surrogate ({reason}).") from None
    if not np.isfinite(probe).all():
        raise SchemaError(
            f"{path}: the {kind} surrogate's booster predicts {probe.ravel()[0]} (its "
            "base_score or a leaf value is not a finite number)."
        )
    return model


def load_surrogate(path: str | Path) -> SavedSurrogate:
    """Read a surrogate written by :func:`save_surrogate`.

    Every value is checked against the schema of the surrogate's kind before the
    model is built: only the known ``params`` and ``state`` keys are accepted, each
    with its type, dtype, dimensions and bounds (arrays finite, scales > 0), and the
    arrays must fit together (e.g. the chained layer shapes of an MLP).

    Parameters
    ----------
    path : str or Path
        The JSON file.

    Returns
    -------
    SavedSurrogate
        The fitted model (predicting bit for bit as the saved one did), its kind,
        the caller's metadata and the provenance fields.

    Raises
    ------
    FileNotFoundError
        If ``path`` is not a file.
    softbend.errors.SchemaError
        If the file is not JSON, not a softbend surrogate, has a newer schema
        version, other units, lacks a key, has a key the schema does not know, or a
        value that breaks its rule (wrong type, dtype or shape, NaN or inf, a
        scale <= 0, an implausible parameter of a correction, sizes that disagree
        with the arrays, training ranges that are not plausible ``[low, high]``
        pairs); the one-line message names the file, the key and the rule.
    softbend.errors.LimitError
        If the JSON nests deeper than the ``nesting`` limit of :mod:`softbend.limits`.
    """
    path = Path(path)
    document = _read_document(path)
    _check_training_ranges(document["metadata"], path)
    try:
        model = _restore(document, path)
    except RecursionError:  # only with SOFTBEND_MAX_NESTING raised far above its default
        raise SchemaError(
            f"{path}: the surrogate nests too deeply to be rebuilt; lower SOFTBEND_MAX_NESTING "
            f"(now {limit('nesting')}) to have it refused on reading."
        ) from None
    return SavedSurrogate(
        model=model,
        kind=document["kind"],
        metadata=document["metadata"],
        softbend_version=document["softbend_version"],
        created_utc=document["created_utc"],
    )
