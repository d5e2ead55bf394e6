"""Sweep backends: the result container, the registry and the analytical backend."""

from __future__ import annotations

import pickle

import numpy as np
import pytest

from softbend import analytical
from softbend.campaign import backends
from softbend.campaign.backends import (
    AnalyticalBackend,
    FaultInjectionBackend,
    SweepResult,
    available_backends,
    check_pressures_mpa,
    default_pressures_mpa,
    get_backend,
    register_backend,
)
from softbend.design import SFRBADesign
from softbend.errors import ConvergenceError

DESIGN = SFRBADesign(100, 6, 2, 2, 5, 8)


# ----------------------------------------------------------------------------- pressure grid


def test_default_grid_is_paper_b_grid_on_exact_decimal_steps():
    grid = default_pressures_mpa()
    assert len(grid) == 101
    assert grid[0] == 0.0 and grid[-1] == 0.5
    # Each value is the double nearest to the decimal grid value (no accumulated drift).
    assert all(grid[i] == float(f"{i * 5 / 1000:.3f}") for i in range(101))
    assert grid[3] == 0.015
    np.testing.assert_allclose(np.diff(grid), 0.005, rtol=1e-12)


def test_custom_grid_and_bad_grids():
    np.testing.assert_array_equal(default_pressures_mpa(0.1, 0.05), [0.0, 0.05, 0.1])
    with pytest.raises(ValueError, match=r"'pmax_mpa'.*whole number of steps"):
        default_pressures_mpa(0.1, 0.03)
    with pytest.raises(ValueError, match="'pmax_mpa'"):
        default_pressures_mpa(-0.1)
    with pytest.raises(ValueError, match="'step_mpa'"):
        default_pressures_mpa(0.1, 0.0)


@pytest.mark.parametrize(
    ("grid", "match"),
    [
        ([0.0, 0.2, 0.1], "strictly increasing. Got 0.1 after 0.2 at position 2"),
        ([0.0, 0.1, 0.1], "strictly increasing"),
        ([-0.1, 0.0], r"\[0, inf\) MPa. Got -0.1 at position 0"),
        ([0.0, np.nan], "finite"),
        ([], "non-empty"),
        ([[0.0, 0.1]], "1-D"),
        ("abc", "sequence of numbers"),
    ],
)
def test_bad_pressure_grids_are_refused_naming_the_field(grid, match):
    with pytest.raises(ValueError, match="'pressures_mpa' of owner") as info:
        check_pressures_mpa(grid, "owner")
    assert info.match(match)


# ----------------------------------------------------------------------------- SweepResult


def _result(n: int = 4, **overrides) -> SweepResult:
    values = {
        "design": DESIGN,
        "pressure_mpa": np.arange(n) * 0.1,
        "angle_deg": np.arange(n) * 10.0,
        "tip_x_mm": np.full(n, 100.0),
        "tip_z_mm": np.zeros(n),
        "converged": np.ones(n, dtype=bool),
        "newton_iterations": np.full(n, 3),
        "wall_time_s": 0.5,
    }
    values.update(overrides)
    return SweepResult(**values)


def test_sweep_result_checks_lengths_truncation_and_types():
    with pytest.raises(ValueError, match="equal lengths"):
        _result(angle_deg=np.zeros(3))
    with pytest.raises(ValueError, match=r"'converged'.*position 1 of 4"):
        _result(converged=[True, False, True, True])
    with pytest.raises(ValueError, match=r"'pressure_mpa'.*strictly increasing"):
        _result(pressure_mpa=[0.0, 0.2, 0.1, 0.3])
    with pytest.raises(ValueError, match="'wall_time_s'"):
        _result(wall_time_s=-1.0)
    with pytest.raises(ValueError, match="'design'"):
        _result(design="100,6,2,2,5,8")
    ok = _result(converged=[True, True, True, False])
    assert ok.n_converged == 3
    assert ok.max_pressure_mpa == pytest.approx(0.2)
    assert ok.max_angle_deg == pytest.approx(20.0)
    assert not ok.angle_deg.flags.writeable


def test_from_angles_ends_the_sweep_at_the_first_failure_and_keeps_it():
    pressures = np.arange(6) * 0.1
    angles = np.array([0.0, 10.0, 20.0, np.nan, 40.0, np.nan])
    result = SweepResult.from_angles(
        DESIGN, pressures, angles, angles + 1.0, angles + 2.0, wall_time_s=0.1
    )
    np.testing.assert_array_equal(result.pressure_mpa, pressures[:4])
    np.testing.assert_array_equal(result.converged, [True, True, True, False])
    assert np.isnan(result.angle_deg[-1]) and np.isnan(result.tip_x_mm[-1])
    assert np.isnan(result.tip_z_mm[-1])
    np.testing.assert_array_equal(result.tip_x_mm[:3], [1.0, 11.0, 21.0])
    np.testing.assert_array_equal(result.newton_iterations, 0)
    assert result.max_pressure_mpa == pytest.approx(0.2)

    complete = SweepResult.from_angles(
        DESIGN, pressures[:3], angles[:3], angles[:3], angles[:3], wall_time_s=0.1
    )
    assert complete.converged.all() and len(complete.pressure_mpa) == 3
    first_fails = SweepResult.from_angles(
        DESIGN, [0.1], [np.nan], [np.nan], [np.nan], wall_time_s=0.0
    )
    assert first_fails.n_converged == 0 and np.isnan(first_fails.max_angle_deg)


def test_sweep_result_pickles_for_workers():
    result = _result(stats={"solver": "x"}, mesh_size=1234)
    clone = pickle.loads(pickle.dumps(result))
    np.testing.assert_array_equal(clone.angle_deg, result.angle_deg)
    assert clone.design == DESIGN and clone.mesh_size == 1234 and clone.stats == {"solver": "x"}


# ----------------------------------------------------------------------------- registry


def test_registry_names_the_allowed_backends():
    assert {"analytical", "fem", "fault-injection"} <= set(available_backends())
    with pytest.raises(
        ValueError, match="'backend' of get_backend must be one of 'analytical', 'fem'"
    ):
        get_backend("abaqus")
    with pytest.raises(ValueError, match="options of backend 'analytical' are invalid"):
        get_backend("analytical", mesh_size=3)


def test_register_backend_plugs_in_a_model_and_refuses_silent_replacement(monkeypatch):
    monkeypatch.setattr(backends, "_REGISTRY", dict(backends._REGISTRY))
    register_backend("analytical-stiff", lambda: AnalyticalBackend(material="fiberglass"))
    assert get_backend("analytical-stiff").material.name.startswith("Fiberglass")
    with pytest.raises(ValueError, match="already registered"):
        register_backend("analytical", AnalyticalBackend)
    with pytest.raises(ValueError, match="'factory'"):
        register_backend("x", 3)


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
    thick = get_backend("analytical").sweep(SFRBADesign(100, 6, 4, 2, 5, 8), grid)
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
    with pytest.raises(ValueError, match="'preset'"):
        get_backend("analytical", material="rubber")
    with pytest.raises(ValueError, match="'material' of AnalyticalBackend"):
        AnalyticalBackend(material=3.0)
    with pytest.raises(ValueError, match="'max_angle_deg'"):
        AnalyticalBackend(max_angle_deg=0.0)
    limited = AnalyticalBackend(max_angle_deg=90.0).sweep(DESIGN, default_pressures_mpa())
    assert not limited.converged[-1] and np.nanmax(limited.angle_deg) <= 90.0


# ----------------------------------------------------------------------------- fault injection


def test_fault_injection_fails_chosen_designs_and_delegates_the_rest():
    grid = default_pressures_mpa(0.1, 0.05)
    backend = get_backend("fault-injection", fail_design_ids=[DESIGN.design_id])
    assert isinstance(backend, FaultInjectionBackend)
    with pytest.raises(ConvergenceError, match="injected failure for design 100,6,2,2,5,8"):
        backend.sweep(DESIGN, grid)
    other = SFRBADesign(120, 6, 2, 2, 5, 8)
    np.testing.assert_array_equal(
        backend.sweep(other, grid).angle_deg, AnalyticalBackend().sweep(other, grid).angle_deg
    )
    with pytest.raises(ValueError, match="'delay_s'"):
        get_backend("fault-injection", delay_s=-1)
    with pytest.raises(ValueError, match="'inner'"):
        get_backend("fault-injection", inner="fault-injection")
