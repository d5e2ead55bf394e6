"""The finite-element model as a :class:`~softbend.models.BendingModel`."""

from __future__ import annotations

from dataclasses import dataclass, field

from numpy.typing import ArrayLike

from softbend.actuators import Design
from softbend.errors import InputError
from softbend.fem.energy import use_compiled
from softbend.fem.options import FEMOptions
from softbend.fem.sfrba.sweep import simulate
from softbend.models import SweepResult

__all__ = ["FEMModel"]


@dataclass(frozen=True)
class FEMModel:
    """The 3D nonlinear finite-element model (paper B §3.1): :func:`simulate` with fixed options.

    Parameters
    ----------
    options : FEMOptions, optional
        Mesh, materials, solver and stop rules; None for the defaults.
    compiled : bool, default False
        Compile the energy to machine code once per process and share it with
        every later design (:mod:`softbend.fem.energy`): about 30 CPU seconds
        of compilation in the background, then faster assembly
        (``benchmarks/bench_fem.py`` compares whole sweeps).
        Worth it for a process that sweeps many designs (a campaign worker); the
        results are the same to round-off.

    Examples
    --------
    >>> from softbend.fem import FEMModel
    >>> from softbend.models import default_pressures_mpa
    >>> result = FEMModel().sweep(design, default_pressures_mpa(0.2))  # doctest: +SKIP
    """

    options: FEMOptions | None = None
    compiled: bool = False
    name: str = field(default="fem", init=False)
    #: One design per task: an FEM sweep takes seconds to minutes, so batching hurts balance.
    preferred_chunk_size: int = field(default=1, init=False)

    def __post_init__(self) -> None:
        if self.options is not None and not isinstance(self.options, FEMOptions):
            raise InputError(
                f"must be FEMOptions or None; got {type(self.options).__name__}", key="options"
            )

    def sweep(self, design: Design, pressures_mpa: ArrayLike) -> SweepResult:
        """Run the load-stepping sweep of ``design`` over ``pressures_mpa`` (MPa)."""
        use_compiled(self.compiled)
        return simulate(design, pressures_mpa, self.options)
