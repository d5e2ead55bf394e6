"""Frictionless penalty contact between two faces of a model: :class:`PenaltyContact`.

The faces that may touch are a *master* and a *minion* group of named boundary
faces. NGSolve's :class:`ngsolve.comp.ContactBoundary` pairs every integration
point of the master faces with the nearest point of the minion faces in the
deformed configuration (within ``maxdist_mm``), and the pairs carry the energy

    Π_c(u) = ∫_master ½ k ⟨d⟩₊² dA,    d = (x_master − x_minion)·n,

with ``x = X + u`` the deformed positions, ``n`` the master's outward unit
normal in the deformed configuration of the last pairing (``cof(F)·N``
normalised, held fixed until the pairs are found anew, so that between
pairings the energy is one smooth function of ``u``; a rigid rotation of both
faces leaves it unchanged) and ``d`` the interpenetration (positive where the
faces overlap, the signed gap is ``−d``); ``k`` is the penalty stiffness, MPa
per mm of interpenetration. The term is added to the bilinear form whose
energy Newton minimises, so the contact pressure ``k·d`` and its Hessian come
with the same automatic differentiation as the elastomer's. A pair counts as touching from ``d = 0``
on (the branch of ``⟨d⟩₊²`` taken at zero is the active one), so two faces
that start in contact are held together from the first solve.

The pairs are found anew by :meth:`PenaltyContact.update` (before every load
step), which also adds them to the form's sparsity pattern: a factorisation of
the Hessian taken before is then stale and the solver must start a new one.

Without friction and with a penalty, equilibrium holds exactly: the force the
pairs carry equals the load pressed through them (the patch test of
``tests/fem/test_contact.py``); the faces overlap by about
``contact pressure / k``, which ``tolerance_mm`` bounds.
"""

from __future__ import annotations

from typing import Any

import numpy as np

from softbend.errors import InputError
from softbend.fem._ngsolve import require_ngsolve

require_ngsolve()  # NGSolve after PyTorch, or one line naming softbend[fem]

__all__ = ["PenaltyContact"]


class PenaltyContact:
    """Penalty contact between the ``master`` and ``minion`` faces of ``fes``'s mesh.

    Parameters
    ----------
    fes : ngsolve.FESpace
        The 3D displacement space (``VectorH1``), mm.
    master, minion : str
        Boundary names (NGSolve region patterns, ``"a|b"``) of the two face groups.
    penalty_mpa_per_mm : float
        Penalty stiffness ``k``: contact pressure per mm of interpenetration, MPa/mm.
    maxdist_mm : float
        Pairs are sought up to this distance apart, mm (faces farther apart
        cannot touch within one load step).
    intorder : int
        Integration order on the master faces.

    Raises
    ------
    InputError
        A face group the mesh does not have, keyed by its name.
    """

    def __init__(
        self,
        fes: Any,
        master: str,
        minion: str,
        *,
        penalty_mpa_per_mm: float,
        maxdist_mm: float,
        intorder: int = 4,
    ) -> None:
        import ngsolve as ngs
        from ngsolve import CoefficientFunction as CF  # noqa: N817

        mesh = fes.mesh
        for key, name in (("master", master), ("minion", minion)):
            if not any(mesh.Boundaries(name).Mask()):
                raise InputError(
                    f"must name boundary faces of the mesh, one of "
                    f"{', '.join(sorted(set(mesh.GetBoundaries())))}; got {name!r}",
                    key=key,
                )
        self.fes = fes
        self.mesh = mesh
        self.master, self.minion = master, minion
        self.penalty = ngs.Parameter(float(penalty_mpa_per_mm))
        self.maxdist_mm = float(maxdist_mm)
        self.intorder = int(intorder)
        u = fes.TrialFunction()
        position = CF((ngs.x, ngs.y, ngs.z))
        # Two boundaries with the same energy: one adds it to the model's form,
        # the other (on the same pairs) to a form of the contact energy alone,
        # whose gradient is the contact forces.
        self.boundary, self._forces_boundary = (
            ngs.ContactBoundary(mesh.Boundaries(master), mesh.Boundaries(minion)) for _ in range(2)
        )
        # The master faces' normal in the configuration of the last pairing, a
        # field held fixed during a solve: the energy is then one smooth function
        # of u between pairings, with exact gradient and Hessian. (The contact
        # boundary's own ``normal`` follows the current state but is not
        # differentiated, so its Newton converged linearly, see the design log.)
        self._normal = ngs.GridFunction(fes)
        self._normal.Set(ngs.specialcf.normal(3), definedon=mesh.Boundaries(master))
        normal = self._normal / ngs.Norm(self._normal)
        for boundary in (self.boundary, self._forces_boundary):
            depth = (position + u - (position.Other() + u.Other())) * normal
            boundary.AddEnergy(ngs.IfPos(-depth, 0.0, 0.5 * self.penalty * depth * depth))
        self._forces_form = ngs.BilinearForm(fes, symmetric=True)
        self._forces: Any = None
        # A rigid translation of the master faces along x, y, z: the contact
        # forces' resultant on them is the gradient applied to these.
        self._translations: list[Any] = []
        for axis in range(3):
            field = ngs.GridFunction(fes)
            e = [0.0, 0.0, 0.0]
            e[axis] = 1.0
            field.Set(CF(tuple(e)), definedon=mesh.Boundaries(master))
            self._translations.append(field.vec.CreateVector())
            self._translations[-1].data = field.vec

    def update(self, gfu: Any, form: Any) -> None:
        """Pair the faces anew in the configuration ``gfu`` and add the pairs to ``form``.

        The master faces' normal is taken at ``gfu`` too and held until the next
        update. After it, a factorisation of ``form``'s Hessian taken before is stale.
        """
        import ngsolve as ngs

        # Nanson: the deformed normal is cof(F)·N (F = I + ∇u), normalised.
        deformed = ngs.Cof(ngs.Id(3) + ngs.Grad(gfu)) * ngs.specialcf.normal(3)
        self._normal.Set(deformed / ngs.Norm(deformed), definedon=self.mesh.Boundaries(self.master))
        self.boundary.Update(gfu, form, self.intorder, self.maxdist_mm, keep_pairs=True)
        self._forces_boundary.Update(gfu, self._forces_form, self.intorder, other=self.boundary)

    def force_n(self, gfu: Any) -> np.ndarray:
        """Resultant of the contact forces on the master faces (x, y, z), N, at ``gfu``.

        With the pairs of the last :meth:`update`.
        """
        if self._forces is None:
            self._forces = gfu.vec.CreateVector()
        self._forces_form.Apply(gfu.vec, self._forces)
        # Pressing the master inwards raises the energy: the force on it is −gradient.
        return -np.array([float(self._forces.InnerProduct(t)) for t in self._translations])

    def mean_depth_mm(self, gfu: Any, force_n: np.ndarray | None = None) -> float:
        """Mean interpenetration of the touching pairs, weighted by their pressure, mm.

        ``∫ k d² dA / ∫ k d dA = 2 Π_c / |F|`` (the contact force ``F`` of
        :meth:`force_n`, computed if not given; exact where the pairs' normals
        agree, as on two flat faces): the mean contact pressure is ``k`` times
        it. 0 where nothing touches.
        """
        force = self.force_n(gfu) if force_n is None else force_n
        magnitude = float(np.linalg.norm(force))
        if magnitude <= 0.0:
            return 0.0
        return 2.0 * self.energy_mj(gfu) / magnitude

    def energy_mj(self, gfu: Any) -> float:
        """The contact energy ``Π_c`` at ``gfu``, mJ (N·mm)."""
        return float(self._forces_form.Energy(gfu.vec))
