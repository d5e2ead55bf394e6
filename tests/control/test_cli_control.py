"""``softbend control simulate`` in-process."""

import json

import pytest

from softbend.cli import main


def test_bad_controller_is_one_line(capsys):
    code = main(["control", "simulate", "--out", "x", "--controller", "pid"])
    assert code == 2
    err = capsys.readouterr().err.strip().splitlines()
    assert len(err) == 1 and "'controller'" in err[0] and "'bang-bang'" in err[0]


def test_bad_reference_is_one_line(capsys):
    assert main(["control", "simulate", "--out", "x", "--reference", "step:x"]) == 2
    assert "'amplitude_deg' of reference step" in capsys.readouterr().err


@pytest.mark.parametrize("controller", ["bang-bang", "pressure-pi"])
def test_simulate_writes_run(tmp_path, capsys, controller):
    out = tmp_path / "run"
    code = main(
        [
            "control",
            "simulate",
            "--out",
            str(out),
            "--duration",
            "1.5",
            "--controller",
            controller,
            "--json",
        ]
    )
    assert code == 0
    payload = json.loads(capsys.readouterr().out)
    assert payload["synthetic"] is True and payload["metrics"]["rising_edges"] == 1
    assert (out / "run.csv").read_text().startswith("t_s,reference_deg,angle_deg")
    assert json.loads((out / "metrics.json").read_text())["controller"] == controller
