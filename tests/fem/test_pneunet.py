"""The PneuNet's finite-element model on a coarse mesh: closed forms, symmetry, physics, touch."""

from __future__ import annotations

import math

import numpy as np
import pytest

import softbend._torch  # noqa: F401  (PyTorch before NGSolve)
from softbend.fem.families import get_family
from softbend.fem.pneunet.description import cavity_volume_mm3
from softbend.models import default_pressures_mpa

FAMILY = get_family("pneunet")
#: Coarse (3 mm is the most the reference's 1.2 mm walls allow), without contact: a sweep
#: stops where the walls first touch.
COARSE = FAMILY.options(maxh_mm=3.0, **FAMILY.contact_options("off"))
#: Three short chambers: a small mesh.
SMALL = "n_chambers=3,chamber_height_mm=12"


@pytest.fixture(scope="module")
def reference_sweep():
    design = FAMILY.parse(SMALL)
    return FAMILY.sweep(design, default_pressures_mpa(0.02, 0.002), COARSE)


def test_zero_pressure_is_the_undeformed_pneunet_with_its_geometric_cavity_volume():
    from softbend.fem.pneunet.model import PneuNetModel

    design = FAMILY.parse(SMALL)
    model = PneuNetModel(design, COARSE)
    reading = model.measure()
    assert reading.angle_deg == pytest.approx(0.0, abs=1e-12)
    assert reading.tip_x_mm == pytest.approx(model.geometry.length_mm)
    # Box cavities: the surface integral of the flux is exact, both halves.
    assert model.cavity_volume_mm3() == pytest.approx(cavity_volume_mm3(design), rel=1e-10)
    assert model.wall_gap_mm() == pytest.approx(design.gap_mm, rel=1e-9)


def test_the_mirrored_vtk_grid_is_twice_the_half_model():
    from softbend.fem.export import actuator_grid
    from softbend.fem.pneunet.model import PneuNetModel

    model = PneuNetModel(FAMILY.parse(SMALL), COARSE)

    def volume(grid):
        p = grid.points[grid.cells[:, :4]]
        edges = np.cross(p[:, 1] - p[:, 0], p[:, 2] - p[:, 0])
        return float(np.einsum("ni,ni->n", edges, p[:, 3] - p[:, 0]).sum() / 6.0)

    half = actuator_grid(model, mirror=False)
    whole = actuator_grid(model, mirror=True)
    assert volume(half) == pytest.approx(model.geometry.half_volume_mm3, rel=1e-9)
    assert volume(whole) == pytest.approx(2.0 * volume(half), rel=1e-12)
    assert whole.points[:, 1].min() == pytest.approx(-model.geometry.half_width_mm)


def test_the_pneunet_bends_towards_its_layer_more_with_pressure(reference_sweep):
    result, _, _ = reference_sweep
    ok = result.converged
    angles = result.angle_deg[ok]
    assert angles[0] == pytest.approx(0.0, abs=1e-9)  # no gravity: no sag
    assert np.all(np.diff(angles) > 0.0)
    assert np.all(result.tip_z_mm[ok][1:] > 0.0)  # towards the strain-limiting layer
    volumes = result.stats["step_volume_mm3"]
    assert volumes[0] == pytest.approx(cavity_volume_mm3(result.design), rel=1e-9)
    assert np.all(np.diff(volumes) > 0.0)
    assert math.isnan(result.stats["fiber_spacing_mm"])


def test_the_volume_rate_is_the_slope_of_the_volume(reference_sweep):
    result, _, history = reference_sweep
    p = history.pressures
    volume = np.array(result.stats["step_volume_mm3"])
    rate = np.array(result.stats["step_volume_rate_mm3_per_mpa"])
    # The trapezoidal rule on the exact slopes gives each step's volume change.
    change = 0.5 * (rate[1:] + rate[:-1]) * np.diff(p)
    assert change == pytest.approx(np.diff(volume), rel=0.05)


def test_touching_walls_stop_the_sweep_with_the_pressure_named(reference_sweep):
    reference, _, _ = reference_sweep
    design = FAMILY.parse(SMALL + ",gap_mm=1")
    result, model, _ = FAMILY.sweep(design, default_pressures_mpa(0.02, 0.001), COARSE)
    reason = result.stats["stop_reason"]
    assert reason.startswith("neighbouring chamber walls touch at ")
    touch_kpa = float(reason.split(" at ")[1].split()[0])
    assert result.pressure_mpa[-1] <= touch_kpa / 1000 + 1e-12
    assert result.converged.all()
    # The last converged step had overlapping walls, the one before did not.
    assert model._gaps[-1][1] <= 0.0 < model._gaps[-2][1]
    # Closer walls touch at a lower pressure than those 2.5 mm apart (if they touch at all).
    assert touch_kpa / 1000 < reference.pressure_mpa[-1] + 1e-12


def test_a_single_chamber_has_no_walls_to_touch():
    from softbend.fem.pneunet.model import PneuNetModel

    model = PneuNetModel(FAMILY.parse("n_chambers=1,chamber_height_mm=12"), COARSE)
    assert model.wall_gap_mm() == math.inf
    assert model.stop_after_step(0.01) is None


@pytest.fixture(scope="module")
def close_walls():
    """Walls 1 mm apart: swept without contact (to the touch, 3–4 kPa) and with it (past it)."""
    design = FAMILY.parse(SMALL + ",gap_mm=1")
    grid = default_pressures_mpa(0.008, 0.0005)
    off = FAMILY.sweep(design, grid, COARSE)
    on = FAMILY.sweep(design, grid, COARSE.replace(contact="on"))
    return off, on


@pytest.mark.slow
def test_with_contact_the_curve_before_the_touch_is_the_contact_free_one(close_walls):
    (off, _, _), (on, _, history) = close_walls
    touch = off.pressure_mpa[-1]
    before = off.pressure_mpa < touch - 1e-12
    assert before.sum() >= 5
    n = int(before.sum())
    assert on.pressure_mpa[:n] == pytest.approx(off.pressure_mpa[:n])
    assert np.abs(on.angle_deg[:n] - off.angle_deg[:n]).max() <= 0.1
    # And it goes on through the touch, the walls pressing on each other.
    assert history.pressures[-1] > touch + 0.003
    assert on.stats["stop_reason"] != off.stats["stop_reason"]


@pytest.mark.slow
def test_contact_force_is_zero_before_the_touch_and_grows_after_it(close_walls):
    (off, _, _), (on, model, history) = close_walls
    touch = off.pressure_mpa[-1]
    p = history.pressures
    force = np.array(on.stats["step_contact_force_n"])
    pressure = np.array(on.stats["step_contact_pressure_kpa"])
    assert len(force) == len(pressure) == len(p)
    assert np.all(force[p < 0.9 * touch] == 0.0)
    assert force[-1] > 0.0 and pressure[-1] > 0.0
    # Overlap within the stated tolerance; the pressure is the penalty times it.
    k = model.options.contact_penalty_mpa_per_mm
    assert max(model.interpenetration_mm) <= model.options.contact_tolerance_mm
    assert pressure[-1] == pytest.approx(1000 * k * model.interpenetration_mm[-1])
    # The bending goes on rising past the touch.
    steps = np.array(on.stats["step_angles_deg"])
    assert np.all(np.diff(steps) > 0.0)


@pytest.mark.slow
def test_the_reference_with_contact_bends_through_the_working_range():
    """`fem run --family pneunet`'s sweep: to 50 kPa or 180°, rising at every output."""
    design = FAMILY.parse("")
    grid = default_pressures_mpa(FAMILY.pmax_mpa, FAMILY.pstep_mpa)
    options = FAMILY.options(threads=1)  # the family's defaults: contact, to 180°
    assert (options.contact, options.max_angle_deg) == ("on", 180.0)
    result = FAMILY.simulate(design, grid, options)
    assert result.converged.all(), result.stats["stop_reason"]
    assert result.max_pressure_mpa == pytest.approx(0.05) or result.max_angle_deg >= 179.0
    assert np.all(np.diff(result.angle_deg) > 0.0)
    assert result.angle_deg[-1] - result.angle_deg[0] >= 90.0
    # The walls press on each other, within the penalty's tolerance.
    pressure_kpa = np.array(result.stats["step_contact_pressure_kpa"])
    assert pressure_kpa[-1] > 0.0
    k = options.contact_penalty_mpa_per_mm
    assert pressure_kpa.max() / (1000.0 * k) <= options.contact_tolerance_mm
