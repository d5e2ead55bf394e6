"""The virtual lab: its gap is what it says, seeded, labelled synthetic."""

from __future__ import annotations

import time
from types import SimpleNamespace

import numpy as np
import pytest

from softbend.analytical import AnalyticalModel
from softbend.errors import ConvergenceError, LimitError
from softbend.transfer.lab import LAB_ACTUATORS, VirtualLab, actuator_id
from softbend.transfer.measurements import load_measurements, save_measurements


def test_the_seven_actuators_of_paper_b_fig7():
    assert [actuator_id(d) for d in LAB_ACTUATORS] == [
        "100,6,2,2,5,8",
        "120,6,2,2,5,8",
        "100,8,2,2,5,8",
        "100,6,3,2,5,8",
        "100,6,2,3,5,8",
        "100,6,2,2,10,8",
        "100,6,2,2,5,10",
    ]


def test_readings_are_labelled_synthetic_with_the_gap(quick_measurements):
    meta = quick_measurements.metadata
    assert meta["synthetic"] == "true"
    for key in (
        "lab.fabrication_error_mm",
        "lab.hysteresis",
        "lab.camera_noise_deg",
        "lab.seed",
        "lab.elastomer_model",
        "lab.as_built",
    ):
        assert key in meta
    frame = quick_measurements.frame
    assert list(dict.fromkeys(frame["actuator_id"])) == [actuator_id(d) for d in LAB_ACTUATORS[:4]]
    assert set(frame["direction"]) == {"loading"}
    for _, part in frame.groupby("actuator_id"):
        p = part["pressure_mpa"].to_numpy()
        assert p[0] == 0.0
        np.testing.assert_allclose(np.diff(p), 0.01, atol=1e-12)  # paper B's 0.01 MPa steps


def test_same_seed_same_numbers_other_seed_other_numbers(quick_lab, quick_measurements):
    again = quick_lab.measure()
    assert again == quick_measurements
    other = VirtualLab(actuators=quick_lab.actuators, plant="analytical", pmax_mpa=0.15, seed=1)
    assert not np.allclose(other.measure().angle_deg[:5], quick_measurements.angle_deg[:5])


def test_without_a_gap_the_lab_reads_the_plant_exactly():
    lab = VirtualLab(
        actuators=LAB_ACTUATORS[:2],
        plant="analytical",
        fabrication_error_mm=0.0,
        hysteresis=0.0,
        camera_noise_deg=0.0,
        pmax_mpa=0.1,
    )
    measured = lab.measure()
    plant = AnalyticalModel(material=lab.elastomer_material())
    for design in LAB_ACTUATORS[:2]:
        rows = measured.frame[measured.frame["actuator_id"] == actuator_id(design)]
        sweep = plant.sweep(design, rows["pressure_mpa"].to_numpy())
        np.testing.assert_allclose(rows["angle_deg"], sweep.angle_deg, rtol=0, atol=1e-12)


def test_hysteresis_branches_bracket_the_elastic_curve_and_meet_at_the_ends():
    h = 0.03
    base = dict(
        actuators=LAB_ACTUATORS[:1],
        plant="analytical",
        fabrication_error_mm=0.0,
        camera_noise_deg=0.0,
        pmax_mpa=0.12,
    )
    elastic = VirtualLab(hysteresis=0.0, **base).measure().angle_deg
    both = VirtualLab(hysteresis=h, unloading=True, **base).measure().frame
    up = both[both["direction"] == "loading"]["angle_deg"].to_numpy()
    down = both[both["direction"] == "unloading"]
    assert down["pressure_mpa"].iloc[0] == pytest.approx(0.11)  # back down from below the top
    down_angle = down["angle_deg"].to_numpy()[::-1]
    assert np.all(up <= elastic + 1e-12)
    assert np.all(down_angle >= elastic[:-1] - 1e-12)
    gap = (down_angle - up[:-1])[1:] / elastic[1:-1]
    assert gap.max() == pytest.approx(2 * h, rel=0.02)  # largest near mid-pressure: 2h
    assert up[-1] == pytest.approx(elastic[-1]) and up[0] == pytest.approx(elastic[0])


def test_fabrication_error_is_seeded_and_bounded():
    lab = VirtualLab(fabrication_error_mm=0.2, seed=5)
    built = lab.as_built()
    assert built == VirtualLab(fabrication_error_mm=0.2, seed=5).as_built()
    for nominal, real in zip(LAB_ACTUATORS, built, strict=True):
        assert abs(real.t_mm - nominal.t_mm) <= 0.2 and abs(real.b_mm - nominal.b_mm) <= 0.2
        assert (real.l_mm, real.r_mm, real.phi_deg) == (nominal.l_mm, nominal.r_mm, nominal.phi_deg)
    assert any(real != nominal for nominal, real in zip(LAB_ACTUATORS, built, strict=True))


def test_the_lab_material_is_its_own_fit_of_the_shipped_test():
    material = VirtualLab().elastomer_material()
    assert "dragon-skin-30" in material.name
    # the shipped test is not paper B's constants (C10 0.11 MPa)
    assert material.model.c10_mpa != pytest.approx(0.11, abs=0.005)


def test_max_angle_stops_the_pressure_ramp():
    lab = VirtualLab(
        actuators=LAB_ACTUATORS[1:2],
        plant="analytical",
        max_angle_deg=90.0,
        camera_noise_deg=0.0,
        hysteresis=0.0,
    )
    angles = lab.measure().angle_deg
    assert angles.max() <= 90.0 and angles.size >= 3


def test_a_csv_round_trip_keeps_the_gap_metadata(tmp_path, quick_measurements):
    path = save_measurements(quick_measurements, tmp_path / "lab.csv")
    assert load_measurements(path) == quick_measurements


@pytest.mark.parametrize(
    ("field", "value"),
    [
        ("plant", "abaqus"),
        ("fabrication_error_mm", -0.1),
        ("hysteresis", 0.5),
        ("camera_noise_deg", float("nan")),
        ("pmax_mpa", 0.0),
        ("max_angle_deg", 400.0),
        ("cycles", 0),
        ("seed", -1),
        ("elastomer", "steel"),
        ("pressure_step_mpa", 0.03),
    ],
)
def test_bad_settings_name_the_field(field, value):
    with pytest.raises(ValueError, match=field if field != "pressure_step_mpa" else "pmax_mpa"):
        VirtualLab(**{field: value})


# --- The virtual lab refuses runs it cannot finish, before any work and as one error ---


def test_a_billion_cycles_are_refused_at_once():
    start = time.perf_counter()
    with pytest.raises(LimitError) as error:
        VirtualLab(plant="analytical", cycles=1_000_000_000)
    assert time.perf_counter() - start < 1.0
    message = str(error.value)
    assert error.value.key == "cycles" and "1,000,000,000" in message
    assert "limit of 1,000 cycles" in message and "SOFTBEND_MAX_CYCLES" in message


def test_the_cycle_limit_can_be_raised(monkeypatch):
    monkeypatch.setenv("SOFTBEND_MAX_CYCLES", "2000")
    assert VirtualLab(plant="analytical", cycles=1500).cycles == 1500


def test_a_max_angle_below_the_first_step_names_the_setting():
    lab = VirtualLab(actuators=LAB_ACTUATORS[:1], plant="analytical", max_angle_deg=0.01)
    with pytest.raises(ValueError, match=r"^max_angle_deg: \(0.01°\) stops actuator"):
        lab.measure()


def test_a_plant_that_stops_at_once_is_a_convergence_error():
    class Stuck:
        name = "stuck"

        def sweep(self, design, pressures):  # converged at 0 MPa, not at the next step
            return SimpleNamespace(
                pressure_mpa=np.asarray(pressures[:2]),
                angle_deg=np.array([0.0, np.nan]),
                converged=np.array([True, False]),
            )

    lab = VirtualLab(actuators=LAB_ACTUATORS[:1], plant="analytical")
    with pytest.raises(ConvergenceError, match=r"actuator 100,6,2,2,5,8: its stuck model stopped"):
        lab.measure(Stuck())


def test_a_camera_noise_beyond_any_angle_names_the_setting():
    with pytest.raises(ValueError) as error:
        VirtualLab(plant="analytical", camera_noise_deg=1e6)
    assert str(error.value) == "camera_noise_deg: must be a number in [0, 90]; got 1000000.0"
    assert VirtualLab(plant="analytical", camera_noise_deg=90.0).camera_noise_deg == 90.0
