"""Parameters of a named factory by their public names: ``NAME=VALUE`` text and TOML values.

A factory of a registry (a controller's, for instance) declares its public
parameters as keyword-only arguments with defaults::

    def bang_bang(model, *, deadzone: float = 0.05, period: float = 0.01): ...

:func:`check_parameters` checks given values against them: an unknown name is
one :class:`UnknownParameterError` line listing the known ones; a value of the
wrong kind is one :class:`ParameterValueError` line naming the parameter and
the kind it must have. Values typed on a command line (``--set deadzone=0.02``)
are parsed by the kind of the parameter (its default's type, else its
annotation): numbers, ``true``/``false`` for booleans, text for strings.
:func:`effective_parameters` fills in the defaults, for the record of a run.
"""

from __future__ import annotations

import inspect
import math
from collections.abc import Callable, Mapping, Sequence
from typing import Any

from softbend.errors import SoftbendError
from softbend.registry import UnknownNameError

__all__ = [
    "ParameterValueError",
    "UnknownParameterError",
    "check_parameters",
    "effective_parameters",
    "parameter_defaults",
    "parse_assignments",
]

_KINDS = {bool: "bool", int: "int", float: "float", str: "str"}
_WORDS = {
    "bool": "true or false",
    "int": "an integer",
    "float": "a number",
    "str": "a string",
    "any": "a number, true/false or a string",
}
_TRUE = ("true", "yes", "on", "1")
_FALSE = ("false", "no", "off", "0")


class UnknownParameterError(UnknownNameError):
    """A parameter name that a factory does not take; ``key`` is the name."""

    def __init__(self, message: str, key: str) -> None:
        super().__init__(message)
        self.key = key


class ParameterValueError(SoftbendError, ValueError):
    """A parameter value of the wrong kind; ``key`` is the parameter's name."""

    def __init__(self, message: str, key: str) -> None:
        super().__init__(message)
        self.key = key


def _kind(parameter: inspect.Parameter) -> str:
    """``"bool"``, ``"int"``, ``"float"``, ``"str"`` or ``"any"`` for one keyword parameter."""
    default = parameter.default
    if type(default) in _KINDS:
        return _KINDS[type(default)]
    note = parameter.annotation
    text = note if isinstance(note, str) else getattr(note, "__name__", str(note))
    words = [w for w in text.replace(" ", "").split("|") if w not in ("None", "NoneType")]
    return words[0] if len(words) == 1 and words[0] in _WORDS else "any"


def _keywords(factory: Callable[..., Any]) -> tuple[dict[str, inspect.Parameter], bool]:
    """The keyword-only parameters of ``factory``, and whether it takes ``**kwargs``."""
    found: dict[str, inspect.Parameter] = {}
    open_ended = False
    for parameter in inspect.signature(factory).parameters.values():
        if parameter.kind is inspect.Parameter.KEYWORD_ONLY:
            found[parameter.name] = parameter
        elif parameter.kind is inspect.Parameter.VAR_KEYWORD:
            open_ended = True
    return found, open_ended


def parameter_defaults(factory: Callable[..., Any]) -> dict[str, Any]:
    """The public parameters of ``factory`` and their defaults (``None`` when it has none)."""
    found, _ = _keywords(factory)
    return {
        name: (None if p.default is inspect.Parameter.empty else p.default)
        for name, p in found.items()
    }


def parse_assignments(items: Sequence[str] | None, field: str) -> dict[str, str]:
    """``["NAME=VALUE", ...]`` as ``{name: text}`` (the values are parsed by the factory's kinds).

    Parameters
    ----------
    items : sequence of str, optional
        The assignments, e.g. the repeated values of ``--set``.
    field : str
        Where they came from, for messages (``"--set"``).

    Raises
    ------
    ValueError
        An item without ``=``, with an empty name, or a name given twice.
    """
    values: dict[str, str] = {}
    for item in items or ():
        name, sep, text = str(item).partition("=")
        name = name.strip()
        if not sep or not name:
            raise ValueError(
                f"The '{field}' values must be NAME=VALUE (e.g. deadzone=0.05). "
                f"Got {item!r} instead."
            )
        if name in values:
            raise ValueError(
                f"The '{field}' parameter {name!r} is given twice ({values[name]!r} and "
                f"{text.strip()!r}); give it once."
            )
        values[name] = text.strip()
    return values


def _from_text(text: str, kind: str) -> Any:
    """A value typed on a command line, as ``kind``; ``ValueError`` when it is not one."""
    word = text.strip().lower()
    if kind == "str":
        return text
    if kind == "bool" or (kind == "any" and word in ("true", "false")):
        if word in _TRUE:
            return True
        if word in _FALSE:
            return False
        raise ValueError(text)
    try:
        return int(word) if kind in ("int", "any") else float(word)
    except ValueError:
        if kind == "int":
            raise
    try:
        return float(word)
    except ValueError:
        if kind == "float":
            raise
    return text


def _typed(value: Any, kind: str) -> Any:
    """A value given as data (TOML, Python), checked to be ``kind``; ``ValueError`` if not."""
    if kind == "bool" and isinstance(value, bool):
        return value
    if kind == "int" and type(value) is int:
        return value
    if kind == "float" and type(value) in (int, float):
        return float(value)
    if kind == "str" and isinstance(value, str):
        return value
    if kind == "any" and type(value) in (bool, int, float, str):
        return value
    raise ValueError(value)


def check_parameters(
    factory: Callable[..., Any],
    values: Mapping[str, Any] | None,
    *,
    owner: str,
    field: str,
    from_text: bool = False,
) -> dict[str, Any]:
    """The given ``values`` checked against the public parameters of ``factory``.

    Parameters
    ----------
    factory : callable
        Its keyword-only parameters (with defaults) are the public ones; one that
        takes ``**kwargs`` also accepts any other name.
    values : mapping, optional
        ``{name: value}``: text from a command line (``from_text``) or data (TOML).
    owner : str
        What the parameters belong to, for messages (``"controller 'bang-bang'"``).
    field : str
        Where the values came from, for messages (``"--set"``).
    from_text : bool, default False
        Parse text values by each parameter's kind (numbers, true/false, text).

    Returns
    -------
    dict
        The given names with their checked values (an int given for a float becomes a float).

    Raises
    ------
    UnknownParameterError
        A name the factory does not take; the message lists the known names.
    ParameterValueError
        A value that is not of the parameter's kind, or a number that is not finite.
    """
    known, open_ended = _keywords(factory)
    checked: dict[str, Any] = {}
    for key, value in (values or {}).items():
        if key not in known and not open_ended:
            raise UnknownParameterError(
                f"Unknown parameter {key!r} of {owner} (in {field}); known: "
                f"{', '.join(known) or 'none'}.",
                key,
            )
        kind = _kind(known[key]) if key in known else "any"
        try:
            result = _from_text(str(value), kind) if from_text else _typed(value, kind)
        except ValueError:
            raise ParameterValueError(
                f"The parameter {key!r} of {owner} (in {field}) must be {_WORDS[kind]}. "
                f"Got {value!r} instead.",
                key,
            ) from None
        if isinstance(result, float) and not math.isfinite(result):
            raise ParameterValueError(
                f"The parameter {key!r} of {owner} (in {field}) must be a finite number. "
                f"Got {value!r} instead.",
                key,
            )
        checked[key] = result
    return checked


def effective_parameters(
    factory: Callable[..., Any], checked: Mapping[str, Any] | None = None
) -> dict[str, Any]:
    """Every public parameter of ``factory``: its default, or the checked value given."""
    return {**parameter_defaults(factory), **(checked or {})}
