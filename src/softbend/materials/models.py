"""Incompressible isotropic hyperelastic models written in the first invariant.

Every model here has a strain energy density that depends on the first invariant
``I1 = λ1² + λ2² + λ3²`` of the right Cauchy–Green tensor only (``λ1 λ2 λ3 = 1``),
so the whole constitutive response follows from ``∂W/∂I1``. For a stretch state
with principal stretches ``λi`` the Cauchy stress differences are
``σi − σj = 2(λi² − λj²)·∂W/∂I1``.

Models (paper B §3.1 compares the three on Dragon Skin 30 and keeps Yeoh):

* :class:`NeoHookean` — ``W = C10 (I1 − 3)``.
* :class:`Yeoh` — ``W = Σ_{i=1}^{3} Ci0 (I1 − 3)^i``.
* :class:`ArrudaBoyce` — the five-term series of ABAQUS (Theory Manual §4.6.1),
  ``W = μ Σ_{i=1}^{5} Ci / λm^(2i−2) · (I1^i − 3^i)`` with
  ``C1..C5 = 1/2, 1/20, 11/1050, 19/7000, 519/673750``.

Units: stresses, moduli and strain energy density in MPa (= N/mm² = mJ/mm³).
The volumetric part is omitted: these are the isochoric laws of a material that is
treated as exactly incompressible.
"""

from __future__ import annotations

import math
import numbers
from collections.abc import Iterable, Mapping
from dataclasses import MISSING, Field, dataclass, fields
from typing import TYPE_CHECKING, Any, ClassVar

import numpy as np
from numpy.typing import ArrayLike

from softbend._validation import (
    check_choice,
    check_finite_array,
    check_object_keys,
    check_range,
    must_be,
)
from softbend.errors import InputError, SchemaError, keyed
from softbend.plausibility import RANGES, implausible_index
from softbend.registry import Registry

__all__ = [
    "MODELS",
    "ArrudaBoyce",
    "HyperelasticModel",
    "NeoHookean",
    "Yeoh",
    "check_constants",
    "get_model_class",
    "model_from_dict",
]


def check_constants(
    data: object, allowed: Iterable[str], required: Iterable[str]
) -> dict[str, float]:
    """The constants of a stored material model, checked before the model is built.

    ``data`` must be a mapping whose keys are among ``allowed`` (and ``"model"``,
    which is dropped) and include ``required``
    (:func:`softbend._validation.check_object_keys`, naming the object by its
    ``"model"``); every value must be a finite real number (not a bool or a
    string), and a constant in MPa (a key ending in ``_mpa``) must lie in the
    plausible range of material constants (``modulus_mpa`` of
    :mod:`softbend.plausibility`).

    Raises
    ------
    SchemaError
        Keyed by the constant at fault: what is allowed and the value received.
    """
    where = str(data.get("model") or "constants") if isinstance(data, Mapping) else "constants"
    checked = check_object_keys(data, where, ["model", *allowed], list(required), SchemaError)
    params = {k: v for k, v in checked.items() if k != "model"}
    limits = RANGES["modulus_mpa"]
    for key, value in params.items():
        real = isinstance(value, numbers.Real) and not isinstance(value, bool | np.bool_)
        if not real or not math.isfinite(value):
            raise SchemaError(must_be("a finite number", value), key=key)
        if key.endswith("_mpa") and implausible_index([value], "modulus_mpa") is not None:
            raise SchemaError(
                must_be(
                    f"a plausible {limits.label} ({limits.low:g} to {limits.high:g} {limits.unit})",
                    value,
                ),
                key=key,
            )
    return {k: float(v) for k, v in params.items()}


def _positive_stretch(stretch: ArrayLike) -> np.ndarray:
    """Stretch as a float array; finite and strictly positive, else an error keyed ``stretch``."""
    values = check_finite_array(stretch, "stretch")
    bad = values <= 0.0
    if bad.any():
        first = int(np.flatnonzero(bad.ravel())[0])
        raise InputError(
            f"must be in (0, inf); got {float(values.ravel()[first])!r} at position {first}",
            key="stretch",
        )
    return values


class HyperelasticModel:
    """Shared behaviour of the incompressible ``W(I1)`` models.

    Subclasses are frozen dataclasses that define :attr:`name`, :meth:`strain_energy`,
    :meth:`dW_dI1` and :attr:`initial_shear_modulus_mpa`.
    """

    #: Registry name of the model ("neo-hookean", "yeoh", "arruda-boyce").
    name: ClassVar[str] = ""

    if TYPE_CHECKING:
        # Every concrete model is a dataclass, so dataclasses.fields accepts it.
        __dataclass_fields__: ClassVar[dict[str, Field[Any]]]

    def energy(self, I1: Any) -> Any:  # pragma: no cover - abstract
        """``W(I1)`` in MPa for any number-like ``I1``: a float, an array or a
        symbolic expression (the FEM passes NGSolve coefficient functions)."""
        raise NotImplementedError

    def strain_energy(self, I1: ArrayLike) -> np.ndarray:
        """Strain energy density ``W(I1)`` in MPa; ``I1`` dimensionless."""
        return self.energy(np.asarray(I1, dtype=float))

    def dW_dI1(self, I1: ArrayLike) -> np.ndarray:  # noqa: N802  # pragma: no cover
        """Derivative ``∂W/∂I1`` in MPa."""
        raise NotImplementedError

    @property
    def initial_shear_modulus_mpa(self) -> float:
        """Small-strain shear modulus ``μ0 = 2·∂W/∂I1`` at ``I1 = 3``, MPa."""
        return float(2.0 * self.dW_dI1(3.0))

    def uniaxial_nominal_stress_mpa(self, stretch: ArrayLike) -> np.ndarray:
        """Nominal (first Piola–Kirchhoff) stress of incompressible uniaxial tension.

        With stretch ``λ`` along the load and ``λ^(-1/2)`` across it,
        ``I1 = λ² + 2/λ`` and ``P = 2(λ − λ⁻²)·∂W/∂I1`` (force per undeformed area).

        Parameters
        ----------
        stretch : array_like
            Axial stretch ``λ`` (deformed / undeformed length), > 0; ``λ < 1`` is
            uniaxial compression.

        Returns
        -------
        numpy.ndarray
            Nominal stress in MPa, same shape as ``stretch``.
        """
        lam = _positive_stretch(stretch)
        I1 = lam**2 + 2.0 / lam
        return 2.0 * (lam - lam**-2) * self.dW_dI1(I1)

    def to_dict(self) -> dict[str, Any]:
        """Parameters as a JSON-friendly mapping, with the registry name under ``"model"``."""
        return {"model": self.name, **{f.name: getattr(self, f.name) for f in fields(self)}}

    @classmethod
    def from_dict(cls, data: object) -> HyperelasticModel:
        """Rebuild a model written by :meth:`to_dict` (any value is checked first).

        Called on :class:`HyperelasticModel` itself it dispatches on ``data["model"]``
        (a name of :data:`MODELS`); called on a concrete class, a ``"model"``
        entry, if present, must match it.

        Raises
        ------
        UnknownNameError
            An unknown or missing ``"model"`` (the message lists the known names).
        SchemaError
            ``data`` is not a mapping, has an unknown or lacks a required key, or
            a constant is not a finite number or (in MPa) outside the plausible
            range of material constants; see :func:`check_constants`.
        """
        if not isinstance(data, Mapping):
            raise SchemaError(must_be("a mapping of constants", data), key="data")
        name = data.get("model")
        if cls is HyperelasticModel:
            return get_model_class(name).from_dict(data)
        if name is not None:
            check_choice(name, "model", (cls.name,))
        params = check_constants(
            data,
            [f.name for f in fields(cls)],
            [f.name for f in fields(cls) if f.default is MISSING],
        )
        return cls(**params)


@dataclass(frozen=True)
class NeoHookean(HyperelasticModel):
    """Incompressible neo-Hookean solid, ``W = C10 (I1 − 3)``.

    Parameters
    ----------
    c10_mpa : float
        Material constant ``C10`` in MPa, > 0; the shear modulus is ``μ = 2 C10``.
    """

    name: ClassVar[str] = "neo-hookean"

    c10_mpa: float

    def __post_init__(self) -> None:
        value = check_range(self.c10_mpa, "c10_mpa", low=0.0)
        object.__setattr__(self, "c10_mpa", value)

    def energy(self, I1: Any) -> Any:
        """``C10 (I1 − 3)`` in MPa (see :meth:`HyperelasticModel.energy`)."""
        return self.c10_mpa * (I1 - 3.0)

    def dW_dI1(self, I1: ArrayLike) -> np.ndarray:  # noqa: N802
        """``∂W/∂I1 = C10`` in MPa, broadcast to the shape of ``I1``."""
        return np.full_like(np.asarray(I1, dtype=float), self.c10_mpa)


@dataclass(frozen=True)
class Yeoh(HyperelasticModel):
    """Incompressible three-term Yeoh solid, ``W = Σ_{i=1}^{3} Ci0 (I1 − 3)^i``.

    Parameters
    ----------
    c10_mpa : float
        ``C10`` in MPa, > 0 (the small-strain shear modulus is ``2 C10``).
    c20_mpa, c30_mpa : float
        ``C20`` and ``C30`` in MPa, any finite sign. A negative ``C20`` softens the
        material at moderate strain and can make it unstable at large strain; the
        model is always stable at small strain because ``C10 > 0``.
    """

    name: ClassVar[str] = "yeoh"

    c10_mpa: float
    c20_mpa: float = 0.0
    c30_mpa: float = 0.0

    def __post_init__(self) -> None:
        object.__setattr__(self, "c10_mpa", check_range(self.c10_mpa, "c10_mpa", low=0.0))
        for field_name in ("c20_mpa", "c30_mpa"):
            value = check_range(getattr(self, field_name), field_name)
            object.__setattr__(self, field_name, value)

    def energy(self, I1: Any) -> Any:
        """``Σ Ci0 (I1 − 3)^i`` in MPa (see :meth:`HyperelasticModel.energy`).

        Terms whose constant is zero are left out of the expression (the value is
        the same): on a symbolic ``I1`` each term costs automatic differentiation.
        """
        d = I1 - 3.0
        if self.c30_mpa != 0.0:
            return d * (self.c10_mpa + d * (self.c20_mpa + d * self.c30_mpa))
        if self.c20_mpa != 0.0:
            return d * (self.c10_mpa + d * self.c20_mpa)
        return self.c10_mpa * d

    def dW_dI1(self, I1: ArrayLike) -> np.ndarray:  # noqa: N802
        """``∂W/∂I1 = C10 + 2 C20 (I1 − 3) + 3 C30 (I1 − 3)²`` in MPa."""
        d = np.asarray(I1, dtype=float) - 3.0
        return self.c10_mpa + d * (2.0 * self.c20_mpa + 3.0 * self.c30_mpa * d)


#: Coefficients C1..C5 of the Arruda–Boyce series (inverse Langevin expansion).
_AB_COEFFS: tuple[float, ...] = (1 / 2, 1 / 20, 11 / 1050, 19 / 7000, 519 / 673750)


@dataclass(frozen=True)
class ArrudaBoyce(HyperelasticModel):
    """Incompressible Arruda–Boyce (eight-chain) solid, five-term series as in ABAQUS.

    ``W = μ Σ_{i=1}^{5} Ci / λm^(2i−2) · (I1^i − 3^i)`` with
    ``C1..C5 = 1/2, 1/20, 11/1050, 19/7000, 519/673750`` (the first five terms of the
    series expansion of the inverse Langevin function). As in ABAQUS, ``μ`` is a
    parameter; the initial shear modulus is
    ``μ0 = μ (1 + 3/(5λm²) + 99/(175λm⁴) + 513/(875λm⁶) + 42039/(67375λm⁸))``,
    and the model tends to neo-Hookean with ``C10 = μ/2`` as ``λm → ∞``.

    Parameters
    ----------
    mu_mpa : float
        The modulus parameter ``μ`` in MPa, > 0.
    lambda_m : float
        Locking stretch of the chains, dimensionless, > 1.
    """

    name: ClassVar[str] = "arruda-boyce"

    mu_mpa: float
    lambda_m: float

    def __post_init__(self) -> None:
        object.__setattr__(self, "mu_mpa", check_range(self.mu_mpa, "mu_mpa", low=0.0))
        object.__setattr__(self, "lambda_m", check_range(self.lambda_m, "lambda_m", low=1.0))

    def _scaled_coeffs(self) -> list[float]:
        return [c / self.lambda_m ** (2 * i) for i, c in enumerate(_AB_COEFFS)]

    def energy(self, I1: Any) -> Any:
        """``μ Σ Ci/λm^(2i−2) (I1^i − 3^i)`` in MPa (see :meth:`HyperelasticModel.energy`)."""
        total = 0.0
        for i, c in enumerate(self._scaled_coeffs(), start=1):
            total = total + c * (I1**i - 3.0**i)
        return self.mu_mpa * total

    def dW_dI1(self, I1: ArrayLike) -> np.ndarray:  # noqa: N802
        """``∂W/∂I1 = μ Σ i·Ci/λm^(2i−2)·I1^(i−1)`` in MPa."""
        x = np.asarray(I1, dtype=float)
        total = np.zeros_like(x)
        for i, c in enumerate(self._scaled_coeffs(), start=1):
            total = total + i * c * x ** (i - 1)
        return self.mu_mpa * total


#: The hyperelastic models by name (each class's ``name``); ``MODELS.register(cls.name, cls)``
#: adds one (:mod:`softbend.materials.fit` fits the models it has a problem for).
MODELS: Registry[type[HyperelasticModel]] = Registry("material model")
for _model in (NeoHookean, Yeoh, ArrudaBoyce):
    MODELS.register(_model.name, _model)
del _model


def get_model_class(name: str | None) -> type[HyperelasticModel]:
    """Return the model class registered under ``name`` (``"neo-hookean"``, ``"yeoh"``, ...).

    Raises
    ------
    UnknownNameError
        If ``name`` is not a name of :data:`MODELS` (the message lists them).
    """
    with keyed("model"):
        return MODELS.get(name)


def model_from_dict(data: Mapping[str, Any]) -> HyperelasticModel:
    """Rebuild any registered model from the mapping written by its ``to_dict``."""
    return HyperelasticModel.from_dict(data)
