"""The parameters of a transfer strategy: read from its constructor, checked, typed from text.

A strategy is a class (see :data:`softbend.transfer.strategies.STRATEGIES`);
its parameters are its constructor's, less the two the library fills itself:
``base`` (the surrogate the strategy starts from) and ``seed`` (given once per
run, ``--seed``). A user sets the others from Python
(``make_strategy("refined", base, epochs=500)``) or as text on the command line
(``--set epochs=500``): text is read by the kind of the parameter's default
(``true``/``false``, an integer, a number, a string, integers separated by
commas for a tuple such as ``hidden_sizes=63,65``). An unknown name is one
:class:`~softbend.registry.UnknownNameError` line listing the known ones.
"""

from __future__ import annotations

import inspect
import math
from collections.abc import Mapping
from typing import Any

from softbend.limits import check_limit
from softbend.registry import UnknownNameError

__all__ = ["FILLED", "check_parameters", "parameter_defaults", "recorded_parameters", "takes"]

#: Constructor parameters the library fills itself: never set by name.
FILLED: tuple[str, ...] = ("base", "seed")

_TRUE = ("true", "yes", "on", "1")
_FALSE = ("false", "no", "off", "0")


def _constructor(cls: type) -> dict[str, inspect.Parameter]:
    kinds = (inspect.Parameter.POSITIONAL_OR_KEYWORD, inspect.Parameter.KEYWORD_ONLY)
    return {p.name: p for p in inspect.signature(cls).parameters.values() if p.kind in kinds}


def takes(cls: type, name: str) -> bool:
    """Whether the constructor of ``cls`` takes the parameter ``name`` (``base``, ``seed``)."""
    return name in _constructor(cls)


def parameter_defaults(cls: type) -> dict[str, Any]:
    """The parameters a user may set on the strategy class ``cls``, with their defaults.

    Its constructor's parameters in order, less :data:`FILLED`; ``None`` for a
    parameter without a default.
    """
    return {
        name: None if p.default is inspect.Parameter.empty else p.default
        for name, p in _constructor(cls).items()
        if name not in FILLED
    }


def _kind(default: Any) -> str:
    if isinstance(default, bool):
        return "true or false"
    if isinstance(default, int):
        return "an integer"
    if isinstance(default, float):
        return "a number"
    if isinstance(default, str):
        return "a string"
    if isinstance(default, tuple) and all(type(v) is int for v in default):
        return "integers separated by commas"
    return ""


def _from_text(text: str, default: Any) -> Any:
    """``text`` read as a value of the kind of ``default``; ``ValueError`` if it is not one."""
    word = str(text).strip()
    if isinstance(default, bool):
        if word.lower() in _TRUE + _FALSE:
            return word.lower() in _TRUE
        raise ValueError(word)
    if isinstance(default, int):
        return int(word)
    if isinstance(default, float):
        value = float(word)
        if not math.isfinite(value):
            raise ValueError(word)
        return value
    if isinstance(default, str):
        return word
    return tuple(int(part) for part in word.split(","))


def check_parameters(
    name: str,
    cls: type,
    values: Mapping[str, Any] | None,
    *,
    field: str = "options",
    from_text: bool = False,
) -> dict[str, Any]:
    """``values`` checked against the parameters of strategy ``name`` (class ``cls``).

    Parameters
    ----------
    name : str
        The strategy's registered name, for messages.
    cls : type
        The strategy class.
    values : mapping, optional
        ``{parameter: value}``; text values when ``from_text``.
    field : str, default "options"
        Where the values came from (``"--set"``), named in messages.
    from_text : bool, default False
        Read each value from text by the kind of the parameter's default.

    Returns
    -------
    dict
        The values, typed.

    Raises
    ------
    UnknownNameError
        A parameter the strategy does not take (the known ones listed).
    ValueError
        A text that is not of the parameter's kind, or a parameter that takes
        a Python object (no text can give it).
    LimitError
        ``epochs`` over the ``epochs`` limit of :mod:`softbend.limits`.
    """
    known = parameter_defaults(cls)
    owner = f"transfer strategy {name!r}"
    checked: dict[str, Any] = {}
    for key, value in dict(values or {}).items():
        if key not in known:
            hint = " (the seed is set once per run: --seed)" if key in FILLED else ""
            raise UnknownNameError(
                f"Unknown parameter {key!r} of {owner} (in {field}){hint}; "
                f"known: {', '.join(known) or 'none'}."
            )
        if from_text:
            kind = _kind(known[key])
            if not kind:
                raise ValueError(
                    f"The parameter {key!r} of {owner} (in {field}) takes a Python object; "
                    "it cannot be set from text."
                )
            try:
                value = _from_text(value, known[key])
            except ValueError:
                raise ValueError(
                    f"The parameter {key!r} of {owner} (in {field}) must be {kind}. "
                    f"Got {value!r} instead."
                ) from None
        if key == "epochs" and isinstance(value, int) and not isinstance(value, bool):
            check_limit("epochs", value, f"The 'epochs' of {owner} (in {field})")
        checked[key] = value
    return checked


def recorded_parameters(estimator: Any) -> dict[str, Any]:
    """Every parameter of a strategy object, ``seed`` included, as it will run (for a record).

    The base surrogate is left out (the record names its file); a value that is
    not a number, a string, a boolean, ``None`` or a tuple of them is written as
    its ``repr``.
    """
    plain = (bool, int, float, str, type(None))
    out: dict[str, Any] = {}
    for key in _constructor(type(estimator)):
        if key == "base":
            continue
        value = getattr(estimator, key, None)
        if isinstance(value, tuple | list) and all(isinstance(v, plain) for v in value):
            value = list(value)
        elif not isinstance(value, plain):
            value = repr(value)
        out[key] = value
    return out
