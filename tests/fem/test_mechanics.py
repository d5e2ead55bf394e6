import math

import numpy as np
import pytest

from softbend.errors import ConvergenceError
from softbend.fem import FEMOptions
from softbend.fem.actuator import ActuatorModel
from softbend.fem.newton import EnergySolver
from softbend.fem.sweep import Step, StepHistory
from softbend.materials import ArrudaBoyce, NeoHookean, Yeoh

from .conftest import REFERENCE


@pytest.mark.parametrize(
    "model", [NeoHookean(0.1), Yeoh(0.11, 0.003, 0.001), ArrudaBoyce(0.2, 3.0)]
)
def test_symbolic_energy_of_the_fem_matches_the_numpy_laws(model):
    """The energy the FEM assembles, an NGSolve expression of I1, is the material's law."""
    import ngsolve as ngs
    from netgen.occ import Box, OCCGeometry, Pnt

    mesh = ngs.Mesh(OCCGeometry(Box(Pnt(0, 0, 0), Pnt(1, 1, 1))).GenerateMesh(maxh=0.5))
    i1 = 3.0 + 2.0 * ngs.x  # I1 from 3 to 5 across the box
    w = model.energy(i1)
    for x in (0.0, 0.2, 1.0):
        value = w(mesh(x, 0.5, 0.5))
        assert value == pytest.approx(float(model.strain_energy(3.0 + 2.0 * x)), rel=1e-12)


@pytest.fixture(scope="module")
def model():
    return ActuatorModel(REFERENCE, FEMOptions(maxh_mm=6.0))


def test_cavity_volume_at_rest_is_the_half_disc_prism(model):
    exact = math.pi * 6.0**2 / 2.0 * 100.0
    assert model.cavity_volume_mm3() == pytest.approx(exact, rel=2e-3)


def test_rest_state_has_zero_energy_and_residual_without_load(model):
    model.set_state(np.zeros_like(model.state()))
    model.set_load(0.0, 0.0)
    assert model.form.Energy(model.gfu.vec) == pytest.approx(0.0, abs=1e-12)
    assert model.solver._norm(model.solver.residual()) == pytest.approx(0.0, abs=1e-10)
    assert model.measure().angle_deg == pytest.approx(0.0, abs=1e-9)


def test_rigid_translation_costs_no_strain_energy(model):
    import ngsolve as ngs

    model.set_load(0.0, 0.0)
    shifted = ngs.GridFunction(model.fes)
    shifted.Set(ngs.CoefficientFunction((0.3, 0.0, -0.2)))
    assert model.form.Energy(shifted.vec) == pytest.approx(0.0, abs=1e-9)


def test_weight_vector_is_the_whole_weight_as_a_dead_load(model):
    """A rigid lift by 1 mm does work −W against gravity; the energy counts it once."""
    import ngsolve as ngs

    lift = ngs.GridFunction(model.fes)
    lift.Set(ngs.CoefficientFunction((0.0, 0.0, 1.0)))
    work = float(model.weight_vector.InnerProduct(lift.vec))
    assert work == pytest.approx(-model._weight_n, rel=2e-3)
    model.set_state(lift.vec.FV().NumPy())
    model.set_load(0.0, 0.5)
    assert model.solver.energy() == pytest.approx(0.5 * model._weight_n, rel=2e-3)
    residual = model.solver.residual().FV().NumPy()
    np.testing.assert_allclose(residual, -0.5 * model.weight_vector.FV().NumPy(), atol=1e-9)
    model.set_state(np.zeros_like(model.state()))


def test_newton_failure_raises_with_residual_and_restores_the_state(model):
    model.set_state(np.zeros_like(model.state()))
    model.set_load(0.05, 1.0)
    solver = EnergySolver(model.form, model.gfu, model.fes.FreeDofs(), max_iterations=1)
    with pytest.raises(ConvergenceError) as info:
        solver.solve(model.force_scale_n(0.05), load=0.05, step=3)
    assert info.value.pressure_mpa == 0.05
    assert info.value.step == 3
    assert info.value.residual > 0
    assert "pressure_mpa=0.05" in str(info.value)
    assert not model.state().any()


def test_hermite_output_is_exact_for_a_cubic():
    def f(p):
        return 3 + 2 * p - 5 * p**2 + 7 * p**3

    def df(p):
        return 2 - 10 * p + 21 * p**2

    steps = [
        Step(p, np.array([f(p)] * 3), np.array([df(p)] * 3), 4) for p in (0.0, 0.013, 0.05, 0.08)
    ]
    history = StepHistory(steps=steps)
    grid = np.linspace(0.0, 0.08, 17)
    np.testing.assert_allclose(history.interpolate(grid)[:, 0], f(grid), rtol=1e-12)


def test_a_first_iteration_that_does_not_contract_gives_up_at_once(model):
    """A start far off the path (a failing load step) costs one iteration, not ten."""
    model.set_state(np.zeros_like(model.state()))
    model.set_load(0.3, 1.0)  # the whole way to 0.3 MPa from rest: far outside the basin
    strict = EnergySolver(model.form, model.gfu, model.fes.FreeDofs(), max_iterations=12)
    with pytest.raises(ConvergenceError):
        strict.solve(model.force_scale_n(0.3), load=0.3)
    assert strict.timings.iterations == 1
    assert not model.state().any()
    lenient = EnergySolver(
        model.form, model.gfu, model.fes.FreeDofs(), max_iterations=12, first_contraction=math.inf
    )
    with pytest.raises(ConvergenceError):
        lenient.solve(model.force_scale_n(0.3), load=0.3)
    assert lenient.timings.iterations > 1
    model.set_state(np.zeros_like(model.state()))
    model.set_load(0.0, 0.0)
