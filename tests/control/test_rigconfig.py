"""The rig TOML: round trip, scaling, and one clear error per bad field."""

import pytest

from softbend.control.rigconfig import RegisterConfig, RigConfig, load_rig_config
from softbend.errors import DatasetError


def test_default_config_round_trips_through_toml(tmp_path):
    config = RigConfig()
    path = tmp_path / "rig.toml"
    path.write_text(config.to_toml())
    assert load_rig_config(path) == config


def test_config_without_angle_round_trips(tmp_path):
    config = RigConfig(angle=None, period_s=0.005)
    path = tmp_path / "rig.toml"
    path.write_text(config.to_toml())
    loaded = load_rig_config(path)
    assert loaded.angle is None and loaded.period_s == 0.005


@pytest.mark.parametrize(
    ("signed", "value", "raw"),
    [(False, 0.1234, 1234), (False, -1.0, 0), (False, 99.0, 0xFFFF), (True, -0.5, 0xFFCE)],
)
def test_register_encoding_rounds_and_saturates(signed, value, raw):
    reg = RegisterConfig(signed=signed, scale=0.01 if signed else 1e-4)
    assert reg.encode(value) == raw


def test_signed_register_decodes_twos_complement():
    reg = RegisterConfig(signed=True, scale=0.01, offset=10.0)
    assert reg.decode(0xFFFF) == pytest.approx(10.0 - 0.01)
    assert reg.decode(reg.encode(-123.45)) == pytest.approx(-123.45)


def _write(tmp_path, text):
    path = tmp_path / "rig.toml"
    path.write_text(text)
    return path


@pytest.mark.parametrize(
    ("text", "needle"),
    [
        ("[pressure]\naddress = 0\n[valvez]\n", ":3: [valvez]: is not a section"),
        ("[pressure]\nadress = 0\n", ":2: pressure.adress: is not a key of [pressure]"),
        ("[connection]\nport = 5\n", "must have a [pressure] section"),
        ('[pressure]\n[connection]\ntransport = "udp"\n', ":3: connection.transport: must"),
        ('[pressure]\n[connection]\ntransport = "rtu"\n', "connection.serial_port: must"),
        ("[pressure]\nscale = 0\n", ":2: pressure.scale: must be a finite non-zero number"),
        ("[pressure]\naddress = 70000\n", ":2: pressure.address: must be an integer in"),
        ("[pressure]\naddress = 1\n[angle]\naddress = 1\n", "must not share input register 1"),
        ("[pressure]\n[valves]\ninlet_coil = 3\noutlet_coil = 3\n", ":4: valves.outlet_coil:"),
        ("[pressure]\n[safety]\nmax_pressure_mpa = 0.7\n", "valid_min_mpa < max_pressure_mpa"),
        ("[pressure]\n[loop]\nperiod_s = -0.01\n", ":3: loop.period_s: must be a number"),
        ("[pressure]\n[connection]\ndevice_id = 300\n", ":3: connection.device_id: must"),
    ],
)
def test_bad_config_is_one_error_naming_the_field(tmp_path, text, needle):
    with pytest.raises(ValueError) as info:
        load_rig_config(_write(tmp_path, text))
    assert needle in str(info.value)
    assert "\n" not in str(info.value)


def test_transport_error_lists_the_allowed_values(tmp_path):
    with pytest.raises(ValueError) as info:
        load_rig_config(_write(tmp_path, '[pressure]\n[connection]\ntransport = "udp"\n'))
    assert "'tcp', 'rtu'" in str(info.value)


def test_invalid_toml_and_missing_file(tmp_path):
    with pytest.raises(DatasetError, match="not valid TOML"):
        load_rig_config(_write(tmp_path, "[pressure\n"))
    with pytest.raises(FileNotFoundError, match="does not exist"):
        load_rig_config(tmp_path / "nope.toml")


# --- Every bad rig TOML is one DatasetError naming the file, the line and the key ---


GOOD = "[pressure]\naddress = 0\nscale = 0.0001\n"


def _write_checks(tmp_path, text):
    path = tmp_path / "rig.toml"
    path.write_text(text, encoding="utf-8")
    return path


@pytest.mark.parametrize(
    ("text", "line", "needle"),
    [
        (
            GOOD + '[connection]\ntimeout_s = "0.05"\n',
            5,
            'connection.timeout_s: must be a number; got "0.05" (a string)',
        ),
        (GOOD + '[loop]\nperiod_s = "0.001"\n', 5, "loop.period_s: must be a number"),
        (GOOD + '[safety]\nmax_pressure_mpa = "0.2"\n', 5, "safety.max_pressure_mpa: must be"),
        (GOOD + "[connection]\nhost = 5\n", 5, "connection.host: must be a string"),
        (GOOD + "[connection]\nhost = 1979-05-27\n", 5, "(a date or time)"),
        (GOOD + "[connection]\nstopbits = true\n", 5, "must be an integer; got true (a boolean)"),
        (GOOD + "[connection]\nport = 502.0\n", 5, "connection.port: must be an integer"),
        (GOOD + "[valves]\ninlet_coil = [0]\n", 5, "valves.inlet_coil: must be an integer"),
        ("[pressure]\naddress = 0\nscale = 1\nsigned = 1\n", 4, "pressure.signed: must be"),
        (GOOD + "[safety]\nmax_pressure_mpa = -0.2\n", 5, "safety.max_pressure_mpa: must be"),
        (GOOD + "[safety]\nmax_pressure_mpa = nan\n", 5, "safety.max_pressure_mpa: must be"),
        (
            GOOD + "[safety]\nvalid_min_mpa = -5.0\n",
            5,
            "safety.valid_min_mpa: must be a plausible gauge pressure (-0.1013 to 2 MPa); got -5.0",
        ),
        (GOOD + "[safety]\nmax_pressure_mpa = 5.0\nvalid_max_mpa = 8.0\n", 5, "plausible"),
        ("[pressure]\naddress = 3\n", 1, "must give 'scale' (no default fits every sensor)"),
        ("[pressure]\nscale = 0.01\n", 1, "must give 'address'"),
        (GOOD + "[angle]\naddress = 1\n", 4, "[angle]: must give 'scale'"),
        (GOOD + "[connection]\nadress = 0\n", 5, "connection.adress: is not a key of"),
        ("loop = 5\n" + GOOD, 1, "[loop]: must be a table"),
        ("pressure = [1]\n", 1, "[pressure]: must be a table"),
        (GOOD + "[valvez]\n", 4, "[valvez]: is not a section"),
        ("[pressure]\naddress = 0\nscale = nan\n", 3, "pressure.scale: must be"),
    ],
)
def test_a_bad_value_or_type_names_file_line_and_key(tmp_path, text, line, needle):
    path = _write_checks(tmp_path, text)
    with pytest.raises(DatasetError) as info:
        load_rig_config(path)
    message = str(info.value)
    assert message.startswith(f"{path}:{line}: "), message
    assert info.value.file == str(path) and info.value.line == line
    assert needle in message and "\n" not in message


def test_the_template_and_its_values_load_unchanged(tmp_path):
    config = RigConfig()
    assert load_rig_config(_write_checks(tmp_path, config.to_toml())) == config
    loaded = load_rig_config(_write_checks(tmp_path, GOOD + "[loop]\nperiod_s = 0.002\n"))
    assert loaded.pressure.scale == 0.0001 and loaded.period_s == 0.002
