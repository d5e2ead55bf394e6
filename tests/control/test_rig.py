import math

import numpy as np
import pytest

from softbend.control.rig import (
    AngleTable,
    RigParams,
    SimulatedRig,
    chamber_pressure_rate_pa_s,
    iso6358_mass_flow_kg_s,
)
from softbend.design import sfrba_design

C, B = 4e-10, 0.3


def test_flow_zero_at_equal_pressures_and_reverses():
    assert iso6358_mass_flow_kg_s(2e5, 2e5, C, B) == 0.0
    forward = iso6358_mass_flow_kg_s(3e5, 2e5, C, B)
    assert forward > 0
    assert iso6358_mass_flow_kg_s(2e5, 3e5, C, B) == pytest.approx(-forward)


def test_choked_flow_independent_of_downstream():
    up = 3e5
    choked = C * up * 1.185
    for down in (0.0, 0.1 * up, 0.2 * up, B * up):
        assert iso6358_mass_flow_kg_s(up, down, C, B) == pytest.approx(choked, rel=1e-12)
    # doubling the upstream pressure doubles the choked flow
    assert iso6358_mass_flow_kg_s(2 * up, 0.0, C, B) == pytest.approx(2 * choked)


def test_flow_continuous_at_critical_ratio_and_decreasing_after():
    up = 3e5
    at = iso6358_mass_flow_kg_s(up, B * up, C, B)
    just_after = iso6358_mass_flow_kg_s(up, (B + 1e-9) * up, C, B)
    assert just_after == pytest.approx(at, rel=1e-6)
    ratios = np.linspace(B, 1.0, 50)
    flows = [iso6358_mass_flow_kg_s(up, r * up, C, B) for r in ratios]
    assert np.all(np.diff(flows) <= 0) and flows[-1] == 0.0


def test_chamber_rate_isothermal_closed_form():
    # rigid volume: dp/dt = R T mdot / V
    rate = chamber_pressure_rate_pa_s(
        2e5, 1e-5, atmosphere_pa=1e5, volume_m3=1e-5, compliance_m3_pa=0.0
    )
    assert rate == pytest.approx(287.05 * 293.15 * 1e-5 / 1e-5)


def _held(table, inlet, outlet, start_mpa=0.0, steps=3000):
    rig = SimulatedRig(table, seed=0)
    rig.p_pa = rig._patm + start_mpa * 1e6
    rig.command(inlet, outlet)
    pressures = []
    for _ in range(steps):
        rig.advance(1)
        pressures.append(rig.pressure_mpa)
    return rig, np.array(pressures)


def test_fills_toward_supply_monotonically(table):
    rig, p = _held(table, True, False)
    assert np.all(np.diff(p) >= 0)
    assert p[-1] == pytest.approx(rig.params.supply_gauge_mpa, abs=1e-4)
    assert p[-1] <= rig.params.supply_gauge_mpa
    assert rig.air_used_kg > 0 and rig.switches == 1


def test_vents_toward_atmosphere_monotonically(table):
    rig, p = _held(table, False, True, start_mpa=0.15)
    assert np.all(np.diff(p) <= 0)
    assert p[-1] == pytest.approx(0.0, abs=1e-4)
    assert p[-1] >= 0.0 and rig.air_used_kg == 0.0


def test_valve_delay(table):
    rig = SimulatedRig(table, seed=0)
    rig.command(True, False)
    rig.advance(4)
    assert not rig.inlet_open and rig.pressure_mpa == 0.0
    rig.advance(2)
    assert rig.inlet_open and rig.pressure_mpa > 0.0


def test_angle_lag_reaches_63_percent_at_time_constant():
    # a step of θ(p): 0° below 1 kPa, 100° above; a quick fill crosses it at once
    table = AngleTable.from_callable(lambda p: np.where(p > 0.0, 100.0, 0.0), 0.5, 501)
    params = RigParams(valve_delay_s=0.0, inlet_conductance_m3_s_pa=1e-7)
    rig = SimulatedRig(table, params, seed=0)
    rig.command(True, False)
    rig.advance(1)  # pressure jumps past the first table step
    start_t, start_angle = rig.t_s, rig.angle_deg
    tau = params.angle_time_constant_s
    rig.advance(round(tau / params.step_s))
    fraction = (rig.angle_deg - start_angle) / (100.0 - start_angle)
    assert rig.t_s - start_t == pytest.approx(tau)
    assert fraction == pytest.approx(1 - math.exp(-1), abs=1e-9)


def test_sensor_quantised_and_seeded(table):
    rig = SimulatedRig(table, seed=3)
    lsb = 0.5 / 4095
    readings = [rig.read_pressure_mpa() for _ in range(50)]
    assert all(abs(r / lsb - round(r / lsb)) < 1e-9 for r in readings)
    rig.reset(3)
    assert [rig.read_pressure_mpa() for _ in range(50)] == readings


def test_params_validation_names_field():
    with pytest.raises(ValueError, match=r"^valve_delay_s: must be a number in \[0, 1\] s; got -1"):
        RigParams(valve_delay_s=-1)
    with pytest.raises(ValueError, match=r"^polytropic_exponent: must be a number in"):
        RigParams(polytropic_exponent=2.0)
    with pytest.raises(ValueError, match=r"^sensor_bits: must be an integer in"):
        RigParams(sensor_bits=1.5)


def test_for_design_volume():
    params = RigParams.for_design(sfrba_design(100, 6, 2, 2, 5, 8))
    assert params.volume_mm3 == pytest.approx(0.5 * math.pi * 36 * 100 + 2000)


def test_angle_table_inverse_round_trip(table):
    for angle in (10.0, 90.0, 300.0):
        assert table(table.inverse(angle)) == pytest.approx(angle)
    assert table.inverse(0.0) == 0.0  # below θ(0): clamped


def test_cavity_compliance_of_a_constant_and_a_linear_dv_dp():
    from softbend.control.rig import cavity_compliance_mm3_per_mpa

    p = np.linspace(0.0, 0.2, 41)
    assert cavity_compliance_mm3_per_mpa(p, np.full_like(p, 30_000.0), 0.2) == pytest.approx(
        30_000.0
    )
    # dV/dp = a + b·p gives V = a·p + b·p²/2; the least-squares line through 0 on [0, P]
    # of a uniform grid has slope a + (b/2)·Σp³/Σp²
    a, b = 40_000.0, 100_000.0
    expected = a + 0.5 * b * np.sum(p**3) / np.sum(p**2)
    assert cavity_compliance_mm3_per_mpa(p, a + b * p, 0.2) == pytest.approx(expected, rel=1e-4)
    # only the steps up to the supply count
    assert cavity_compliance_mm3_per_mpa(p, a + b * p, 0.1) < expected
    with pytest.raises(ValueError, match="at least two converged steps"):
        cavity_compliance_mm3_per_mpa([0.0], [1.0], 0.2)


@pytest.mark.slow
def test_default_compliance_is_the_fem_cavity_of_the_default_design():
    import softbend._torch  # noqa: F401  (PyTorch before NGSolve, as softbend.fem loads them)

    pytest.importorskip("ngsolve")
    from softbend.fem.model import FEMModel

    design = sfrba_design(100, 6, 2, 2, 5, 8)
    result = FEMModel().sweep(design, np.round(np.linspace(0.0, 0.2, 21), 4))
    params = RigParams.from_fem_sweep(result)
    assert params.compliance_mm3_per_mpa == pytest.approx(
        RigParams().compliance_mm3_per_mpa, rel=0.01
    )
    assert params.volume_mm3 == pytest.approx(RigParams().volume_mm3, rel=1e-3)


def test_from_fem_sweep_refuses_a_result_without_volumes():
    from softbend.analytical import AnalyticalModel

    result = AnalyticalModel().sweep(sfrba_design(100, 6, 2, 2, 5, 8), [0.0, 0.05, 0.1])
    with pytest.raises(ValueError, match="must be an FEM sweep"):
        RigParams.from_fem_sweep(result)


def test_commanded_is_the_latest_command_before_the_valves_switch(table):
    rig = SimulatedRig(table, RigParams(valve_delay_s=0.005))
    rig.command(True, False)
    assert rig.commanded == (True, False) and not rig.inlet_open
    rig.command(False, True)
    assert rig.commanded == (False, True)
    rig.advance(10)
    assert (rig.inlet_open, rig.outlet_open) == rig.commanded == (False, True)
