"""Actuator descriptions: the named design parameters a lab's actuator is described by.

softbend's learning pipeline (train → predict → transfer → design search →
control) does not depend on an actuator's geometry, only on its description:
the design parameters (name, unit, range, kind, manufacturing resolution), the
constraints between them, and the pressure and angle columns with their units.
Paper B's fiber-reinforced actuator is one registered description
(``"sfrba"``); a lab's own actuator is another, registered in Python or read
from the columns of its simulation table (:meth:`Actuator.from_table`).

Every model saved by ``softbend train`` records the description it was
trained with (:meth:`Actuator.to_dict`), so that predict, transfer, design
search and control name the model's own parameters and check them in their
own units::

    from softbend.actuators import ACTUATORS, Actuator, DesignParameter

    pneunet = Actuator(
        name="my-pneunet",
        title="PneuNet, 8 to 14 chambers",
        parameters=(
            DesignParameter("n_chambers", "", 8, 14, kind="integer"),
            DesignParameter("wall_mm", "mm", 1.0, 3.0, resolution=0.1),
            DesignParameter("layer", "", kind="categorical", levels=("paper", "fabric")),
        ),
        pressure_column="p_kpa",
        pressure_unit="kPa",
        constraints=("wall_mm <= 3",),
    )
    ACTUATORS.register(pneunet.name, pneunet)

A categorical parameter's levels are stored as their index (0, 1, …) in
every model input; :meth:`DesignParameter.encode` and
:meth:`DesignParameter.decode` convert. A design of an actuator is a
:class:`Design` (its description and a value of each parameter).

The package holds one idea a module: a design parameter (:mod:`.parameters`),
constraints between parameters (:mod:`.constraints`), the description and its
registry (:mod:`.description`), a design (:mod:`.design`), and the registered
descriptions, one module each: paper B's actuator (:mod:`.sfrba`, simulated by
the FEM family ``"sfrba"``) and the PneuNet (:mod:`.pneunet`, whose FEM family
:mod:`softbend.fem.pneunet.description` imports it). Importing the package
registers both.
"""

from __future__ import annotations

from softbend.actuators.description import (
    ACTUATORS,
    Actuator,
    actuator_from,
    get_actuator,
    load_actuator,
    parse_ranges,
)
from softbend.actuators.design import Design
from softbend.actuators.parameters import (
    PRESSURE_UNITS,
    ActuatorError,
    DesignParameter,
    pressure_to_mpa,
)
from softbend.actuators.pneunet import PNEUNET
from softbend.actuators.sfrba import SFRBA

__all__ = [
    "ACTUATORS",
    "PNEUNET",
    "PRESSURE_UNITS",
    "SFRBA",
    "Actuator",
    "ActuatorError",
    "Design",
    "DesignParameter",
    "actuator_from",
    "get_actuator",
    "load_actuator",
    "parse_ranges",
    "pressure_to_mpa",
]
