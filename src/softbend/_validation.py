"""Input checks that produce one message format everywhere.

Every check raises an :class:`~softbend.errors.InputError` (a ``ValueError``)
that carries the input's key and says what the value must be and what it was::

    t_mm: must be a number in (0, inf); got -2.0

The command line names the option for the key (:mod:`softbend.cli._options`);
the same wording serves the declared ranges of :mod:`softbend.parameters`, the
rig file and the table readers.
"""

from __future__ import annotations

import math
import numbers
from collections.abc import Iterable, Mapping, Sequence
from typing import Any

import numpy as np

from softbend.errors import DatasetError, InputError


def _fmt_bound(value: float) -> str:
    if math.isinf(value):
        return "inf" if value > 0 else "-inf"
    return f"{value:g}"


def interval_text(
    low: float, high: float, *, low_inclusive: bool = False, high_inclusive: bool = False
) -> str:
    """An interval as text: ``(0, inf)``, ``[100, 160]`` (infinite bounds are always open)."""
    left = "[" if low_inclusive and math.isfinite(low) else "("
    right = "]" if high_inclusive and math.isfinite(high) else ")"
    return f"{left}{_fmt_bound(low)}, {_fmt_bound(high)}{right}"


def must_be(requirement: str, value: Any) -> str:
    """The one wording of a failed check: ``must be <requirement>; got <value>``."""
    return f"must be {requirement}; got {short_repr(value)}"


def check_range(
    value: Any,
    key: str,
    *,
    low: float = -math.inf,
    high: float = math.inf,
    low_inclusive: bool = False,
    high_inclusive: bool = False,
) -> float:
    """Return ``value`` as a float if it lies in the interval, else raise :class:`InputError`.

    Parameters
    ----------
    value : object
        The value to check; must convert to a finite float (``inf`` only if a
        bound allows it).
    key : str
        The input's name, with its unit suffix (``"t_mm"``).
    low, high : float
        Interval bounds.
    low_inclusive, high_inclusive : bool
        Whether the bounds belong to the interval.

    Returns
    -------
    float
        The validated value.
    """
    interval = interval_text(low, high, low_inclusive=low_inclusive, high_inclusive=high_inclusive)
    error = InputError(must_be(f"a number in {interval}", value), key=key)
    if isinstance(value, bool):
        raise error
    try:
        number = float(value)
    except (TypeError, ValueError, OverflowError):
        raise error from None
    if math.isnan(number):
        raise error
    below = number < low or (number == low and not low_inclusive)
    above = number > high or (number == high and not high_inclusive)
    if below or above:
        raise error
    return number


def check_choice(value: Any, key: str, choices: Iterable[Any]) -> Any:
    """Return ``value`` if it is one of ``choices``, else raise :class:`InputError`."""
    options = list(choices)
    if value not in options:
        allowed = ", ".join(repr(c) for c in options)
        raise InputError(must_be(f"one of {allowed}", value), key=key)
    return value


def check_int(value: Any, key: str, *, low: int = 0) -> int:
    """Return ``value`` as an int if it is an integer (not a bool) ``>= low``, else raise.

    Raises
    ------
    InputError
        ``key: must be an integer in [low, inf); got ...``.
    """
    if isinstance(value, bool) or not isinstance(value, numbers.Integral) or value < low:
        raise InputError(must_be(f"an integer in [{low}, inf)", value), key=key)
    return int(value)


def check_finite_array(values: Any, key: str) -> np.ndarray:
    """Convert to a float array and raise :class:`DatasetError` if anything is NaN or infinite."""
    array = np.asarray(values, dtype=float)
    bad = ~np.isfinite(array)
    if bad.any():
        first = int(np.flatnonzero(bad.ravel())[0])
        raise DatasetError(
            f"must be finite; got {float(array.ravel()[first])} at position {first} "
            f"({int(bad.sum())} non-finite values in all)",
            key=key,
        )
    return array


def short_repr(value: Any, limit: int = 60) -> str:
    """A value as JSON (else its repr), cut to ``limit`` characters, for error messages."""
    import json

    try:
        text = json.dumps(value)
    except (TypeError, ValueError):
        text = repr(value)
    return text if len(text) <= limit else text[: limit - 3] + "..."


def check_object_keys(
    value: Any,
    where: str,
    allowed: Sequence[str],
    required: Sequence[str],
    error: type[Exception],
) -> Mapping[str, Any]:
    """``value`` if it is a mapping with only ``allowed`` keys and every ``required`` one.

    For the objects of a structured file (JSON, TOML). Otherwise raises ``error``
    naming ``where`` (the object's place in the file) and the keys at fault.
    """
    if not isinstance(value, Mapping):
        raise error(f"'{where}' must be a JSON object; got {short_repr(value)}")
    unknown = [str(k) for k in value if k not in allowed]
    if unknown:
        raise error(
            f"unknown key(s) {', '.join(map(repr, unknown))} in '{where}'; "
            f"allowed keys: {', '.join(allowed)}"
        )
    missing = [k for k in required if k not in value]
    if missing:
        raise error(f"'{where}' lacks the key(s) {', '.join(missing)}")
    return value
