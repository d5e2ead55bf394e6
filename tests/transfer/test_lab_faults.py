"""The virtual lab refuses runs it cannot finish, before any work and as one error."""

from __future__ import annotations

import time
from types import SimpleNamespace

import numpy as np
import pytest

from softbend.errors import ConvergenceError, LimitError
from softbend.transfer.lab import LAB_ACTUATORS, VirtualLab


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
