"""Every bad rig TOML is one DatasetError naming the file, the line and the key."""

import pytest

from softbend.control.rigconfig import RigConfig, load_rig_config
from softbend.errors import DatasetError, LimitError

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
            "The 'timeout_s' of [connection] of the rig config must be a number. "
            'Got "0.05" (a string) instead.',
        ),
        (GOOD + '[loop]\nperiod_s = "0.001"\n', 5, "'period_s' of [loop]"),
        (GOOD + '[safety]\nmax_pressure_mpa = "0.2"\n', 5, "'max_pressure_mpa' of [safety]"),
        (GOOD + "[connection]\nhost = 5\n", 5, "'host' of [connection] of the rig config must be"),
        (GOOD + "[connection]\nhost = 1979-05-27\n", 5, "(a date or time)"),
        (GOOD + "[connection]\nstopbits = true\n", 5, "must be an integer. Got true (a boolean)"),
        (GOOD + "[connection]\nport = 502.0\n", 5, "'port' of [connection]"),
        (GOOD + "[valves]\ninlet_coil = [0]\n", 5, "'inlet_coil' of [valves]"),
        ("[pressure]\naddress = 0\nscale = 1\nsigned = 1\n", 4, "'signed' of [pressure]"),
        (GOOD + "[safety]\nmax_pressure_mpa = -0.2\n", 5, "'max_pressure_mpa' of [safety]"),
        (GOOD + "[safety]\nmax_pressure_mpa = nan\n", 5, "'max_pressure_mpa' of [safety]"),
        (
            GOOD + "[safety]\nvalid_min_mpa = -5.0\n",
            5,
            "The 'valid_min_mpa' of [safety] of the rig config must be a plausible gauge "
            "pressure (-0.1013 to 2 MPa). Got -5.0 instead.",
        ),
        (GOOD + "[safety]\nmax_pressure_mpa = 5.0\nvalid_max_mpa = 8.0\n", 5, "plausible"),
        ("[pressure]\naddress = 3\n", 1, "must give 'scale' (no default fits every sensor)"),
        ("[pressure]\nscale = 0.01\n", 1, "must give 'address'"),
        (GOOD + "[angle]\naddress = 1\n", 4, "The [angle] of the rig config must give 'scale'"),
        (GOOD + "[connection]\nadress = 0\n", 5, "key 'adress' of [connection]"),
        ("loop = 5\n" + GOOD, 1, "The [loop] of the rig config must be a table"),
        ("pressure = [1]\n", 1, "The [pressure] of the rig config must be a table"),
        (GOOD + "[valvez]\n", 4, "section 'valvez'"),
        ("[pressure]\naddress = 0\nscale = nan\n", 3, "'scale' of [pressure]"),
    ],
)
def test_a_bad_value_or_type_names_file_line_and_key(tmp_path, text, line, needle):
    path = _write(tmp_path, text)
    with pytest.raises(DatasetError) as info:
        load_rig_config(path)
    message = str(info.value)
    assert message.startswith(f"{path}, line {line}: "), message
    assert needle in message and "\n" not in message


def test_a_toml_syntax_error_names_the_file_line_and_column(tmp_path):
    path = _write(tmp_path, GOOD + "[safety]\nmax_pressure_mpa = = 0.2\n")
    with pytest.raises(DatasetError) as info:
        load_rig_config(path)
    assert str(info.value) == f"{path}, line 5, column 20: not valid TOML: Invalid value."


def test_deep_nesting_and_bad_bytes_are_one_line(tmp_path):
    # the nesting limit of JSON files, counted on the text before the parser sees it
    path = _write(tmp_path, "[pressure]\naddress = 0\nx = " + "[" * 20_000 + "]" * 20_000 + "\n")
    with pytest.raises(DatasetError) as info:
        load_rig_config(path)
    assert str(info.value).startswith(f"{path}, line 3: nested 20,000 levels deep under the key")
    assert "SOFTBEND_MAX_NESTING" in str(info.value)
    path.write_text("[pressure]\naddress = 0\n" + "[a" + ".b" * 100 + "]\nc = 1\n")
    with pytest.raises(DatasetError, match="SOFTBEND_MAX_NESTING"):
        load_rig_config(path)  # tables nested by dotted headers: the same limit
    path.write_bytes(b"[pressure]\n# a\x00b\n")
    with pytest.raises(DatasetError, match=f"{path}: the rig config is not text"):
        load_rig_config(path)
    path.write_bytes(b"\xff\xfe[pressure]\n")
    with pytest.raises(DatasetError, match=f"{path}: .*not UTF-8 text"):
        load_rig_config(path)


def test_a_rig_config_over_the_size_limit_is_refused(tmp_path, monkeypatch):
    monkeypatch.setenv("SOFTBEND_MAX_FILE_MIB", "1")
    path = _write(tmp_path, GOOD + "# " + "x" * 2**21 + "\n")
    with pytest.raises(LimitError, match="SOFTBEND_MAX_FILE_MIB"):
        load_rig_config(path)


def test_from_dict_refuses_wrong_types_without_a_traceback():
    with pytest.raises(DatasetError, match="the rig config: The 'period_s' of \\[loop\\]"):
        RigConfig.from_dict({"pressure": {"address": 0, "scale": 1.0}, "loop": {"period_s": "1"}})
    with pytest.raises(DatasetError, match="must be a table of keys"):
        RigConfig.from_dict([1, 2])


def test_the_template_and_its_values_load_unchanged(tmp_path):
    config = RigConfig()
    assert load_rig_config(_write(tmp_path, config.to_toml())) == config
    loaded = load_rig_config(_write(tmp_path, GOOD + "[loop]\nperiod_s = 0.002\n"))
    assert loaded.pressure.scale == 0.0001 and loaded.period_s == 0.002
