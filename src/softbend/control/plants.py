"""What plays the actuator in a control run: θ(p) tables from a surrogate, the FEM, the lab.

The controllers always use their own model (a surrogate); the rig's angle map
can be that same model (no mismatch), the design's FEM sweep in the shipped
Table 1 dataset, or the design's virtual-lab readings (the reality gap a
controller meets on a real actuator). :data:`PLANTS` names them;
:func:`plant_table` picks one by name. A plant factory is
``factory(design, model_table) -> AngleTable``; adding one is one
``PLANTS.register(name, factory)`` call.

A lab's own actuator plays the plant from a file instead of a name: a saved
surrogate (``model.json``, e.g. the one ``softbend transfer refine`` wrote for
it) or a measurements CSV (``readings.csv``: its loading readings of the
design, smoothed), as ``--plant model.json`` or ``--plant readings.csv``.

A model of ``softbend identify`` (a pressure input, an angle output) plays the
plant by its dynamics instead of a θ(p) table
(:mod:`softbend.control.identified_plant`; :func:`plant_table` does not take it).

The text of ``--plant`` is parsed once (:func:`parse_plant`) into a
:class:`~softbend.control.plant_choice.PlantChoice`, and :func:`plant_table`
dispatches on its kind.

A saved surrogate of any actuator plays the plant of its design
(:class:`~softbend.actuators.Design`): its θ(p) is tabulated in MPa,
the rig's unit, from the model's own pressure unit. A plant that is of one
actuator only (``fem``, ``lab`` and a measurements CSV are paper B's) says so in
:data:`PLANT_ACTUATORS`; a registered plant may also give the rig's chamber
compliance (:data:`PLANT_COMPLIANCES`).
"""

from __future__ import annotations

from collections.abc import Callable
from pathlib import Path
from typing import TYPE_CHECKING

import numpy as np

from softbend.actuators import SFRBA, Actuator, Design
from softbend.control.designs import actuator_of_design, control_design
from softbend.control.plant_choice import PlantChoice
from softbend.control.rig import AngleTable
from softbend.errors import InputError
from softbend.registry import Registry, UnknownNameError

if TYPE_CHECKING:
    import pandas as pd

    from softbend.surrogates.persistence import SavedSurrogate
    from softbend.transfer.measurements import Measurements

__all__ = [
    "PLANTS",
    "PLANT_ACTUATORS",
    "PLANT_COMPLIANCES",
    "check_plant",
    "check_plant_actuator",
    "fem_angle_table",
    "fem_plant",
    "in_table1",
    "lab_angle_table",
    "lab_plant",
    "parse_plant",
    "plant_compliance",
    "plant_file",
    "plant_table",
    "shipped_angle_table",
    "support_warnings",
    "surrogate_plant",
]

#: Plant factories by name: ``factory(design, model_table) -> AngleTable``.
PLANTS: Registry[Callable[[Design, AngleTable], AngleTable]] = Registry("plant")

#: The actuator a plant is of alone, by the plant's name (``"measurements"``: a CSV):
#: paper B's FEM, virtual lab and measurement files. Any other plant takes a design
#: of the controller's model's actuator.
PLANT_ACTUATORS: dict[str, Actuator] = {"fem": SFRBA, "lab": SFRBA, "measurements": SFRBA}

#: The chamber compliance a registered plant gives the rig:
#: ``compliance(design, supply_mpa) -> mm³/MPa or None`` (None: the design's default).
PLANT_COMPLIANCES: dict[str, Callable[[Design, float], float | None]] = {}


def plant_file(name: str) -> Path | None:
    """``name`` as a plant file (an existing ``.json`` or ``.csv``), else None."""
    path = Path(name)
    return path if path.suffix.lower() in (".json", ".csv") and path.is_file() else None


def parse_plant(plant: str | PlantChoice) -> PlantChoice:
    """What ``plant`` names: a registered plant or a plant file, of which kind.

    An existing ``.csv`` file is measurements; an existing ``.json`` file is a model
    of ``softbend identify`` when it was saved by it, else a saved surrogate; anything
    else must be a name of :data:`PLANTS`. A :class:`PlantChoice` is returned as it is.

    Raises
    ------
    UnknownNameError
        Keyed ``plant``: neither (the message lists the names and says a file may be given).
    """
    if isinstance(plant, PlantChoice):
        return plant
    from softbend.control.identified_plant import is_identified_plant

    text = str(plant)
    path = plant_file(text)
    if path is not None and path.suffix.lower() == ".csv":
        return PlantChoice("measurements", text, path)
    if path is not None:
        return PlantChoice("identified" if is_identified_plant(path) else "surrogate", text, path)
    try:
        PLANTS.check(text)
    except UnknownNameError as exc:
        raise UnknownNameError(
            f"{exc.detail} A plant may also be the path of a saved surrogate (.json), of a "
            "model of 'softbend identify' (.json) or of measurements (.csv).",
            key="plant",
        ) from None
    return PlantChoice("named", text)


def check_plant(plant: str | PlantChoice) -> str:
    """``plant`` if it names a plant: a name of :data:`PLANTS` or a plant file
    (:func:`parse_plant`; UnknownNameError else)."""
    return parse_plant(plant).text


def _own_actuator(choice: PlantChoice) -> Actuator | None:
    """The actuator ``choice`` is of alone (:data:`PLANT_ACTUATORS`), else None."""
    return PLANT_ACTUATORS.get(choice.text if choice.kind == "named" else choice.kind)


def check_plant_actuator(plant: str | PlantChoice, design: Design) -> None:
    """Refuse a plant of one actuator alone for a design of another (InputError keyed plant)."""
    choice = parse_plant(plant)
    own, actuator = _own_actuator(choice), actuator_of_design(design)
    if own is not None and own.name != actuator.name:
        raise InputError(
            f"{choice.text!r} is of {own.title} only; the design {design} is of the "
            f"actuator {actuator.name}: use the plant 'surrogate' (the controller's model) or "
            "a saved surrogate .json of that actuator",
            key="plant",
        )


def plant_compliance(plant: str | PlantChoice, design: Design, supply_mpa: float) -> float | None:
    """The rig's chamber compliance the plant gives for ``design``, mm³/MPa, else None."""
    choice = parse_plant(plant)
    compliance = PLANT_COMPLIANCES.get(choice.text) if choice.kind == "named" else None
    if compliance is None:
        return None
    check_plant_actuator(choice, design)
    return compliance(design, supply_mpa)


def plant_table(
    plant: str | PlantChoice,
    design: Design,
    model_table: AngleTable,
    *,
    pmax_mpa: float = 0.5,
) -> AngleTable:
    """The plant ``plant`` of ``design``: a name of :data:`PLANTS`, or a plant file.

    Parameters
    ----------
    plant : str or PlantChoice
        A name of :data:`PLANTS` (``model_table`` for "surrogate"), the path of a
        saved surrogate (``.json``: its θ(p) for ``design``) or of a measurements
        CSV (``.csv``: the design's loading readings, smoothed as
        :func:`lab_angle_table` does), or that text parsed (:func:`parse_plant`).
        Anything else raises :class:`~softbend.registry.UnknownNameError` listing
        the known names; an identified model has no θ(p) table (InputError).
    design : Design
        The design, of the controller's model's actuator; a plant of another
        actuator alone (:data:`PLANT_ACTUATORS`) is refused.
    model_table : AngleTable
        θ(p) of the controllers' own model.
    pmax_mpa : float, default 0.5
        The top of a saved surrogate's table, MPa gauge.
    """
    choice = parse_plant(plant)
    check_plant_actuator(choice, design)
    if choice.kind == "named":
        # a registered plant receives the design the controller's model takes
        return PLANTS.get(choice.text)(design, model_table)
    if choice.kind == "surrogate":
        from softbend.surrogates.persistence import load_surrogate

        saved = load_surrogate(choice.text)
        own = control_design(design, saved.actuator, source=f"the plant {choice.path}")
        return AngleTable.from_surrogate(saved.model, own, pmax_mpa=pmax_mpa)
    if choice.kind == "measurements":
        from softbend.transfer.measurements import load_measurements

        readings = load_measurements(choice.text)
        return lab_angle_table(design, measurements=readings, source=choice.text)
    raise InputError(
        f"is the identified model {choice.text}: its dynamics play the actuator, it has no "
        "θ(p) table of a design",
        key="plant",
    )


def surrogate_plant(design: Design, model_table: AngleTable) -> AngleTable:
    """The controllers' own model as the plant: no model mismatch."""
    return model_table


def in_table1(design: Design) -> bool:
    """Whether ``design`` is one of the 972 of Table 1 (its FEM sweep is shipped)."""
    from softbend.design import TABLE1_LEVELS

    return all(
        any(np.isclose(value, level) for level in TABLE1_LEVELS[name])
        for name, value in design.as_dict().items()
    )


def fem_compliance(design: Design, supply_mpa: float) -> float | None:
    """The chamber compliance of a design's own FEM sweep up to the supply, mm³/MPa.

    None for a design of Table 1 (its rig keeps the default compliance); another is
    swept once and cached (:func:`softbend.control.fem_plant.fem_curve`).
    """
    if in_table1(design):
        return None
    from softbend.control.fem_plant import fem_curve

    return fem_curve(design).compliance_mm3_per_mpa(supply_mpa)


def fem_plant(design: Design, model_table: AngleTable) -> AngleTable:
    """The design's FEM sweep: shipped for Table 1 (:func:`fem_angle_table`), else solved once.

    A design outside Table 1 is swept by the FEM on demand and kept in a cache
    folder (:func:`softbend.control.fem_plant.fem_curve`).
    """
    if in_table1(design):
        return fem_angle_table(design)
    from softbend.control.fem_plant import fem_curve

    return fem_curve(design).table()


def support_warnings(
    saved: SavedSurrogate,
    design: Design,
    up_to_mpa: float,
    *,
    role: str = "the controller's model",
) -> tuple[float | None, str | None, str | None]:
    """How far a saved surrogate's θ(p) of ``design`` holds, and where up to ``up_to_mpa`` not.

    A rig reaches any pressure up to its supply; a surrogate's θ(p) past the
    pressure its nearest training designs were swept to, or past the largest
    angle it was trained on, is an extrapolation
    (:mod:`softbend.surrogates.support`).

    Parameters
    ----------
    saved : SavedSurrogate
        A loaded surrogate file (``.model`` and ``.metadata``), of any actuator.
    design : Design
        The design, of the actuator of ``saved`` (a design of another actuator
        with the same parameters is taken by its values).
    up_to_mpa : float
        The largest pressure the rig reaches (its supply), MPa gauge.
    role : str
        What the model plays and its file, for the message.

    Returns
    -------
    supported_mpa : float or None
        The largest supported pressure at ``design``, MPa; None when the file
        records no support.
    pressure_note : str or None
        A phrase when ``up_to_mpa`` lies past ``supported_mpa`` (pressures in the
        model's unit).
    angle_note : str or None
        A phrase when θ(p) up to the supported pressure passes the largest
        angle trained on.
    """
    from softbend.surrogates.support import Support

    record = saved.metadata.get("support")
    if not isinstance(record, dict):
        return None, None, None
    actuator = getattr(saved, "actuator", actuator_of_design(design))
    own = control_design(design, actuator, source=role)
    support = Support.from_dict(record, parameters=actuator.names)
    scale, unit = 1.0 / actuator.to_mpa, actuator.pressure_unit  # from MPa to the model's unit
    native = float(support.max_pressure(own.as_array()[None, :])[0])
    limit = native / scale
    shown_limit, shown_supply = f"{native:.3g} {unit}", f"{up_to_mpa * scale:g} {unit}"
    pressure_note = angle_note = None
    if up_to_mpa > limit * (1 + 1e-9):
        pressure_note = (
            f"{role} was trained near the design {own} up to {shown_limit} only: its "
            f"θ(p) from there to the supply ({shown_supply}) is an extrapolation"
        )
    reach = min(up_to_mpa, limit)
    angles = np.asarray(
        saved.model.predict(own.feature_rows(np.linspace(0.0, reach, 101), unit="MPa"))
    )
    if np.max(angles) > support.angle_limit_deg:
        reach_text = f"{reach * scale:.3g} {unit}"
        angle_note = (
            f"{role} predicts {np.max(angles):.4g}° for the design {own} below "
            f"{reach_text}, beyond the largest angle it was trained on "
            f"({support.max_angle_deg:.4g}°)"
        )
    return limit, pressure_note, angle_note


def lab_plant(design: Design, model_table: AngleTable) -> AngleTable:
    """The design's virtual-lab loading readings, smoothed (:func:`lab_angle_table`)."""
    return lab_angle_table(design)


def shipped_angle_table(design: Design, pmax_mpa: float = 0.5, points: int = 501) -> AngleTable:
    """θ(p) of ``design`` from the shipped FEM-trained MLP (``transfer.base.load_base``)."""
    from softbend.transfer.base import load_base

    return AngleTable.from_surrogate(load_base(), design, pmax_mpa=pmax_mpa, points=points)


def fem_angle_table(
    design: Design,
    pmax_mpa: float = 0.5,
    points: int = 501,
    data: pd.DataFrame | None = None,
) -> AngleTable:
    """θ(p) of ``design`` from its FEM sweep in the shipped Table 1 dataset: a plant unlike the MLP.

    With this as the rig's angle map and the MLP as the controller's virtual
    sensor, the controller meets the model error it would meet on a real
    actuator. The converged samples of the sweep are interpolated linearly onto
    the table's grid; beyond the sweep's last pressure (it stops at 300° or an
    instability) θ is extrapolated linearly with the slope of its last two
    samples, which the references used here (≤ 90°) only reach in overshoot.

    Parameters
    ----------
    design : Design
        One of the 972 designs of Table 1.
    pmax_mpa, points : float, int
        The table's grid, as :meth:`AngleTable.from_callable`.
    data : pandas.DataFrame, optional
        The dataset (default :func:`softbend.datasets.table1_fem`).
    """
    from softbend.datasets import table1_fem

    frame = table1_fem() if data is None else data
    mask = np.ones(len(frame), dtype=bool)
    for name, value in design.as_dict().items():
        mask &= np.isclose(frame[name].to_numpy(dtype=float), value)
    rows = frame[mask & frame["converged"].to_numpy(dtype=bool)].sort_values("pressure_mpa")
    if len(rows) < 2:
        levels = {name: sorted(float(v) for v in frame[name].unique()) for name in design.as_dict()}
        allowed = "; ".join(
            f"{k} in {', '.join(f'{v:g}' for v in vals)}" for k, vals in levels.items()
        )
        raise InputError(
            f"{design} is not in the FEM dataset (Table 1: {allowed}); use a surrogate plant "
            "for it",
            key="design",
        )
    p = rows["pressure_mpa"].to_numpy(dtype=float)
    a = rows["angle_deg"].to_numpy(dtype=float)
    return AngleTable.from_callable(_extrapolated(p, a), pmax_mpa=pmax_mpa, points=points)


def _extrapolated(p: np.ndarray, a: np.ndarray) -> Callable[[np.ndarray], np.ndarray]:
    """Linear interpolation of (p, a), extended past ``p[-1]`` with the last segment's slope."""
    slope = (a[-1] - a[-2]) / (p[-1] - p[-2])

    def angle(q: np.ndarray) -> np.ndarray:
        return np.where(q > p[-1], a[-1] + slope * (q - p[-1]), np.interp(q, p, a))

    return angle


def lab_angle_table(
    design: Design,
    pmax_mpa: float = 0.5,
    points: int = 501,
    measurements: Measurements | None = None,
    degree: int = 3,
    source: str = "the virtual lab",
) -> AngleTable:
    """θ(p) of ``design`` as measured: the virtual lab's loading readings, smoothed.

    The plant of a control run that meets the reality gap (another elastomer fit,
    fabrication error, hysteresis: :mod:`softbend.transfer.lab`) while the
    controller's model is the FEM-trained MLP. The loading-branch readings of
    the design are fitted by a least-squares polynomial of ``degree`` in p
    (removing the camera noise), tabulated up to the last reading, and extended
    past it linearly with the end slope.

    Parameters
    ----------
    design : Design
        One of the measured actuators (paper B Fig. 7).
    measurements : Measurements, optional
        Default: the shipped virtual-lab readings
        (:func:`softbend.transfer.lab.shipped_measurements`). The rows of
        ``design`` are found by its six design columns.
    degree : int, default 3
    source : str
        What the readings are, for the message when ``design`` has too few.
    """
    from softbend.transfer.lab import shipped_measurements
    from softbend.transfer.measurements import MEASUREMENT_COLUMNS

    data = (shipped_measurements() if measurements is None else measurements).frame
    columns = list(MEASUREMENT_COLUMNS[:6])  # l, r, t, b, phi, lc
    mask = (data["direction"] == "loading").to_numpy(dtype=bool, copy=True)
    for column, value in zip(columns, design.as_array(), strict=True):
        mask &= np.isclose(data[column].to_numpy(dtype=float), value)
    rows = data[mask]
    if len(rows) <= degree:
        designs = data[columns].drop_duplicates().to_numpy()
        known = ", ".join(",".join(f"{v:g}" for v in row) for row in designs)
        raise InputError(
            f"has no measured loading curve in {source} (fewer than {degree + 1} readings; "
            f"measured designs: {known}); use the 'surrogate' or 'fem' plant for {design}",
            key="design",
        )
    p = rows["pressure_mpa"].to_numpy(dtype=float)
    coef = np.polynomial.polynomial.polyfit(p, rows["angle_deg"].to_numpy(dtype=float), degree)
    grid = np.linspace(0.0, float(p.max()), 64)
    smooth = np.polynomial.polynomial.polyval(grid, coef)
    return AngleTable.from_callable(_extrapolated(grid, smooth), pmax_mpa=pmax_mpa, points=points)


PLANTS.register("surrogate", surrogate_plant)
PLANTS.register("fem", fem_plant)
PLANTS.register("lab", lab_plant)
PLANT_COMPLIANCES["fem"] = fem_compliance
