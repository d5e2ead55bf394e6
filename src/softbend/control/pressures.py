"""The supply pressure of a control run as given: with a unit, or in the unit of its actuator.

The rig works in MPa gauge. A supply given with a unit suffix (``20psi``, ``138kPa``,
``0.2MPa``) is converted from it; a bare number is in the pressure unit of the run's
actuator (:func:`run_pressure_unit`): a lab's model trained in kPa takes ``--supply 60``
as 60 kPa, paper B's models (MPa) take ``0.2`` as 0.2 MPa, as they always did.
"""

from __future__ import annotations

from pathlib import Path
from typing import TYPE_CHECKING

from softbend.errors import InputError, keyed

if TYPE_CHECKING:
    from softbend.control.plant_choice import PlantChoice

__all__ = ["run_pressure_unit", "run_supply_mpa", "supply_mpa"]


def run_pressure_unit(model: str | Path | None, plant: str | PlantChoice) -> str:
    """The pressure unit of a run's actuator, in which a bare supply pressure is read.

    Parameters
    ----------
    model : path, optional
        The controller's model (``--model``).
    plant : str
        The plant (``--plant``): a name or a file.

    Returns
    -------
    str
        The plant's unit when it is a saved surrogate (its description's pressure unit)
        or a model of ``softbend identify`` (its pressure input's unit); else the unit
        of ``model`` when given; else ``"MPa"`` (paper B's shipped MLP, FEM and virtual
        lab, and its measurements ``.csv``).

    Raises
    ------
    SoftbendError
        Keyed ``plant`` or ``model``: a plant that is neither a name nor a file, or a
        model file that cannot be read (as the run itself would say).
    """
    from softbend.control.plants import parse_plant
    from softbend.surrogates.persistence import load_surrogate

    with keyed("plant"):
        unit = parse_plant(plant).pressure_unit()
    if unit is not None:
        return unit
    if model is not None:
        with keyed("model"):
            return str(load_surrogate(model).actuator.pressure_unit)
    return "MPa"


def supply_mpa(supply: str | float | None, unit: str) -> float | None:
    """A supply pressure as given, in MPa gauge, checked (None stays None).

    Parameters
    ----------
    supply : str or float, optional
        A number in ``unit`` (``"60"``), or a number with a unit suffix (``"20psi"``,
        ``"138 kPa"``; :func:`softbend.units.parse_pressure`).
    unit : str
        The unit of a bare number (:func:`run_pressure_unit`).

    Raises
    ------
    InputError
        Keyed ``supply_mpa``: text that is not a pressure, an unknown unit, or a
        pressure that is not a plausible gauge pressure
        (:func:`~softbend.control.setup.check_supply`; the message gives the value as
        typed and in MPa).
    """
    from softbend.control.setup import check_supply
    from softbend.units import PRESSURE_UNITS, convert_pressure, parse_pressure

    if supply is None:
        return None
    text = str(supply).strip()
    with keyed("supply_mpa"):
        try:  # a bare number, nan and inf included: in the run's unit
            mpa = convert_pressure(float(text), unit, "MPa")
            shown = None if unit == "MPa" else f"{text} {unit} ({mpa:.6g} MPa)"
        except ValueError:
            try:
                mpa = parse_pressure(text, "MPa", "supply")
            except InputError:
                raise InputError(
                    f"must be a pressure: a number, optionally with a unit "
                    f"({', '.join(PRESSURE_UNITS)}), e.g. 200kPa; got {text!r}"
                ) from None
            shown = f"{text} ({mpa:.6g} MPa)"
        return check_supply(mpa, given=shown)


def run_supply_mpa(
    supply: str | float | None, model: str | Path | None, plant: str | PlantChoice
) -> float | None:
    """:func:`supply_mpa` of a run: a bare number in :func:`run_pressure_unit` of its
    ``model`` and ``plant`` (looked up only for a bare number), in MPa gauge."""
    if supply is None:
        return None
    try:
        float(str(supply).strip())
    except ValueError:  # a unit suffix (or not a pressure): the unit is its own
        return supply_mpa(supply, "MPa")
    return supply_mpa(supply, run_pressure_unit(model, plant))
