"""Material presets of the fiber-reinforced bending actuator of paper B (§3.1).

Densities are in tonne/mm³, the density unit consistent with mm, N, MPa and s
(1 g/cm³ = 1e-9 tonne/mm³).

* :data:`DRAGON_SKIN_30` — the elastomer body (Smooth-On Dragon Skin 30), Yeoh
  C10 = 0.11, C20 = 0.003, C30 = 0 MPa, 1.08 g/cm³. Paper B fits the three models
  of :mod:`softbend.materials.models` to uniaxial data of Dragon Skin 30 and keeps
  Yeoh (R² = 0.9982, RMSE = 0.0204 MPa).
* :data:`FIBERGLASS_LAYER` — the 0.1 mm strain-limiting layer (fiberglass S2-120),
  Yeoh C10 = 7.9 MPa, C20 = C30 = 0, 2.40 g/cm³ (paper B after Polygerinos et al. 2015).
* :data:`KEVLAR_FIBER` — the 0.28 mm Kevlar reinforcement, linear elastic
  E = 31076 MPa, ν = 0.36, 1.67 g/cm³; modelled as beams of radius
  :data:`KEVLAR_MODELLED_RADIUS_MM` = 0.07 mm, half the real radius, which paper B
  (after Polygerinos et al. 2015) uses to reduce the modelled fiber stiffness.
"""

from __future__ import annotations

from collections.abc import Mapping
from dataclasses import dataclass
from typing import Any, ClassVar

from softbend._validation import check_choice, check_object_keys, check_range, must_be
from softbend.errors import InputError, SchemaError, keyed
from softbend.materials.models import HyperelasticModel, Yeoh, check_constants
from softbend.references import MATERIALS, values
from softbend.registry import Registry

__all__ = [
    "DRAGON_SKIN_30",
    "FIBERGLASS_LAYER",
    "G_PER_CM3_TO_T_PER_MM3",
    "KEVLAR_FIBER",
    "KEVLAR_MODELLED_RADIUS_MM",
    "PRESETS",
    "LinearElastic",
    "Material",
    "get_preset",
]

#: Conversion factor from g/cm³ to tonne/mm³.
G_PER_CM3_TO_T_PER_MM3 = 1e-9

#: Radius of the beams that model the Kevlar fibers in paper B, mm (real diameter 0.28 mm).
KEVLAR_MODELLED_RADIUS_MM: float = MATERIALS["kevlar"]["modelled_radius_mm"].value

# Paper B §3.1 constants of the presets below (:data:`softbend.references.MATERIALS`).
_DS30, _GLASS, _KEVLAR = (values(MATERIALS[k]) for k in ("dragon-skin-30", "fiberglass", "kevlar"))


@dataclass(frozen=True)
class LinearElastic:
    """Isotropic linear elastic material (small strain), used for the fibers.

    Parameters
    ----------
    e_mpa : float
        Young's modulus in MPa, > 0.
    nu : float
        Poisson's ratio, dimensionless, in (-1, 0.5).
    """

    name: ClassVar[str] = "linear-elastic"

    e_mpa: float
    nu: float

    def __post_init__(self) -> None:
        object.__setattr__(self, "e_mpa", check_range(self.e_mpa, "e_mpa", low=0.0))
        object.__setattr__(self, "nu", check_range(self.nu, "nu", low=-1.0, high=0.5))

    @property
    def shear_modulus_mpa(self) -> float:
        """Shear modulus ``G = E / (2(1 + ν))`` in MPa."""
        return self.e_mpa / (2.0 * (1.0 + self.nu))

    @property
    def bulk_modulus_mpa(self) -> float:
        """Bulk modulus ``K = E / (3(1 − 2ν))`` in MPa."""
        return self.e_mpa / (3.0 * (1.0 - 2.0 * self.nu))

    def to_dict(self) -> dict[str, Any]:
        """Parameters as a JSON-friendly mapping with ``"model": "linear-elastic"``."""
        return {"model": self.name, "e_mpa": self.e_mpa, "nu": self.nu}

    @classmethod
    def from_dict(cls, data: Mapping[str, Any]) -> LinearElastic:
        """Rebuild from :meth:`to_dict` output (checked as :func:`check_constants` says)."""
        if isinstance(data, Mapping):
            check_choice(data.get("model", cls.name), "model", (cls.name,))
        params = check_constants(data, ("e_mpa", "nu"), ("e_mpa", "nu"))
        return cls(**params)


def _model_from_dict(data: object) -> HyperelasticModel | LinearElastic:
    if isinstance(data, Mapping) and data.get("model") == LinearElastic.name:
        return LinearElastic.from_dict(data)
    return HyperelasticModel.from_dict(data)


@dataclass(frozen=True)
class Material:
    """A named material: a constitutive model, a density and where the values come from.

    Parameters
    ----------
    name : str
        Human-readable name, non-empty.
    model : HyperelasticModel or LinearElastic
        Constitutive law (stresses in MPa).
    density_t_per_mm3 : float
        Mass density in tonne/mm³, > 0 (1 g/cm³ = 1e-9 tonne/mm³).
    source : str
        Provenance of the values (paper, section, data set).
    """

    name: str
    model: HyperelasticModel | LinearElastic
    density_t_per_mm3: float
    source: str = ""

    def __post_init__(self) -> None:
        if not isinstance(self.name, str) or not self.name.strip():
            raise InputError(must_be("a non-empty string", self.name), key="name")
        if not isinstance(self.model, HyperelasticModel | LinearElastic):
            raise InputError(
                "must be a HyperelasticModel (NeoHookean, Yeoh, ArrudaBoyce) or "
                f"LinearElastic; got {self.model!r}",
                key="model",
            )
        density = check_range(self.density_t_per_mm3, "density_t_per_mm3", low=0.0)
        object.__setattr__(self, "density_t_per_mm3", density)
        if not isinstance(self.source, str):
            raise InputError(must_be("a string", self.source), key="source")

    @property
    def density_g_per_cm3(self) -> float:
        """Mass density in g/cm³."""
        return self.density_t_per_mm3 / G_PER_CM3_TO_T_PER_MM3

    def to_dict(self) -> dict[str, Any]:
        """JSON-friendly mapping; the model is nested as its own ``to_dict``."""
        return {
            "name": self.name,
            "model": self.model.to_dict(),
            "density_t_per_mm3": self.density_t_per_mm3,
            "source": self.source,
        }

    @classmethod
    def from_dict(cls, data: Mapping[str, Any]) -> Material:
        """Rebuild from :meth:`to_dict` output.

        Raises
        ------
        SchemaError
            ``data`` is not a mapping, lacks ``name``, ``model`` or
            ``density_t_per_mm3``, has another key than those and ``source``
            (:func:`softbend._validation.check_object_keys`), or the density is
            not a number; the model is checked as in
            :meth:`HyperelasticModel.from_dict`.
        ValueError
            A value out of range (as the constructor says).
        """
        keys = ("name", "model", "density_t_per_mm3", "source")
        check_object_keys(data, "material", keys, keys[:3], SchemaError)
        density = data["density_t_per_mm3"]
        if isinstance(density, bool) or not isinstance(density, int | float):
            raise SchemaError(must_be("a number (tonne/mm³)", density), key="density_t_per_mm3")
        return cls(
            name=data["name"],
            model=_model_from_dict(data["model"]),
            density_t_per_mm3=density,
            source=data.get("source", ""),
        )


_PAPER_B = "Ye et al., Sens. Actuators A 368 (2024) 115095, §3.1"

#: Dragon Skin 30 silicone, Yeoh C10 = 0.11, C20 = 0.003, C30 = 0 MPa; 1.08 g/cm³.
DRAGON_SKIN_30 = Material(
    name="Dragon Skin 30",
    model=Yeoh(c10_mpa=_DS30["c10_mpa"], c20_mpa=_DS30["c20_mpa"], c30_mpa=_DS30["c30_mpa"]),
    density_t_per_mm3=_DS30["density_g_per_cm3"] * G_PER_CM3_TO_T_PER_MM3,
    source=f"{_PAPER_B}: Yeoh fit to uniaxial tension of Dragon Skin 30 (R² 0.9982).",
)

#: Fiberglass strain-limiting layer (0.1 mm), Yeoh C10 = 7.9 MPa; 2.40 g/cm³.
FIBERGLASS_LAYER = Material(
    name="Fiberglass strain-limiting layer",
    model=Yeoh(c10_mpa=_GLASS["c10_mpa"], c20_mpa=_GLASS["c20_mpa"], c30_mpa=_GLASS["c30_mpa"]),
    density_t_per_mm3=_GLASS["density_g_per_cm3"] * G_PER_CM3_TO_T_PER_MM3,
    source=f"{_PAPER_B}, after Polygerinos et al., IEEE Trans. Robot. 31 (2015) 778.",
)

#: Kevlar fiber, linear elastic E = 31076 MPa, ν = 0.36; 1.67 g/cm³.
KEVLAR_FIBER = Material(
    name="Kevlar fiber",
    model=LinearElastic(e_mpa=_KEVLAR["e_mpa"], nu=_KEVLAR["nu"]),
    density_t_per_mm3=_KEVLAR["density_g_per_cm3"] * G_PER_CM3_TO_T_PER_MM3,
    source=(
        f"{_PAPER_B}: 0.28 mm fiber modelled as beams of radius 0.07 mm "
        "(half the real radius, after Polygerinos et al. 2015)."
    ),
)

#: The presets by name; ``PRESETS.register("my-silicone", Material(...))`` adds one.
PRESETS: Registry[Material] = Registry("material preset")
PRESETS.register("dragon-skin-30", DRAGON_SKIN_30)
PRESETS.register("fiberglass", FIBERGLASS_LAYER)
PRESETS.register("kevlar", KEVLAR_FIBER)


def get_preset(name: str) -> Material:
    """Return the preset registered under ``name`` (``"dragon-skin-30"``, ...).

    Parameters
    ----------
    name : str
        A name of :data:`PRESETS`.

    Raises
    ------
    UnknownNameError
        Keyed ``name``, listing the known names.
    """
    with keyed("name"):
        return PRESETS.get(name)
