"""One design of an actuator: its description and the value of every design parameter.

:class:`Design` is the one design type of softbend: an FEM family makes one
(:meth:`~softbend.fem.families.FEMFamily.design`), a campaign sweeps and stores
it by its :attr:`Design.design_id`, a model takes its :meth:`Design.feature_rows`,
a design search finds it and a controller drives it.
"""

from __future__ import annotations

import hashlib
from collections.abc import Mapping, Sequence
from dataclasses import dataclass, field
from typing import Any

import numpy as np
from numpy.typing import ArrayLike

from softbend.actuators.description import Actuator
from softbend.actuators.parameters import ActuatorError, pressure_to_mpa

__all__ = ["Design"]


@dataclass(frozen=True)
class Design:
    """One design of ``actuator``: a value (model-input code) of each design parameter.

    Parameters
    ----------
    actuator : Actuator
        The description the design is of.
    values : mapping of str to float, or sequence of float
        The value of every design parameter, by name or in the order of
        ``actuator.names``, in the parameters' units (a categorical level as its
        index). Held in the description's order; not checked against its ranges
        here (:meth:`checked` does, as an FEM family's ``make_design`` does).

    Raises
    ------
    ActuatorError
        Values that do not name exactly the description's parameters.
    """

    actuator: Actuator = field(repr=False)
    values: Mapping[str, float] = field(default_factory=dict)

    def __post_init__(self) -> None:
        names = self.actuator.names
        given = self.values
        if not isinstance(given, Mapping):
            numbers = np.asarray(given, dtype=float).ravel().tolist()
            if len(numbers) != len(names):
                raise ActuatorError(
                    f"a design of {self.actuator.name} has {len(names)} values "
                    f"({', '.join(names)}); got {len(numbers)}"
                )
            given = dict(zip(names, numbers, strict=True))
        if set(given) != set(names):
            missing = [n for n in names if n not in given]
            unknown = [n for n in given if n not in names]
            raise ActuatorError(
                f"a design of {self.actuator.name} names {', '.join(names)}; "
                f"missing {missing}, unknown {unknown}"
            )
        object.__setattr__(self, "values", {n: float(given[n]) for n in names})

    @classmethod
    def checked(cls, actuator: Actuator, values: Mapping[str, float] | ArrayLike) -> Design:
        """The design of ``values``, checked by ``actuator``.

        The description's own check (:attr:`~softbend.actuators.Actuator.check_values`)
        runs first, then its ranges, kinds and constraints.

        Raises
        ------
        InputError
            One error naming the parameter or constraint at fault (an
            :class:`ActuatorError`, or the description's own check's error).
        """
        design = cls(actuator, values)  # type: ignore[arg-type]  # checked in __post_init__
        if actuator.check_values is not None:
            design = cls(actuator, actuator.check_values(design.as_dict()))
        actuator.check_designs(design.as_array())
        return design

    def __hash__(self) -> int:
        return hash((self.actuator.name, tuple(self.values.items())))

    def __getattr__(self, name: str) -> float:
        values = self.__dict__.get("values", {})
        if name in values:
            return values[name]
        raise AttributeError(name)

    @property
    def cavity_volume_mm3(self) -> float:
        """Undeformed cavity volume, mm³, from the design's geometry
        (:attr:`~softbend.actuators.Actuator.cavity_volume`).

        Raises
        ------
        AttributeError
            When the description gives no cavity volume of its designs.
        """
        volume = self.actuator.cavity_volume
        if volume is None:
            raise AttributeError(
                f"the designs of {self.actuator.name} give no cavity volume (cavity_volume_mm3)"
            )
        return float(volume(self.values))

    @property
    def design_id(self) -> str:
        """Stable 16-hex-digit identifier: a SHA-1 of the values rounded to 1e-6.

        The description's :attr:`~softbend.actuators.Actuator.design_ids` says
        what is hashed: ``"values"`` the values alone (``"100.000000,6.000000,..."``),
        ``"named"`` its FEM family (else its name) and the named values
        (``"pneunet:n_chambers=5.000000,..."``).
        """
        if self.actuator.design_ids == "values":
            canonical = ",".join(f"{v:.6f}" for v in self.values.values())
        else:
            prefix = self.actuator.fem_family or self.actuator.name
            named = ",".join(f"{k}={v:.6f}" for k, v in self.values.items())
            canonical = f"{prefix}:{named}"
        return hashlib.sha1(canonical.encode()).hexdigest()[:16]

    def as_dict(self) -> dict[str, float]:
        """The values as an ordered ``{name: value}`` mapping (levels as their index)."""
        return dict(self.values)

    def record(self) -> dict[str, Any]:
        """``{name: value}`` with whole numbers as integers and levels by name (JSON-friendly)."""
        return self.actuator.design_record(list(self.values.values()))

    def as_array(self) -> np.ndarray:
        """The values as a float array in the description's order."""
        return np.array(list(self.values.values()), dtype=float)

    def feature_rows(
        self, pressures: Sequence[float] | np.ndarray, *, unit: str | None = None
    ) -> np.ndarray:
        """Model inputs for this design at each pressure: one row per pressure.

        Parameters
        ----------
        pressures : array_like, shape (n,)
            Gauge pressures in ``unit`` (not checked here: models check their grids).
        unit : {"kPa", "MPa", "bar", "psi"}, optional
            Unit of ``pressures``; default the description's pressure unit.

        Returns
        -------
        numpy.ndarray, shape (n, n_parameters + 1)
            The design's values then the pressure in the description's unit
            (the columns :attr:`~softbend.actuators.Actuator.features`).
        """
        p = np.asarray(pressures, dtype=float).reshape(-1)
        if unit is not None and unit != self.actuator.pressure_unit:
            p = p * (pressure_to_mpa(unit) / self.actuator.to_mpa)
        rows = np.empty((p.size, len(self.values) + 1))
        rows[:, :-1] = self.as_array()
        rows[:, -1] = p
        return rows

    def as_text(self) -> str:
        """The design as text that reads back: ``100,6,2,2,5,8`` (the values in order, for
        a description whose ids hash its values, paper B's) or ``n_chambers=5,
        wall_mm=1.2, ...`` (named values, as an FEM family parses them)."""
        if self.actuator.design_ids == "values":
            return ",".join(f"{v:g}" for v in self.values.values())
        return ", ".join(f"{k}={v:g}" for k, v in self.values.items())

    def __str__(self) -> str:
        """The design for messages: :meth:`as_text` for paper B's, else by name in its
        units, levels by name (``n_chambers=5, wall_mm=1.2 mm, layer=paper``)."""
        if self.actuator.design_ids == "values":
            return self.as_text()
        return self.actuator.describe(list(self.values.values()))
