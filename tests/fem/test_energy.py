"""The energy terms: compiled once per process and shared by models of other designs."""

import numpy as np
import pytest

from softbend.design import sfrba_design
from softbend.fem import FEMModel, FEMOptions, energy, use_compiled
from softbend.fem.actuator import ActuatorModel

OPTIONS = FEMOptions(maxh_mm=6.0)
DESIGN_A = sfrba_design(100, 6, 2, 2, 5, 8)
DESIGN_B = sfrba_design(120, 8, 3, 2, 10, 12)  # other mesh, fiber angle and spacing


def _state(model, seed):
    rng = np.random.default_rng(seed)
    values = rng.normal(scale=0.02, size=len(model.state()))
    return np.where(model.solver.free_mask, values, 0.0)


def _evaluate(model, state, pressure):
    """Energy, residual and Hessian times a fixed vector at ``state`` and ``pressure``."""
    model.set_state(state)
    model.set_load(pressure, 1.0)
    solver = model.solver
    energy_value = solver.energy()
    residual = np.array(solver.residual().FV().NumPy(), copy=True)
    solver.factorize()
    probe = model.gfu.vec.CreateVector()
    probe.FV().NumPy()[:] = np.where(solver.free_mask, 1.0, 0.0)
    product = (solver.form.mat * probe).Evaluate()
    return energy_value, residual, np.array(product.FV().NumPy(), copy=True)


@pytest.fixture(scope="module")
def interpreted():
    use_compiled(False)
    return ActuatorModel(DESIGN_A, OPTIONS), ActuatorModel(DESIGN_B, OPTIONS)


@pytest.fixture(scope="module")
def compiled():
    if not energy.compiler_available():
        pytest.skip("no C++ compiler (ngscxx) to compile the energy with")
    use_compiled(True, wait=True)
    try:
        yield ActuatorModel(DESIGN_A, OPTIONS), ActuatorModel(DESIGN_B, OPTIONS)
    finally:
        use_compiled(False)


def test_interpreted_models_have_terms_of_their_own(interpreted):
    a, b = interpreted
    assert a.terms is not b.terms
    assert not a.terms.compiled


def test_compiled_models_share_one_set_of_terms(compiled):
    a, b = compiled
    assert a.terms is b.terms
    assert a.terms.compiled


@pytest.mark.parametrize("index", [0, 1])
def test_compiled_terms_evaluate_like_the_interpreted_ones(interpreted, compiled, index):
    """Same energy, residual and Hessian to round-off, for both designs."""
    slow, fast = interpreted[index], compiled[index]
    state = _state(slow, seed=index)
    expected = _evaluate(slow, state, 0.04)
    got = _evaluate(fast, state, 0.04)
    assert got[0] == pytest.approx(expected[0], rel=1e-11)
    for g, e in zip(got[1:], expected[1:], strict=True):
        np.testing.assert_allclose(g, e, rtol=1e-9, atol=1e-9 * np.abs(e).max())


def test_a_model_keeps_its_design_when_another_uses_the_shared_terms(compiled):
    """Model B's pressure, fiber angle and stiffness never leak into model A's energy."""
    a, b = compiled
    state_a = _state(a, seed=3)
    first = _evaluate(a, state_a, 0.03)
    _evaluate(b, _state(b, seed=4), 0.12)  # sets the shared parameters to B's values
    again = _evaluate(a, state_a, 0.03)
    assert again[0] == first[0]
    np.testing.assert_array_equal(again[1], first[1])
    np.testing.assert_array_equal(again[2], first[2])


def test_pressure_enters_through_the_bound_parameter(interpreted):
    """The pressure term is linear in p: dE/dp is the cavity term, −V (half model)."""
    a, _ = interpreted
    state = _state(a, seed=5)
    e1 = _evaluate(a, state, 0.01)[0]
    e2 = _evaluate(a, state, 0.03)[0]
    half_volume = a.cavity_volume_mm3() / 2.0
    assert (e2 - e1) / 0.02 == pytest.approx(-half_volume, rel=1e-9)


def test_fem_model_switches_compilation_for_its_process():
    from softbend.campaign import get_backend

    assert FEMModel(OPTIONS, compiled=True).compiled
    assert not FEMModel(OPTIONS).compiled
    assert get_backend("fem", compiled=True, maxh_mm=6.0).compiled
    assert not get_backend("fem").compiled


def test_another_thread_compiles_terms_of_its_own(compiled):
    """Threads do not share the parameters: a Dask worker may run two sweeps at once."""
    import threading

    a, _ = compiled
    seen = []
    worker = threading.Thread(target=lambda: seen.append(ActuatorModel(DESIGN_A, OPTIONS).terms))
    use_compiled(True, wait=False)
    try:
        worker.start()
        worker.join()
    finally:
        use_compiled(True, wait=True)
    assert seen and seen[0] is not a.terms
    assert seen[0].compiled
