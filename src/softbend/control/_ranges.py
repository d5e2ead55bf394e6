"""The declared ranges of the control package, checked where the values are used.

A controller class or :class:`~softbend.control.rig.RigParams` declares the
range of each numeric parameter once (:func:`softbend.parameters.declare_ranges`);
the registered factories and the settings of the simulated rig reuse those
declarations (:func:`ranges_of`), and the constructors check their arguments
against the same ones (:func:`check_declared`): one source of truth for
``--set``, ``--rig-param``, a rig TOML and Python.
"""

from __future__ import annotations

import math
import numbers
from collections.abc import Callable
from typing import Any

from softbend.parameters import Range, declared_ranges

__all__ = ["check_declared", "ranges_of"]


def check_declared(
    value: Any, name: str, owner: str, declared: Range, *, integer: bool = False
) -> Any:
    """``value`` as a float (an int with ``integer``) when it lies in ``declared``.

    Parameters
    ----------
    value : Any
        The value given.
    name : str
        Its name, for the message (with its unit, e.g. ``"valve_delay_s"``).
    owner : str
        What it belongs to, for the message (``"RigParams"``).
    declared : Range
        The declared range.
    integer : bool, default False
        The value must be an integer.

    Raises
    ------
    ValueError
        One line naming the parameter, its range and the value: not a number
        (a boolean is not one), not finite, or out of the range.
    """
    kind = "an integer" if integer else "a number"
    message = (
        f"The '{name}' of {owner} must be {kind} in {declared.describe()}. Got {value!r} instead."
    )
    wanted = numbers.Integral if integer else numbers.Real
    if isinstance(value, bool) or not isinstance(value, wanted):
        raise ValueError(message)
    number = int(value) if integer and isinstance(value, numbers.Integral) else float(value)
    if not (integer or math.isfinite(number)) or not declared.contains(number):
        raise ValueError(message)
    return number


def ranges_of(entry: Callable[..., Any], **names: str) -> dict[str, Range]:
    """The declared ranges of ``entry``'s parameters under other names.

    ``ranges_of(BangBang, deadzone="deadzone_fraction")`` is
    ``{"deadzone": <the Range of BangBang's deadzone_fraction>}``: a factory
    declares the ranges of the class it builds (:func:`declare_ranges`).
    """
    declared = declared_ranges(entry)
    return {mine: declared[theirs] for mine, theirs in names.items()}
