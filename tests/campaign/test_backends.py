"""The campaign's registry of bending models, the analytical model through it, fault injection."""

from __future__ import annotations

import numpy as np
import pytest

from softbend import analytical
from softbend.analytical import AnalyticalModel
from softbend.campaign import backends
from softbend.campaign.backends import (
    AnalyticalBackend,
    FaultInjectionBackend,
    available_backends,
    default_pressures_mpa,
    get_backend,
    register_backend,
)
from softbend.design import sfrba_design
from softbend.errors import ConvergenceError

DESIGN = sfrba_design(100, 6, 2, 2, 5, 8)


# ----------------------------------------------------------------------------- registry


def test_registry_names_the_allowed_backends():
    assert {"analytical", "fem", "fault-injection"} <= set(available_backends())
    assert backends.BACKENDS.names()[:3] == ("analytical", "fem", "fault-injection")
    with pytest.raises(
        ValueError,
        match=r"^backend: Unknown campaign backend 'abaqus'; known: analytical, fem, ",
    ):
        get_backend("abaqus")
    with pytest.raises(ValueError, match="options of backend 'analytical' are invalid"):
        get_backend("analytical", mesh_size=3)


def test_register_backend_plugs_in_a_model_and_refuses_silent_replacement():
    register_backend("analytical-stiff", lambda: AnalyticalModel(material="fiberglass"))
    try:
        assert get_backend("analytical-stiff").material.name.startswith("Fiberglass")
        assert "analytical-stiff" in available_backends()
        assert "analytical-stiff" in backends.public_backends()
    finally:
        backends.BACKENDS.unregister("analytical-stiff")
    assert "analytical-stiff" not in available_backends()
    with pytest.raises(ValueError, match="already registered"):
        register_backend("analytical", AnalyticalModel)
    assert AnalyticalBackend is AnalyticalModel  # the earlier name still works
    with pytest.raises(ValueError, match=r"^factory: must be callable"):
        register_backend("x", 3)
    with pytest.raises(ValueError, match="lower-case"):
        register_backend("My Model", AnalyticalModel)


def test_backend_for_run_builds_public_backends_with_what_the_command_line_gives():
    assert backends.public_backends()[:2] == ("analytical", "fem")
    assert isinstance(backends.backend_for_run("analytical", compiled=True), AnalyticalModel)
    with pytest.raises(
        ValueError, match=r"^backend: Unknown .*'fault-injection'.*; known: analytical"
    ):
        backends.backend_for_run("fault-injection")
    with pytest.raises(ValueError, match=r"^model: must be given with"):
        backends.backend_for_run("analytical", model="m.json")
    register_backend("from-file", lambda path: AnalyticalModel())
    try:
        assert isinstance(backends.backend_for_run("from-file", model="m.json"), AnalyticalModel)
        only = r"saved file \(backend (surrogate or )?from-file\), and only then"
        with pytest.raises(ValueError, match=only):
            backends.backend_for_run("from-file")
    finally:
        backends.BACKENDS.unregister("from-file")


# ----------------------------------------------------------------------------- analytical


def test_analytical_backend_matches_the_model_and_the_physics():
    grid = default_pressures_mpa(0.2, 0.02)
    result = get_backend("analytical").sweep(DESIGN, grid)
    assert result.converged.all() and len(result.pressure_mpa) == len(grid)
    np.testing.assert_array_equal(result.angle_deg, analytical.bending_angle_deg(DESIGN, grid))
    # No gravity: straight at 0 MPa with the tip at l + lc on the axis.
    assert result.angle_deg[0] == 0.0
    assert result.tip_x_mm[0] == pytest.approx(DESIGN.l_mm + DESIGN.lc_mm)
    assert result.tip_z_mm[0] == pytest.approx(0.0, abs=1e-12)
    # More pressure bends more; the tip moves towards the bending side.
    assert np.all(np.diff(result.angle_deg) > 0)
    assert np.all(np.diff(result.tip_z_mm[:5]) > 0)
    assert result.mesh_size is None and (result.newton_iterations == 0).all()
    assert result.wall_time_s > 0
    # A thicker top wall is stiffer: less bending at every pressure.
    thick = get_backend("analytical").sweep(sfrba_design(100, 6, 4, 2, 5, 8), grid)
    assert np.all(thick.angle_deg[1:] < result.angle_deg[1:])


def test_analytical_sweep_ends_where_the_model_stops_converging(soft_design):
    grid = default_pressures_mpa()
    result = get_backend("analytical").sweep(soft_design, grid)
    with pytest.warns(RuntimeWarning):
        full = analytical.bending_angle_deg(soft_design, grid)
    first_nan = int(np.flatnonzero(np.isnan(full))[0])
    assert len(result.pressure_mpa) == first_nan + 1 < len(grid)
    assert result.converged[:-1].all() and not result.converged[-1]
    assert np.isnan(result.angle_deg[-1])
    np.testing.assert_array_equal(result.angle_deg[:-1], full[:first_nan])
    assert result.max_pressure_mpa == grid[first_nan - 1]
    # The model's warning is kept with the result instead of being raised in a worker.
    assert "does not converge" in result.stats["warnings"][0]


def test_analytical_backend_options():
    assert get_backend("analytical", material="dragon-skin-30").material.name == "Dragon Skin 30"
    with pytest.raises(ValueError, match="Unknown material preset 'rubber'; known: dragon-skin"):
        get_backend("analytical", material="rubber")
    with pytest.raises(ValueError, match=r"^material: must be"):
        AnalyticalModel(material=3.0)
    with pytest.raises(ValueError, match=r"^max_angle_deg: must be a number in"):
        AnalyticalModel(max_angle_deg=0.0)
    limited = AnalyticalModel(max_angle_deg=90.0).sweep(DESIGN, default_pressures_mpa())
    assert not limited.converged[-1] and np.nanmax(limited.angle_deg) <= 90.0


# ----------------------------------------------------------------------------- fault injection


def test_fault_injection_fails_chosen_designs_and_delegates_the_rest():
    grid = default_pressures_mpa(0.1, 0.05)
    backend = get_backend("fault-injection", fail_design_ids=[DESIGN.design_id])
    assert isinstance(backend, FaultInjectionBackend)
    with pytest.raises(ConvergenceError, match="injected failure for design 100,6,2,2,5,8"):
        backend.sweep(DESIGN, grid)
    other = sfrba_design(120, 6, 2, 2, 5, 8)
    np.testing.assert_array_equal(
        backend.sweep(other, grid).angle_deg, AnalyticalModel().sweep(other, grid).angle_deg
    )
    with pytest.raises(ValueError, match=r"^delay_s: must be a number in"):
        get_backend("fault-injection", delay_s=-1)
    with pytest.raises(ValueError, match=r"^inner: must be another backend"):
        get_backend("fault-injection", inner="fault-injection")
