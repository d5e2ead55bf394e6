"""The actuator's energy terms, optionally compiled to machine code once per process.

:func:`energy_terms` builds the integrands of the total potential energy of
the half actuator (elastomer, strain-limiting layer, the two fiber families,
the pressure's ``−p·V``) and the cavity's volume flux. The design enters them
only through four :class:`ngsolve.Parameter` values (pressure, ``cos φ``,
``sin φ``, the fibers' smeared stiffness), so one set of expressions serves
every design of a campaign.

That is what makes NGSolve's compiled coefficient functions pay
(``Compile(realcompile=True)``: the expression tree is written out as C++ and
built with the compiler NGSolve ships a wrapper for, ``ngscxx``). Compiled, the
elastomer's Hessian assembles 1.3–1.7 times faster, the fibers' about three times
and the residual about three times (``benchmarks/bench_fem_solver.py assembly``);
but each term takes 5–6 s to compile, more than it saves on one sweep of 10–20 s.
With :func:`use_compiled` on, the terms are compiled once per thread (the five
terms compile side by side, about 30 CPU seconds) and shared by every later
model of the same materials in that thread, whatever its mesh or design: a
campaign worker or a benchmark sweeping many designs pays once. A model binds
its own parameter values before every evaluation (:meth:`EnergyTerms.bind`), so
models alive at the same time do not disturb each other; models in other
threads (a Dask worker running several tasks at once) get terms of their own.
Where no compiler is found the terms are used as interpreted expressions, with a warning.
"""

from __future__ import annotations

import logging
import math
import os
import shutil
import sys
import threading
from dataclasses import dataclass
from typing import TYPE_CHECKING, Any

from softbend.fem._ngsolve import require_ngsolve
from softbend.fem.mechanics import fiber_energy, membrane_energy, solid_energy, volume_flux
from softbend.fem.options import FEMOptions

if TYPE_CHECKING:
    from ngsolve import FESpace

require_ngsolve()  # NGSolve after PyTorch, or one line naming softbend[fem]

__all__ = ["EnergyTerms", "compiler_available", "energy_terms", "use_compiled"]

logger = logging.getLogger(__name__)

_state = {"enabled": False, "wait": False, "warned": False}
#: Per thread (the parameters are shared state): compiled terms by the options
#: they depend on (materials, fiber law, element order).
_local = threading.local()


@dataclass
class EnergyTerms:
    """Integrands of the energy (per reference volume or area) and their parameters.

    Attributes
    ----------
    solid, layer, fiber, pressure_work : CoefficientFunction
        Elastomer (on ``dx``), layer membrane (on ``ds("bottom")``), both fiber
        families (on ``ds("outer|bottom")``) and ``p·w·n`` (on ``ds("cavity")``).
    flux : CoefficientFunction
        ``w·n``, the cavity's volume flux without the pressure.
    pressure, cos_phi, sin_phi, fiber_stiffness : ngsolve.Parameter
        The values a design and a load step set (MPa, –, –, N/mm).
    compiled : bool
        Whether the expressions are compiled to machine code.
    """

    solid: Any
    layer: Any
    fiber: Any
    pressure_work: Any
    flux: Any
    pressure: Any
    cos_phi: Any
    sin_phi: Any
    fiber_stiffness: Any
    compiled: bool

    def bind(self, pressure_mpa: float, phi_deg: float, stiffness_n_per_mm: float) -> None:
        """Set the parameters to one model's values (cheap: four scalar writes)."""
        phi = math.radians(phi_deg)
        self.pressure.Set(float(pressure_mpa))
        self.cos_phi.Set(math.cos(phi))
        self.sin_phi.Set(math.sin(phi))
        self.fiber_stiffness.Set(float(stiffness_n_per_mm))


def use_compiled(enabled: bool = True, *, wait: bool = False) -> None:
    """Compile the energy terms once per process from now on (or stop doing so).

    Worth it when the process sweeps many designs (a campaign worker, a
    benchmark); a single sweep is faster without (see the module docstring).
    With ``wait`` the first model waits for the machine code instead of
    starting with the interpreted terms.
    """
    _state["enabled"] = bool(enabled)
    _state["wait"] = bool(wait)


def compiler_available() -> bool:
    """Whether NGSolve's compiler wrapper ``ngscxx`` and a C++ compiler are on the path.

    The wrapper is installed beside the Python interpreter of the environment
    NGSolve lives in; that folder is put on ``PATH`` when it is not there.
    """
    here = os.path.dirname(sys.executable)
    path = os.environ.get("PATH", "")
    if shutil.which("ngscxx", path=path) is None and os.path.exists(os.path.join(here, "ngscxx")):
        os.environ["PATH"] = here + os.pathsep + path
    return shutil.which("ngscxx") is not None and shutil.which("c++") is not None


def energy_terms(fes: FESpace, options: FEMOptions) -> EnergyTerms:
    """The energy terms for a model on ``fes`` (a 3D ``VectorH1`` space).

    Interpreted terms of its own unless :func:`use_compiled` is on; then this
    thread's compiled terms for these materials, compiled on first use.
    """
    if not _state["enabled"]:
        return _build(fes, options, compile_code=False)
    if not compiler_available():
        if not _state["warned"]:
            logger.warning("no C++ compiler (ngscxx) found: the FEM energy is not compiled")
            _state["warned"] = True
        return _build(fes, options, compile_code=False)
    cache = _local.__dict__.setdefault("terms", {})
    key = _key(fes, options)
    if key not in cache:
        cache[key] = _build(fes, options, compile_code=True)
    return cache[key]


def _key(fes: FESpace, options: FEMOptions) -> str:
    import json

    parts = {
        "space": [type(fes).__name__, int(fes.globalorder)],
        "elastomer": options.elastomer.to_dict(),
        "layer": options.layer.to_dict(),
        "bulk_ratio": options.bulk_ratio,
        "layer_thickness_mm": options.layer_thickness_mm,
        "fiber_law": options.fiber_law,
    }
    return json.dumps(parts, sort_keys=True, default=str)


def _build(fes: FESpace, options: FEMOptions, *, compile_code: bool) -> EnergyTerms:
    import ngsolve as ngs
    from ngsolve import CoefficientFunction as CF  # noqa: N817
    from ngsolve import Cross, Grad, Id, Norm, specialcf

    o = options
    u = fes.TrialFunction()
    F = Id(3) + Grad(u)
    Fs = Id(3) + Grad(u).Trace()
    normal = specialcf.normal(3)
    mu0 = o.elastomer_model.initial_shear_modulus_mpa
    pressure, cos_phi, sin_phi = ngs.Parameter(0.0), ngs.Parameter(1.0), ngs.Parameter(0.0)
    stiffness = ngs.Parameter(0.0)

    solid = solid_energy(F, o.elastomer_model, o.bulk_ratio * mu0)
    ex, ey = CF((1.0, 0.0, 0.0)), CF((0.0, 1.0, 0.0))
    layer = membrane_energy(Fs, (ex, ey), o.layer_model, o.layer_thickness_mm)
    circumferential = Cross(normal, ex)
    circumferential = circumferential / Norm(circumferential)
    fiber = 0.0
    for sign in (1.0, -1.0):
        direction = cos_phi * circumferential + sign * sin_phi * ex
        fiber = fiber + fiber_energy(Fs, direction, stiffness, o.fiber_law)
    position = CF((ngs.x, ngs.y, ngs.z)) + u.Trace()
    flux = volume_flux(position, Fs, normal, axes=(0, 2))  # = −(cavity volume) density
    pressure_work = pressure * flux

    terms = [solid, layer, fiber, pressure_work, flux]
    if compile_code:
        # Without waiting: the compilers run in the background, side by side,
        # and each term is evaluated as an interpreted expression until its
        # machine code is loaded.
        # (With ``wait`` the last call waits for the others and its own.)
        last = len(terms) - 1
        terms = [
            term.Compile(realcompile=True, wait=_state["wait"] and k == last)
            for k, term in enumerate(terms)
        ]
        logger.info(
            "FEM energy terms compiling to machine code (%s)",
            "waited for" if _state["wait"] else "in the background",
        )
    else:
        terms = [term.Compile() for term in terms]
    solid, layer, fiber, pressure_work, flux = terms
    return EnergyTerms(
        solid,
        layer,
        fiber,
        pressure_work,
        flux,
        pressure,
        cos_phi,
        sin_phi,
        stiffness,
        compiled=compile_code,
    )
