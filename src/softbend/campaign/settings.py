"""What a campaign's numbers depend on: its backend's settings, recorded and compared.

A campaign database records, when its first run starts, the settings of the
backend that change the numbers (:func:`backend_settings`): the backend's name,
the pressure grid, the FEM options (largest element size ``maxh_mm``, element
order, fibers, gravity, stop rules, solver tolerances) or the options of another
backend, and the elastomer (its constitutive model and constants, its density
and, for a fit of ``softbend materials fit``, the SHA-256 of the ``fit.json``).
A resumed run, or a shard merged in, with other settings is refused
(:class:`SettingsMismatchError`, naming each differing setting with both
values) unless the change is accepted; a database written before settings were
recorded resumes with an :class:`UncheckedSettingsWarning`.

The settings are one JSON object; they are compared flattened to dotted names
(``options.maxh_mm``, ``material.model.c10``), leaving out what only labels a
setting (:data:`UNCOMPARED`: the material's name, source and spec, the path of
its file, any ``source``).
"""

from __future__ import annotations

import dataclasses
import json
import math
import os
from collections.abc import Mapping
from pathlib import Path
from typing import TYPE_CHECKING, Any, cast

import numpy as np

from softbend.errors import SoftbendError
from softbend.materials.models import HyperelasticModel
from softbend.materials.presets import DRAGON_SKIN_30, LinearElastic, Material

if TYPE_CHECKING:
    from softbend.fem.options import FEMOptions
    from softbend.models import BendingModel

__all__ = [
    "SETTINGS_VERSION",
    "UNCOMPARED",
    "SettingsMismatchError",
    "UncheckedSettingsWarning",
    "backend_settings",
    "describe_differences",
    "fem_options_of",
    "settings_differences",
]

#: Version of the layout of :func:`backend_settings` (recorded, not compared).
SETTINGS_VERSION = 1

#: Dotted names (and their children) recorded but not compared: labels, not numbers.
UNCOMPARED: tuple[str, ...] = (
    "version",
    "material.name",
    "material.source",
    "material.given.spec",
    "material.given.file",
    "material.given.model",
    "options.source",
)
#: Any setting whose last part is one of these is a label too (``options.layer.source``).
_LABELS = ("source",)

# Fields of a backend that do not change its numbers (or are recorded elsewhere).
_NOT_SETTINGS = frozenset({"name", "compiled", "preferred_chunk_size", "material", "options"})
# FEM options that change the run time, not the numbers (beyond round-off).
_FEM_NOT_SETTINGS = ("threads", "elastomer")
_MISSING = object()


class UncheckedSettingsWarning(UserWarning):
    """A campaign database without recorded settings: a resume could not be checked."""


class SettingsMismatchError(SoftbendError, ValueError):
    """A campaign resumed with settings other than those it recorded.

    Keyed ``accept_new_settings`` (what lets such a run go on); the message
    names the database and each differing setting.

    Parameters
    ----------
    path : path
        The campaign database.
    differences : list of (name, recorded, given)
        As :func:`settings_differences`.
    """

    def __init__(
        self, path: str | os.PathLike[str], differences: list[tuple[str, Any, Any]]
    ) -> None:
        self.path = Path(path)
        self.differences = differences
        super().__init__(
            f"must be set to resume the campaign {str(self.path)!r} with settings other than "
            f"those it recorded: {describe_differences(differences)}; or resume with the "
            "recorded settings, or write to a new database",
            key="accept_new_settings",
        )


def describe_differences(
    differences: list[tuple[str, Any, Any]], *, recorded: str = "there", given: str = "here"
) -> str:
    """``"NAME is A there, B here; ..."`` for the first eight differences (and how many more)."""
    shown = "; ".join(
        f"{name} is {_show(a)} {recorded}, {_show(b)} {given}" for name, a, b in differences[:8]
    )
    more = f"; and {len(differences) - 8} more" if len(differences) > 8 else ""
    return shown + more


def _show(value: object) -> str:
    if value is _MISSING:
        return "not recorded"
    if isinstance(value, float):
        return f"{value:g}"
    if isinstance(value, str):
        return repr(value)
    return json.dumps(value, default=str)


def fem_options_of(backend: object) -> FEMOptions | None:
    """The :class:`~softbend.fem.FEMOptions` of an FEM backend (defaults for None), else None."""
    if getattr(backend, "name", None) != "fem" or not hasattr(backend, "options"):
        return None
    from softbend.fem.options import FEMOptions

    options = getattr(backend, "options", None)
    return FEMOptions() if options is None else cast(FEMOptions, options)


def _material_record(
    material: Material | HyperelasticModel | LinearElastic, given: Mapping[str, str] | None
) -> dict[str, Any]:
    """A material (or a bare constitutive model) as settings, with what named it."""
    record = material.to_dict() if isinstance(material, Material) else {"model": material.to_dict()}
    if given:
        record["given"] = dict(given)
    return record


def _plain_fields(backend: object) -> dict[str, Any]:
    """A dataclass backend's options that are plain values (numbers, text, None)."""
    if not dataclasses.is_dataclass(backend):
        return {}
    out = {}
    for f in dataclasses.fields(backend):
        value = getattr(backend, f.name)
        if f.init and f.name not in _NOT_SETTINGS and isinstance(value, int | float | str | None):
            out[f.name] = value
    return out


def backend_settings(
    backend: BendingModel,
    pressures_mpa: np.ndarray,
    *,
    material_given: Mapping[str, str] | None = None,
) -> dict[str, Any]:
    """The settings of ``backend`` that change a campaign's numbers, as JSON-ready data.

    Parameters
    ----------
    backend : BendingModel
        The campaign's backend. For the FEM its :class:`~softbend.fem.FEMOptions`
        (but the threads) are recorded; for a dataclass backend its plain options
        (``max_angle_deg`` of the analytical model); a wrapper with an ``inner``
        backend (``"fault-injection"``) records the inner one's.
    pressures_mpa : numpy.ndarray
        The campaign's pressure grid, MPa.
    material_given : mapping, optional
        What named the material (:func:`~softbend.materials.choice.material_spec_record`:
        the spec, and a fit's file and SHA-256), recorded with it.

    Returns
    -------
    dict
        ``version``, ``backend``, ``pressures_mpa`` (``count``, ``first``,
        ``last``, MPa), ``options`` and, for a backend with an elastomer,
        ``material`` (name, model and constants, density in tonne/mm³, source and
        ``given``).
    """
    grid = np.asarray(pressures_mpa, dtype=float)
    settings: dict[str, Any] = {
        "version": SETTINGS_VERSION,
        "backend": str(backend.name),
        "pressures_mpa": {
            "count": len(grid),
            "first": float(grid[0]) if len(grid) else None,
            "last": float(grid[-1]) if len(grid) else None,
        },
    }
    inner = getattr(backend, "inner", None)
    described: Any = inner if inner is not None and hasattr(inner, "sweep") else backend
    if described is not backend:
        settings["inner_backend"] = str(described.name)
    fem = fem_options_of(described)
    material: Any = None
    if fem is not None:
        options = fem.to_dict()
        for name in _FEM_NOT_SETTINGS:
            options.pop(name, None)
        settings["options"] = options
        material = fem.elastomer
    else:
        settings["options"] = _plain_fields(described)
        if any(f.name == "material" for f in _fields(described)):
            material = described.material if described.material is not None else DRAGON_SKIN_30
    if material is not None:
        settings["material"] = _material_record(material, material_given)
    return json.loads(json.dumps(settings, default=str))


def _fields(backend: object) -> tuple[dataclasses.Field[Any], ...]:
    if dataclasses.is_dataclass(backend):
        return dataclasses.fields(backend)
    return ()


def _flatten(value: object, prefix: str = "") -> dict[str, Any]:
    if isinstance(value, Mapping) and value:
        out: dict[str, Any] = {}
        for key, item in value.items():
            out.update(_flatten(item, f"{prefix}.{key}" if prefix else str(key)))
        return out
    return {prefix: value}


def _compared(name: str) -> bool:
    if name.rpartition(".")[2] in _LABELS:
        return False
    return not any(name == u or name.startswith(u + ".") for u in UNCOMPARED)


def _same(a: object, b: object) -> bool:
    if isinstance(a, float) and isinstance(b, float) and math.isnan(a) and math.isnan(b):
        return True
    return bool(a == b)


def settings_differences(
    recorded: Mapping[str, Any], given: Mapping[str, Any]
) -> list[tuple[str, Any, Any]]:
    """The settings that differ, as ``(dotted name, recorded, given)``, sorted by name.

    A setting present on one side only differs too (shown as "not recorded"); the
    names of :data:`UNCOMPARED` are left out.
    """
    mine, theirs = _flatten(recorded), _flatten(json.loads(json.dumps(given, default=str)))
    return [
        (name, mine.get(name, _MISSING), theirs.get(name, _MISSING))
        for name in sorted(set(mine) | set(theirs))
        if _compared(name) and not _same(mine.get(name, _MISSING), theirs.get(name, _MISSING))
    ]
