"""The parameters of a transfer strategy: read from its constructor, checked, typed from text.

A strategy is a class (see :data:`softbend.transfer.strategies.STRATEGIES`);
its parameters are its constructor's, less the two the library fills itself:
``base`` (the surrogate the strategy starts from) and ``seed`` (given once per
run, ``--seed``). A user sets the others from Python
(``make_strategy("refined", base, epochs=500)``) or as text on the command line
(``--set epochs=500``): text is read by the kind of the parameter's default
(``true``/``false``, an integer, a number, a string, integers separated by
commas for a tuple such as ``hidden_sizes=63,65``), by the rules of
:mod:`softbend.parameters` that the controllers' parameters follow too. An
unknown name is one :class:`~softbend.parameters.UnknownParameterError` line
listing the known ones.
"""

from __future__ import annotations

import inspect
from collections.abc import Mapping
from typing import Any

from softbend import parameters as _parameters

__all__ = ["FILLED", "check_parameters", "parameter_defaults", "recorded_parameters", "takes"]

#: Constructor parameters the library fills itself: never set by name.
FILLED: tuple[str, ...] = ("base", "seed")

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


def check_parameters(
    name: str,
    cls: type,
    values: Mapping[str, Any] | None,
    *,
    field: str = "options",
    from_text: bool = False,
) -> dict[str, Any]:
    """``values`` checked against the parameters of strategy ``name`` (class ``cls``).

    :func:`softbend.parameters.check_parameters` on the constructor of ``cls``,
    less :data:`FILLED`.

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
        A value that is not of the parameter's kind.
    LimitError
        ``epochs`` over the ``epochs`` limit of :mod:`softbend.limits`.
    """
    return _parameters.check_parameters(
        cls,
        values,
        owner=f"transfer strategy {name!r}",
        field=field,
        from_text=from_text,
        skip=FILLED,
        keyword_only=False,
        hints=_HINTS,
    )


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
