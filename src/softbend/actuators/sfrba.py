"""Paper B's soft fiber-reinforced bending actuator (SFRBA), as a registered description.

A chamber of length ``l`` with a semicircular top of inner radius ``r`` and wall
thickness ``t``, a flat bottom wall of thickness ``b`` carrying the
strain-limiting layer, fibers wound at ``phi`` degrees and a distal cap of length
``lc`` (mm and degrees). What is paper B's own is data here: the short names
``l, r, t, b, phi, lc`` a design search uses, the ids of its designs (a hash of
the values alone), and its Table 1 grid. Its FEM family is ``"sfrba"``
(:mod:`softbend.fem.families`); its designs are built and checked by
:func:`softbend.design.sfrba_design`.
"""

from __future__ import annotations

import math
from collections.abc import Mapping

import numpy as np

from softbend._validation import check_range
from softbend.actuators.description import ACTUATORS, Actuator
from softbend.actuators.parameters import DesignParameter
from softbend.errors import InputError
from softbend.parameters import Range
from softbend.references import DESIGN_SPACE, SURROGATES, values

__all__ = ["BOUNDS", "SFRBA", "cavity_volume_mm3", "check_sfrba", "elastomer_volume_mm3"]

#: ``{parameter: (low, high, low_inclusive)}`` a design accepts; every upper bound inclusive.
BOUNDS: dict[str, tuple[float, float, bool]] = {
    "l_mm": (0.0, 1000.0, False),
    "r_mm": (0.0, 100.0, False),
    "t_mm": (0.0, 50.0, False),
    "b_mm": (0.0, 50.0, False),
    "phi_deg": (0.0, 60.0, True),
    "lc_mm": (0.0, 200.0, False),
}

_DESCRIBED: dict[str, tuple[str, str]] = {
    "l_mm": ("mm", "chamber length"),
    "r_mm": ("mm", "inner radius of the semicircular chamber"),
    "t_mm": ("mm", "top wall thickness"),
    "b_mm": ("mm", "bottom wall thickness"),
    "phi_deg": ("deg", "fiber winding angle from the circumferential direction"),
    "lc_mm": ("mm", "distal cap length"),
}


def check_sfrba(values: dict[str, float]) -> dict[str, float]:
    """Paper B's check of one design ``{name: value}`` (mm and degrees): its bounds
    (:data:`BOUNDS`, open below but for φ) and a wall thinner than the radius.

    Raises
    ------
    InputError
        Keyed by the parameter at fault: its interval and the value received; for a
        wall not thinner than the radius (key ``t_mm``), the rule and both values.
    """
    checked = {}
    for name, (low, high, low_inclusive) in BOUNDS.items():
        checked[name] = check_range(
            values[name],
            name,
            low=low,
            high=high,
            low_inclusive=low_inclusive,
            high_inclusive=True,
        )
    if checked["t_mm"] >= checked["r_mm"]:
        raise InputError(
            f"must be less than r_mm ({checked['r_mm']:g}): a wall thinner than the chamber "
            f"radius; got {checked['t_mm']:g}",
            key="t_mm",
        )
    return checked


def cavity_volume_mm3(values: Mapping[str, float]) -> float:
    """Undeformed volume of the chamber, mm³: ``½·π·r²·l``.

    The chamber is a half-disc of radius ``r`` (the semicircular top standing
    on the flat bottom wall) extruded over the chamber length ``l``. The FEM
    meshes half of it (the half model ``y ≥ 0``), the rig's air volume starts
    from all of it.
    """
    return 0.5 * math.pi * values["r_mm"] ** 2 * values["l_mm"]


def elastomer_volume_mm3(designs: np.ndarray) -> np.ndarray:
    """Elastomer of each design (rows of 6: l, r, t, b, φ, lc), mm³.

    The half-cylindrical wall ``½·π·((r+t)² − r²)·l``, the strain-limiting layer
    ``2·(r+t)·b·l`` under it, and the two end caps ``π·(r+t)²/2·lc`` (fibres neglected).
    """
    d = np.atleast_2d(np.asarray(designs, dtype=np.float64))
    length, r, t, b, lc = d[:, 0], d[:, 1], d[:, 2], d[:, 3], d[:, 5]
    outer = r + t
    wall = 0.5 * np.pi * (outer**2 - r**2) * length
    layer = 2.0 * outer * b * length
    caps = 0.5 * np.pi * outer**2 * lc
    return wall + layer + caps


#: Paper B's actuator: the description of every campaign and shipped model.
SFRBA: Actuator = ACTUATORS.register(
    "sfrba",
    Actuator(
        name="sfrba",
        title="paper B's soft fiber-reinforced bending actuator",
        parameters=tuple(
            DesignParameter(
                name,
                unit,
                BOUNDS[name][0],
                BOUNDS[name][1],
                resolution=0.1 if unit == "mm" else 1.0,
                description=text,
            )
            for name, (unit, text) in _DESCRIBED.items()
        ),
        pressure_column="pressure_mpa",
        pressure_unit="MPa",
        angle_column="angle_deg",
        constraints=("t_mm < r_mm",),
        fem_family="sfrba",
        design_ids="values",
        short_names=tuple(name.rsplit("_", 1)[0] for name in _DESCRIBED),
        grid=tuple(DESIGN_SPACE[name].value for name in _DESCRIBED),
        quantities={
            **{n: "fiber_angle_deg" if n == "phi_deg" else "length_mm" for n in _DESCRIBED},
            "pressure_mpa": "pressure_mpa",
        },
        mape_floor_deg=1.0,
        transfer_mape_floor_deg=0.0,
        analytical=True,
        published_cv=values(SURROGATES),
        named_in_outputs=False,
        search_steps=tuple(1.0 if unit == "deg" else 0.5 for unit, _ in _DESCRIBED.values()),
        search_limits=tuple(
            Range(
                BOUNDS[name][0],
                BOUNDS[name][1],
                unit,
                "the values a design may take",
                BOUNDS[name][2],
            )
            for name, (unit, _) in _DESCRIBED.items()
        ),
        check_values=check_sfrba,
        cavity_volume=cavity_volume_mm3,
        elastomer_volume=elastomer_volume_mm3,
    ),
)
