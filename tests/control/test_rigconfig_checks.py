"""Every bad rig TOML is one DatasetError naming the file, the line and the key."""

import pytest

from softbend.control.rigconfig import RigConfig, load_rig_config
from softbend.errors import DatasetError

GOOD = "[pressure]\naddress = 0\nscale = 0.0001\n"


def _write(tmp_path, text):
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
    path = _write(tmp_path, text)
    with pytest.raises(DatasetError) as info:
        load_rig_config(path)
    message = str(info.value)
    assert message.startswith(f"{path}:{line}: "), message
    assert info.value.file == str(path) and info.value.line == line
    assert needle in message and "\n" not in message


def test_the_template_and_its_values_load_unchanged(tmp_path):
    config = RigConfig()
    assert load_rig_config(_write(tmp_path, config.to_toml())) == config
    loaded = load_rig_config(_write(tmp_path, GOOD + "[loop]\nperiod_s = 0.002\n"))
    assert loaded.pressure.scale == 0.0001 and loaded.period_s == 0.002
