"""The parameters of a transfer strategy: read from its constructor, checked, typed from text.

A strategy is a class (see :data:`softbend.transfer.strategies.STRATEGIES`);
its parameters are its constructor's, less the three the library fills itself:
``base`` (the surrogate the strategy starts from), ``seed`` (given once per
run, ``--seed``) and ``actuator`` (that of the readings). A user sets the others from Python
(``make_strategy("refined", base, epochs=500)``) or as text on the command line
(``--set epochs=500``): text is read by the kind of the parameter's default
(``true``/``false``, an integer, a number, a string, integers separated by
commas for a tuple such as ``hidden_sizes=63,65``), by the rules of
:mod:`softbend.parameters` that the controllers' parameters follow too. An
unknown name is one :class:`~softbend.parameters.UnknownParameterError` line
listing the known ones.

Every numeric parameter of a strategy declares the range it accepts beside its
class (:func:`~softbend.parameters.declare_ranges`), and every value, typed on
a command line or given as data, is held to it before any work: a value outside
is one :class:`~softbend.parameters.ParameterValueError` line naming the
parameter and the range. A tuple annotated with a fixed number of items
(``hidden_sizes: tuple[int, int]``, the sizes of two hidden layers) must have
that many. :func:`check_estimator` holds a strategy built directly
(``RefinedMLP(base, learning_rate=...)``) to the same ranges when it is fitted.
"""

from __future__ import annotations

import inspect
import re
from collections.abc import Mapping
from typing import Any

from softbend import parameters as _parameters

__all__ = [
    "FILLED",
    "check_estimator",
    "check_parameters",
    "describe_range",
    "item_count",
    "parameter_defaults",
    "recorded_parameters",
    "takes",
]

#: Constructor parameters the library fills itself: never set by name.
FILLED: tuple[str, ...] = ("base", "seed", "actuator")

_HINTS = {"seed": "the seed is set once per run: --seed"}


def _constructor(cls: type) -> dict[str, inspect.Parameter]:
    return _parameters.public_parameters(cls, keyword_only=False)[0]


def takes(cls: type, name: str) -> bool:
    """Whether the constructor of ``cls`` takes the parameter ``name`` (``base``, ``seed``)."""
    return name in _constructor(cls)


def parameter_defaults(cls: type) -> dict[str, Any]:
    """The parameters a user may set on the strategy class ``cls``, with their defaults.

    Its constructor's parameters in order, less :data:`FILLED`; ``None`` for a
    parameter without a default.
    """
    return _parameters.parameter_defaults(cls, skip=FILLED, keyword_only=False)


def item_count(cls: type, name: str) -> int | None:
    """The number of items the tuple parameter ``name`` of ``cls`` must have, or None.

    Read from its annotation: ``tuple[int, int]`` is 2; ``tuple[int, ...]``, a
    parameter that is not a tuple, or one without an annotation is None.
    """
    parameter = _constructor(cls).get(name)
    if parameter is None:
        return None
    note = parameter.annotation
    text = note if isinstance(note, str) else str(note)
    found = re.fullmatch(r"\s*tuple\[([^\[\]]*)\]\s*(\|\s*None\s*)?", text)
    if found is None or "..." in found.group(1):
        return None
    return len([part for part in found.group(1).split(",") if part.strip()])


def _count_words(cls: type, key: str, count: int) -> str:
    """``"2 integers separated by commas, each in [1, 1024] units"``."""
    declared = _parameters.declared_ranges(cls).get(key)
    each = f", each in {declared.interval()}" if declared is not None else ""
    unit = f" {declared.unit}" if declared is not None and declared.unit else ""
    return f"{count} integers separated by commas{each}{unit}"


def describe_range(cls: type, key: str) -> str | None:
    """The declared range of parameter ``key`` of ``cls`` as text; None if it declares none.

    ``"(0, 1] standardized units"``; a tuple of a fixed number of items
    (:func:`item_count`) says so: ``"2 integers separated by commas, each in [1, 1024] ..."``.
    """
    declared = _parameters.declared_ranges(cls).get(key)
    if declared is None:
        return None
    count = item_count(cls, key)
    return _count_words(cls, key, count) if count is not None else declared.describe()


def _check_one(cls: type, key: str, value: object, *, from_text: bool) -> dict[str, Any]:
    """One parameter checked by :func:`softbend.parameters.check_parameters`, and its count."""
    count = item_count(cls, key)
    try:
        checked = _parameters.check_parameters(
            cls, {key: value}, from_text=from_text, skip=FILLED, keyword_only=False, hints=_HINTS
        )
    except _parameters.ParameterValueError:
        if count is None:
            raise
        checked = {}
    result = checked.get(key)
    if count is not None and not (isinstance(result, tuple) and len(result) == count):
        raise _parameters.ParameterValueError(
            f"must be {_count_words(cls, key, count)}; got {_items(value)}", key=key
        )
    return checked


def _items(value: object) -> str:
    """A value given for a tuple parameter, with its number of items: ``'0,0' (2 values)``."""
    if isinstance(value, str):
        n = len(value.split(","))
    elif isinstance(value, tuple | list):
        n = len(value)
    else:
        return repr(value)
    shown = repr(value) if len(repr(value)) <= 60 else repr(value)[:57] + "..."
    return f"{shown} ({n} value{'s' * (n != 1)})"


def check_parameters(
    cls: type, values: Mapping[str, object] | None, *, from_text: bool = False
) -> dict[str, Any]:
    """``values`` checked against the parameters of the strategy class ``cls``.

    :func:`softbend.parameters.check_parameters` on the constructor of ``cls``,
    less :data:`FILLED`. An error's key is the parameter's name; a caller that
    hands on its own parameter re-keys it (:func:`softbend.errors.keyed`:
    ``settings``, ``options``), and the parameter's name moves into the message.

    Parameters
    ----------
    cls : type
        The strategy class.
    values : mapping, optional
        ``{parameter: value}``; text values when ``from_text``.
    from_text : bool, default False
        Read each value from text by the kind of the parameter.

    Returns
    -------
    dict
        The values, typed.

    Raises
    ------
    UnknownParameterError
        A parameter the strategy does not take (the known ones listed).
    ParameterValueError
        A value that is not of the parameter's kind, not finite, outside its
        declared range, or a tuple of another number of items than its
        annotation's (:func:`item_count`).
    LimitError
        ``epochs`` over the ``epochs`` limit of :mod:`softbend.limits`.
    """
    checked: dict[str, Any] = {}
    for key, value in (values or {}).items():
        checked.update(_check_one(cls, key, value, from_text=from_text))
    return checked


def check_estimator(estimator: object) -> dict[str, Any]:
    """The ranged parameters of a strategy object, checked as :func:`check_parameters` does.

    For a strategy built directly (``RefinedMLP(base, learning_rate=...)``) or
    changed by ``set_params``: its fit calls this before any work. An error's
    key is the parameter's name, as the constructor calls it.

    Parameters
    ----------
    estimator : object
        The strategy object; every parameter of its class with a declared range is read.

    Returns
    -------
    dict
        The checked values of those parameters.
    """
    cls = type(estimator)
    known = _constructor(cls)
    values = {
        key: getattr(estimator, key)
        for key in _parameters.declared_ranges(cls)
        if key in known and key not in FILLED and hasattr(estimator, key)
    }
    return check_parameters(cls, values)


def recorded_parameters(estimator: object) -> dict[str, Any]:
    """Every parameter of a strategy object, ``seed`` included, as it will run (for a record).

    The base surrogate and the actuator are left out (the record names the base's
    file and its actuator); a value that is
    not a number, a string, a boolean, ``None`` or a tuple of them is written as
    its ``repr``.
    """
    plain = (bool, int, float, str, type(None))
    out: dict[str, Any] = {}
    for key in _constructor(type(estimator)):
        if key in ("base", "actuator"):
            continue
        value = getattr(estimator, key, None)
        if isinstance(value, tuple | list) and all(isinstance(v, plain) for v in value):
            value = list(value)
        elif not isinstance(value, plain):
            value = repr(value)
        out[key] = value
    return out
