"""Save and load fitted surrogates as one JSON file, without pickle.

A saved surrogate records what it is (``kind``), how it was configured
(``params``, from ``get_params``), what it learned (``state``: the fitted
arrays as nested lists, or the XGBoost booster as JSON text), what it maps
(``features`` and ``units`` of :mod:`softbend.surrogates.features`, ``target``)
and where it came from (``softbend_version``, ``created_utc`` and the caller's
``metadata``, e.g. the training data hash and cross-validated metrics)::

    {"format": "softbend-surrogate", "schema_version": 2, "kind": "plr",
     "features": [...], "units": {...}, "target": "angle_deg",
     "softbend_version": "0.1.0", "created_utc": "2025-01-01T00:00:00+00:00",
     "metadata": {...}, "params": {...}, "state": {...}}

The ``kind`` is the name of the surrogate's family
(:data:`softbend.surrogates.families.FAMILIES`: ``plr``, ``xgb``, ``mlp`` or any
family registered with a :class:`~softbend.surrogates.families.Storage`), or that
of a composite of :mod:`softbend.surrogates.corrected` (:data:`COMPOSITE_KINDS`).

Schema versions: version 2 names the kind by its family. Version 1 files named
the polynomial ``"polynomial"`` and XGBoost ``"xgboost"`` (a family's
``legacy_kinds``); they load as ``plr`` and ``xgb``, inner surrogates of a
composite included, and everything else in them reads as before.

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

Loading trusts nothing in the file: each kind has a schema (a family's
``storage.schema``, a composite's in ``COMPOSITE_SCHEMAS``) listing
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

:func:`load_state` checks a file by the same rules but, for the families asked
for, returns the validated arrays without building the estimator (nor importing
its class and scikit-learn): ``softbend predict`` computes a saved MLP's angles
from them with NumPy alone, bit for bit those of the estimator.
"""

from __future__ import annotations

import importlib
import json
import logging
import math
import os
import sys
from collections.abc import Callable, Iterator, Mapping, Sequence
from contextlib import contextmanager
from dataclasses import dataclass, field
from datetime import UTC, datetime
from pathlib import Path
from typing import TYPE_CHECKING, Any, cast

import numpy as np

from softbend import __version__
from softbend._io import json_safe, write_text_atomic
from softbend._validation import must_be, short_repr
from softbend.actuators import ACTUATORS, SFRBA, Actuator
from softbend.errors import InputError, SchemaError, SoftbendError, keyed
from softbend.limits import check_limit, limit
from softbend.plausibility import RANGES, implausible_index
from softbend.surrogates.families import FAMILIES, Family, legacy_kinds
from softbend.surrogates.features import FEATURES, TARGET
from softbend.surrogates.jsonvalues import encode as _encode
from softbend.surrogates.jsonvalues import encode_params
from softbend.surrogates.jsonvalues import plain_json as _plain_json
from softbend.surrogates.protocol import Surrogate
from softbend.surrogates.schema import COMPOSITE_SCHEMAS, Rule

if TYPE_CHECKING:
    from softbend.surrogates.corrected import MeanEnsemble

logger = logging.getLogger(__name__)

__all__ = [
    "COMPOSITE_KINDS",
    "FORMAT",
    "SCHEMA_VERSION",
    "SavedState",
    "SavedSurrogate",
    "check_fitted_surrogate",
    "kind_of",
    "load_light",
    "load_state",
    "load_surrogate",
    "model_units",
    "save_surrogate",
    "saved_kinds",
]

#: Format tag of a saved surrogate file.
FORMAT = "softbend-surrogate"

#: Newest schema version this softbend writes and reads (2: the kind is the family's name).
SCHEMA_VERSION = 2

#: Surrogates built on other surrogates (:mod:`softbend.surrogates.corrected`), by
#: kind, and the class each is restored into: their ``state`` holds the inner
#: surrogates as whole documents (``base``, ``members``).
_COMPOSITES: dict[str, tuple[str, str]] = {
    "affine-corrected": ("softbend.surrogates.corrected", "AffineCorrected"),
    "gp-corrected": ("softbend.surrogates.corrected", "GPCorrected"),
    "ensemble": ("softbend.surrogates.corrected", "MeanEnsemble"),
    "pressure-scaled": ("softbend.surrogates.corrected", "PressureScaled"),
}

#: Kinds of the composites (not families: they wrap fitted surrogates).
COMPOSITE_KINDS: tuple[str, ...] = tuple(_COMPOSITES)

#: Inner surrogates nest at most this deep (a corrected ensemble of corrected MLPs).
_MAX_DEPTH = 4

#: Fitted attributes that prediction needs, per composite kind.
_COMPOSITE_STATE: dict[str, tuple[str, ...]] = {
    "affine-corrected": ("base", "scale_", "offset_", "residual_std_"),
    "gp-corrected": ("base", "z_mean_", "z_scale_", "kernel_theta_", "inputs_", "targets_"),
    "ensemble": ("members", "residual_std_"),
    "pressure-scaled": ("base", "scale_", "residual_std_"),
}


def saved_kinds() -> tuple[str, ...]:
    """Kinds this softbend saves and loads: every family with a storage, then the composites."""
    stored = tuple(name for name, family in FAMILIES.items() if family.storage is not None)
    return (*stored, *COMPOSITE_KINDS)


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


def model_units(actuator: Actuator) -> dict[str, str]:
    """The ``units`` a saved model of ``actuator`` records: each input's, and degrees."""
    units = actuator.units
    return {**{name: units[name] for name in actuator.features}, TARGET: "deg"}


def actuator_of(metadata: dict[str, Any], default: Actuator = SFRBA) -> Actuator:
    """The actuator description recorded in a model's ``metadata["actuator"]``.

    A recorded description equal to a registered one (:data:`softbend.actuators.ACTUATORS`)
    is that registered description, with what a file does not record (its
    plausible quantities, MAPE floors). A model without one (every model of a
    softbend campaign, every model saved before descriptions existed, and an
    inner model of a composite) is ``default``'s: paper B's actuator
    (:data:`softbend.actuators.SFRBA`) unless the caller says otherwise.
    """
    record = metadata.get("actuator") if isinstance(metadata, dict) else None
    if record is None:
        return default
    described = Actuator.from_dict(record)
    registered = ACTUATORS.get(described.name) if described.name in ACTUATORS else None
    return registered if registered == described else described


@dataclass(frozen=True)
class SavedSurrogate:
    """A surrogate read back by :func:`load_surrogate`.

    Attributes
    ----------
    model : estimator
        The fitted surrogate (``PolynomialRegressor``, ``NormalizedMLPRegressor``,
        ``xgboost.XGBRegressor``, a composite or a registered family's estimator);
        it maps inputs :data:`FEATURES` (mm, deg, MPa) to the bending angle in degrees.
    kind : str
        Its family's name or composite kind (one of :func:`saved_kinds`); a file of
        schema version 1 gives the family's name too (``plr``, not ``polynomial``).
    metadata : dict
        The caller's metadata as given to :func:`save_surrogate` (after a JSON
        round trip: tuples become lists, NumPy numbers Python numbers).
    softbend_version : str
        Version of softbend that wrote the file.
    created_utc : str
        When the file was written, ISO 8601 in UTC.
    """

    model: Surrogate
    kind: str
    metadata: dict[str, Any] = field(default_factory=dict)
    softbend_version: str = ""
    created_utc: str = ""

    @property
    def actuator(self) -> Actuator:
        """The actuator description the model was trained with (paper B's when unrecorded)."""
        return actuator_of(self.metadata)


def _stored(kind: str) -> Family:
    """The family ``kind`` if it can be saved (a family with a storage)."""
    with keyed("kind"):
        family = FAMILIES.get(kind)
    if family.storage is None:
        raise InputError(
            f"must be a family with a storage; the surrogate family {kind!r} declares none: "
            "it cannot be saved or loaded",
            key="kind",
        )
    return family


def _class_of(kind: str) -> type:
    if kind in _COMPOSITES:
        module, name = _COMPOSITES[kind]
        return getattr(importlib.import_module(module), name)
    family = _stored(kind)
    assert family.storage is not None  # _stored refuses a family without a storage
    return family.storage.estimator_class(f"The {family.title} surrogate ({kind!r})")


def _allowed() -> str:
    classes = [
        (family.storage.class_name, name)
        for name, family in FAMILIES.items()
        if family.storage is not None
    ]
    classes += [(cls, kind) for kind, (_, cls) in _COMPOSITES.items()]
    return ", ".join(f"{cls} ({kind!r})" for cls, kind in classes)


def kind_of(model: object) -> str:
    """The kind of a surrogate: its family's name (``"plr"``, ...) or its composite kind.

    Only the exact classes count (a subclass could change what ``params`` and
    ``state`` mean). No heavy module is imported: a model's class is loaded
    whenever the model exists.

    Parameters
    ----------
    model : estimator
        A fitted surrogate of a family with a storage (``PolynomialRegressor``,
        ``NormalizedMLPRegressor``, ``xgboost.XGBRegressor``, ...) or a composite.

    Returns
    -------
    str
        One of :func:`saved_kinds`.

    Raises
    ------
    softbend.errors.InputError
        For any other type (key ``model``), naming the allowed ones.
    """
    for name, family in FAMILIES.items():
        if family.storage is not None and family.storage.holds(model):
            return name
    for kind, (module, name) in _COMPOSITES.items():
        cls = getattr(sys.modules.get(module), name, None)
        if cls is not None and type(model) is cls:
            return kind
    raise InputError(f"must be one of {_allowed()}; got {type(model).__name__}", key="model")


def check_fitted_surrogate(model: object, features: Sequence[str] = FEATURES) -> str:
    """Return the kind of a fitted surrogate on the inputs ``features``, or raise a clear error.

    Parameters
    ----------
    model : estimator
        The surrogate to check.
    features : sequence of str
        The inputs it must take, in order (its actuator's
        :attr:`~softbend.actuators.Actuator.features`; default paper B's seven).

    Returns
    -------
    str
        The model's kind.

    Raises
    ------
    softbend.errors.InputError
        Unknown model type, or a model fitted on other inputs than ``features``
        (key ``model``).
    sklearn.exceptions.NotFittedError
        If the model is not fitted (a ``ValueError`` too).
    """
    kind = kind_of(model)
    name = type(model).__name__
    if kind in COMPOSITE_KINDS:
        fitted = True  # built from fitted surrogates, each checked when saved
    else:
        storage = FAMILIES.get(kind).storage
        assert storage is not None  # kind_of names only families with a storage
        fitted = (
            storage.codec.is_fitted(model)
            if storage.codec is not None
            else all(hasattr(model, key) for key in storage.required_state)
        )
    if not fitted:
        from sklearn.exceptions import NotFittedError  # only here: loading needs no sklearn

        raise NotFittedError(
            f"This {name} instance is not fitted yet. Call 'fit' before saving or exporting it."
        )
    n_features = int(cast(Surrogate, model).n_features_in_)
    if n_features != len(features):
        raise InputError(
            f"must be fitted on the {len(features)} surrogate inputs ({', '.join(features)}); "
            f"got a {name} with n_features_in_ = {n_features}",
            key="model",
        )
    names = getattr(model, "feature_names_in_", None)
    if names is not None and [str(n) for n in names] != list(features):
        raise InputError(
            f"must be fitted on the columns {', '.join(features)} in this order; "
            f"got a {name} fitted on {', '.join(map(str, names))}",
            key="model",
        )
    return kind


# --- save --------------------------------------------------------------------------------------


def _params(model: Surrogate, kind: str) -> dict[str, Any]:
    storage = FAMILIES.get(kind).storage
    assert storage is not None  # kind_of names only families with a storage
    codec = storage.codec
    return codec.params(model) if codec is not None else encode_params(model)


def _document(model: Surrogate, kind: str, actuator: Actuator, depth: int = 0) -> dict[str, Any]:
    """The saved form of a checked model of ``actuator``, without ``metadata``."""
    return {
        "format": FORMAT,
        "schema_version": SCHEMA_VERSION,
        "kind": kind,
        "features": list(actuator.features),
        "units": model_units(actuator),
        "target": TARGET,
        "softbend_version": __version__,
        "created_utc": datetime.now(UTC).isoformat(timespec="seconds"),
        "params": {} if kind in COMPOSITE_KINDS else _params(model, kind),
        "state": _state(model, kind, actuator, depth),
    }


def _inner(model: Surrogate, actuator: Actuator, depth: int) -> dict[str, Any]:
    """An inner surrogate of a composite as a whole document (empty metadata)."""
    if depth >= _MAX_DEPTH:
        raise InputError(
            f"must nest surrogates at most {_MAX_DEPTH} deep; got a model nesting deeper",
            key="model",
        )
    kind = check_fitted_surrogate(model, actuator.features)
    return {**_document(model, kind, actuator, depth + 1), "metadata": {}}


def _composite_state(model: Surrogate, kind: str, actuator: Actuator, depth: int) -> dict[str, Any]:
    state: dict[str, Any]
    if kind == "ensemble":
        members = cast("MeanEnsemble", model).members_
        state = {"members": [_inner(m, actuator, depth) for m in members]}
    else:
        base = getattr(model, "base")  # noqa: B009 (a composite's)
        state = {"base": _inner(base, actuator, depth)}
    names = [key for key in _COMPOSITE_STATE[kind] if key not in ("base", "members")]
    return state | {key: _encode(getattr(model, key), key) for key in names}


def _state(model: Surrogate, kind: str, actuator: Actuator, depth: int = 0) -> dict[str, Any]:
    if kind in COMPOSITE_KINDS:
        return _composite_state(model, kind, actuator, depth)
    storage = FAMILIES.get(kind).storage
    assert storage is not None  # kind_of names only families with a storage
    if storage.codec is not None:
        return storage.codec.state(model)
    state = {}
    fitted = [k for k in vars(model) if k.endswith("_") and not k.startswith("_")]
    for key in fitted:
        try:
            state[key] = _encode(getattr(model, key), key)
        except TypeError as err:
            if key in storage.required_state:
                raise InputError(
                    f"must hold fitted attributes JSON can hold; its '{key}' "
                    f"({type(model).__name__}) cannot be saved: {err}",
                    key="model",
                ) from None
            logger.debug("save_surrogate leaves out %s: %s", key, err)
    return state


def save_surrogate(
    model: Surrogate, path: str | os.PathLike[str], *, metadata: dict[str, Any] | None = None
) -> Path:
    """Write a fitted surrogate to one JSON file (atomically) and return its path.

    Parameters
    ----------
    model : estimator
        A fitted surrogate on the inputs of the actuator ``metadata["actuator"]``
        records (paper B's seven :data:`FEATURES`, mm, deg, MPa, when it records none),
        predicting the bending angle in degrees: of a family with a storage
        (``PolynomialRegressor``, ``NormalizedMLPRegressor``,
        ``xgboost.XGBRegressor``, ...) or a composite; its ``kind`` is the family's
        name.
    path : str or os.PathLike
        File to write; parent folders are created. An existing file is replaced
        only once the new one is complete.
    metadata : dict, optional
        JSON-serializable provenance with string keys, e.g. ``data_hash``,
        ``metrics``, ``cv`` and ``actuator`` (the description the model is of,
        :meth:`~softbend.actuators.Actuator.to_dict`); NumPy numbers and arrays are
        written as Python ones, NaN and infinities as ``null`` (the file is strict JSON).

    Returns
    -------
    Path
        The written file.

    Raises
    ------
    softbend.errors.InputError
        Unknown model type (naming the allowed kinds), a model fitted on other than
        its actuator's inputs, a parameter (key ``model``) or ``metadata`` (key ``metadata``)
        that JSON cannot hold.
    sklearn.exceptions.NotFittedError
        If the model is not fitted.
    """
    if metadata is None:
        metadata = {}
    try:
        actuator = actuator_of(metadata)
    except ValueError as err:
        raise InputError(
            f"must hold a valid 'actuator' description; got one that is not: {err}",
            key="metadata",
        ) from None
    return _save(model, Path(path), metadata, actuator)


def _save(model: Surrogate, path: Path, metadata: dict[str, Any], actuator: Actuator) -> Path:
    kind = check_fitted_surrogate(model, actuator.features)
    if not isinstance(metadata, dict) or not all(isinstance(k, str) for k in metadata):
        raise InputError(
            f"must be a dict with string keys; got {type(metadata).__name__}", key="metadata"
        )
    try:  # strict JSON: NaN and infinities become null
        metadata_json = json.dumps(json_safe(metadata), default=_plain_json, allow_nan=False)
    except (TypeError, ValueError, RecursionError) as err:
        raise InputError(
            f"must be JSON-serializable; got an error: {err}", key="metadata"
        ) from None
    document = _document(model, kind, actuator)
    # One top-level key per line: the header stays readable, big arrays stay on one line.
    # Every non-finite float is tagged by _encode, so the text is strict JSON.
    lines = [
        f"{json.dumps(key)}: {json.dumps(value, allow_nan=False)}"
        for key, value in document.items()
    ]
    lines.insert(-2, f'"metadata": {metadata_json}')
    return write_text_atomic(Path(path), "{\n " + ",\n ".join(lines) + "\n}\n")


# --- load --------------------------------------------------------------------------------------


def _depth(value: object) -> int:
    """How deep JSON objects and arrays nest in ``value`` (a number 0, ``[]`` 1), iteratively."""
    deepest, stack = 0, [(value, 1)] if isinstance(value, dict | list) else []
    while stack:
        item, level = stack.pop()
        children = item.values() if isinstance(item, dict) else item
        deepest = max(deepest, level)
        stack.extend((child, level + 1) for child in children if isinstance(child, dict | list))
    return deepest


@contextmanager
def _in_file(path: Path | str) -> Iterator[None]:
    """Name ``path`` as the file of any :class:`SchemaError` raised inside."""
    try:
        yield
    except SchemaError as error:
        if error.file is None:
            error.file = str(path)
        raise


@contextmanager
def _within(field_path: str) -> Iterator[None]:
    """Put the keys of the errors of an inner surrogate under its field (``state.base``)."""
    try:
        yield
    except SchemaError as error:
        error.key = field_path if error.key is None else f"{field_path}.{error.key}"
        raise


def _read_document(path: Path) -> dict[str, Any]:
    if not path.is_file():
        raise FileNotFoundError(f"No saved surrogate at {path}.")
    try:
        document = json.loads(path.read_text(encoding="utf-8"))
    except (ValueError, UnicodeDecodeError) as err:  # JSONDecodeError, a 5000-digit number
        raise SchemaError(
            f"not a softbend surrogate: not valid JSON ({err})", file=str(path)
        ) from None
    except RecursionError:  # the parser recurses once per level
        raise SchemaError(
            "not a softbend surrogate: its JSON nests too deeply to be read (a softbend "
            f"surrogate nests at most {limit('nesting')} levels, the limit SOFTBEND_MAX_NESTING)",
            file=str(path),
        ) from None
    check_limit("nesting", _depth(document), f"The JSON nesting of {path}")
    with _in_file(path):
        return _checked_document(document)


def _checked_document(document: object, within: Actuator = SFRBA) -> dict[str, Any]:
    """``document`` if its header is that of a softbend surrogate, else a :class:`SchemaError`
    keyed by the header field at fault (the caller names the file).

    Its features and units are those of the actuator its metadata records, else of
    ``within`` (paper B's for a file; the composite's for an inner surrogate).
    """
    if not isinstance(document, dict) or document.get("format") != FORMAT:
        found = document.get("format") if isinstance(document, dict) else type(document).__name__
        shown = repr(found) if isinstance(found, str | None) else short_repr(found)
        raise SchemaError(f"not a softbend surrogate: format {shown}, expected {FORMAT!r}")
    version = document.get("schema_version")
    if isinstance(version, bool) or not isinstance(version, int) or version < 1:
        raise SchemaError(
            must_be(f"an integer from 1 to {SCHEMA_VERSION} (invalid schema_version)", version),
            key="schema_version",
        )
    if version > SCHEMA_VERSION:
        raise SchemaError(
            f"{version} is newer than this softbend ({__version__}) reads (up to "
            f"{SCHEMA_VERSION}); upgrade softbend to load it",
            key="schema_version",
        )
    missing = [key for key in _HEADER_KEYS if key not in document]
    if missing:
        raise SchemaError(f"an incomplete softbend surrogate: key(s) {', '.join(missing)} missing")
    unknown = [key for key in document if key not in ("format", "schema_version", *_HEADER_KEYS)]
    if unknown:
        raise SchemaError(
            f"unknown key(s) {', '.join(map(repr, unknown))} in a softbend surrogate; "
            f"allowed keys: format, schema_version, {', '.join(_HEADER_KEYS)}"
        )
    kind = document["kind"]
    if version == 1 and isinstance(kind, str):  # migration: version 1 named two kinds otherwise
        kind = document["kind"] = legacy_kinds().get(kind, kind)
    if not isinstance(kind, str) or kind not in saved_kinds():
        shown = repr(kind) if isinstance(kind, str) else short_repr(kind)
        raise SchemaError(
            f"must be one of {', '.join(map(repr, saved_kinds()))}; "
            f"got the unknown surrogate kind {shown}",
            key="kind",
        )
    for key in ("params", "state", "metadata", "units"):
        if not isinstance(document[key], dict):
            raise SchemaError(must_be("a JSON object", document[key]), key=key)
    try:
        actuator = actuator_of(document["metadata"], within)
    except ValueError as err:
        raise SchemaError(f"is not valid: {err}", key="metadata.actuator") from None
    features, units = list(actuator.features), model_units(actuator)
    if document["features"] != features or document["target"] != TARGET:
        raise SchemaError(
            f"maps {short_repr(document['features'])} -> {short_repr(document['target'])}"
            f"; its actuator's surrogates map {features} -> {TARGET!r}",
            key="features",
        )
    if document["units"] != units:
        wrong = next(
            (name for name in units if document["units"].get(name) != units[name]),
            next(iter(set(document["units"]) - set(units)), ""),
        )
        got = short_repr(document["units"].get(wrong)) if wrong in document["units"] else "none"
        raise SchemaError(
            f"must be {json.dumps(units)} (the units every softbend surrogate maps); "
            f"got {got} for {wrong!r}",
            key="units",
        )
    for key in ("softbend_version", "created_utc"):
        if not isinstance(document[key], str):
            raise SchemaError(must_be("a string", document[key]), key=key)
    return document


def _validated(
    values: dict[str, Any], rules: dict[str, Rule], kind: str, section: str
) -> dict[str, Any]:
    """``values`` decoded by their rules; a key without a rule or a broken rule raises
    (keyed ``section.key``)."""
    unknown = [key for key in values if key not in rules]
    if unknown:
        raise SchemaError(
            f"unknown {section} key(s) {', '.join(map(repr, unknown))} for the {kind} "
            f"surrogate; allowed keys: {', '.join(rules)}",
            key=section,
        )
    decoded = {}
    for key, value in values.items():
        with _within(f"{section}.{key}"):
            decoded[key] = rules[key](value)
    return decoded


def _check_training_ranges(metadata: dict[str, Any], actuator: Actuator) -> None:
    """Refuse ``metadata["training_ranges"]`` unless one plausible ``[low, high]`` per input.

    A range that is not two finite numbers (a NaN low end) would silently stop the
    extrapolation check of :func:`softbend.surrogates.predict.predict_angles`. An
    input ``actuator.quantities`` names must lie in that quantity's plausible range.
    """
    if "training_ranges" not in metadata:
        return
    ranges = metadata["training_ranges"]
    key = "metadata.training_ranges"
    features = actuator.features
    if not isinstance(ranges, dict):
        raise SchemaError(
            must_be(f"an object of [low, high] per input ({', '.join(features)})", ranges),
            key=key,
        )
    unknown = [name for name in ranges if name not in features]
    missing = [name for name in features if name not in ranges]
    if unknown or missing:
        found = (
            f"unknown input(s) {', '.join(map(repr, unknown))}"
            if unknown
            else f"no range for {', '.join(missing)}"
        )
        raise SchemaError(
            f"must give [low, high] for each input {', '.join(features)}; got {found}", key=key
        )
    for name, pair in ranges.items():
        quantity = actuator.quantities.get(name)
        values: list[float] = []
        if isinstance(pair, list) and len(pair) == 2 and all(type(v) in (int, float) for v in pair):
            try:
                values = [float(v) for v in pair]
            except OverflowError:  # an integer beyond float64
                values = []
        if (
            not values
            or not all(math.isfinite(v) for v in values)
            or (quantity is not None and implausible_index(values, quantity) is not None)
            or values[0] > values[1]
        ):
            plausible = ""
            if quantity is not None:
                bounds = RANGES[quantity]
                plausible = (
                    f", from {bounds.low:g} to {bounds.high:g} {actuator.units[name]} "
                    f"(a plausible {bounds.label})"
                )
            raise SchemaError(
                must_be(f"[low, high]: two finite numbers with low <= high{plausible}", pair),
                key=f"{key}.{name}",
            )


def _check_support(metadata: dict[str, Any], actuator: Actuator) -> None:
    """Refuse ``metadata["support"]`` unless a :class:`~softbend.surrogates.support.Support`
    record of the design parameters of ``actuator``.

    A broken support would silently stop the check of
    :func:`softbend.surrogates.predict.predict_angles` that a prediction lies
    where the training data were.
    """
    if "support" not in metadata:
        return
    from softbend.surrogates.support import Support

    try:
        Support.from_dict(metadata["support"], parameters=actuator.names)
    except ValueError as err:  # an InputError keyed by the record's field, if one is at fault
        field_key = getattr(err, "key", None)
        detail = err.detail if isinstance(err, SoftbendError) else str(err)
        raise SchemaError(
            f"{detail} (the training support: each training design's largest pressure and "
            "the largest angle)",
            key="metadata.support" + (f".{field_key}" if field_key else ""),
        ) from None


@dataclass(frozen=True)
class _Reading:
    """What restoring a file's surrogates needs: the actuator it is of, and the families
    built from their arrays (:func:`load_light`; none for :func:`load_surrogate`)."""

    actuator: Actuator
    builders: Mapping[str, Callable[[SavedState], Any]] = field(default_factory=dict)


def _restore_inner(
    value: object, path: Path | str, key: str, reading: _Reading, depth: int
) -> Surrogate:
    with _within(f"state.{key}"):
        if depth >= _MAX_DEPTH:
            raise SchemaError(f"surrogates nest at most {_MAX_DEPTH} deep")
        return _restore(_checked_document(value, reading.actuator), path, reading, depth + 1)


def _restore_composite(
    document: dict[str, Any], path: Path | str, reading: _Reading, depth: int
) -> Surrogate:
    """A composite's inner surrogates restored (and validated) first, then the composite."""
    kind = document["kind"]
    if document["params"]:
        raise SchemaError(
            must_be(f"empty: the {kind} surrogate takes no params", document["params"]),
            key="params",
        )
    schema = COMPOSITE_SCHEMAS[kind]
    state = _validated(document["state"], schema.state, kind, "state")
    schema.inputs(state, reading.actuator)
    schema.check(state)
    cls = _class_of(kind)
    if kind == "ensemble":
        members = [
            _restore_inner(m, path, f"members[{i}]", reading, depth)
            for i, m in enumerate(state["members"])
        ]
        return cast(Surrogate, cls(members, state["residual_std_"]))
    base = _restore_inner(state["base"], path, "base", reading, depth)
    if kind == "affine-corrected":
        return cast(Surrogate, cls(base, state["scale_"], state["offset_"], state["residual_std_"]))
    if kind == "pressure-scaled":
        return cast(Surrogate, cls(base, state["scale_"], state["residual_std_"]))
    try:
        return cast(
            Surrogate,
            cls(
                base,
                *(
                    state[k]
                    for k in ("z_mean_", "z_scale_", "kernel_theta_", "inputs_", "targets_")
                ),
            ),
        )
    except (ValueError, np.linalg.LinAlgError) as err:  # a kernel matrix that is not positive
        raise SchemaError(f"cannot rebuild the {kind} surrogate ({err})") from None


def _check_required(document: dict[str, Any], required: tuple[str, ...]) -> None:
    missing = [key for key in required if key not in document["state"]]
    if missing:
        raise SchemaError(
            f"an incomplete softbend surrogate: state key(s) {', '.join(missing)} missing for "
            f"kind {document['kind']!r}",
            key="state",
        )


def _family_state(document: dict[str, Any], actuator: Actuator) -> dict[str, Any]:
    """A family's state, every value validated by its schema (rules across keys and against
    the inputs of ``actuator`` included)."""
    kind = document["kind"]
    storage = _stored(kind).storage
    assert storage is not None  # _stored refuses a family without a storage
    _check_required(document, storage.required_state)
    schema = storage.schema
    state = _validated(document["state"], schema.state, kind, "state")
    schema.inputs(state, actuator)
    schema.check(state)
    return state


def _check_against(
    kind: str, params: dict[str, Any], state: dict[str, Any], features: Sequence[str]
) -> None:
    """The declared sizes (defaults included) against the arrays, and the inputs ``features``."""
    storage = _stored(kind).storage
    assert storage is not None  # _stored refuses a family without a storage
    storage.schema.against(params, state)
    n_features = state.get("n_features_in_")
    if isinstance(n_features, bool) or n_features != len(features):
        raise SchemaError(
            f"must be {len(features)}: the {kind} surrogate must take the inputs "
            f"{', '.join(features)}; got {short_repr(n_features)}",
            key="state.n_features_in_",
        )


def _restore(
    document: dict[str, Any], path: Path | str, reading: _Reading, depth: int = 0
) -> Surrogate:
    """The model of a document, every params and state value validated by its kind's schema
    and against the inputs of the actuator being read."""
    kind = document["kind"]
    if kind in COMPOSITE_KINDS:
        _check_required(document, _COMPOSITE_STATE[kind])
        return _restore_composite(document, path, reading, depth)
    storage = _stored(kind).storage
    assert storage is not None  # _stored refuses a family without a storage
    actuator = reading.actuator
    builder = reading.builders.get(kind)
    if builder is not None and _arrays_suffice(document):
        return cast(Surrogate, builder(_saved_state(document, actuator)))
    state = _family_state(document, actuator)
    if builder is not None and storage.codec is not None:  # the builder may decline: None
        light = builder(SavedState(kind, document["params"], state, document["metadata"], actuator))
        if light is not None:
            return cast(Surrogate, light)
    cls = _class_of(kind)
    if storage.codec is not None:
        return storage.codec.restore(cls, document["params"], state, str(path))
    model = cls(**_validated(document["params"], storage.schema.params or {}, kind, "params"))
    for key, value in state.items():  # keys of the schema only
        setattr(model, key, value)
    _check_against(
        kind,
        model.get_params(deep=False),
        {**state, "n_features_in_": getattr(model, "n_features_in_", None)},
        actuator.features,
    )
    return cast(Surrogate, model)


def load_surrogate(path: str | os.PathLike[str]) -> SavedSurrogate:
    """Read a surrogate written by :func:`save_surrogate`.

    Every value is checked against the schema of the surrogate's kind before the
    model is built: only the known ``params`` and ``state`` keys are accepted, each
    with its type, dtype, dimensions and bounds (arrays finite, scales > 0), and the
    arrays must fit together (e.g. the chained layer shapes of an MLP).

    Parameters
    ----------
    path : str or os.PathLike
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
    return _load(Path(path), {})


def _load(path: Path, builders: Mapping[str, Callable[[SavedState], Any]]) -> SavedSurrogate:
    """:func:`load_surrogate`, with the families in ``builders`` built from their arrays."""
    document = _read_document(path)
    reading = _Reading(actuator_of(document["metadata"]), builders)
    with _in_file(path):
        _check_training_ranges(document["metadata"], reading.actuator)
        _check_support(document["metadata"], reading.actuator)
        return _saved_surrogate(document, path, reading)


def _saved_surrogate(document: dict[str, Any], path: Path, reading: _Reading) -> SavedSurrogate:
    """The surrogate of a checked document, built."""
    try:
        model = _restore(document, path, reading)
    except RecursionError:  # only with SOFTBEND_MAX_NESTING raised far above its default
        raise SchemaError(
            "the surrogate nests too deeply to be rebuilt; lower SOFTBEND_MAX_NESTING "
            f"(now {limit('nesting')}) to have it refused on reading"
        ) from None
    return SavedSurrogate(
        model=model,
        kind=document["kind"],
        metadata=document["metadata"],
        softbend_version=document["softbend_version"],
        created_utc=document["created_utc"],
    )


@dataclass(frozen=True)
class SavedState:
    """A saved family surrogate read by :func:`load_state`: validated, its estimator not built.

    Attributes
    ----------
    kind : str
        Its family's name (one of the ``kinds`` asked for).
    params : dict
        Every constructor parameter of the estimator, validated by the family's schema.
    state : dict
        The fitted attributes (arrays in the units of :data:`FEATURES`, degrees),
        validated by the family's schema exactly as :func:`load_surrogate` does.
    metadata : dict
        The caller's metadata, as :attr:`SavedSurrogate.metadata`.
    described : Actuator, optional
        The actuator the model is of, when the file gave it (an inner surrogate of a
        composite takes the composite's); else the one ``metadata`` records.
    """

    kind: str
    params: dict[str, Any]
    state: dict[str, Any]
    metadata: dict[str, Any] = field(default_factory=dict)
    described: Actuator | None = None

    @property
    def actuator(self) -> Actuator:
        """The actuator description the model was trained with (paper B's when unrecorded)."""
        return self.described if self.described is not None else actuator_of(self.metadata)


def load_state(path: str | os.PathLike[str], kinds: tuple[str, ...]) -> SavedState | SavedSurrogate:
    """Read a surrogate as its validated arrays where its kind is in ``kinds``, else built.

    For a family in ``kinds`` whose file gives every constructor parameter and no
    ``feature_names_in_`` (which the estimator checks on each prediction), the
    file is checked by the same rules as :func:`load_surrogate` but the estimator
    is not built, so its class and what it imports (scikit-learn) stay unloaded:
    a caller that computes the prediction from the arrays (the MLP's
    :func:`softbend.surrogates.mlp_core.mlp_forward`) gets the same numbers,
    bit for bit. Any other file is :func:`load_surrogate`'s result.

    Parameters
    ----------
    path : str or os.PathLike
        The JSON file.
    kinds : tuple of str
        Family names (see :func:`saved_kinds`) to return as :class:`SavedState`.

    Returns
    -------
    SavedState or SavedSurrogate

    Raises
    ------
    FileNotFoundError, softbend.errors.SchemaError, softbend.errors.LimitError
        As :func:`load_surrogate`.
    """
    path = Path(path)
    document = _read_document(path)
    with _in_file(path):
        return _load_state(document, path, kinds)


def _arrays_suffice(document: dict[str, Any]) -> bool:
    """Whether a family's file gives everything its prediction needs without its estimator:
    no codec, every constructor parameter, and no ``feature_names_in_`` (checked by the
    estimator on each prediction)."""
    kind = document["kind"]
    storage = None if kind in COMPOSITE_KINDS else _stored(kind).storage
    return (
        storage is not None
        and storage.codec is None
        and storage.schema.params is not None
        and set(storage.schema.params) <= set(document["params"])
        and "feature_names_in_" not in document["state"]
    )


def _saved_state(document: dict[str, Any], actuator: Actuator) -> SavedState:
    """A family's document validated as :func:`load_surrogate` does, its estimator not built."""
    kind = document["kind"]
    storage = _stored(kind).storage
    assert storage is not None and storage.schema.params is not None  # _arrays_suffice
    state = _family_state(document, actuator)
    params = _validated(document["params"], storage.schema.params, kind, "params")
    _check_against(kind, params, state, actuator.features)
    return SavedState(kind, params, state, document["metadata"], actuator)


def _load_state(
    document: dict[str, Any], path: Path, kinds: tuple[str, ...]
) -> SavedState | SavedSurrogate:
    actuator = actuator_of(document["metadata"])
    _check_training_ranges(document["metadata"], actuator)
    _check_support(document["metadata"], actuator)
    if document["kind"] in kinds and _arrays_suffice(document):
        return _saved_state(document, actuator)
    return _saved_surrogate(document, path, _Reading(actuator))


def load_light(
    path: str | os.PathLike[str], builders: Mapping[str, Callable[[SavedState], Any]]
) -> SavedSurrogate:
    """:func:`load_surrogate`, with the families in ``builders`` built from their arrays.

    Every family surrogate in the file (the file's own, or one inside a composite:
    the base of a correction, the members of an ensemble) whose kind is in
    ``builders`` and whose arrays suffice (as for :func:`load_state`) is validated by
    the same rules and then built by ``builders[kind](saved_state)`` instead of its
    estimator, so its class and what it imports (scikit-learn, PyTorch) stay
    unloaded. A family with its own codec (XGBoost) is offered its state checked by
    its schema (``params`` as written); the builder returns None to have the
    estimator built instead. The composites are built as by :func:`load_surrogate`.

    Parameters
    ----------
    path : str or os.PathLike
        The JSON file.
    builders : mapping of str to callable
        Family name → a callable taking a :class:`SavedState` and returning an
        object with ``predict(rows)`` (degrees) and ``n_features_in_``.

    Returns
    -------
    SavedSurrogate
        As :func:`load_surrogate`; its ``model`` (or a composite's inner models) may
        be a builder's predictor.

    Raises
    ------
    FileNotFoundError, softbend.errors.SchemaError, softbend.errors.LimitError
        As :func:`load_surrogate`.
    """
    return _load(Path(path), dict(builders))
