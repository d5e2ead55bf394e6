"""``softbend control rig-config`` keeps hand edits; rig TOML errors are one line, exit 2."""

import pytest

from softbend.cli import main


def _one_line(capsys):
    err = capsys.readouterr().err.strip().splitlines()
    assert len(err) == 1, err
    assert err[0].startswith("softbend: error: ")
    return err[0]


def test_rig_config_refuses_to_overwrite_a_file_without_force(tmp_path, capsys):
    path = tmp_path / "rig.toml"
    assert main(["control", "rig-config", "--out", str(path)]) == 0
    capsys.readouterr()
    edited = path.read_text(encoding="utf-8").replace("port = 5020", "port = 1502")
    path.write_text(edited, encoding="utf-8")
    assert main(["control", "rig-config", "--out", str(path), "--port", "5099"]) == 2
    line = _one_line(capsys)
    assert str(path) in line and "--force" in line and "'--out'" in line
    assert path.read_text(encoding="utf-8") == edited  # the hand edit is kept
    assert main(["control", "rig-config", "--out", str(path), "--port", "5099", "--force"]) == 0
    assert "port = 5099" in path.read_text(encoding="utf-8")
    assert not [p.name for p in tmp_path.iterdir() if p.name != "rig.toml"]  # no temporary left


def test_rig_config_refuses_a_bad_port_naming_the_option(tmp_path, capsys):
    assert (
        main(["control", "rig-config", "--out", str(tmp_path / "r.toml"), "--port", "70000"]) == 2
    )
    assert "--port: must be an integer in [0, 65535]; got 70000" in _one_line(capsys)
    assert not (tmp_path / "r.toml").exists()


@pytest.mark.parametrize(
    ("text", "needles"),
    [
        (
            '[pressure]\naddress = 0\nscale = 1e-4\n[connection]\ntimeout_s = "0.05"\n',
            [":5: connection.timeout_s: must be a number"],
        ),
        ("[pressure]\naddress = = 0\n", ["line 2, column 11", "not valid TOML"]),
        ("[pressure]\naddress = 3\n", [":1: [pressure]: must give 'scale'"]),
    ],
)
def test_run_and_serve_refuse_a_bad_rig_toml_in_one_line(tmp_path, capsys, text, needles):
    config = tmp_path / "rig.toml"
    config.write_text(text, encoding="utf-8")
    for command in (["run", "--rig", "modbus", "--out", str(tmp_path / "o")], ["serve"]):
        assert main(["control", *command, "--config", str(config)]) == 2
        line = _one_line(capsys)
        assert str(config) in line
        for needle in needles:
            assert needle in line


@pytest.mark.parametrize("supply", ["-0.1", "0", "50", "nan"])
def test_an_absurd_supply_pressure_is_one_line(tmp_path, capsys, supply):
    args = ["control", "simulate", "--out", str(tmp_path / "o"), "--supply", supply]
    assert main(args) == 2
    line = _one_line(capsys)
    assert "--supply: must be a gauge pressure in (0, 2] MPa" in line


def test_simulate_never_leaves_half_an_output(tmp_path, capsys, monkeypatch):
    import errno

    out = tmp_path / "run"
    args = ["control", "simulate", "--out", str(out), "--duration", "0.5", "--json"]
    assert main(args) == 0
    capsys.readouterr()
    before = {name: (out / name).read_bytes() for name in ("run.csv", "metrics.json", "run.png")}

    def full_disk(run, path, title):
        with open(path, "wb") as handle:
            handle.write(b"\x89PNG half")
        raise OSError(errno.ENOSPC, "No space left on device", str(path))

    monkeypatch.setattr("softbend.reports.control_figures.run_figure", full_disk)
    assert main([*args[:-1], "--seed", "3"]) == 2
    line = _one_line(capsys)
    assert "'--out'" in line and "No space left on device" in line
    assert (out / "run.png").read_bytes() == before["run.png"]
    listed = sorted(p.name for p in out.iterdir())
    assert listed == [".softbend-manifest.json", "metrics.json", "run.csv", "run.png"]
