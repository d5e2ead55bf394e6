"""Public parameters of a registered implementation: ``NAME=VALUE`` text and data values.

A registry entry (a controller factory, a transfer strategy class) declares its
public parameters in its signature, with defaults::

    def bang_bang(model, *, deadzone: float = 0.05, period: float = 0.01): ...
    class RefinedMLP:
        def __init__(self, base, *, epochs: int = 1000, learning_rate: float = 6e-4): ...

:func:`check_parameters` checks given values against them: an unknown name is
one :class:`UnknownParameterError` line listing the known ones; a value of the
wrong kind is one :class:`ParameterValueError` line naming the parameter and
the kind it must have. Text typed on a command line (``--set deadzone=0.02``,
parsed by :func:`parse_assignments`) is read by the parameter's kind: the type
of its default, else its annotation: ``true``/``false`` for booleans, an
integer, a number, a string, or integers separated by commas for a tuple of
integers (``hidden_sizes=63,65``). An ``epochs`` parameter is held to the
``epochs`` limit of :mod:`softbend.limits`. :func:`effective_parameters` fills
in the defaults, for the record of a run.

Every numeric parameter also declares the physical or computational range it
accepts, beside its definition::

    @declare_ranges(deadzone=Range(0, 0.5, "fraction of the target"),
                    period=Range(1e-4, 10, "s"))
    def bang_bang(model, *, deadzone: float = 0.05, period: float = 0.01): ...

:func:`check_parameters` holds each given value to its range before any work
(a tuple of integers element by element, and to ``max_items``), and the
guarantees page lists the declarations (:func:`declared_ranges`).
"""

from __future__ import annotations

import inspect
import math
import numbers
from collections.abc import Callable, Collection, Mapping, Sequence
from dataclasses import dataclass
from typing import Any, TypeVar

from softbend._validation import must_be
from softbend.errors import InputError, SoftbendError, keyed
from softbend.limits import check_limit
from softbend.registry import UnknownNameError

__all__ = [
    "ParameterValueError",
    "Range",
    "UnknownParameterError",
    "check_parameters",
    "declare_ranges",
    "declared_ranges",
    "effective_parameters",
    "parameter_defaults",
    "parse_assignments",
    "public_parameters",
]

_KINDS = {bool: "bool", int: "int", float: "float", str: "str"}
_WORDS = {
    "bool": "true or false",
    "int": "an integer",
    "float": "a number",
    "str": "a string",
    "ints": "integers separated by commas",
    "any": "a number, true/false or a string",
}
_TRUE = ("true", "yes", "on", "1")
_FALSE = ("false", "no", "off", "0")


class UnknownParameterError(UnknownNameError):
    """A parameter name that an implementation does not take; ``key`` is the name.

    The message is the predicate (``is not a parameter; known: a, b``):
    ``str(error)`` puts the key in front.
    """


class ParameterValueError(SoftbendError, ValueError):
    """A parameter value of the wrong kind; ``key`` is the parameter's name.

    The message is the predicate (``must be an integer; got 2.5``).
    """


def _bound(value: float) -> str:
    if math.isinf(value):
        return "inf" if value > 0 else "-inf"
    return f"{value:g}"


@dataclass(frozen=True)
class Range:
    """The values a numeric parameter accepts: an interval, and what it means.

    Parameters
    ----------
    low, high : float
        The bounds (``-inf``/``inf`` for none).
    unit : str, default ""
        The unit of the values, for messages and the guarantees page (``"s"``).
    why : str, default ""
        Why the bounds are where they are, for the guarantees page.
    low_inclusive, high_inclusive : bool, default True
        Whether the bounds belong to the interval.
    max_items : int, optional
        For a tuple of integers (``hidden_sizes``): the most items; each item
        is held to the interval.
    """

    low: float = -math.inf
    high: float = math.inf
    unit: str = ""
    why: str = ""
    low_inclusive: bool = True
    high_inclusive: bool = True
    max_items: int | None = None

    def interval(self) -> str:
        """The interval as text, e.g. ``[1e-05, 0.01]`` or ``(0, inf)``."""
        left = "[" if self.low_inclusive and math.isfinite(self.low) else "("
        right = "]" if self.high_inclusive and math.isfinite(self.high) else ")"
        return f"{left}{_bound(self.low)}, {_bound(self.high)}{right}"

    def describe(self) -> str:
        """The interval with its unit and item count, e.g. ``[1e-05, 0.01] s``."""
        text = self.interval() + (f" {self.unit}" if self.unit else "")
        if self.max_items is not None:
            text = f"1 to {self.max_items} values, each in {text}"
        return text

    def requirement(self) -> str:
        """What a value must be, for messages: ``in [1e-05, 0.01] s``, ``1 to 8 values, …``."""
        return self.describe() if self.max_items is not None else f"in {self.describe()}"

    def contains(self, value: object) -> bool:
        """Whether ``value`` (a number, or a tuple of them with ``max_items``) is accepted."""
        if isinstance(value, tuple | list):
            if self.max_items is not None and not 1 <= len(value) <= self.max_items:
                return False
            return all(self.contains(v) for v in value)
        if isinstance(value, bool) or not isinstance(value, numbers.Real):
            return True  # not a number: the kind check speaks for it
        number: float | int = int(value) if isinstance(value, numbers.Integral) else float(value)
        if isinstance(number, float) and math.isnan(number):
            return False
        # Python compares an integer of any size with a float exactly: no float() overflow.
        below = number < self.low or (number == self.low and not self.low_inclusive)
        above = number > self.high or (number == self.high and not self.high_inclusive)
        return not (below or above)


def _shown(value: object) -> str:
    """``repr(value)`` for a message, cut short (an integer of 400 digits is not read)."""
    text = repr(value)
    return text if len(text) <= 60 else f"{text[:45]}... ({len(text)} characters)"


Entry = TypeVar("Entry", bound=Callable[..., Any])


def declare_ranges(**ranges: Range) -> Callable[[Entry], Entry]:
    """Declare the :class:`Range` of public parameters of a factory or class.

    Used as a decorator; the ranges are read by :func:`check_parameters` and
    listed by :func:`declared_ranges`. A class inherits its parents'
    declarations, and its own override them.
    """

    def attach(entry: Entry) -> Entry:
        known, open_ended = public_parameters(entry, keyword_only=False)
        unknown = [name for name in ranges if name not in known and not open_ended]
        if unknown:
            raise TypeError(f"{entry!r} has no parameter(s) {', '.join(unknown)} to declare")
        inherited = dict(getattr(entry, "__parameter_ranges__", {}))
        entry.__parameter_ranges__ = {**inherited, **ranges}  # type: ignore[attr-defined]
        return entry

    return attach


def declared_ranges(entry: Callable[..., Any]) -> dict[str, Range]:
    """The declared :class:`Range` of each parameter of ``entry`` (empty if none)."""
    return dict(getattr(entry, "__parameter_ranges__", {}))


def public_parameters(
    entry: Callable[..., Any], *, skip: Collection[str] = (), keyword_only: bool = True
) -> tuple[dict[str, inspect.Parameter], bool]:
    """The public parameters of ``entry`` and whether it takes ``**kwargs``.

    Parameters
    ----------
    entry : callable
        A factory function or a class (its constructor's parameters).
    skip : collection of str
        Names the library fills itself (a strategy's ``base`` and ``seed``).
    keyword_only : bool, default True
        Only keyword-only parameters are public (a factory's model comes first,
        positionally); False: positional-or-keyword ones too.
    """
    kinds: set[inspect._ParameterKind] = {inspect.Parameter.KEYWORD_ONLY}
    if not keyword_only:
        kinds.add(inspect.Parameter.POSITIONAL_OR_KEYWORD)
    found: dict[str, inspect.Parameter] = {}
    open_ended = False
    for parameter in inspect.signature(entry).parameters.values():
        if parameter.kind is inspect.Parameter.VAR_KEYWORD:
            open_ended = True
        elif parameter.kind in kinds and parameter.name not in skip:
            found[parameter.name] = parameter
    return found, open_ended


def parameter_defaults(
    entry: Callable[..., Any], *, skip: Collection[str] = (), keyword_only: bool = True
) -> dict[str, Any]:
    """The public parameters of ``entry`` and their defaults (``None`` when one has none)."""
    found, _ = public_parameters(entry, skip=skip, keyword_only=keyword_only)
    return {
        name: (None if p.default is inspect.Parameter.empty else p.default)
        for name, p in found.items()
    }


def effective_parameters(
    entry: Callable[..., Any],
    checked: Mapping[str, Any] | None = None,
    *,
    skip: Collection[str] = (),
    keyword_only: bool = True,
) -> dict[str, Any]:
    """Every public parameter of ``entry``: its default, or the checked value given."""
    return {**parameter_defaults(entry, skip=skip, keyword_only=keyword_only), **(checked or {})}


def parse_assignments(
    items: Sequence[str] | None,
) -> dict[str, str]:
    """``["NAME=VALUE", ...]`` as ``{name: text}`` (the values are read later, by kind).

    Parameters
    ----------
    items : sequence of str, optional
        The assignments, e.g. the repeated values of ``--set``.

    Raises
    ------
    InputError
        Without a key (the caller names its option with
        :func:`softbend.errors.keyed`): an item without ``=``, with an empty
        name, or a name given twice.
    """
    values: dict[str, str] = {}
    for item in items or ():
        name, sep, text = str(item).partition("=")
        name = name.strip()
        if not sep or not name:
            raise InputError("an assignment " + must_be("NAME=VALUE (e.g. epochs=500)", item))
        if name in values:
            raise InputError(
                f"the parameter {name!r} is given twice ({values[name]!r} and "
                f"{text.strip()!r}); give it once"
            )
        values[name] = text.strip()
    return values


def _is_ints(value: object) -> bool:
    return isinstance(value, tuple | list) and all(
        isinstance(v, numbers.Integral) and not isinstance(v, bool) for v in value
    )


def _kind(parameter: inspect.Parameter) -> str:
    """The kind of one parameter: from its default's type, else from its annotation."""
    default = parameter.default
    if type(default) in _KINDS:
        return _KINDS[type(default)]
    if isinstance(default, tuple) and default and _is_ints(default):
        return "ints"
    note = parameter.annotation
    text = note if isinstance(note, str) else getattr(note, "__name__", str(note))
    words = [w for w in text.replace(" ", "").split("|") if w not in ("None", "NoneType")]
    if len(words) == 1 and words[0].startswith("tuple[int"):
        return "ints"
    return words[0] if len(words) == 1 and words[0] in _KINDS.values() else "any"


def _from_text(text: str, kind: str) -> Any:
    """A value typed on a command line, as ``kind``; ``ValueError`` when it is not one."""
    word = text.strip().lower()
    if kind == "str":
        return text.strip()
    if kind == "ints":
        return tuple(int(part) for part in word.split(","))
    if kind == "bool" or (kind == "any" and word in _TRUE[:1] + _FALSE[:1]):
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
    return text.strip()


def _typed(value: Any, kind: str) -> Any:
    """A value given as data (TOML, Python), checked to be ``kind``; ``ValueError`` if not."""
    real = isinstance(value, numbers.Real) and not isinstance(value, bool)
    if kind == "bool" and isinstance(value, bool):
        return value
    if kind == "int" and isinstance(value, numbers.Integral) and not isinstance(value, bool):
        return int(value)
    if kind == "float" and real:
        return float(value)
    if kind == "str" and isinstance(value, str):
        return value
    if kind == "ints" and _is_ints(value):
        return tuple(int(v) for v in value)
    if kind == "any" and (real or isinstance(value, bool | str)):
        return value
    raise ValueError(value)


def check_parameters(
    entry: Callable[..., Any],
    values: Mapping[str, Any] | None,
    *,
    from_text: bool = False,
    skip: Collection[str] = (),
    keyword_only: bool = True,
    hints: Mapping[str, str] | None = None,
) -> dict[str, Any]:
    """The given ``values`` checked against the public parameters of ``entry``.

    Parameters
    ----------
    entry : callable
        A factory or a class; see :func:`public_parameters`. One that takes
        ``**kwargs`` also accepts any other name.
    values : mapping, optional
        ``{name: value}``: text from a command line (``from_text``) or data (TOML, Python).
    from_text : bool, default False
        Read text values by each parameter's kind.
    skip, keyword_only
        As for :func:`public_parameters`.
    hints : mapping, optional
        ``{name: text}`` added to the message when a skipped name is given
        (``{"seed": "the seed is set once per run: --seed"}``).

    Returns
    -------
    dict
        The given names with their checked values (an integer given for a number
        becomes a float, a list of integers a tuple).

    Raises
    ------
    UnknownParameterError
        A name ``entry`` does not take (the key); the message lists the known names.
    ParameterValueError
        A value that is not of the parameter's kind, a number that is not finite,
        or a value outside its declared :class:`Range`; the key is the parameter.
    LimitError
        ``epochs`` over the ``epochs`` limit of :mod:`softbend.limits`.
    """
    known, open_ended = public_parameters(entry, skip=skip, keyword_only=keyword_only)
    ranges = declared_ranges(entry)
    checked: dict[str, Any] = {}
    for key, value in (values or {}).items():
        if key not in known and not open_ended:
            hint = f" ({hints[key]})" if hints and key in hints else ""
            raise UnknownParameterError(
                f"is not a parameter{hint}; known: {', '.join(known) or 'none'}", key=key
            )
        kind = _kind(known[key]) if key in known else "any"
        try:
            result = _from_text(str(value), kind) if from_text else _typed(value, kind)
        except (ValueError, OverflowError):  # an integer too large for a float is no number
            raise ParameterValueError(
                f"must be {_WORDS[kind]}; got {_shown(value)}", key=key
            ) from None
        if isinstance(result, float) and not math.isfinite(result):
            raise ParameterValueError(f"must be a finite number; got {_shown(value)}", key=key)
        if key == "epochs" and kind == "int":
            with keyed(key):
                check_limit("epochs", result, "the value")
        declared = ranges.get(key)
        if declared is not None and not declared.contains(result):
            shown = _shown(",".join(map(str, result))) if isinstance(result, tuple) else None
            shown = shown.strip("'") if shown is not None else _shown(value)
            raise ParameterValueError(f"must be {declared.requirement()}; got {shown}", key=key)
        checked[key] = result
    return checked
