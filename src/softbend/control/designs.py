"""The design a control run is of: a :class:`~softbend.actuators.Design` of the model's actuator.

A control run's rig and controllers work in MPa gauge; a model takes rows
``(*design values, p)`` with ``p`` in its description's pressure unit, which
:meth:`Design.feature_rows(p, unit="MPa") <softbend.actuators.Design.feature_rows>`
converts. :func:`control_design` reads the ``--design`` text (or a design, or
its values) by the model's description.
"""

from __future__ import annotations

from collections.abc import Sequence

import numpy as np

from softbend.actuators import Actuator, Design
from softbend.errors import InputError, keyed

__all__ = [
    "DEFAULT_DESIGN",
    "DEFAULT_DESIGNS",
    "actuator_of_design",
    "control_design",
]

#: The actuator of paper B's control experiments (l, r, t, b, phi, lc in mm and degrees).
DEFAULT_DESIGN = "100,6,2,2,5,8"

#: The design a control run is of when none is given, by actuator name (paper B's
#: control experiments); an actuator not named here needs one.
DEFAULT_DESIGNS: dict[str, str] = {"sfrba": DEFAULT_DESIGN}


def actuator_of_design(design: Design) -> Actuator:
    """The actuator description ``design`` is of."""
    return design.actuator


def control_design(
    design: str | Design | Sequence[float] | None,
    actuator: Actuator,
    *,
    source: str = "the model",
) -> Design:
    """``design`` as a design of ``actuator``, checked against its description.

    Parameters
    ----------
    design : str, Design, sequence of float or None
        Text: ``"A=1,B=2,..."`` by the description's parameter names, or the
        values in their order (paper B's ``"l,r,t,b,phi,lc"``), in the units of
        its description. None: the actuator's default design
        (:data:`DEFAULT_DESIGNS`), if it has one.
    actuator : Actuator
        The description of the controller's model.
    source : str
        What the description belongs to (``"the model m.json"``), for messages.

    Raises
    ------
    InputError
        A design that is not one of ``actuator`` (the message names its parameters),
        or none given for an actuator without a default design; its key is ``design``.
    """
    if design is None:
        if actuator.name not in DEFAULT_DESIGNS:
            raise InputError(
                f"must be given for {source}, of the actuator {actuator.name} "
                f"({', '.join(actuator.names)}): {actuator.design_hint()}",
                key="design",
            )
        design = DEFAULT_DESIGNS[actuator.name]
    if isinstance(design, Design):
        if design.actuator.names != actuator.names:
            raise InputError(
                f"is a design of the actuator {design.actuator.name}, but "
                f"{source} is of {actuator.name} ({', '.join(actuator.names)}); "
                f"give {actuator.design_hint()}",
                key="design",
            )
        with keyed("design"):
            return Design.checked(actuator, design.as_array())
    with keyed("design"):
        if isinstance(design, str):
            return Design.checked(actuator, actuator.parse_design(design))
        return Design.checked(actuator, np.asarray(design, dtype=float))
