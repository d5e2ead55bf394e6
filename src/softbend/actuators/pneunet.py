"""The PneuNet as a registered description: a row of chambers on a strain-limiting layer.

Its FEM family (:mod:`softbend.fem.pneunet.description`) builds and sweeps its
designs; this module holds only what the learning pipeline knows of it: its
eight design parameters, their ranges (the campaign's design space) and the
constraints that leave every chamber a cavity.
"""

from __future__ import annotations

from softbend.actuators.description import ACTUATORS, Actuator
from softbend.actuators.parameters import DesignParameter

__all__ = ["PNEUNET"]

_PARAMETERS: tuple[DesignParameter, ...] = (
    DesignParameter(
        "n_chambers", "", 3, 8, kind="integer", description="number of chambers in the row"
    ),
    DesignParameter(
        "chamber_length_mm",
        "mm",
        5.0,
        12.0,
        resolution=0.1,
        description="outer length of one chamber along the actuator, walls included",
    ),
    DesignParameter(
        "chamber_width_mm",
        "mm",
        10.0,
        20.0,
        resolution=0.1,
        description="outer width of a chamber across the actuator (and of the base)",
    ),
    DesignParameter(
        "chamber_height_mm",
        "mm",
        8.0,
        25.0,
        resolution=0.1,
        description="outer height of a chamber above the base",
    ),
    DesignParameter(
        "wall_mm",
        "mm",
        0.8,
        2.5,
        resolution=0.1,
        description="thickness of the expanding walls facing the neighbouring chambers",
    ),
    DesignParameter(
        "outer_wall_mm",
        "mm",
        1.5,
        3.0,
        resolution=0.1,
        description="thickness of the side walls and the roof of a chamber",
    ),
    DesignParameter(
        "gap_mm",
        "mm",
        1.0,
        5.0,
        resolution=0.1,
        description="gap between neighbouring chambers",
    ),
    DesignParameter(
        "base_mm",
        "mm",
        1.0,
        4.0,
        resolution=0.1,
        description="thickness of the base under the chambers, strain-limiting layer below",
    ),
)

#: The PneuNet: a row of chambers on a strain-limiting layer, the FEM's second family.
PNEUNET: Actuator = ACTUATORS.register(
    "pneunet",
    Actuator(
        name="pneunet",
        title="PneuNet: a row of inflatable chambers on a strain-limiting layer",
        parameters=_PARAMETERS,
        pressure_column="pressure_mpa",
        pressure_unit="MPa",
        angle_column="angle_deg",
        constraints=(
            "2 * wall_mm < chamber_length_mm",
            "2 * outer_wall_mm < chamber_width_mm",
            "outer_wall_mm < chamber_height_mm",
        ),
        fem_family="pneunet",
    ),
)
