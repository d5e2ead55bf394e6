"""Design vector of the soft fiber-reinforced bending actuator (SFRBA) and design spaces.

The actuator of paper B: a chamber of length ``l`` with a semicircular top of
inner radius ``r`` and wall thickness ``t``, a flat rectangular bottom wall of
thickness ``b`` carrying the strain-limiting layer, double-helix fibers wound at
``phi`` degrees from the circumferential direction, and a distal cap of length
``lc``. All lengths in mm, the angle in degrees.

``DesignSpace.table1()`` is paper B Table 1 (972 designs); ``DesignSpace.sample``
draws space-filling designs (Latin hypercube or Sobol) over the same ranges.
:class:`FamilyDesign` holds a design of another FEM actuator family (the
PneuNet) as named values; its family checks them
(:mod:`softbend.fem.families`).
"""

from __future__ import annotations

import hashlib
import itertools
import math
from collections.abc import Iterator, Mapping, Sequence
from dataclasses import asdict, dataclass, field
from typing import Literal

import numpy as np

from softbend._validation import check_choice, check_range, must_be
from softbend.errors import InputError, keyed
from softbend.references import DESIGN_SPACE, MATERIALS, MEASURED_ACTUATORS

#: Order of the design parameters in tables, arrays and CLI strings.
PARAMETERS: tuple[str, ...] = ("l_mm", "r_mm", "t_mm", "b_mm", "phi_deg", "lc_mm")

#: Inputs of every model of the bending angle (paper B §3.2 and §4.1), in this
#: order: the design vector and the gauge pressure (mm, deg, MPa).
FEATURES: tuple[str, ...] = (*PARAMETERS, "pressure_mpa")

#: The quantity of :data:`softbend.plausibility.RANGES` of each feature: the
#: range a value read from a file or a model must lie in.
FEATURE_QUANTITIES: dict[str, str] = {
    **{name: "fiber_angle_deg" if name == "phi_deg" else "length_mm" for name in PARAMETERS},
    "pressure_mpa": "pressure_mpa",
}

#: Fixed quantities of paper B (mm, §2.1; :data:`softbend.references.MATERIALS`).
FIBER_DIAMETER_MM: float = MATERIALS["kevlar"]["diameter_mm"].value
STRAIN_LIMITING_LAYER_MM: float = MATERIALS["fiberglass"]["thickness_mm"].value


# (low, high, low_inclusive); every upper bound is inclusive.
_BOUNDS: dict[str, tuple[float, float, bool]] = {
    "l_mm": (0.0, 1000.0, False),
    "r_mm": (0.0, 100.0, False),
    "t_mm": (0.0, 50.0, False),
    "b_mm": (0.0, 50.0, False),
    "phi_deg": (0.0, 60.0, True),
    "lc_mm": (0.0, 200.0, False),
}
#: ``{parameter: (low, high, low_inclusive)}`` a design accepts, by short name (``l``, ``phi``).
DESIGN_LIMITS: dict[str, tuple[float, float, bool]] = {
    name.rsplit("_", 1)[0]: limits for name, limits in _BOUNDS.items()
}


@dataclass(frozen=True)
class SFRBADesign:
    """One fiber-reinforced bending actuator design.

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

    l_mm: float
    r_mm: float
    t_mm: float
    b_mm: float
    phi_deg: float
    lc_mm: float

    def __post_init__(self) -> None:
        for name in PARAMETERS:
            low, high, low_inclusive = _BOUNDS[name]
            value = check_range(
                getattr(self, name),
                name,
                low=low,
                high=high,
                low_inclusive=low_inclusive,
                high_inclusive=True,
            )
            object.__setattr__(self, name, value)
        if self.t_mm >= self.r_mm:
            raise InputError(
                f"must be less than r_mm ({self.r_mm:g}): a wall thinner than the chamber "
                f"radius; got {self.t_mm:g}",
                key="t_mm",
            )

    @classmethod
    def from_sequence(cls, values: Sequence[float]) -> SFRBADesign:
        """Build a design from ``(l, r, t, b, phi, lc)`` in that order."""
        values = list(values)
        if len(values) != len(PARAMETERS):
            raise InputError(  # the wording other messages quote: "A design needs 6 values"
                f"A design needs {len(PARAMETERS)} values ({', '.join(PARAMETERS)}); "
                f"got {len(values)}"
            )
        return cls(*values)

    @classmethod
    def parse(cls, text: str) -> SFRBADesign:
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
            return cls.from_sequence(values)

    @property
    def cavity_volume_mm3(self) -> float:
        """Undeformed volume of the chamber, mm³: ``½·π·r²·l``.

        The chamber is a half-disc of radius ``r`` (the semicircular top standing
        on the flat bottom wall) extruded over the chamber length ``l``. The FEM
        meshes half of it (the half model ``y ≥ 0``), the rig's air volume starts
        from all of it.
        """
        return 0.5 * math.pi * self.r_mm**2 * self.l_mm

    @property
    def design_id(self) -> str:
        """Stable 16-hex-digit identifier: a SHA-1 of the parameters rounded to 1e-6."""
        canonical = ",".join(f"{getattr(self, n):.6f}" for n in PARAMETERS)
        return hashlib.sha1(canonical.encode()).hexdigest()[:16]

    def as_dict(self) -> dict[str, float]:
        """Parameters as an ordered ``{name: value}`` mapping."""
        return {k: v for k, v in asdict(self).items() if k in PARAMETERS}

    def as_array(self) -> np.ndarray:
        """Parameters as a float array in :data:`PARAMETERS` order."""
        return np.array([getattr(self, n) for n in PARAMETERS], dtype=float)

    def feature_rows(self, pressures_mpa: Sequence[float] | np.ndarray) -> np.ndarray:
        """Model inputs for this design at each pressure: one row per pressure.

        Parameters
        ----------
        pressures_mpa : array_like, shape (n,)
            Gauge pressures, MPa (not checked here: models check their grids).

        Returns
        -------
        numpy.ndarray, shape (n, 7)
            Columns :data:`FEATURES`: l, r, t, b (mm), φ (deg), lc (mm), P (MPa).
        """
        pressures = np.asarray(pressures_mpa, dtype=float).reshape(-1)
        rows = np.empty((pressures.size, len(FEATURES)))
        rows[:, :-1] = self.as_array()
        rows[:, -1] = pressures
        return rows

    def __str__(self) -> str:
        return ",".join(f"{getattr(self, n):g}" for n in PARAMETERS)


#: The seven actuators paper B measured (Fig. 7), nominal (l, r, t, b, φ, lc) in mm and
#: degrees: the reference (100, 6, 2, 2, 5, 8) and one parameter changed at a time
#: (:data:`softbend.references.MEASURED_ACTUATORS`).
PAPER_B_FIG7_DESIGNS: tuple[SFRBADesign, ...] = tuple(
    SFRBADesign(*values) for values in MEASURED_ACTUATORS.value
)


@dataclass(frozen=True)
class DesignSpace:
    """A finite set of designs.

    Parameters
    ----------
    designs : tuple of SFRBADesign
        The designs, unique, in a stable order.
    name : str
        A label for reports.
    """

    designs: tuple[SFRBADesign, ...]
    name: str = "custom"

    def __post_init__(self) -> None:
        ids = [d.design_id for d in self.designs]
        if len(set(ids)) != len(ids):
            duplicates = len(ids) - len(set(ids))
            raise InputError(f"must be unique; got {duplicates} duplicates", key="designs")

    def __len__(self) -> int:
        return len(self.designs)

    def __iter__(self) -> Iterator[SFRBADesign]:
        return iter(self.designs)

    def __getitem__(self, index: int) -> SFRBADesign:
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
        return cls(tuple(SFRBADesign(*c) for c in combos), name=name)

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
        return cls(tuple(SFRBADesign(*row) for row in values), name=f"{method}-{n}-seed{seed}")

    def to_frame(self):  # -> pandas.DataFrame
        """Designs as a DataFrame with ``design_id`` and one column per parameter."""
        import pandas as pd

        rows = [{"design_id": d.design_id, **d.as_dict()} for d in self.designs]
        return pd.DataFrame(rows, columns=["design_id", *PARAMETERS])


#: Levels of paper B Table 1 (:data:`softbend.references.DESIGN_SPACE`).
TABLE1_LEVELS: dict[str, tuple[float, ...]] = {
    name: DESIGN_SPACE[name].value for name in PARAMETERS
}


@dataclass(frozen=True)
class FamilyDesign:
    """One design of a FEM family other than paper B's: named values, in the family's order.

    Parameters
    ----------
    family : str
        The family's registry name (``"pneunet"``).
    values : mapping of str to float
        Every design parameter of the family, in its units (see the family's
        :attr:`FEMFamily.actuator`). Check values with :meth:`FEMFamily.design`,
        which builds designs; this class only holds them.
    """

    family: str
    values: Mapping[str, float] = field(default_factory=dict)

    def __post_init__(self) -> None:
        object.__setattr__(self, "values", {k: float(v) for k, v in dict(self.values).items()})

    def __hash__(self) -> int:
        return hash((self.family, tuple(self.values.items())))

    def __getattr__(self, name: str) -> float:
        values = self.__dict__.get("values", {})
        if name in values:
            return values[name]
        raise AttributeError(name)

    @property
    def design_id(self) -> str:
        """Stable 16-hex-digit identifier: a SHA-1 of the family and its values rounded to 1e-6."""
        canonical = self.family + ":" + ",".join(f"{k}={v:.6f}" for k, v in self.values.items())
        return hashlib.sha1(canonical.encode()).hexdigest()[:16]

    def as_dict(self) -> dict[str, float]:
        """Parameters as an ordered ``{name: value}`` mapping."""
        return dict(self.values)

    def as_array(self) -> np.ndarray:
        """Parameters as a float array in the family's order."""
        return np.array(list(self.values.values()), dtype=float)

    def __str__(self) -> str:
        return ", ".join(f"{k}={v:g}" for k, v in self.values.items())
