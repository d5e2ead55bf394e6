"""The Newton energy minimiser on small problems with known answers."""

from __future__ import annotations

import math

import numpy as np
import pytest

from softbend.errors import ConvergenceError
from softbend.fem.newton import EnergySolver

ngsolve = pytest.importorskip("ngsolve")


def _problem(nonlinear: bool, order: int = 2):
    """min ∫ ½|∇u|² (+ ¼u⁴) − f·u on the unit square, u = 0 on the boundary."""
    from netgen.geom2d import unit_square

    mesh = ngsolve.Mesh(unit_square.GenerateMesh(maxh=0.25))
    space = ngsolve.H1(mesh, order=order, dirichlet=".*")
    u = space.TrialFunction()
    energy = 0.5 * ngsolve.InnerProduct(ngsolve.grad(u), ngsolve.grad(u))
    if nonlinear:
        energy = energy + 0.25 * u**4
    form = ngsolve.BilinearForm(space, symmetric=True)
    form += ngsolve.Variation(energy * ngsolve.dx)
    rhs = ngsolve.LinearForm(space)
    rhs += 50.0 * space.TestFunction() * ngsolve.dx
    rhs.Assemble()
    gfu = ngsolve.GridFunction(space)
    return form, gfu, space.FreeDofs(), rhs.vec


def _direct_linear_solution(space_vec, form, freedofs, load):
    form.AssembleLinearization(space_vec)  # at u = 0: the stiffness matrix
    return (form.mat.Inverse(freedofs, inverse="sparsecholesky") * load).Evaluate()


def test_a_quadratic_energy_converges_in_one_iteration_to_the_linear_solution():
    form, gfu, freedofs, load = _problem(nonlinear=False)
    solver = EnergySolver(form, gfu, freedofs, load=load)
    report = solver.solve(force_scale=float(load.Norm()))
    assert report.iterations == 1 and report.line_search_cuts == 0
    expected = _direct_linear_solution(gfu.vec.CreateVector(), form, freedofs, load)
    np.testing.assert_allclose(gfu.vec.FV().NumPy(), expected.FV().NumPy(), rtol=1e-10)
    assert solver.timings.factorizations == 1


def test_a_nonlinear_energy_converges_quadratically_and_stops_at_a_minimum():
    form, gfu, freedofs, load = _problem(nonlinear=True)
    solver = EnergySolver(form, gfu, freedofs, load=load, rtol=1e-12)
    # From u = 0 the first iteration cuts the residual less than tenfold: the
    # give-up rule meant for a sweep's predicted starts would stop it.
    solver.first_contraction = math.inf
    residuals = []
    original = solver._norm
    solver._norm = lambda vec: residuals.append(original(vec)) or residuals[-1]
    report = solver.solve(force_scale=float(load.Norm()))
    assert 2 <= report.iterations <= 8
    # Quadratic convergence: each full step at least squares the relative residual.
    relative = [r / residuals[0] for r in residuals[-3:]]
    assert relative[2] < 10 * relative[1] ** 2 or relative[2] < 1e-14
    # At the minimum the gradient vanishes and any small perturbation raises the energy.
    assert report.residual <= 1e-12 * float(load.Norm())
    minimum = solver.energy()
    rng = np.random.default_rng(0)
    mask = solver.free_mask
    for _ in range(3):
        kick = gfu.vec.CreateVector()
        kick.FV().NumPy()[:] = 1e-3 * rng.standard_normal(len(mask)) * mask
        trial = gfu.vec.CreateVector()
        trial.data = gfu.vec + kick
        assert solver.energy(trial) > minimum


def test_a_hopeless_first_iteration_gives_up_and_restores_the_start():
    form, gfu, freedofs, load = _problem(nonlinear=True)
    solver = EnergySolver(form, gfu, freedofs, load=load, rtol=1e-12)
    solver.first_contraction = 1e-30  # no first iteration cuts the residual that much
    start = gfu.vec.FV().NumPy().copy()
    with pytest.raises(ConvergenceError, match="did not converge in 1 iterations"):
        solver.solve(force_scale=float(load.Norm()), load=0.1, step=3)
    np.testing.assert_array_equal(gfu.vec.FV().NumPy(), start)
    solver.first_contraction = math.inf  # the rule off: the same solve converges
    assert solver.solve(force_scale=float(load.Norm())).iterations >= 2


def test_too_few_iterations_is_a_convergence_error_with_the_residual():
    form, gfu, freedofs, load = _problem(nonlinear=True)
    solver = EnergySolver(form, gfu, freedofs, load=load, rtol=1e-14, max_iterations=1)
    with pytest.raises(ConvergenceError) as caught:
        solver.solve(force_scale=float(load.Norm()))
    assert caught.value.residual > 0.0


def _solve(chord_above: float, chord_accept: float = 0.5):
    form, gfu, freedofs, load = _problem(nonlinear=True)
    solver = EnergySolver(form, gfu, freedofs, load=load, rtol=1e-12)
    solver.first_contraction = math.inf
    solver.chord_above, solver.chord_accept = chord_above, chord_accept
    report = solver.solve(force_scale=float(load.Norm()))
    return report, solver, gfu.vec.FV().NumPy().copy()


def test_chord_steps_reach_the_same_minimum_with_fewer_factorizations():
    plain_report, plain, plain_u = _solve(chord_above=math.inf)
    report, solver, u = _solve(chord_above=1e3)
    assert plain_report.chord_steps == 0 and plain.timings.chord_steps == 0
    assert report.chord_steps >= 1 and solver.timings.chord_steps == report.chord_steps
    assert solver.timings.factorizations < plain.timings.factorizations
    assert report.residual <= 1e-12 * float(solver.load.Norm())
    np.testing.assert_allclose(u, plain_u, rtol=0, atol=1e-9 * np.abs(plain_u).max())


def test_a_rejected_chord_step_is_undone_exactly():
    # No chord step can cut the residual to zero: every one is tried and undone,
    # and the solve is Newton's (to round-off: two plain solves differ by 1e-15).
    _, plain, plain_u = _solve(chord_above=math.inf)
    report, solver, u = _solve(chord_above=0.0, chord_accept=0.0)
    assert report.chord_steps == 0 and solver.timings.chord_rejected >= 1
    assert solver.timings.factorizations == plain.timings.factorizations
    np.testing.assert_allclose(u, plain_u, rtol=0, atol=1e-12 * np.abs(plain_u).max())
