"""The declared ranges of the control package, checked where the values are used.

A controller class or :class:`~softbend.control.rig.RigParams` declares the
range of each numeric parameter once (:func:`softbend.parameters.declare_ranges`);
the registry checks the values given by name against them
(:func:`softbend.parameters.check_parameters`), and the constructors check their
arguments against the same ones (:func:`check_declared`), in the wording of
:mod:`softbend._validation`: one source of truth for ``--set``, ``--rig-param``,
a rig TOML and Python.
"""

from __future__ import annotations

import math
import numbers

from softbend._validation import must_be
from softbend.errors import InputError
from softbend.parameters import Range

__all__ = ["check_declared"]


def check_declared(
    value: object, name: str, declared: Range, *, integer: bool = False
) -> float | int:
    """``value`` as a float (an int with ``integer``) when it lies in ``declared``.

    Parameters
    ----------
    value : object
        The value given.
    name : str
        Its key (with its unit, e.g. ``"valve_delay_s"``).
    declared : Range
        The declared range.
    integer : bool, default False
        The value must be an integer.

    Raises
    ------
    InputError
        ``name: must be a number in [low, high] unit; got value``: not a number
        (a boolean is not one), not finite, or out of the range.
    """
    kind = "an integer" if integer else "a number"
    error = InputError(must_be(f"{kind} in {declared.describe()}", value), key=name)
    wanted = numbers.Integral if integer else numbers.Real
    if isinstance(value, bool) or not isinstance(value, wanted):
        raise error
    number = int(value) if integer and isinstance(value, numbers.Integral) else float(value)  # type: ignore[arg-type]
    if not (integer or math.isfinite(number)) or not declared.contains(number):
        raise error
    return number
