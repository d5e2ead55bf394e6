"""Design vector of the soft fiber-reinforced bending actuator (SFRBA) and design spaces.

The actuator of paper B: a chamber of length ``l`` with a semicircular top of
inner radius ``r`` and wall thickness ``t``, a flat rectangular bottom wall of
thickness ``b`` carrying the strain-limiting layer, double-helix fibers wound at
``phi`` degrees from the circumferential direction, and a distal cap of length
``lc``. All lengths in mm, the angle in degrees.

``DesignSpace.table1()`` is paper B Table 1 (972 designs); ``DesignSpace.sample``
draws space-filling designs (Latin hypercube or Sobol) over the same ranges.
A design is a :class:`~softbend.actuators.Design` of :data:`~softbend.actuators.SFRBA`;
:func:`sfrba_design` builds one and checks it (:func:`parse_sfrba` from the CLI's
``"l,r,t,b,phi,lc"``, :func:`sfrba_from_sequence` from six values).
"""

from __future__ import annotations

import itertools
from collections.abc import Iterator, Mapping, Sequence
from dataclasses import dataclass
from typing import Literal

import numpy as np

from softbend._validation import check_choice, check_range, must_be
from softbend.actuators import SFRBA, Design
from softbend.actuators.sfrba import BOUNDS, check_sfrba
from softbend.errors import InputError, keyed
from softbend.references import MATERIALS, MEASURED_ACTUATORS

#: Order of the design parameters in tables, arrays and CLI strings.
PARAMETERS: tuple[str, ...] = SFRBA.names

#: Inputs of every model of the bending angle (paper B §3.2 and §4.1), in this
#: order: the design vector and the gauge pressure (mm, deg, MPa).
FEATURES: tuple[str, ...] = (*PARAMETERS, "pressure_mpa")

#: The quantity of :data:`softbend.plausibility.RANGES` of each feature: the
#: range a value read from a file or a model must lie in.
FEATURE_QUANTITIES: dict[str, str] = dict(SFRBA.quantities)

#: Fixed quantities of paper B (mm, §2.1; :data:`softbend.references.MATERIALS`).
FIBER_DIAMETER_MM: float = MATERIALS["kevlar"]["diameter_mm"].value
STRAIN_LIMITING_LAYER_MM: float = MATERIALS["fiberglass"]["thickness_mm"].value


#: ``{parameter: (low, high, low_inclusive)}`` a design accepts, by short name (``l``, ``phi``).
DESIGN_LIMITS: dict[str, tuple[float, float, bool]] = {
    name.rsplit("_", 1)[0]: limits for name, limits in BOUNDS.items()
}


def sfrba_design(
    l_mm: float, r_mm: float, t_mm: float, b_mm: float, phi_deg: float, lc_mm: float
) -> Design:
    """One design of paper B's fiber-reinforced actuator, checked.

    Parameters
    ----------
    l_mm : float
        Chamber length, mm; in (0, 1000].
    r_mm : float
        Inner radius of the semicircular chamber, mm; in (0, 100].
    t_mm : float
        Thickness of the semicircular top wall, mm; in (0, 50] and less than
        ``r_mm`` (see below).
    b_mm : float
        Thickness of the flat bottom wall, mm; in (0, 50].
    phi_deg : float
        Fiber winding angle measured from the circumferential direction, degrees;
        in [0, 60]. Small angles confine radial expansion best.
    lc_mm : float
        Length of the distal (tip) cap, mm; in (0, 200].

    Returns
    -------
    Design
        A design of :data:`~softbend.actuators.SFRBA`.

    Notes
    -----
    The wall must be thinner than the chamber radius, ``t_mm < r_mm``: the
    actuator is a thin-walled chamber whose pressure bends it, and every model
    here rests on that. The analytical model lets the walls only stretch axially
    and thin through their thickness, with the fibers on the outer surface
    confining the chamber; with ``t >= r`` the "chamber" is a narrow hole in a
    thick rod (``100,1,50,2,5,10`` has a 2 mm bore in a 102 mm wide body) that
    no fiber-reinforced actuator of paper B resembles. Paper B Table 1 has
    ``t/r <= 2/3`` (t 2–4 mm, r 6–10 mm).

    Raises
    ------
    ValueError
        Naming the field, the allowed interval and the value received; for a wall
        not thinner than the radius, the rule and both values.
    """
    values = (l_mm, r_mm, t_mm, b_mm, phi_deg, lc_mm)
    return Design(SFRBA, check_sfrba(dict(zip(PARAMETERS, values, strict=True))))


def sfrba_from_sequence(values: Sequence[float]) -> Design:
    """Paper B's design of ``(l, r, t, b, phi, lc)`` in that order (:func:`sfrba_design`)."""
    values = list(values)
    if len(values) != len(PARAMETERS):
        raise InputError(  # the wording other messages quote: "A design needs 6 values"
            f"A design needs {len(PARAMETERS)} values ({', '.join(PARAMETERS)}); got {len(values)}"
        )
    return sfrba_design(*values)


def parse_sfrba(text: str) -> Design:
    """Parse ``"100,6,2,2,5,10"`` (l, r, t, b, phi, lc) as used on the CLI.

    Errors are keyed ``design`` and name the value at fault in the message
    (``design: t_mm: must be less than r_mm (6) ...``).
    """
    try:
        values = [float(v) for v in text.split(",")]
    except ValueError:
        raise InputError(
            must_be(f"six comma-separated numbers ({', '.join(PARAMETERS)})", text),
            key="design",
        ) from None
    with keyed("design"):
        return sfrba_from_sequence(values)


#: The seven actuators paper B measured (Fig. 7), nominal (l, r, t, b, φ, lc) in mm and
#: degrees: the reference (100, 6, 2, 2, 5, 8) and one parameter changed at a time
#: (:data:`softbend.references.MEASURED_ACTUATORS`).
PAPER_B_FIG7_DESIGNS: tuple[Design, ...] = tuple(
    sfrba_design(*values) for values in MEASURED_ACTUATORS.value
)


@dataclass(frozen=True)
class DesignSpace:
    """A finite set of designs.

    Parameters
    ----------
    designs : tuple of Design
        The designs, unique, in a stable order.
    name : str
        A label for reports.
    """

    designs: tuple[Design, ...]
    name: str = "custom"

    def __post_init__(self) -> None:
        ids = [d.design_id for d in self.designs]
        if len(set(ids)) != len(ids):
            duplicates = len(ids) - len(set(ids))
            raise InputError(f"must be unique; got {duplicates} duplicates", key="designs")

    def __len__(self) -> int:
        return len(self.designs)

    def __iter__(self) -> Iterator[Design]:
        return iter(self.designs)

    def __getitem__(self, index: int) -> Design:
        return self.designs[index]

    def shard(self, index: int, count: int) -> DesignSpace:
        """Every ``count``-th design from ``index`` on: shard ``index`` of ``count`` (0-based).

        The shards of one space are disjoint and together hold every design once,
        so a long campaign can run as several shorter ones (on one machine after
        another, or on several) whose databases are merged afterwards; taking
        every ``count``-th design spreads cheap and expensive designs evenly.

        Raises
        ------
        ValueError
            ``count < 1`` or ``index`` not in ``0 … count − 1``.
        """
        if isinstance(count, bool) or not isinstance(count, int) or count < 1:
            raise InputError(must_be("an integer in [1, inf)", count), key="count")
        if isinstance(index, bool) or not isinstance(index, int) or not 0 <= index < count:
            raise InputError(must_be(f"an integer in [0, {count - 1}]", index), key="index")
        return DesignSpace(self.designs[index::count], name=f"{self.name}[{index}/{count}]")

    @classmethod
    def grid(cls, levels: Mapping[str, Sequence[float]], name: str = "grid") -> DesignSpace:
        """Full factorial grid over ``levels``, one sequence per name in :data:`PARAMETERS`."""
        missing = [p for p in PARAMETERS if p not in levels]
        extra = [p for p in levels if p not in PARAMETERS]
        if missing or extra:
            raise InputError(
                f"must name exactly {', '.join(PARAMETERS)}; missing {missing}, unknown {extra}",
                key="levels",
            )
        combos = itertools.product(*(levels[p] for p in PARAMETERS))
        return cls(tuple(sfrba_design(*c) for c in combos), name=name)

    @classmethod
    def table1(cls) -> DesignSpace:
        """Paper B Table 1: 4 x 3 x 3 x 3 x 3 x 3 = 972 designs."""
        return cls.grid(TABLE1_LEVELS, name="table1")

    @classmethod
    def corners(cls) -> DesignSpace:
        """The 64 corners of Table 1 (each parameter at its minimum or maximum)."""
        levels = {p: (min(v), max(v)) for p, v in TABLE1_LEVELS.items()}
        return cls.grid(levels, name="table1-corners")

    @classmethod
    def sample(
        cls,
        n: int,
        *,
        method: Literal["lhs", "sobol"] = "lhs",
        seed: int = 0,
        bounds: dict[str, tuple[float, float]] | None = None,
    ) -> DesignSpace:
        """Space-filling sample of ``n`` designs over ``bounds`` (default: Table 1 ranges).

        Parameters
        ----------
        n : int
            Number of designs, at least 1.
        method : {"lhs", "sobol"}
            Latin hypercube (optimised by random CD) or scrambled Sobol sequence.
        seed : int
            Seed of the sampler; the same seed gives the same designs.
        bounds : dict, optional
            ``{parameter: (low, high)}`` for every parameter.
        """
        from scipy.stats import qmc

        n = int(check_range(n, "n", low=1, low_inclusive=True))
        check_choice(method, "method", ("lhs", "sobol"))
        bounds = bounds or {p: (min(v), max(v)) for p, v in TABLE1_LEVELS.items()}
        low = np.array([bounds[p][0] for p in PARAMETERS], dtype=float)
        high = np.array([bounds[p][1] for p in PARAMETERS], dtype=float)
        if method == "lhs":
            sampler = qmc.LatinHypercube(d=len(PARAMETERS), seed=seed)
        else:
            sampler = qmc.Sobol(d=len(PARAMETERS), scramble=True, seed=seed)
        unit = sampler.random(n)
        values = np.round(qmc.scale(unit, low, high), 6)
        return cls(tuple(sfrba_design(*row) for row in values), name=f"{method}-{n}-seed{seed}")

    def to_frame(self):  # -> pandas.DataFrame
        """Designs as a DataFrame with ``design_id`` and one column per parameter."""
        import pandas as pd

        rows = [{"design_id": d.design_id, **d.as_dict()} for d in self.designs]
        return pd.DataFrame(rows, columns=["design_id", *PARAMETERS])


#: Levels of paper B Table 1 (:attr:`SFRBA.grid <softbend.actuators.Actuator.grid>`).
TABLE1_LEVELS: dict[str, tuple[float, ...]] = dict(zip(PARAMETERS, SFRBA.grid, strict=True))
