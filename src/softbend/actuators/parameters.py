"""A design parameter of an actuator: its name, unit, range, kind and resolution.

Also the pressure units a description may use and the error every description,
design or table raises when it breaks its actuator's declared parameters.
"""

from __future__ import annotations

import math
import re
from collections.abc import Mapping
from dataclasses import dataclass
from typing import Any, Literal

import numpy as np

from softbend import units
from softbend._validation import must_be, short_repr
from softbend.errors import SoftbendError

#: Factor from each pressure unit an actuator is described in to MPa (:mod:`softbend.units`).
PRESSURE_UNITS: dict[str, float] = {u: f for u, f in units.PRESSURE_UNITS.items() if u != "Pa"}

Kind = Literal["continuous", "integer", "categorical"]
KINDS: tuple[str, ...] = ("continuous", "integer", "categorical")

_NAME = re.compile(r"^[A-Za-z_][A-Za-z0-9_]{0,63}$")


class ActuatorError(SoftbendError, ValueError):
    """A description, design or table that breaks an actuator's declared parameters."""


def pressure_to_mpa(
    unit: str,
) -> float:
    """The factor from ``unit`` (kPa, MPa, bar or psi; case as written) to MPa.

    Raises
    ------
    ActuatorError
        For any other unit (key ``pressure_unit``), naming the four allowed.
    """
    if unit not in PRESSURE_UNITS:
        lowered = {u.lower(): u for u in PRESSURE_UNITS}
        hint = f" (did you mean {lowered[unit.lower()]}?)" if str(unit).lower() in lowered else ""
        raise ActuatorError(
            must_be(f"one of {', '.join(PRESSURE_UNITS)}", unit) + hint, key="pressure_unit"
        )
    return PRESSURE_UNITS[unit]


def check_name(name: object, what: str) -> str:
    if not isinstance(name, str) or not _NAME.match(name):
        raise ActuatorError(
            f"The {what} must be a name of letters, digits and '_' (not starting with a digit, "
            f"at most 64 characters); got {name!r}."
        )
    return name


@dataclass(frozen=True)
class DesignParameter:
    """One named design parameter of an actuator.

    Parameters
    ----------
    name : str
        Column name in tables and models (``"l_mm"``, ``"n_chambers"``).
    unit : str
        Unit of its values (``"mm"``, ``"deg"``; ``""`` for a count or a level).
    low, high : float
        The range the description covers (inclusive). For a categorical
        parameter they are taken from its levels (0 to len(levels) - 1).
    kind : {"continuous", "integer", "categorical"}
        Continuous values, whole numbers, or one of ``levels``.
    levels : tuple, optional
        A categorical parameter's levels (strings or numbers), in the order
        of their index codes.
    resolution : float, optional
        Manufacturing resolution (the step a design search rounds to), in ``unit``.
    description : str
        What the parameter is, for tables and documentation.
    sampled : bool, default False
        Whether ``low`` and ``high`` are only the span a simulation table
        sampled (:meth:`Actuator.from_table`), not a declared range: a value
        outside them is not refused here, and a model trained on the table
        flags it as outside its training ranges instead.
    """

    name: str
    unit: str = ""
    low: float = -math.inf
    high: float = math.inf
    kind: Kind = "continuous"
    levels: tuple[Any, ...] | None = None
    resolution: float | None = None
    description: str = ""
    sampled: bool = False

    def __post_init__(self) -> None:
        check_name(self.name, "name of a design parameter")
        if self.kind not in KINDS:
            raise ActuatorError(
                f"The kind of design parameter {self.name!r} must be one of "
                f"{', '.join(KINDS)}; got {self.kind!r}."
            )
        if self.kind == "categorical":
            levels = self.levels or ()
            if len(levels) < 2 or len(set(map(str, levels))) != len(levels):
                raise ActuatorError(
                    f"The categorical design parameter {self.name!r} needs two or more distinct "
                    f"levels; got {self.levels!r}."
                )
            object.__setattr__(self, "levels", tuple(levels))
            object.__setattr__(self, "low", 0.0)
            object.__setattr__(self, "high", float(len(levels) - 1))
        elif self.levels is not None:
            raise ActuatorError(
                f"Only a categorical design parameter has levels; {self.name!r} is {self.kind}."
            )
        low, high = float(self.low), float(self.high)
        if math.isnan(low) or math.isnan(high) or low > high:
            raise ActuatorError(
                f"The range of design parameter {self.name!r} must have low <= high; "
                f"got [{self.low}, {self.high}]."
            )
        object.__setattr__(self, "low", low)
        object.__setattr__(self, "high", high)
        if self.resolution is not None and not (
            math.isfinite(self.resolution) and self.resolution > 0
        ):
            raise ActuatorError(
                f"The resolution of design parameter {self.name!r} must be finite and > 0; "
                f"got {self.resolution!r}."
            )

    @property
    def label(self) -> str:
        """``name (unit)`` for table headers and axis labels."""
        return f"{self.name} ({self.unit})" if self.unit else self.name

    def encode(self, value: object) -> float:
        """The model input of ``value``: a level's index for a categorical parameter."""
        if self.kind == "categorical":
            assert self.levels is not None
            for index, level in enumerate(self.levels):
                if str(level) == str(value).strip() or (
                    not isinstance(level, str) and _same_number(level, value)
                ):
                    return float(index)
            raise ActuatorError(
                f"{self.name} must be one of the levels {', '.join(map(str, self.levels))}; "
                f"got {short_repr(value)}"
            )
        try:
            number = float(value)  # type: ignore[arg-type]  # refused by except
        except (TypeError, ValueError):
            raise ActuatorError(
                f"{self.name} must be a number ({self._what()}); got {short_repr(value)}"
            ) from None
        return number

    def decode(self, code: float) -> Any:
        """The value a model input ``code`` stands for (a level for a categorical parameter)."""
        if self.kind == "categorical":
            assert self.levels is not None
            return self.levels[round(code)]
        if self.kind == "integer":
            return round(code)
        return float(code)

    def snap(self, values: np.ndarray) -> np.ndarray:
        """``values`` moved to the nearest buildable value: a level, a whole number,
        or a multiple of the resolution, inside the range."""
        out = np.clip(np.asarray(values, dtype=float), self.low, self.high)
        if self.kind in ("integer", "categorical"):
            return np.clip(np.round(out), math.ceil(self.low), math.floor(self.high))
        if self.resolution is not None:
            out = np.round(out / self.resolution) * self.resolution
            return np.clip(out, self.low, self.high)
        return out

    def check(self, codes: np.ndarray) -> None:
        """Raise one :class:`ActuatorError` for the first code outside the range or kind.

        The message names the parameter (``n_folds must be a whole number in [3, 9];
        got 5.5``), so an error re-keyed to the input it came from keeps it.
        """
        values = np.asarray(codes, dtype=float)
        bad = ~np.isfinite(values)
        if bad.any():
            raise ActuatorError(
                f"{self.name} must be finite ({self._what()}); got {float(values[bad][0])!r}"
            )
        eps = 1e-9 * max(1.0, abs(self.low), abs(self.high))
        outside = (values < self.low - eps) | (values > self.high + eps)
        if outside.any() and not (self.sampled and self.kind != "categorical"):
            shown = (
                self.decode(values[outside][0])
                if self.kind == "categorical"
                else values[outside][0]
            )
            got = f"{shown:g}" if isinstance(shown, float) else repr(shown)
            raise ActuatorError(f"{self.name} must be {self._what()}; got {got}")
        if self.kind in ("integer", "categorical"):
            fractional = np.abs(values - np.round(values)) > 1e-9
            if fractional.any():
                raise ActuatorError(
                    f"{self.name} must be {self._what()}; got {values[fractional][0]:g}"
                )

    def _what(self) -> str:
        if self.kind == "categorical":
            assert self.levels is not None
            return f"one of {', '.join(map(str, self.levels))}"
        unit = f" {self.unit}" if self.unit else ""
        if self.sampled and self.kind == "integer":
            return "a whole number"
        if self.sampled:
            return f"in{unit}" if unit else "any value"
        span = f"in [{self.low:g}, {self.high:g}]{unit}"
        return f"a whole number {span}" if self.kind == "integer" else span

    def to_dict(self) -> dict[str, Any]:
        """JSON-friendly form (:meth:`from_dict` reads it back)."""
        out: dict[str, Any] = {"name": self.name, "unit": self.unit, "kind": self.kind}
        if self.kind == "categorical":
            out["levels"] = list(self.levels or ())
        else:
            out["low"], out["high"] = self.low, self.high
        if self.resolution is not None:
            out["resolution"] = self.resolution
        if self.description:
            out["description"] = self.description
        if self.sampled:
            out["sampled"] = True
        return out

    @classmethod
    def from_dict(cls, data: Mapping[str, Any]) -> DesignParameter:
        """The parameter :meth:`to_dict` wrote; one :class:`ActuatorError` for a bad record."""
        if not isinstance(data, Mapping):
            raise ActuatorError(f"A design parameter must be an object; got {data!r}.")
        allowed = {
            "name",
            "unit",
            "kind",
            "levels",
            "low",
            "high",
            "resolution",
            "description",
            "sampled",
        }
        unknown = sorted(set(data) - allowed)
        if unknown:
            raise ActuatorError(
                f"Unknown key(s) {', '.join(unknown)} in design parameter "
                f"{data.get('name')!r}; allowed: {', '.join(sorted(allowed))}."
            )
        levels = data.get("levels")
        sampled = data.get("sampled", False)
        if not isinstance(sampled, bool):
            raise ActuatorError(
                f"The 'sampled' of design parameter {data.get('name')!r} must be true or false; "
                f"got {sampled!r}."
            )
        return cls(
            name=data.get("name"),  # type: ignore[arg-type]  # checked in __post_init__
            unit=str(data.get("unit", "")),
            low=_number(data.get("low", -math.inf)),
            high=_number(data.get("high", math.inf)),
            kind=data.get("kind", "continuous"),
            levels=tuple(levels) if isinstance(levels, list | tuple) else levels,
            resolution=None if data.get("resolution") is None else _number(data["resolution"]),
            description=str(data.get("description", "")),
            sampled=sampled,
        )


def _number(value: object) -> float:
    if isinstance(value, bool) or not isinstance(value, int | float):
        raise ActuatorError(f"A bound or resolution must be a number; got {value!r}.")
    return float(value)


def _same_number(level: object, value: object) -> bool:
    try:
        return float(level) == float(value)  # type: ignore[arg-type]  # refused by except
    except (TypeError, ValueError):
        return False
