"""An identified dynamic model as the actuator of the simulated rig, and the rig set from one.

``softbend identify`` fits a NARX model of recorded time series and saves it
(``model.json``, :func:`softbend.identification.dynamics.load_identified`). One
with a single pressure input and an angle output can play the actuator of a
control run (``--plant DIR/model.json``): its dynamics replace the rig's
quasi-static θ(p) and first-order angle lag. The rig feeds the true chamber
pressure (MPa gauge, converted to the unit of the model's input by the
column's name: ``_mpa``, ``_kpa``, ``_bar``, ``_pa``, ``_psi``) to the model
every sample period (zero-order hold), and the model's angle output, held in
between, is the true angle (:class:`NARXAngle`).

A controller needs a θ(p) of its own: without ``--model`` it is the model's
steady state, the angle it settles to from rest under each pressure held, over
a grid up to the supply (:meth:`IdentifiedPlant.angle_table`).

The same model also sets the simulated rig of another plant
(``--rig-from DIR/model.json``, :func:`rig_settings_from`): the time constant
and the delay of its step reading from pressure to angle become the rig's
``angle_time_constant_s`` and ``valve_delay_s``.
"""

from __future__ import annotations

import math
import warnings
from dataclasses import dataclass
from pathlib import Path
from typing import TYPE_CHECKING, Any

import numpy as np

from softbend import units
from softbend.control.rig import RIG_RANGES, AngleTable
from softbend.errors import InputError

if TYPE_CHECKING:
    from softbend.identification.dynamics import IdentifiedModel

__all__ = [
    "IdentifiedPlant",
    "NARXAngle",
    "angle_output",
    "identified_plant",
    "is_identified_plant",
    "pressure_unit",
    "rig_settings_from",
]

#: Grid points of the steady-state θ(p) of an identified plant.
STEADY_POINTS = 41

#: A fall of the steady-state θ(p) by more than this share of its rise is reported.
MONOTONE_TOLERANCE = 0.02

#: The fields of the rig that an identified model sets (``--rig-from``), and what from.
RIG_FROM_FIELDS: dict[str, str] = {
    "angle_time_constant_s": "time constant",
    "valve_delay_s": "delay",
}


def pressure_unit(name: str) -> tuple[str, float] | None:
    """The unit of a pressure column by its name's end, and its units per MPa, else None
    (:func:`softbend.units.pressure_unit_of`)."""
    return units.pressure_unit_of(name.strip())


def _is_angle(name: str) -> bool:
    """Whether an output column's name says it is an angle in degrees."""
    unit = units.unit_from_name(name.strip(), ("angle",))
    if unit:  # the name says its unit: degrees, or not
        return unit == "deg"
    return name.strip().lower().startswith(("angle", "theta"))


def angle_output(output_names: tuple[str, ...] | list[str], source: str) -> int:
    """The index of the one output that is an angle in degrees, else one InputError."""
    angles = [i for i, name in enumerate(output_names) if _is_angle(name)]
    if len(angles) == 1:
        return angles[0]
    shown = ", ".join(output_names)
    what = "none is" if not angles else f"{len(angles)} are"
    raise InputError(
        f"must have one output that is an angle in degrees (a column named angle…, theta… "
        f"or …_deg) to play the actuator; {source} has the outputs {shown}, and {what}",
        key="plant",
    )


def is_identified_plant(path: str | Path) -> bool:
    """Whether ``path`` is an existing ``.json`` of a model saved by ``softbend identify``."""
    file = Path(path)
    if file.suffix.lower() != ".json" or not file.is_file():
        return False
    from softbend.identification.dynamics import is_identified_model

    return bool(is_identified_model(file))


class NARXAngle:
    """The angle of an identified model stepped at its sample period: an ``AngleDynamics``.

    At rest the model's outputs are its steady state under zero gauge pressure.
    Each :meth:`advance` adds ``dt_s`` to the time; once a sample period has
    passed, the pressure now (zero-order hold) enters the model's input history
    and the model steps one sample; the angle is held in between.

    Parameters
    ----------
    plant : IdentifiedPlant
    """

    def __init__(self, plant: IdentifiedPlant) -> None:
        self.plant = plant
        model = plant.identified.model
        self._model = model
        self._period = float(plant.sample_period_s)
        self._scale = plant.input_scale
        self._index = plant.angle_index
        self._rest = np.asarray(plant.rest_outputs, dtype=float)
        # standardized, as the model's maps take them (multi.MultiNARX)
        self._u_mean, self._u_std = float(model.u_mean_[0]), float(model.u_std_[0])
        self._y_mean, self._y_std = model.y_mean_, model.y_std_
        self._low = (model.y_low_ - model.y_mean_) / model.y_std_
        self._high = (model.y_high_ - model.y_mean_) / model.y_std_
        # a learned first-order lag on the (standardized) input, as the model's free run
        # applies it: u_f(t) = a·u_f(t−1) + (1−a)·u(t), a = exp(−1/τ), τ in samples
        tau = getattr(model, "input_tau_", None)
        self._lag = 0.0 if tau is None or float(tau[0]) <= 0 else math.exp(-1.0 / float(tau[0]))
        self.reset()

    def reset(self) -> float:
        """Back to rest (zero gauge pressure, the outputs settled); the angle then, degrees."""
        model = self._model
        rest = (self._rest - self._y_mean) / self._y_std
        # newest first: y(t−1) … y(t−na) and u(t−1) … u(t−nb+1), standardized
        self._ys = [rest.copy() for _ in range(model.output_lags)]
        at_rest = (0.0 - self._u_mean) / self._u_std
        self._us = [at_rest] * (model.input_lags - 1)
        self._filtered = at_rest  # the input filter's state, settled at rest
        self._t = 0.0
        self._samples = 0
        self.angle_deg = float(self._rest[self._index])
        return self.angle_deg

    def _step(self, u: float) -> None:
        """One sample of the model: φ(t) = [y(t−1), …, y(t−na), u(t), …, u(t−nb+1)]."""
        us = (u - self._u_mean) / self._u_std
        if self._lag:
            us = self._filtered = self._lag * self._filtered + (1.0 - self._lag) * us
        phi = np.concatenate([*self._ys, [us, *self._us]])[None, :]
        with np.errstate(all="ignore"):
            new = np.array([float(e.predict(phi)[0]) for e in self._model.estimators_])
        new = np.clip(np.nan_to_num(new, nan=0.0), self._low, self._high)
        self._ys = [new, *self._ys[:-1]]
        self._us = [us, *self._us[:-1]] if self._us else []
        j = self._index
        self.angle_deg = float(new[j] * self._y_std[j] + self._y_mean[j])

    def advance(self, pressure_mpa: float, dt_s: float) -> float:
        """The angle after ``dt_s`` more seconds at the gauge pressure ``pressure_mpa``, degrees.

        The model steps once for each sample instant ``n·T`` (T its sample period)
        reached, with the pressure now as its input ``u(n)``.
        """
        self._t += dt_s
        period = self._period
        while self._t >= (self._samples + 1) * period * (1.0 - 1e-9):
            self._samples += 1
            self._step(pressure_mpa * self._scale)
        return self.angle_deg


@dataclass(frozen=True)
class IdentifiedPlant:
    """A model of ``softbend identify`` checked to play the actuator of a control run.

    Attributes
    ----------
    path : Path
        Its file.
    identified : IdentifiedModel
    input_unit : str
        The unit of its pressure input (``MPa``, ``kPa``, ``bar``, ``psi``, ``Pa``).
    input_scale : float
        Units of its input per MPa.
    angle_index : int
        Which output is the angle, degrees.
    rest_outputs : tuple of float
        Its outputs at rest (zero gauge pressure held until settled).
    """

    path: Path
    identified: IdentifiedModel
    input_unit: str
    input_scale: float
    angle_index: int
    rest_outputs: tuple[float, ...]

    @property
    def sample_period_s(self) -> float:
        """The model's sample period, s."""
        return float(self.identified.sample_period_s)  # type: ignore[arg-type]

    @property
    def angle_name(self) -> str:
        """The name of the angle output."""
        return self.identified.output_names[self.angle_index]

    def describe(self) -> str:
        """The plant in one line: its file, structure and sample period."""
        return (
            f"identified model {self.path} ({self.identified.model.describe()}), sample period "
            f"{self.sample_period_s:.4g} s"
        )

    def dynamics(self) -> NARXAngle:
        """A fresh :class:`NARXAngle` of this model (one per rig)."""
        return NARXAngle(self)

    def steady_angles_deg(self, pressures_mpa: np.ndarray) -> np.ndarray:
        """The angle each gauge pressure (MPa) held settles to, degrees.

        :meth:`~softbend.identification.dynamics.IdentifiedModel.steady_states` of the
        pressures in the model's input unit.
        """
        u = np.asarray(pressures_mpa, dtype=float).reshape(-1, 1) * self.input_scale
        return self.identified.steady_states(u)[:, self.angle_index].copy()

    def angle_table(
        self, pmax_mpa: float, points: int = STEADY_POINTS, *, check: bool = True
    ) -> AngleTable:
        """The steady-state θ(p) on a uniform grid from 0 to ``pmax_mpa`` MPa gauge.

        With ``check`` (the table is a controller's), since a controller inverts its
        rising branch (:meth:`AngleTable.inverse`): a θ(p) that never rises is
        refused (InputError keyed ``plant``); one that falls back by more than
        :data:`MONOTONE_TOLERANCE` of its rise is a warning saying up to which
        angle the controller can aim.
        """
        p = np.linspace(0.0, pmax_mpa, points)
        angles = self.steady_angles_deg(p)
        if not check:
            return AngleTable(p, angles)
        rise = float(np.max(angles) - angles[0])
        if not rise > 0.0:
            raise InputError(
                f"must bend more as the pressure rises for a controller to invert its θ(p): the "
                f"steady state of {self.path} is {angles[0]:.4g}° at 0 MPa and no more up to the "
                f"supply ({pmax_mpa:g} MPa); give a controller's model (--model)",
                key="plant",
            )
        fall = np.maximum.accumulate(angles) - angles
        worst = int(np.argmax(fall))
        if fall[worst] > MONOTONE_TOLERANCE * rise:
            peak = int(np.argmax(angles[: worst + 1]))
            warnings.warn(
                f"The steady-state θ(p) of the identified model {self.path} is not monotone: it "
                f"falls from {angles[peak]:.4g}° at {p[peak]:.3g} MPa to {angles[worst]:.4g}° at "
                f"{p[worst]:.3g} MPa; a controller aims by its rising branch, up to "
                f"{np.max(angles):.4g}° (give --model for another θ(p)).",
                UserWarning,
                stacklevel=3,
            )
        return AngleTable(p, angles)


def identified_plant(path: str | Path, *, role: str = "--plant") -> IdentifiedPlant:
    """Load a model of ``softbend identify`` and check that it can play the actuator.

    Requirements: exactly one input, a pressure (its column's name ends in
    ``_mpa``, ``_kpa``, ``_bar``, ``_pa`` or ``_psi``); one output that is an
    angle in degrees (:func:`angle_output`); a time column of known unit (its
    name ends in ``_s`` or ``_ms``, so that the sample period is known in
    seconds). Each missing one is an InputError keyed ``plant`` saying what is needed.
    """
    from softbend.identification.dynamics import load_identified

    file = Path(path)
    identified = load_identified(file)
    source = f"the identified model {file} ({role})"
    inputs = list(identified.input_names)
    found = [pressure_unit(name) for name in inputs]
    if len(inputs) != 1 or found[0] is None:
        suffixes = ", ".join("_" + unit.lower() for unit in units.PRESSURE_UNITS)
        raise InputError(
            "must have exactly one input, a pressure whose column name gives its unit (ending "
            f"in {suffixes}) to play the actuator; {source} has the inputs {', '.join(inputs)}",
            key="plant",
        )
    if identified.sample_period_s is None:
        raise InputError(
            "must have a time column of known unit (e.g. time_s or t_ms) for the rig to step it "
            f"in seconds; {source} was identified on "
            f"{identified.time_name or 'the sample index'}, whose unit is unknown",
            key="plant",
        )
    index = angle_output(tuple(identified.output_names), source)
    unit, scale = found[0]
    rest = identified.steady_state(np.zeros(1))
    return IdentifiedPlant(
        path=file,
        identified=identified,
        input_unit=unit,
        input_scale=scale,
        angle_index=index,
        rest_outputs=tuple(float(v) for v in np.asarray(rest).reshape(-1)),
    )


def rig_settings_from(path: str | Path) -> tuple[dict[str, float], dict[str, Any]]:
    """The rig's angle lag and valve delay from an identified model's step reading.

    The reading of the model's pressure input to its angle output
    (:func:`softbend.identification.dynamics.step_readings`) gives
    ``angle_time_constant_s`` (its time constant) and ``valve_delay_s`` (its
    delay), each held to its declared range (:data:`~softbend.control.rig.RIG_RANGES`).

    Returns
    -------
    settings : dict
        ``{field: value}``, s.
    record : dict
        Where they came from, for a run's summary: the file, the reading, each value.

    Raises
    ------
    InputError
        Keyed ``rig_from``: a model that cannot play the actuator
        (:func:`identified_plant`), a reading without a time constant or delay, or
        a value outside the field's range.
    """
    from softbend.identification.dynamics import step_readings

    file = Path(path)
    if not is_identified_plant(file):
        raise InputError(
            "must be a model saved by 'softbend identify' (its --out folder's model.json); "
            f"got {str(file)!r}",
            key="rig_from",
        )
    try:
        plant = identified_plant(file, role="--rig-from")
    except InputError as error:
        raise InputError(error.detail, key="rig_from") from None
    identified = plant.identified
    source = identified.input_names[0]
    target = plant.angle_name
    reading = next(
        (r for r in step_readings(identified) if r.input == source and r.output == target), None
    )
    if reading is None:
        raise InputError(
            f"must give a step reading of {source} → {target}; {file} gives none", key="rig_from"
        )
    values = {
        "angle_time_constant_s": reading.time_constant_s,
        "valve_delay_s": reading.delay_s,
    }
    settings: dict[str, float] = {}
    for name, value in values.items():
        what = RIG_FROM_FIELDS[name]
        if value is None or not math.isfinite(value):
            raise InputError(
                f"must give the {what} of its step reading {source} → {target} to set the rig's "
                f"{name}; {file} gives none (the response may not settle in its reading)",
                key="rig_from",
            )
        declared = RIG_RANGES[name]
        if not declared.contains(value):
            raise InputError(
                f"must give a {what} ({source} → {target}) within the rig's {name} range "
                f"{declared.describe()}; {file} gives {value:.4g} s",
                key="rig_from",
            )
        settings[name] = float(value)
    record = {
        "file": str(file),
        "reading": f"{source} → {target}",
        "gain": reading.gain,
        **settings,
    }
    return settings, record
