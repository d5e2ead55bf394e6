"""Settings of the simulated rig from NAME=VALUE text, a mapping and a rig TOML's [simulation]."""

from dataclasses import fields

import pytest

from softbend.control.rig import RigParams, SimulatedRig
from softbend.control.rigconfig import RigConfig, load_rig_config, rig_config_template
from softbend.control.rigs import (
    RIG_SETTINGS,
    rig_parameter_catalog,
    rig_params_for,
    rig_settings,
)
from softbend.design import sfrba_design
from softbend.errors import DatasetError
from softbend.parameters import ParameterValueError, UnknownParameterError

DESIGN = sfrba_design(100, 6, 2, 2, 5, 8)


def test_text_is_read_by_the_kind_of_each_field():
    got = rig_settings(["valve_delay_s=0.02", "sensor_bits=10", "tubing_mm3=500", "step_s=1e-3"])
    assert got == {"valve_delay_s": 0.02, "sensor_bits": 10, "tubing_mm3": 500.0, "step_s": 1e-3}
    assert type(got["sensor_bits"]) is int and type(got["tubing_mm3"]) is float


def test_text_overrides_the_mapping_and_the_supply_overrides_both():
    table = {"valve_delay_s": 0.01, "camera_noise_deg": 0.5, "supply_gauge_mpa": 0.15}
    got = rig_settings(["valve_delay_s=0.03"], table, supply_mpa=0.25)
    assert got == {"valve_delay_s": 0.03, "camera_noise_deg": 0.5, "supply_gauge_mpa": 0.25}


def test_an_unknown_name_is_one_line_listing_the_known_ones():
    with pytest.raises(UnknownParameterError) as info:
        rig_settings(["valve_dealy_s=0.02"])
    message = str(info.value)
    assert "\n" not in message
    assert message.startswith("rig_assignments: valve_dealy_s: is not a parameter; known: ")
    for name in ("valve_delay_s", "tubing_mm3", "critical_ratio", "inlet_conductance_m3_s_pa"):
        assert name in message


@pytest.mark.parametrize(
    ("item", "needle"),
    [
        ("sensor_bits=1.5", "sensor_bits: must be an integer; got '1.5'"),
        ("valve_delay_s=fast", "valve_delay_s: must be a number; got 'fast'"),
        ("camera_noise_deg=nan", "finite"),
        ("valve_delay_s", "NAME=VALUE"),
    ],
)
def test_a_value_of_the_wrong_kind_is_one_line(item, needle):
    with pytest.raises(ValueError, match=needle):
        rig_settings([item])


@pytest.mark.parametrize(
    ("item", "interval"),
    [
        ("valve_delay_s=-0.001", "[0, 1] s"),
        ("valve_delay_s=1e9", "[0, 1] s"),
        ("critical_ratio=1", "[0, 0.95]"),
        ("polytropic_exponent=1.6", "[1, 1.4]"),
        ("step_s=0.05", "[1e-05, 0.01] s"),
        ("step_s=1e-9", "[1e-05, 0.01] s"),
        ("inlet_conductance_m3_s_pa=0", "[1e-12, 1e-07] m³/(s·Pa)"),
        ("tubing_mm3=-1", "[0, 1e+06] mm³"),
    ],
)
def test_the_ranges_are_those_of_rigparams(item, interval):
    name, _, text = item.partition("=")
    with pytest.raises(ParameterValueError) as info:
        rig_settings([item])
    assert info.value.key == "rig_assignments"
    assert str(info.value) == f"rig_assignments: {name}: must be in {interval}; got '{text}'"
    # the same declaration holds RigParams itself (and the tubing of for_design)
    with pytest.raises(ValueError, match=f"^{name}: must be a number in"):
        if name == "tubing_mm3":
            RigParams.for_design(DESIGN, tubing_mm3=float(text))
        else:
            RigParams(**{name: float(text)})


def test_sensor_bits_over_32_is_refused():
    with pytest.raises(ParameterValueError, match=r"\[0, 32\]"):
        rig_settings(["sensor_bits=40"])


def test_supply_and_its_setting_must_agree():
    with pytest.raises(
        ValueError, match=r"^supply_mpa: must equal the rig setting supply_gauge_mpa"
    ):
        rig_settings(["supply_gauge_mpa=0.3"], supply_mpa=0.2)
    assert rig_settings(["supply_gauge_mpa=0.25"], supply_mpa=0.25) == {"supply_gauge_mpa": 0.25}
    with pytest.raises(ParameterValueError) as info:
        rig_settings(supply_mpa=-0.1)
    assert str(info.value).startswith(
        "supply_mpa: supply_gauge_mpa: must be in (0, 2] MPa; got -0.1"
    )


def test_volume_and_tubing_together_are_refused():
    with pytest.raises(ValueError, match=r"^rig_assignments: volume_mm3.*tubing_mm3.*give one"):
        rig_settings(["tubing_mm3=100"], {"volume_mm3": 5000.0})


def test_a_name_given_twice_is_refused():
    with pytest.raises(ValueError, match=r"^rig_assignments: the parameter .* is given twice"):
        rig_settings(["valve_delay_s=0.01", "valve_delay_s=0.02"])


def test_tubing_volume_is_added_to_the_cavity():
    none = rig_params_for(DESIGN, {"tubing_mm3": 0.0})
    assert none.volume_mm3 == pytest.approx(DESIGN.cavity_volume_mm3)
    more = rig_params_for(DESIGN, {"tubing_mm3": 5000.0})
    assert more.volume_mm3 - none.volume_mm3 == pytest.approx(5000.0)
    assert rig_params_for(DESIGN).volume_mm3 == pytest.approx(DESIGN.cavity_volume_mm3 + 2000.0)
    # an explicit chamber volume wins over the design's
    assert rig_params_for(DESIGN, {"volume_mm3": 1234.0, "tubing_mm3": 9.0}).volume_mm3 == 1234.0


def test_settings_override_the_derived_defaults():
    rig = rig_params_for(DESIGN, {"compliance_mm3_per_mpa": 1e4}, compliance_mm3_per_mpa=3e4)
    assert rig.compliance_mm3_per_mpa == 1e4
    assert rig_params_for(DESIGN, {}, compliance_mm3_per_mpa=3e4).compliance_mm3_per_mpa == 3e4


def _rise_s(table, params, level_mpa=0.05, horizon_s=1.0):
    """Time from opening the inlet valve to the chamber's true pressure reaching ``level_mpa``."""
    rig = SimulatedRig(table, params, seed=0)
    rig.command(True, False)
    t = 0.0
    while t < horizon_s:
        t += params.step_s
        rig.sleep_until(t)
        if rig.pressure_mpa >= level_mpa:
            return t
    raise AssertionError(f"the chamber did not reach {level_mpa} MPa in {horizon_s} s")


def test_a_larger_valve_delay_delays_the_rise_by_the_difference(table):
    quick = _rise_s(table, rig_params_for(DESIGN, rig_settings(["valve_delay_s=0.005"])))
    slow = _rise_s(table, rig_params_for(DESIGN, rig_settings(["valve_delay_s=0.045"])))
    assert slow - quick == pytest.approx(0.04, abs=2e-3)


def test_more_tubing_fills_slower(table):
    small = _rise_s(table, rig_params_for(DESIGN, rig_settings(["tubing_mm3=0"])), 0.1)
    large = _rise_s(table, rig_params_for(DESIGN, rig_settings(["tubing_mm3=20000"])), 0.1)
    assert large > 1.5 * small


def test_the_catalog_lists_every_field_with_its_default_and_meaning():
    rows = rig_parameter_catalog()
    names = [r["name"] for r in rows]
    assert names == [f.name for f in fields(RigParams)] + ["tubing_mm3"]
    assert set(RIG_SETTINGS) == set(names) and all(r["what"] for r in rows)
    defaults = {r["name"]: r["default"] for r in rows}
    assert defaults["valve_delay_s"] == RigParams().valve_delay_s and defaults["tubing_mm3"] == 2000


# The [simulation] table of a rig TOML


def _write(tmp_path, body):
    path = tmp_path / "rig.toml"
    path.write_text("[pressure]\naddress = 0\nscale = 1e-4\n\n[simulation]\n" + body)
    return path


def test_the_simulation_table_is_read_checked_and_written_back(tmp_path):
    path = _write(tmp_path, "valve_delay_s = 0.02\ntubing_mm3 = 500\nsensor_bits = 10\n")
    config = load_rig_config(path)
    assert config.simulation == (
        ("valve_delay_s", 0.02),
        ("tubing_mm3", 500.0),
        ("sensor_bits", 10),
    )
    again = tmp_path / "again.toml"
    again.write_text(config.to_toml())
    assert load_rig_config(again) == config
    assert "[simulation]" not in RigConfig().to_toml()


def test_the_template_with_its_simulation_table_uncommented_loads(tmp_path):
    text = rig_config_template().replace("# [simulation]", "[simulation]")
    text = text.replace("# valve_delay_s", "valve_delay_s").replace("# tubing_mm3", "tubing_mm3")
    path = tmp_path / "rig.toml"
    path.write_text(text)
    assert dict(load_rig_config(path).simulation) == {"valve_delay_s": 0.005, "tubing_mm3": 2000.0}


@pytest.mark.parametrize(
    ("body", "needles"),
    [
        (
            "valve_delay_s = 0.01\nvalve_dlay_s = 0.02\n",
            [":7: simulation.valve_dlay_s: is not", "tubing_mm3"],
        ),
        ('valve_delay_s = "fast"\n', [":6: simulation.valve_delay_s: must be a number"]),
        ("sensor_bits = 1.5\n", [":6: simulation.sensor_bits: must be an integer"]),
        ("critical_ratio = true\n", [":6: simulation.critical_ratio: must be a number"]),
        ("camera_noise_deg = -1.0\n", [":6: simulation.camera_noise_deg:", "[0, 10] °"]),
    ],
)
def test_a_bad_simulation_key_is_one_dataset_error_with_its_line(tmp_path, body, needles):
    path = _write(tmp_path, body)
    with pytest.raises(DatasetError) as info:
        load_rig_config(path)
    message = str(info.value)
    assert message.startswith(str(path))
    for needle in needles:
        assert needle in message


def test_a_simulation_key_that_is_not_a_table_is_refused(tmp_path):
    path = tmp_path / "rig.toml"
    path.write_text("simulation = 3\n[pressure]\naddress = 0\nscale = 1e-4\n")
    with pytest.raises(DatasetError, match=r":1: \[simulation\]: must be a table"):
        load_rig_config(path)


def test_rig_params_on_a_hardware_rig_are_refused():
    from softbend.control.runs import plan_loop

    with pytest.raises(ValueError, match=r"^rig_assignments: .*the rig modbus is hardware"):
        plan_loop(rig="modbus", rig_assignments=["valve_delay_s=0.02"])


def test_the_served_rig_takes_the_simulation_table_and_rig_param_over_it(tmp_path):
    pytest.importorskip("pymodbus")
    from softbend.control.runs import simulated_server

    path = _write(tmp_path, "valve_delay_s = 0.01\ncamera_noise_deg = 0.5\n")
    server = simulated_server(config=path, rig_assignments=["valve_delay_s=0.03"], port=0)
    params = server.plant.rig.params
    assert params.valve_delay_s == 0.03 and params.camera_noise_deg == 0.5
