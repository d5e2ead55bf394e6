"""Planning a campaign from its choices, all checked before anything runs.

:func:`plan_campaign` reads what ``softbend campaign run`` is given for any FEM
family: the family, its design space (or one shard of it), the pressure grid,
the elastomer and the backend that sweeps the designs (a family swept by the
registered backends, paper B's, takes any of them; another its own FEM), and
refuses a campaign that would not fit the machine
(:func:`softbend.campaign.footprint.check_footprint`). A registered backend
that lives in a higher package (the surrogate) must be registered first.
"""

from __future__ import annotations

import os
from dataclasses import dataclass
from typing import TYPE_CHECKING, Any

from softbend.errors import InputError, keyed

if TYPE_CHECKING:
    from collections.abc import Sequence

    import numpy as np

    from softbend.campaign.backends import Backend, ResolvedMaterial
    from softbend.fem.families import FEMFamily

__all__ = ["CampaignPlan", "campaign_backend", "plan_campaign"]


@dataclass(frozen=True)
class CampaignPlan:
    """What a campaign run will sweep, and with what.

    Attributes
    ----------
    family : FEMFamily
        The designs' FEM family.
    designs
        The designs of the space (of the shard when one is asked for), with its
        ``name`` (and, for a family's drawn space, ``rejected``).
    backend : Backend
        What sweeps each design.
    pressures_mpa : numpy.ndarray
        The pressure grid, MPa.
    material : ResolvedMaterial or None
        The elastomer given, None for the backend's own.
    rejected : str
        ``"NAME: N designs; K draws rejected (...)"`` of the whole space, or ``""``.
    """

    family: FEMFamily
    designs: Any
    backend: Backend
    pressures_mpa: np.ndarray
    material: ResolvedMaterial | None
    rejected: str


def plan_campaign(
    db: str | os.PathLike[str],
    *,
    family: str = "sfrba",
    backend: str | None = None,
    model: str | os.PathLike[str] | None = None,
    space: str | None = None,
    ranges: Sequence[str] | None = None,
    seed: int = 0,
    shard: str | None = None,
    pmax_mpa: float | None = None,
    pstep_mpa: float | None = None,
    scheduler: str | None = None,
    allow_large: bool = False,
    compiled: bool = True,
    maxh_mm: float | None = None,
    material: str | None = None,
    contact: str | None = None,
) -> CampaignPlan:
    """Check a campaign's choices and build its designs.

    Parameters
    ----------
    db : path
        The campaign database (its folder's free disk is checked).
    family : str
        Registry name of the FEM family (:data:`~softbend.fem.families.FEM_FAMILIES`).
    backend : str, optional
        Campaign backend name (default: ``analytical`` for a family swept by the
        registered backends, else ``fem``, the family's own sweep).
    model : path, optional
        A saved surrogate, for the ``surrogate`` backend.
    space : str, optional
        The design space (:func:`softbend.campaign.spaces.campaign_space`).
    ranges : sequence of str, optional
        ``NAME=LOW:HIGH`` ranges of a sampled space.
    seed : int
        Seed of the ``lhs``/``sobol`` samplers.
    shard : str, optional
        ``K/N``: only shard ``K`` of ``N`` of the space.
    pmax_mpa, pstep_mpa : float, optional
        The pressure grid, MPa (default the family's campaign grid).
    scheduler : str, optional
        A Dask scheduler address (checked here, reached when the run starts).
    allow_large : bool
        Run a campaign estimated above the soft memory and disk limits.
    compiled : bool
        The FEM backend compiles its energy once per worker.
    maxh_mm : float, optional
        The FEM's largest element size, mm.
    material : str, optional
        An elastomer preset or fit file (:func:`~softbend.campaign.backends.resolve_material`).
    contact : {"off", "on"}, optional
        Contact between walls that touch, for a family with them (default: the
        family's, on for the PneuNet).

    Raises
    ------
    InputError, LimitError
        Keyed by the choice at fault.
    """
    from softbend._validation import check_int
    from softbend.campaign.backends import resolve_material
    from softbend.campaign.footprint import campaign_footprint, check_footprint, parse_shard
    from softbend.campaign.runner import parse_scheduler_address
    from softbend.campaign.spaces import campaign_space
    from softbend.fem.families import get_family

    with keyed("family"):
        fem_family = get_family(family)
    spec = campaign_space(space, fem_family, ranges)
    check_int(seed, "seed")
    shard_of = parse_shard(shard) if shard is not None else None
    pressures = fem_family.campaign_pressures_mpa(pmax_mpa, pstep_mpa)
    chosen = resolve_material(material) if material is not None else None  # read once
    backend_obj = campaign_backend(
        fem_family, backend, model, chosen, maxh_mm, compiled, contact=contact
    )
    if scheduler is not None:
        parse_scheduler_address(scheduler)
    k, count = shard_of or (0, 1)
    n_stored = len(range(k, spec.n_designs, count))  # designs of the shard
    check_footprint(
        campaign_footprint(spec.n_designs, len(pressures), n_stored=n_stored),
        db,
        allow_large=allow_large,
    )
    designs = spec.build(seed)
    rejected = getattr(designs, "describe_rejected", lambda: "")()
    said = f"{designs.name}: {len(designs)} designs; {rejected}" if rejected else ""
    if shard_of is not None:
        designs = designs.shard(*shard_of)
    return CampaignPlan(fem_family, designs, backend_obj, pressures, chosen, said)


def campaign_backend(
    fem_family: FEMFamily,
    backend: str | None,
    model: str | os.PathLike[str] | None,
    chosen: ResolvedMaterial | None,
    maxh_mm: float | None,
    compiled: bool,
    *,
    contact: str | None = None,
) -> Backend:
    """The backend named ``backend`` for ``fem_family``'s designs (checked).

    A family swept by the registered backends
    (:attr:`~softbend.fem.families.FEMFamily.backends` None, paper B's)
    takes any of them (default ``analytical``); another only its own FEM sweep
    (``fem``, the default), with ``maxh_mm``, the material and ``contact``.
    """
    from softbend.campaign.backends import backend_for_run
    from softbend.campaign.family_schema import family_backend

    if fem_family.backends is None:
        fem_family.contact_options(contact)  # checked: "off" only
        return backend_for_run(
            "analytical" if backend is None else backend,
            model=model,
            compiled=compiled,
            material=chosen,
            maxh_mm=maxh_mm,
        )
    if backend not in (None, "fem"):
        raise InputError(
            f"must be fem for the {fem_family.name} family (its own FEM sweep); got {backend!r}",
            key="backend",
        )
    if model is not None:
        raise InputError(
            f"applies to --backend surrogate of paper B's actuator; the {fem_family.name} "
            f"family runs its FEM; got {str(model)!r}",
            key="model",
        )
    if maxh_mm is not None and (
        isinstance(maxh_mm, bool) or not (isinstance(maxh_mm, int | float) and maxh_mm > 0)
    ):
        raise InputError(f"must be a size > 0 mm; got {maxh_mm!r}", key="maxh_mm")
    material = None if chosen is None else chosen.material
    return family_backend(fem_family, maxh_mm=maxh_mm, material=material, contact=contact)
