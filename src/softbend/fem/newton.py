"""Newton's method on a potential energy, with a line search and honest failure.

:class:`EnergySolver` owns one NGSolve ``BilinearForm`` built from ``Variation``
terms (the total potential energy), the displacement ``GridFunction`` and the
free degrees of freedom, and optionally a load that does not depend on the
state (``−λ f·u``, a dead load such as gravity, assembled once and scaled by the
factor ``λ``: its Hessian is zero, so it is kept out of the differentiated
form). :meth:`EnergySolver.solve` minimises the energy from the current state:
exact Newton steps on the automatically differentiated Hessian,
factorised by sparse Cholesky (the symbolic factorisation is reused), with a
backtracking line search on the energy. Round-off makes energy differences
meaningless near convergence (the energy is ~1e4 times the last decreases), so
there a step is accepted when it lowers the residual instead.

While the residual is still far above the tolerance, each Newton step is
followed by one chord step with the same factorisation (a two-step Newton
method, Shamanskii's): after a full step, what is left of the residual is
mostly the second-order term along that step, which the same Hessian removes
for the price of a solve and two evaluations instead of an assembly and a
factorisation. The chord step is kept only when it at least halves the
residual without raising the energy. On the 64 corner sweeps of
``benchmarks/bench_fem.py`` it cut the Newton iterations from 6388 to 5628
(``benchmarks/reference/bench_fem_compiled.jsonl`` and ``bench_fem_chord.jsonl``).

Convergence is measured on the residual force: ``‖r‖₂ ≤ rtol·force_scale`` where
the caller states the force scale of the load (pressure resultant, weight). A
solve that does not converge raises :class:`~softbend.errors.ConvergenceError`
with the residual and the iteration; the state is then restored, so the caller
can cut the load step and retry. Time spent in assembly and factorisation is
accumulated in :attr:`EnergySolver.timings`.
"""

from __future__ import annotations

import logging
import math
import time
from collections.abc import Callable
from dataclasses import dataclass, field
from typing import TYPE_CHECKING, Any

import numpy as np

from softbend.errors import ConvergenceError

if TYPE_CHECKING:
    from ngsolve import BaseVector

__all__ = ["EnergySolver", "NewtonReport"]

logger = logging.getLogger(__name__)


@dataclass
class NewtonReport:
    """What one converged Newton solve did."""

    iterations: int
    residual: float
    line_search_cuts: int
    chord_steps: int = 0


@dataclass
class _Timings:
    assembly_s: float = 0.0
    factorization_s: float = 0.0
    residual_s: float = 0.0
    solve_s: float = 0.0
    iterations: int = 0
    factorizations: int = 0
    chord_steps: int = 0
    chord_rejected: int = 0

    def as_dict(self) -> dict[str, float]:
        return {k: float(v) for k, v in self.__dict__.items()}


@dataclass
class EnergySolver:
    """Newton minimiser of the energy ``form`` over ``gfu``'s free dofs.

    Parameters
    ----------
    form : ngsolve.BilinearForm
        Symmetric form made of ``Variation`` terms (the potential energy).
    gfu : ngsolve.GridFunction
        Displacement, mm; the solve starts from and updates it.
    freedofs : ngsolve.BitArray
        Degrees of freedom not fixed by Dirichlet conditions.
    rtol : float
        Relative residual tolerance.
    max_iterations : int
        Newton iterations per solve.
    load : ngsolve.BaseVector, optional
        Dead load ``f`` (N per dof), the gradient of a potential ``−f·u``.
    load_factor : ngsolve.Parameter, optional
        Its scale ``λ`` (read at every evaluation); 1 if not given.
    stall_iteration, stall_factor
        Early give-up rule (see the attributes).
    """

    form: Any
    gfu: Any
    freedofs: Any
    rtol: float = 1e-8
    max_iterations: int = 25
    load: Any = None
    load_factor: Any = None
    #: Give up early when, after this many iterations, the residual is still
    #: ``stall_factor`` times the tolerance (not yet in Newton's quadratic phase):
    #: a shorter load step is cheaper than a long crawl.
    stall_iteration: int = 6
    stall_factor: float = 1e4
    #: Give up earlier still when, after this many iterations, the residual has
    #: not even fallen below ``progress_factor`` times the residual after the
    #: first iteration: a start outside Newton's basin (the failed steps of a
    #: sweep look like this). The first iteration is the reference because it
    #: removes the large residual of the stiff fibers from any starting guess.
    progress_iteration: int = 3
    progress_factor: float = 0.3
    #: Give up after the first iteration when it has not cut the residual of the
    #: starting guess at least this much: a converging step of a sweep cuts it
    #: 100-fold or more (the predictor is close), a step that fails cuts it by
    #: less than half or raises it, and goes on failing for 5–10 costly
    #: iterations (``math.inf`` turns the rule off).
    first_contraction: float = 0.1
    #: After a Newton step that leaves the residual above ``chord_above`` times
    #: the tolerance, try one chord step with the same factorisation (kept when
    #: it cuts the residual to at most ``chord_accept`` times and does not raise
    #: the energy; ``math.inf`` turns chord steps off). Near the tolerance every
    #: step is a Newton step, so the last factorisation of a solve is taken
    #: close to the solution, where the sweep reuses it for the tangent ``du/dp``.
    chord_above: float = 1e3
    chord_accept: float = 0.5
    #: Called before every evaluation of ``form`` (energy, residual, Hessian):
    #: a model whose energy terms are shared with other models sets its own
    #: parameter values there.
    prepare: Callable[[], None] | None = None
    timings: _Timings = field(default_factory=_Timings)

    def __post_init__(self) -> None:
        vec = self.gfu.vec
        self._res = vec.CreateVector()
        self._du = vec.CreateVector()
        self._backup = vec.CreateVector()
        self._before_chord = vec.CreateVector()
        self._res_before_chord = vec.CreateVector()
        self._inverse = None
        self._mask = np.array(list(self.freedofs), dtype=bool)

    @property
    def free_mask(self) -> np.ndarray:
        """Boolean mask of the free degrees of freedom."""
        return self._mask

    @property
    def has_factorization(self) -> bool:
        """Whether a Hessian has been factorised yet."""
        return self._inverse is not None

    def forget_factorization(self) -> None:
        """Drop the factorised Hessian: the next :meth:`factorize` starts a new one.

        For a form whose sparsity changed (new contact pairs).
        """
        self._inverse = None

    def _prepare(self) -> None:
        if self.prepare is not None:
            self.prepare()

    # -- energy and its derivatives ---------------------------------------------------
    def _load_scale(self) -> float:
        return 1.0 if self.load_factor is None else float(self.load_factor.Get())

    def energy(self, vec: BaseVector | None = None) -> float:
        """Total potential energy at ``vec`` (default: the current state), mJ."""
        vec = self.gfu.vec if vec is None else vec
        self._prepare()
        value = float(self.form.Energy(vec))
        if self.load is not None:
            value -= self._load_scale() * float(self.load.InnerProduct(vec))
        return value

    def residual(self, out: BaseVector | None = None) -> BaseVector:
        """Gradient of the energy at the current state (N); fixed dofs are not masked."""
        out = self._res if out is None else out
        start = time.perf_counter()
        self._prepare()
        self.form.Apply(self.gfu.vec, out)
        if self.load is not None:
            out.data -= self._load_scale() * self.load
        self.timings.residual_s += time.perf_counter() - start
        return out

    def _norm(self, vec: BaseVector) -> float:
        values = vec.FV().NumPy()
        return float(math.sqrt(float((values[self._mask] ** 2).sum())))

    def factorize(self) -> Any:
        """Assemble the Hessian at the current state and factorise it."""
        start = time.perf_counter()
        self._prepare()
        self.form.AssembleLinearization(self.gfu.vec)
        middle = time.perf_counter()
        if self._inverse is None:
            self._inverse = self.form.mat.Inverse(self.freedofs, inverse="sparsecholesky")
        else:
            self._inverse.Update()
        end = time.perf_counter()
        self.timings.assembly_s += middle - start
        self.timings.factorization_s += end - middle
        self.timings.factorizations += 1
        return self._inverse

    def solve_tangent(self, rhs: BaseVector, out: BaseVector) -> BaseVector:
        """``out = K⁻¹ rhs`` with the last factorised Hessian."""
        start = time.perf_counter()
        out.data = self._inverse * rhs
        self.timings.solve_s += time.perf_counter() - start
        return out

    # -- Newton ----------------------------------------------------------------------
    def solve(self, force_scale: float, *, load: float | None = None, step: int | None = None):
        """Minimise the energy from the current state.

        Parameters
        ----------
        force_scale : float
            Size of the applied load, N; the solve converges when the residual
            norm drops below ``rtol·force_scale``.
        load, step : optional
            Pressure (MPa) and step index, only for error messages.

        Returns
        -------
        NewtonReport

        Raises
        ------
        ConvergenceError
            If the residual is not below tolerance after ``max_iterations``, or
            becomes non-finite, or no step along the Newton direction lowers the
            energy or the residual. The state is restored to where it started.
        """
        tolerance = self.rtol * max(force_scale, 1e-12)
        vec, du, res = self.gfu.vec, self._du, self._res
        self._backup.data = vec
        cuts = chords = 0
        residual = self._norm(self.residual())
        start_residual, after_first = residual, math.inf
        logger.debug("Newton start: residual %.3g N (tolerance %.3g N)", residual, tolerance)
        energy: float | None = None
        for iteration in range(self.max_iterations + 1):
            if iteration == 1:
                after_first = residual
            if not math.isfinite(residual):
                break
            if residual <= tolerance:
                self.timings.iterations += iteration
                return NewtonReport(iteration, residual, cuts, chords)
            if iteration == self.max_iterations:
                break
            if self._hopeless(iteration, residual, start_residual, after_first, tolerance):
                break
            self.factorize()
            self.solve_tangent(res, du)
            alpha, residual, n_cuts, energy = self._line_search(residual, energy)
            cuts += n_cuts
            logger.debug(
                "Newton iteration %d: step %.3g, residual %.3g N (tolerance %.3g N)",
                iteration + 1,
                alpha,
                residual,
                tolerance,
            )
            if alpha == 0.0:
                break
            if energy is not None and residual > self.chord_above * tolerance:
                chord = self._chord_step(residual, energy)
                if chord is not None:
                    chords += 1
                    residual, energy = chord
        self.timings.iterations += iteration
        vec.data = self._backup
        raise ConvergenceError(
            f"Newton did not converge in {iteration} iterations (tolerance {tolerance:.3g} N)",
            pressure_mpa=load,
            step=step,
            residual=residual,
        )

    def _chord_step(self, residual0: float, energy0: float) -> tuple[float, float] | None:
        """One full step ``u -= K⁻¹ r`` with the last factorisation, kept or undone.

        Kept when the residual falls to ``chord_accept·residual0`` or below and
        the energy does not rise beyond round-off: returns the new residual norm
        and energy. Otherwise state and residual vector are restored (without
        another evaluation) and None is returned.
        """
        vec, du, res = self.gfu.vec, self._du, self._res
        self._before_chord.data = vec
        self._res_before_chord.data = res
        self.solve_tangent(res, du)
        vec.data -= du
        energy = self.energy(vec)
        residual = self._norm(self.residual())
        roundoff = 1e-11 * max(abs(energy0), 1.0)
        if (
            math.isfinite(energy)
            and residual <= self.chord_accept * residual0
            and energy <= energy0 + roundoff
        ):
            self.timings.chord_steps += 1
            return residual, energy
        vec.data = self._before_chord
        res.data = self._res_before_chord
        self.timings.chord_rejected += 1
        return None

    def _hopeless(
        self,
        iteration: int,
        residual: float,
        start_residual: float,
        after_first: float,
        tolerance: float,
    ) -> bool:
        """The early give-up rules (see the attributes); never within ``stall_factor``·tol."""
        if residual <= self.stall_factor * tolerance:
            return False
        if iteration >= self.stall_iteration:
            return True
        if iteration == 1 and residual > self.first_contraction * start_residual:
            return True
        return (
            iteration == self.progress_iteration and residual > self.progress_factor * after_first
        )

    def _line_search(
        self, residual0: float, energy0: float | None = None
    ) -> tuple[float, float, int, float | None]:
        """Step ``u -= α du``; returns ``(α, residual norm, cuts, energy)`` (α = 0: failed).

        ``energy0``: the energy at the current state when already known (the
        previous line search ended there), saving one evaluation.
        """
        vec, du = self.gfu.vec, self._du
        if energy0 is None:
            energy0 = self.energy(vec)
        slope = -float(du.InnerProduct(self._res))  # d/dα E(u − α du) at α = 0
        alpha = 1.0
        for cuts in range(12):
            vec.data -= alpha * du
            energy = self.energy(vec)
            residual = self._norm(self.residual())
            roundoff = 1e-11 * max(abs(energy0), 1.0)
            if math.isfinite(energy) and math.isfinite(residual):
                if abs(energy - energy0) <= roundoff or slope >= 0.0:
                    # Energy differences drown in round-off (or the Hessian is not
                    # positive definite here): judge the step by the residual.
                    if residual < residual0:
                        return alpha, residual, cuts, energy
                elif energy <= energy0 + 1e-4 * alpha * slope:
                    return alpha, residual, cuts, energy
            vec.data += alpha * du
            alpha *= 0.5
        self.residual()
        return 0.0, residual0, 12, energy0
