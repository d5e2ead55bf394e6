"""The campaign's registry of bending models, by name.

The campaign runner sweeps any :class:`~softbend.models.BendingModel`; this
module maps the names a command line or a database uses to them
(:data:`BACKENDS`, a :class:`~softbend.registry.Registry` of factories)::

    backend = get_backend("analytical")      # softbend.analytical.AnalyticalModel
    backend = get_backend("fem", maxh_mm=4)  # softbend.fem.FEMModel
    result = backend.sweep(design, default_pressures_mpa())

One call adds a backend: ``register_backend("my-model", factory)``, where
``factory(**options)`` returns the model. A backend read from a saved file takes
its path as the option ``path``; :func:`backend_for_run` gives it the file of a
command line (``softbend campaign run --backend NAME --model FILE``), and a backend
that takes an elastomer (:func:`takes_material`: ``"fem"``, ``"analytical"``) its
``--material`` (:func:`resolve_material`, :func:`with_material`). A trained
surrogate is such a backend, ``"surrogate"``; it is registered from above the
campaign in the pipeline (surrogates sit above it), so that a campaign can also
run on a :class:`softbend.surrogates.SurrogateModel` passed as an object to
:func:`~softbend.campaign.run_campaign`.

The sweep result, the pressure grid and the protocol live in
:mod:`softbend.models` and are re-exported here.

Backends are sent to worker processes (pickled), so they must be plain picklable
objects and must not hold open resources; they are built once in the coordinating
process, which validates their options before any work starts.
"""

from __future__ import annotations

import dataclasses
import inspect
import logging
import os
import time
from collections.abc import Callable, Iterable, Mapping
from dataclasses import dataclass, field
from typing import TYPE_CHECKING, Any, NamedTuple, cast

import numpy as np

from softbend._validation import check_range, must_be, short_repr
from softbend.actuators import Design
from softbend.analytical import AnalyticalModel
from softbend.errors import ConvergenceError, InputError, SoftbendError, keyed
from softbend.materials.presets import Material
from softbend.models import (
    DEFAULT_PMAX_MPA,
    DEFAULT_PSTEP_MPA,
    BendingModel,
    SweepResult,
    check_pressures_mpa,
    default_pressures_mpa,
)
from softbend.registry import Registry

if TYPE_CHECKING:
    from softbend.fem.options import FEMOptions

__all__ = [
    "BACKENDS",
    "DEFAULT_PMAX_MPA",
    "DEFAULT_PSTEP_MPA",
    "INTERNAL_BACKENDS",
    "AnalyticalBackend",
    "Backend",
    "BendingModel",
    "FaultInjectionBackend",
    "MaterialGiven",
    "ResolvedMaterial",
    "SweepResult",
    "available_backends",
    "backend_for_run",
    "check_pressures_mpa",
    "default_pressures_mpa",
    "get_backend",
    "public_backends",
    "register_backend",
    "resolve_material",
    "takes_material",
    "with_material",
]

logger = logging.getLogger(__name__)

#: What the campaign runner needs from a model (the same protocol as every model's).
Backend = BendingModel

#: The analytical model under its earlier name.
AnalyticalBackend = AnalyticalModel


def _import_fem() -> Any:
    try:
        from softbend import fem
    except ImportError as exc:
        raise SoftbendError(
            "the FEM backend needs softbend.fem (not available in this installation)"
        ) from exc
    return fem


def _make_fem(
    options: FEMOptions | None = None,
    *,
    compiled: bool = False,
    material: MaterialGiven | None = None,
    **fem_options: object,
) -> BendingModel:
    fem = _import_fem()
    if material is not None:
        if "elastomer" in fem_options:
            raise InputError(
                f"must be given either as material or as elastomer, not both; got {material!r}",
                key="material",
            )
        if options is None:
            fem_options["elastomer"] = resolve_material(material).material
        else:
            options = options.replace(elastomer=resolve_material(material).material)
    if fem_options:
        if options is not None:
            raise InputError(
                "must be given either as options or as keywords, not both; got options and "
                f"{sorted(fem_options)}",
                key="options",
            )
        make_options = getattr(fem, "FEMOptions", None)
        if make_options is None:
            raise InputError(
                "must be given as options=<object>: this softbend.fem has no FEMOptions to "
                f"build them from keywords {sorted(fem_options)}",
                key="options",
            )
        options = make_options(**fem_options)
    return fem.FEMModel(options=options, compiled=compiled)


@dataclass(frozen=True)
class FaultInjectionBackend:
    """Diagnostic wrapper: another backend, slowed down and failing for chosen designs.

    It exercises the campaign machinery with a real model behind it: resuming
    after the coordinating process is killed (``delay_s`` leaves time to kill it
    mid-run), recording failed designs (``fail_design_ids``), surviving a worker
    process that dies (``crash_design_ids``, as a solver that segfaults) and
    checking that a Dask cluster's workers can import softbend. It is registered
    as ``"fault-injection"``; options: ``inner`` (backend name, default
    ``"analytical"``), ``inner_options`` (dict), ``delay_s``, ``fail_design_ids``,
    ``crash_design_ids``.

    Parameters
    ----------
    inner : Backend
        The backend that does the work.
    delay_s : float
        Sleep before each sweep, s, in [0, 3600].
    fail_design_ids : frozenset of str
        Designs (by :attr:`Design.design_id`) whose sweep raises
        :class:`~softbend.errors.ConvergenceError` instead of running.
    crash_design_ids : frozenset of str
        Designs whose sweep ends the process running it at once (``os._exit``),
        without cleanup. Only meaningful in worker processes: in a serial campaign
        it ends the coordinating process itself.
    """

    inner: Backend
    delay_s: float = 0.0
    fail_design_ids: frozenset[str] = frozenset()
    crash_design_ids: frozenset[str] = frozenset()
    name: str = field(default="fault-injection", init=False)

    def sweep(self, design: Design, pressures_mpa: np.ndarray) -> SweepResult:
        """Sleep ``delay_s``, then fail or delegate to the inner backend."""
        start = time.perf_counter()
        if self.delay_s:
            time.sleep(self.delay_s)
        if design.design_id in self.crash_design_ids:
            os._exit(70)
        if design.design_id in self.fail_design_ids:
            raise ConvergenceError(
                f"injected failure for design {design}", pressure_mpa=float(pressures_mpa[0])
            )
        result = self.inner.sweep(design, pressures_mpa)
        stats = {**result.stats, "inner_backend": self.inner.name, "delay_s": self.delay_s}
        return SweepResult(
            design=result.design,
            pressure_mpa=result.pressure_mpa,
            angle_deg=result.angle_deg,
            tip_x_mm=result.tip_x_mm,
            tip_z_mm=result.tip_z_mm,
            converged=result.converged,
            newton_iterations=result.newton_iterations,
            wall_time_s=time.perf_counter() - start,
            mesh_size=result.mesh_size,
            stats=stats,
        )


def _make_fault_injection(
    inner: str = "analytical",
    inner_options: Mapping[str, Any] | None = None,
    delay_s: float = 0.0,
    fail_design_ids: str | Iterable[object] = (),
    crash_design_ids: str | Iterable[object] = (),
) -> FaultInjectionBackend:
    if inner == "fault-injection":
        raise InputError(must_be("another backend", inner), key="inner")
    delay = check_range(
        delay_s,
        "delay_s",
        low=0.0,
        high=3600.0,
        low_inclusive=True,
        high_inclusive=True,
    )
    return FaultInjectionBackend(
        inner=get_backend(inner, **dict(inner_options or {})),
        delay_s=delay,
        fail_design_ids=_id_set(fail_design_ids),
        crash_design_ids=_id_set(crash_design_ids),
    )


def _id_set(ids: str | Iterable[object]) -> frozenset[str]:
    if isinstance(ids, str):
        ids = [ids]
    return frozenset(str(i) for i in ids)


#: Registered for tests and the library, not offered on the command line.
INTERNAL_BACKENDS: tuple[str, ...] = ("fault-injection",)

#: The backends by name: ``factory(**options) -> Backend``, in registration order.
BACKENDS: Registry[Callable[..., Backend]] = Registry("campaign backend")
BACKENDS.register("analytical", AnalyticalModel)
BACKENDS.register("fem", _make_fem)
BACKENDS.register("fault-injection", _make_fault_injection)


def register_backend(name: str, factory: Callable[..., Backend], *, replace: bool = False) -> None:
    """Make ``factory(**options)`` available as ``get_backend(name, **options)``.

    Parameters
    ----------
    name : str
        Registry name: lower case, no spaces (``"my-model"``).
    factory : callable
        Returns an object satisfying :class:`Backend`. It runs in the coordinating
        process; the backend it returns is pickled to the workers. A backend read
        from a saved file takes the file as the keyword ``path``.
    replace : bool
        Allow replacing an existing registration.

    Raises
    ------
    ValueError
        A factory that is not callable, a name that is not lower case without
        spaces, or a name already registered (without ``replace``).
    """
    if not callable(factory):
        raise InputError(must_be("callable", factory), key="factory")
    BACKENDS.register(name, factory, replace=replace)


def available_backends() -> tuple[str, ...]:
    """Names accepted by :func:`get_backend`."""
    return BACKENDS.names()


def public_backends() -> tuple[str, ...]:
    """Names a command line offers: every backend but the :data:`INTERNAL_BACKENDS`."""
    return tuple(name for name in BACKENDS if name not in INTERNAL_BACKENDS)


def get_backend(name: str, **options: object) -> Backend:
    """Build the backend registered as ``name`` with ``options``.

    Raises
    ------
    UnknownNameError
        For an unknown name (listing the registered ones).
    ValueError
        For an option the backend does not take.
    SoftbendError
        If the backend's implementation is not installed (``"fem"`` without
        ``softbend.fem``).
    """
    with keyed("backend"):
        factory = BACKENDS.get(name)
    try:
        inspect.signature(factory).bind(**options)
    except TypeError as exc:
        raise ValueError(f"The options of backend {name!r} are invalid: {exc}.") from None
    backend = factory(**options)
    if not isinstance(backend, Backend):
        raise SoftbendError(
            f"The factory of backend {name!r} returned {type(backend).__name__}, "
            "which has no 'name' and 'sweep'."
        )
    return backend


def backend_for_run(
    name: str,
    *,
    model: str | os.PathLike[str] | None = None,
    compiled: bool = False,
    material: MaterialGiven | None = None,
    maxh_mm: float | None = None,
) -> Backend:
    """The backend a command line names, built with what the command line gives it.

    Parameters
    ----------
    name : str
        One of :func:`public_backends`.
    model : path, optional
        The saved file of a backend read from one (its factory takes ``path``,
        e.g. ``"surrogate"``); required for such a backend, refused for others.
    compiled : bool, default False
        Passed to a backend whose factory takes it (``"fem"``: compile the energy).
    material : str, path, Material or ResolvedMaterial, optional
        The elastomer of a backend that takes one (:func:`takes_material`), as
        :func:`resolve_material` reads it; refused for others. Default: the
        backend's own (Dragon Skin 30).
    maxh_mm : float, optional
        Largest element size of the ``"fem"`` backend, mm (> 0); refused for others.
        Default: the FEM's own (:class:`~softbend.fem.FEMOptions`).

    Raises
    ------
    UnknownNameError
        Keyed ``backend``: a name that is not a public backend (the public ones listed).
    InputError
        Keyed ``model``: a file given to a backend that reads none, or none to
        one that does; keyed ``material``: a material given to a backend that
        takes none; keyed ``maxh_mm``: a mesh size of another backend than the
        FEM's, or one not above 0.
    UnknownNameError, SchemaError
        Keyed ``material``: neither a preset nor a readable ``fit.json``.
    """
    public = Registry[Callable[..., Backend]](BACKENDS.kind)
    for known in public_backends():
        public.register(known, BACKENDS.get(known))
    with keyed("backend"):
        takes = inspect.signature(public.get(name)).parameters
    if material is not None and "material" not in takes:
        raise _no_material(f"backend {name!r}")
    if ("path" in takes) != (model is not None):
        from_file = [n for n in public if "path" in inspect.signature(public.get(n)).parameters]
        shown = f"backend {' or '.join(from_file)}" if from_file else "none is registered"
        raise InputError(
            f"must be given with a backend read from a saved file ({shown}), and only "
            f"then; got backend {name!r} and model {short_repr(model)}",
            key="model",
        )
    options: dict[str, object] = {"path": model} if model is not None else {}
    if material is not None:
        options["material"] = resolve_material(material).material
    if "compiled" in takes:
        options["compiled"] = compiled
    if maxh_mm is not None:
        if name != "fem":
            raise InputError(
                f"is the mesh size of the 'fem' backend; got backend {name!r}, which has no mesh",
                key="maxh_mm",
            )
        if isinstance(maxh_mm, bool) or not (isinstance(maxh_mm, int | float) and maxh_mm > 0):
            raise InputError(must_be("a size > 0 mm", maxh_mm), key="maxh_mm")
        options["maxh_mm"] = float(maxh_mm)
    return get_backend(name, **options)


def takes_material(name: str) -> bool:
    """Whether the backend registered as ``name`` takes an elastomer (a ``material`` option)."""
    with keyed("backend"):
        return "material" in inspect.signature(BACKENDS.get(name)).parameters


def _no_material(given: str) -> InputError:
    takers = [n for n in public_backends() if takes_material(n)]
    return InputError(
        f"applies to a backend that takes a material ({', '.join(takers)}); got {given}",
        key="material",
    )


class ResolvedMaterial(NamedTuple):
    """A material read once, and what named it."""

    material: Material
    #: :func:`~softbend.materials.choice.material_spec_record` of a spec (the
    #: spec, and a fit's file and SHA-256); None for a Material object.
    given: dict[str, str] | None = None


#: What names a material: a preset name, ``fit.json[#model]``, or the material itself.
MaterialGiven = str | os.PathLike[str] | Material | ResolvedMaterial


def resolve_material(material: MaterialGiven) -> ResolvedMaterial:
    """The material ``material`` names, and what named it (None for a Material object).

    Parameters
    ----------
    material : str, path, Material or ResolvedMaterial
        A preset name, ``fit.json[#model]`` (as
        :func:`~softbend.materials.choice.material_from_spec`), a material, or
        one already resolved (returned as it is: a spec is read once).

    Returns
    -------
    ResolvedMaterial
        The material, and :func:`~softbend.materials.choice.material_spec_record`
        of a spec (the spec, and a fit's file and SHA-256).

    Raises
    ------
    InputError, UnknownNameError, SchemaError
        Keyed ``material``: not a spec of a material.
    """
    if isinstance(material, ResolvedMaterial):
        return material
    if isinstance(material, Material):
        return ResolvedMaterial(material)
    from softbend.materials.choice import material_from_spec, material_spec_record

    if not isinstance(material, str | os.PathLike):
        raise InputError(
            must_be("a preset name, the path of a fit.json or a Material", material),
            key="material",
        )
    with keyed("material"):
        return ResolvedMaterial(material_from_spec(material), material_spec_record(material))


def with_material(backend: Backend, material: Material) -> Backend:
    """``backend`` with ``material`` as its elastomer.

    The FEM's :class:`~softbend.fem.FEMOptions` get it as their ``elastomer``;
    a backend with a ``material`` field (the analytical model) as that; a
    wrapper (``"fault-injection"``) passes it to its inner backend. The result
    is a new object, picklable as the backend was.

    Raises
    ------
    InputError
        Keyed ``material``: a backend that takes no material.
    """
    from softbend.campaign.settings import fem_options_of

    options = fem_options_of(backend)
    target: Any = backend  # a dataclass, checked below
    names: set[str] = set()
    if dataclasses.is_dataclass(target) and not isinstance(target, type):
        names = {f.name for f in dataclasses.fields(target)}
    if options is not None and "options" in names:
        return cast(
            Backend, dataclasses.replace(target, options=options.replace(elastomer=material))
        )
    if "material" in names:
        return cast(Backend, dataclasses.replace(target, material=material))
    inner = getattr(backend, "inner", None)
    if "inner" in names and isinstance(inner, Backend):
        return cast(Backend, dataclasses.replace(target, inner=with_material(inner, material)))
    raise _no_material(f"backend {backend.name!r}")
