"""Input checks that produce one message format everywhere.

The format follows scikit-learn's parameter validation::

    The 'wall_thickness_mm' of SFRBADesign must be in (0, inf). Got -2.0 instead.
"""

from __future__ import annotations

import math
import numbers
from collections.abc import Iterable, Mapping, Sequence
from typing import Any

import numpy as np

from softbend.errors import DatasetError


def _fmt_bound(value: float) -> str:
    if math.isinf(value):
        return "inf" if value > 0 else "-inf"
    return f"{value:g}"


def check_range(
    value: Any,
    name: str,
    owner: str,
    *,
    low: float = -math.inf,
    high: float = math.inf,
    low_inclusive: bool = False,
    high_inclusive: bool = False,
) -> float:
    """Return ``value`` as a float if it lies in the interval, else raise ``ValueError``.

    Parameters
    ----------
    value : Any
        The value to check; must convert to a finite float (``inf`` only if a
        bound allows it).
    name : str
        Field name used in the message, with its unit suffix (``"t_mm"``).
    owner : str
        Name of the object or function the field belongs to.
    low, high : float
        Interval bounds.
    low_inclusive, high_inclusive : bool
        Whether the bounds belong to the interval.

    Returns
    -------
    float
        The validated value.
    """
    interval = (
        ("[" if low_inclusive else "(")
        + f"{_fmt_bound(low)}, {_fmt_bound(high)}"
        + ("]" if high_inclusive else ")")
    )
    message = f"The '{name}' of {owner} must be a number in {interval}. Got {value!r} instead."
    if isinstance(value, bool):
        raise ValueError(message)
    try:
        number = float(value)
    except (TypeError, ValueError):
        raise ValueError(message) from None
    if math.isnan(number):
        raise ValueError(message)
    below = number < low or (number == low and not low_inclusive)
    above = number > high or (number == high and not high_inclusive)
    if below or above:
        raise ValueError(message)
    return number


def check_choice(value: Any, name: str, owner: str, choices: Iterable[Any]) -> Any:
    """Return ``value`` if it is one of ``choices``, else raise ``ValueError``."""
    options = list(choices)
    if value not in options:
        allowed = ", ".join(repr(c) for c in options)
        raise ValueError(
            f"The '{name}' of {owner} must be one of {allowed}. Got {value!r} instead."
        )
    return value


def check_int(value: Any, name: str, owner: str, *, low: int = 0) -> int:
    """Return ``value`` as an int if it is an integer (not a bool) ``>= low``, else raise.

    Raises
    ------
    ValueError
        ``The 'name' of owner must be an integer in [low, inf). Got ... instead.``
    """
    if isinstance(value, bool) or not isinstance(value, numbers.Integral) or value < low:
        raise ValueError(
            f"The '{name}' of {owner} must be an integer in [{low}, inf). Got {value!r} instead."
        )
    return int(value)


def check_finite_array(values: Any, name: str, owner: str) -> np.ndarray:
    """Convert to a float array and raise :class:`DatasetError` if anything is NaN or infinite."""
    array = np.asarray(values, dtype=float)
    bad = ~np.isfinite(array)
    if bad.any():
        first = int(np.flatnonzero(bad.ravel())[0])
        raise DatasetError(
            f"The '{name}' of {owner} must be finite. Got {array.ravel()[first]!r} "
            f"at position {first} ({int(bad.sum())} non-finite values in all)."
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
