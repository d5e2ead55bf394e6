"""The design a control run is of: paper B's actuator, or any actuator a model describes.

A control run's rig and controllers work in MPa gauge. A saved surrogate of
paper B's actuator takes rows ``(l, r, t, b, phi, lc, p)`` in mm, degrees and
MPa, and its design is a :class:`~softbend.design.SFRBADesign`, exactly as
before models of other actuators existed. A model of another actuator
(:class:`~softbend.actuators.Actuator`: named parameters, its own pressure
unit) takes rows ``(*design codes, p)`` with ``p`` in its own unit; its design
is a :class:`ModelDesign`, which answers the same calls as an ``SFRBADesign``
(:meth:`ModelDesign.as_array`, :meth:`ModelDesign.feature_rows` from MPa,
``str``) so that θ(p) tables, the virtual sensor and the support check take
either. :func:`control_design` parses the ``--design`` text by the model's
actuator.
"""

from __future__ import annotations

from collections.abc import Sequence
from dataclasses import dataclass, field
from typing import Any

import numpy as np

from softbend.actuators import SFRBA, Actuator
from softbend.design import SFRBADesign
from softbend.errors import InputError, keyed

__all__ = [
    "DEFAULT_DESIGN",
    "ModelDesign",
    "actuator_of_design",
    "control_design",
]

#: The actuator of paper B's control experiments (l, r, t, b, phi, lc in mm and degrees).
DEFAULT_DESIGN = "100,6,2,2,5,8"


@dataclass(frozen=True)
class ModelDesign:
    """A design of an actuator other than paper B's, as a model of it takes it.

    Attributes
    ----------
    actuator : Actuator
        The description the model was trained with.
    codes : ndarray
        The model inputs of the design, in the order of ``actuator.names`` (a
        categorical level as its index), checked against the description.
    """

    actuator: Actuator
    codes: np.ndarray = field(repr=False)

    def __post_init__(self) -> None:
        codes = self.actuator.check_designs(np.asarray(self.codes, dtype=float).ravel())[0]
        object.__setattr__(self, "codes", codes)

    @property
    def pressure_scale(self) -> float:
        """Factor from MPa (the rig's unit) to the model's pressure unit."""
        return 1.0 / self.actuator.to_mpa

    def as_array(self) -> np.ndarray:
        """The design codes (a copy)."""
        return self.codes.copy()

    def feature_rows(self, pressures_mpa: Sequence[float] | np.ndarray) -> np.ndarray:
        """Model inputs at each gauge pressure given in MPa: the pressure in the model's unit."""
        p = np.asarray(pressures_mpa, dtype=float).ravel()
        rows = np.empty((p.size, self.codes.size + 1))
        rows[:, :-1] = self.codes
        rows[:, -1] = p * self.pressure_scale
        return rows

    def as_record(self) -> dict[str, Any]:
        """``{name: value}`` of the design, levels by name (JSON-friendly)."""
        return self.actuator.design_record(self.codes.tolist())

    def __str__(self) -> str:
        return self.actuator.describe(self.codes.tolist())


def actuator_of_design(design: SFRBADesign | ModelDesign) -> Actuator:
    """The actuator description ``design`` is of (paper B's for an ``SFRBADesign``)."""
    return design.actuator if isinstance(design, ModelDesign) else SFRBA


def control_design(
    design: str | SFRBADesign | ModelDesign | Sequence[float] | None,
    actuator: Actuator,
    *,
    source: str = "the model",
) -> SFRBADesign | ModelDesign:
    """``design`` as a design of ``actuator``, checked against its description.

    Parameters
    ----------
    design : str, SFRBADesign, ModelDesign, sequence of float or None
        Text: for paper B's actuator ``"l,r,t,b,phi,lc"`` (mm, degrees) or
        ``"l_mm=100,..."``; for another ``"A=1,B=2,..."`` by its parameter names
        (or the values in their order), in the units of its description.
        None: paper B's :data:`DEFAULT_DESIGN`; another actuator has no
        default design.
    actuator : Actuator
        The description of the controller's model.
    source : str
        What the description belongs to (``"the model m.json"``), for messages.

    Raises
    ------
    InputError
        A design that is not one of ``actuator`` (the message names its parameters),
        or none given for an actuator other than paper B's; its key is ``design``.
    """
    if actuator == SFRBA:
        if design is None:
            return SFRBADesign.parse(DEFAULT_DESIGN)
        if isinstance(design, SFRBADesign):
            return design
        if isinstance(design, ModelDesign):
            return SFRBADesign.from_sequence(design.codes.tolist())
        if isinstance(design, str):
            if "=" in design:
                with keyed("design"):
                    codes = actuator.parse_design(design)
                return SFRBADesign.from_sequence(codes.tolist())
            return SFRBADesign.parse(design)
        return SFRBADesign.from_sequence([float(v) for v in design])
    if design is None:
        raise InputError(
            f"must be given for {source}, of the actuator {actuator.name} "
            f"({', '.join(actuator.names)}): {actuator.design_hint()}",
            key="design",
        )
    if isinstance(design, SFRBADesign):
        raise InputError(
            f"is a design of paper B's actuator, but {source} is of the actuator "
            f"{actuator.name}; give {actuator.design_hint()}",
            key="design",
        )
    if isinstance(design, ModelDesign):
        if design.actuator.names != actuator.names:
            raise InputError(
                f"is a design of the actuator {design.actuator.name}, but "
                f"{source} is of {actuator.name} ({', '.join(actuator.names)})",
                key="design",
            )
        return ModelDesign(actuator, design.codes)
    if isinstance(design, str):
        with keyed("design"):
            return ModelDesign(actuator, actuator.parse_design(design))
    return ModelDesign(actuator, np.asarray(design, dtype=float))
