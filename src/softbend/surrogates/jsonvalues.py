"""The JSON form of a saved surrogate's parameters and fitted values.

:func:`encode` turns a value into strict JSON that :func:`decode` turns back into
an equal object of the same type (the format is that of
:mod:`softbend.surrogates.persistence`):

- a Python float or NumPy float64 is a plain number, a NaN or infinite one
  ``{"__float__": "nan" | "inf" | "-inf"}``;
- an array is ``{"__ndarray__": nested list, "dtype": ..., "shape": ...}`` (dtype
  a bool, integer or float one, or ``"str"``), a NumPy scalar
  ``{"__scalar__": value, "dtype": ...}``, a tuple ``{"__tuple__": [...]}``;
- None, bools, ints, strings, lists and dicts with string keys are themselves.
"""

from __future__ import annotations

from pathlib import Path
from typing import Any, Protocol, cast

import numpy as np

from softbend._validation import short_repr
from softbend.errors import InputError
from softbend.surrogates.schema import tag_float, untag_float

__all__ = ["decode", "encode", "encode_params", "plain_json"]


class _Estimator(Protocol):
    """A scikit-learn style estimator: its constructor parameters by name."""

    def get_params(self, deep: bool = True) -> dict[str, Any]: ...


def _tagged(nested: object) -> Any:
    """A nested list of an array's elements with its NaN and infinities as tags."""
    if isinstance(nested, list):
        return [_tagged(v) for v in nested]
    return tag_float(nested) if isinstance(nested, float) else nested


def encode(value: object, where: str) -> Any:
    """Strict-JSON form of ``value`` that :func:`decode` turns back into an equal object.

    Parameters
    ----------
    value : object
        The value to write.
    where : str
        Its name (a parameter or fitted attribute), for the error message.

    Raises
    ------
    TypeError
        For a value of another type (an object, an array of another dtype).
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
        return {"__tuple__": [encode(v, where) for v in value]}
    if isinstance(value, list):
        return [encode(v, where) for v in value]
    if isinstance(value, dict) and all(isinstance(k, str) for k in value):
        return {k: encode(v, where) for k, v in value.items()}
    raise TypeError(f"{where}: values of type {type(value).__name__} cannot be saved")


def _untagged(nested: object) -> Any:
    """A nested list of an array's elements with its tags of non-finite floats as floats."""
    if isinstance(nested, list):
        return [_untagged(v) for v in nested]
    return untag_float(nested)


def _dtype(name: object) -> np.dtype:
    """The NumPy dtype ``name`` of a saved array or scalar: a bool, integer or float one."""
    dtype = np.dtype(name) if isinstance(name, str) else None
    if dtype is None or dtype.kind not in "biuf":
        raise TypeError(f"dtype {short_repr(name)} is none of bool, integer, float or 'str'")
    return dtype


def decode(value: object) -> Any:
    """The object :func:`encode` wrote (raises KeyError, TypeError, ValueError, RuleError)."""
    if isinstance(value, list):
        return [decode(v) for v in value]
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
        return tuple(decode(v) for v in value["__tuple__"])
    return {k: decode(v) for k, v in value.items()}


def encode_params(model: object) -> dict[str, Any]:
    """The encoded ``get_params(deep=False)`` of an estimator.

    Raises
    ------
    softbend.errors.InputError
        Key ``model``: a parameter JSON cannot hold, naming it and the estimator's class.
    """
    params = {}
    for key, value in cast(_Estimator, model).get_params(deep=False).items():
        try:
            params[key] = encode(value, key)
        except TypeError:
            raise InputError(
                "must have JSON-serializable parameters to be saved (None, numbers, strings, "
                f"arrays, lists, tuples, dicts); got {type(value).__name__} for the parameter "
                f"'{key}' of {type(model).__name__}",
                key="model",
            ) from None
    return params


def plain_json(value: object) -> Any:
    """``json.dumps`` fallback for caller metadata: NumPy numbers and arrays as Python ones."""
    if isinstance(value, np.generic | np.ndarray):
        return value.tolist()
    if isinstance(value, Path):
        return str(value)
    raise TypeError(f"values of type {type(value).__name__} are not JSON-serializable")
