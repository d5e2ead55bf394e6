"""The seam between bending models: the pressure grid and the sweep result."""

from __future__ import annotations

import pickle

import numpy as np
import pytest

from softbend.design import sfrba_design
from softbend.models import SweepResult, check_pressures_mpa, default_pressures_mpa

DESIGN = sfrba_design(100, 6, 2, 2, 5, 8)


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
    with pytest.raises(ValueError, match=r"^pmax_mpa: must be a whole number of steps") as info:
        default_pressures_mpa(0.1, 0.03)
    assert info.value.key == "pmax_mpa" and "steps of 0.03 MPa; got 0.1" in str(info.value)
    with pytest.raises(ValueError, match=r"^pmax_mpa: "):
        default_pressures_mpa(-0.1)
    with pytest.raises(ValueError, match=r"^step_mpa: "):
        default_pressures_mpa(0.1, 0.0)
    with pytest.raises(ValueError, match=r"^pmax_mpa: must give a grid of at most 100001"):
        default_pressures_mpa(100.0, 1e-4)


@pytest.mark.parametrize(
    ("grid", "match"),
    [
        ([0.0, 0.2, 0.1], "strictly increasing; got 0.1 after 0.2 at position 2"),
        ([0.0, 0.1, 0.1], "strictly increasing"),
        ([-0.1, 0.0], r"\[0, inf\) MPa; got -0.1 at position 0"),
        ([0.0, np.nan], "finite"),
        ([], "non-empty"),
        ([[0.0, 0.1]], "1-D"),
        ("abc", "sequence of numbers"),
    ],
)
def test_bad_pressure_grids_are_refused_naming_the_field(grid, match):
    with pytest.raises(ValueError, match=r"^pressures_mpa: must be") as info:
        check_pressures_mpa(grid)
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
    with pytest.raises(ValueError, match=r"^angle_deg: must have the length of 'pressure_mpa'"):
        _result(angle_deg=np.zeros(3))
    with pytest.raises(ValueError, match=r"^converged: .*position 1 of 4"):
        _result(converged=[True, False, True, True])
    with pytest.raises(ValueError, match=r"^pressure_mpa: must be strictly increasing"):
        _result(pressure_mpa=[0.0, 0.2, 0.1, 0.3])
    with pytest.raises(ValueError, match=r"^wall_time_s: "):
        _result(wall_time_s=-1.0)
    with pytest.raises(ValueError, match=r"^design: must be a Design"):
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
