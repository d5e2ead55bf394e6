"""Campaigns over any FEM actuator family: its backend, and what its database records.

A campaign sweeps the designs of one family of
:data:`~softbend.fem.families.FEM_FAMILIES` (paper B's ``"sfrba"``, the
PneuNet, ...), and its database records the family's name and actuator
description (:class:`FamilySchema`): the ``designs`` table has the family's
parameter columns, named and in the units of its
:class:`~softbend.actuators.Actuator`, and ``softbend train`` reads the
description back (:func:`softbend.campaign.store.campaign_actuator`). A family
that is not :attr:`~softbend.fem.families.FEMFamily.recorded` (paper B's, whose
databases predate families) records neither: a database that names no family
holds its designs (:data:`~softbend.fem.families.FIRST_FAMILY`). Any family's designs are swept
with its own FEM sweep by :class:`FamilyBackend`; paper B's also by the
registered backends (``analytical``, ``fem``, ``surrogate``).
"""

from __future__ import annotations

from dataclasses import dataclass, field
from typing import TYPE_CHECKING, Any, NamedTuple, TypeAlias

from softbend.actuators import Design

if TYPE_CHECKING:
    import numpy as np

    from softbend.fem.families import FEMFamily
    from softbend.fem.options import FEMOptions
    from softbend.models import SweepResult

__all__ = [
    "CampaignDesign",
    "FamilyBackend",
    "FamilySchema",
    "family_backend",
    "is_design",
]

#: A design a campaign sweeps: paper B's, or one of another FEM family.
CampaignDesign: TypeAlias = Design


def is_design(value: object) -> bool:
    """Whether ``value`` is one design (a :class:`~softbend.actuators.Design`)."""
    return isinstance(value, Design)


class FamilySchema(NamedTuple):
    """What a campaign database records of its family.

    Attributes
    ----------
    name : str
        The family's registry name (``"sfrba"``, ``"pneunet"``).
    parameters : tuple of str
        The ``designs`` table's parameter columns, in the family's order.
    actuator : dict, optional
        The family's :meth:`~softbend.actuators.Actuator.to_dict`, recorded with
        its name; None: the database records neither (a family that is not
        :attr:`~softbend.fem.families.FEMFamily.recorded`, paper B's).
    """

    name: str
    parameters: tuple[str, ...]
    actuator: dict[str, Any] | None = None

    @classmethod
    def of(cls, family: FEMFamily | str | None) -> FamilySchema:
        """The schema of a family: an object, a registered name, or None for
        :data:`~softbend.fem.families.FIRST_FAMILY`."""
        from softbend.fem.families import FIRST_FAMILY, get_family

        if not hasattr(family, "actuator"):
            family = get_family(str(family or FIRST_FAMILY))
        assert not isinstance(family, str | None)
        actuator = family.actuator.to_dict() if family.recorded else None
        return cls(family.name, tuple(family.names), actuator)


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
    family: FEMFamily,
    *,
    maxh_mm: float | None = None,
    material: Any = None,
    contact: str | None = None,
) -> FamilyBackend:
    """The backend of a family's campaign: its options with ``maxh_mm`` (mm), ``material``
    and ``contact``.

    ``maxh_mm`` None takes the family's :attr:`~softbend.fem.families.FEMFamily.maxh_mm`;
    ``material`` (a :class:`~softbend.materials.presets.Material`) None the family's
    elastomer; ``contact`` ("on" or "off", for a family whose walls touch) None the
    family's default (the PneuNet's: on, its shipped dataset's settings;
    :meth:`~softbend.fem.families.FEMFamily.contact_options`).
    """
    overrides: dict[str, Any] = {"maxh_mm": family.maxh_mm if maxh_mm is None else maxh_mm}
    overrides.update(family.contact_options(contact))
    if material is not None:
        overrides["elastomer"] = material
    return FamilyBackend(family, family.options(**overrides))
