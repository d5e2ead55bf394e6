"""Campaigns over any FEM actuator family: its backend, and what its database records.

A campaign of paper B's actuator (family ``"sfrba"``) is what it always was: its
designs are :class:`~softbend.actuators.Design`, its ``designs`` table has the
columns ``l_mm`` ... ``lc_mm`` and its database records no family. A campaign of
another family of :data:`~softbend.fem.families.FEM_FAMILIES` sweeps
:class:`~softbend.actuators.Design` objects with the family's own FEM
sweep (:class:`FamilyBackend`), and its database records the family's name and
actuator description (:class:`FamilySchema`): the ``designs`` table then has the
family's parameter columns, named and in the units of its
:class:`~softbend.actuators.Actuator`, and ``softbend train`` reads the
description back (:func:`softbend.campaign.store.campaign_actuator`).
"""

from __future__ import annotations

from dataclasses import dataclass, field
from typing import TYPE_CHECKING, Any, NamedTuple, TypeAlias

from softbend.actuators import Design
from softbend.design import PARAMETERS

if TYPE_CHECKING:
    import numpy as np

    from softbend.fem.families import FEMFamily
    from softbend.fem.options import FEMOptions
    from softbend.models import SweepResult

__all__ = [
    "DEFAULT_FAMILY",
    "CampaignDesign",
    "FamilyBackend",
    "FamilySchema",
    "family_backend",
]

#: The family of a campaign database that records none: paper B's actuator.
DEFAULT_FAMILY = "sfrba"

#: A design a campaign sweeps: paper B's, or one of another FEM family.
CampaignDesign: TypeAlias = Design


class FamilySchema(NamedTuple):
    """What a campaign database records of its family.

    Attributes
    ----------
    name : str
        The family's registry name (``"sfrba"``, ``"pneunet"``).
    parameters : tuple of str
        The ``designs`` table's parameter columns, in the family's order.
    actuator : dict, optional
        The family's :meth:`~softbend.actuators.Actuator.to_dict` (None for paper B's).
    """

    name: str
    parameters: tuple[str, ...]
    actuator: dict[str, Any] | None = None

    @classmethod
    def paper_b(cls) -> FamilySchema:
        """Paper B's actuator: the columns of every campaign database before families."""
        return cls(DEFAULT_FAMILY, tuple(PARAMETERS))

    @classmethod
    def of(cls, family: FEMFamily | str | None) -> FamilySchema:
        """The schema of a family (an object, a registered name, or None for paper B's)."""
        if family is None:
            return cls.paper_b()
        if isinstance(family, str):
            from softbend.fem.families import get_family

            family = get_family(family)
        if family.name == DEFAULT_FAMILY:
            return cls.paper_b()
        return cls(family.name, tuple(family.names), family.actuator.to_dict())


@dataclass(frozen=True)
class FamilyBackend:
    """The FEM sweep of one family, as a campaign backend (``name`` ``"fem"``).

    Parameters
    ----------
    family : FEMFamily
        The family; sent to the workers with the backend (its sweep is a
        function of an importable module, so it pickles by reference).
    options : FEMOptions
        The options of every sweep (:meth:`FEMFamily.options`: the family's
        defaults with the run's mesh size and material).
    """

    family: FEMFamily
    options: FEMOptions
    name: str = field(default="fem", init=False)
    preferred_chunk_size: int = field(default=1, init=False)

    def sweep(self, design: CampaignDesign, pressures_mpa: np.ndarray) -> SweepResult:
        """The family's sweep of ``design`` over ``pressures_mpa`` (MPa)."""
        return self.family.simulate(design, pressures_mpa, self.options)


def family_backend(
    family: FEMFamily, *, maxh_mm: float | None = None, material: Any = None
) -> FamilyBackend:
    """The backend of a family's campaign: its options with ``maxh_mm`` (mm) and ``material``.

    ``maxh_mm`` None takes the family's :attr:`~softbend.fem.families.FEMFamily.maxh_mm`;
    ``material`` (a :class:`~softbend.materials.presets.Material`) None the family's
    elastomer.
    """
    overrides: dict[str, Any] = {"maxh_mm": family.maxh_mm if maxh_mm is None else maxh_mm}
    if material is not None:
        overrides["elastomer"] = material
    return FamilyBackend(family, family.options(**overrides))
