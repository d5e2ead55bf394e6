"""``softbend control simulate`` with an identified model as the plant or the rig's source,
and the design's trust signal in its table and JSON."""

import json

import pytest

from softbend.cli import main

from ..control.identified_models import DELAY_S, TAU_S, save_fopdt
from .conftest import one_error_line

SHIPPED_MLP = "src/softbend/data/transfer/table1_fem_mlp.json"


@pytest.fixture(scope="module")
def fopdt(tmp_path_factory):
    return save_fopdt(tmp_path_factory.mktemp("ident") / "model.json")


def test_identified_plant_in_table_and_json(tmp_path, capsys, fopdt):
    out = tmp_path / "ctl"
    args = ["control", "simulate", "--plant", str(fopdt), "--reference", "step:60:0",
            "--duration", "0.5", "--out", str(out)]  # fmt: skip
    assert main(args) == 0
    table = capsys.readouterr().out
    assert "on the identified actuator" in table
    assert "identified model" in table and "(arx na=1 nb=4)" in table
    assert "its steady-state θ(p), 0–0.2 MPa" in table
    saved = json.loads((out / "metrics.json").read_text())
    assert saved["plant_description"].startswith(f"identified model {fopdt} (arx na=1 nb=4)")
    assert saved["design"] is None and saved["design_supported"] is None


def test_identified_plant_refuses_design(tmp_path, capsys, fopdt):
    args = ["control", "simulate", "--plant", str(fopdt), "--design", "100,6,2,2,5,8",
            "--out", str(tmp_path / "x")]  # fmt: skip
    assert main(args) == 2
    line = one_error_line(capsys)
    assert "--design" in line and "identified" in line and "--model" in line


@pytest.mark.parametrize(
    ("options", "words"),
    [
        ({"inputs": ("p1_kpa", "p2_kpa")}, "exactly one input, a pressure"),
        ({"outputs": ("x_mm",)}, "one output that is an angle in degrees"),
        ({"time": "t"}, "a time column of known unit"),
    ],
)
def test_identified_plant_refusals(tmp_path, capsys, options, words):
    path = save_fopdt(tmp_path / "model.json", **options)
    args = ["control", "simulate", "--plant", str(path), "--out", str(tmp_path / "x")]
    assert main(args) == 2
    line = one_error_line(capsys)
    assert "--plant" in line and words in line


def test_rig_from_sets_lag_and_delay(tmp_path, capsys, fopdt):
    args = ["control", "simulate", "--rig-from", str(fopdt), "--duration", "0.3",
            "--out", str(tmp_path / "ctl"), "--json"]  # fmt: skip
    assert main(args) == 0
    payload = json.loads(capsys.readouterr().out)
    assert payload["rig"]["angle_time_constant_s"] == pytest.approx(TAU_S, rel=1e-3)
    assert payload["rig"]["valve_delay_s"] == pytest.approx(DELAY_S)
    assert payload["rig_from"]["used"] == ["angle_time_constant_s", "valve_delay_s"]
    assert payload["rig_from"]["reading"] == "pressure_mpa → angle_deg"


def test_rig_from_out_of_range_is_one_line(tmp_path, capsys):
    slow = save_fopdt(tmp_path / "slow.json", tau_s=2.0, period_s=0.1)
    args = ["control", "simulate", "--rig-from", str(slow), "--out", str(tmp_path / "x")]
    assert main(args) == 2
    line = one_error_line(capsys)
    assert "--rig-from" in line and "angle_time_constant_s range [0, 1] s" in line


def test_design_outside_training_data_says_so(tmp_path, capsys):
    args = ["control", "simulate", "--design", "8,6,2,2,5,8", "--plant", SHIPPED_MLP,
            "--reference", "square:90:4", "--duration", "0.3",
            "--out", str(tmp_path / "ctl")]  # fmt: skip
    assert main(args) == 0
    captured = capsys.readouterr()
    assert "l_mm 8 outside [100, 160]" in captured.err  # the warning
    assert "design in the model's training data" in captured.out
    assert "no (l_mm 8 outside [100, 160])" in captured.out
    saved = json.loads((tmp_path / "ctl" / "metrics.json").read_text())
    assert saved["design_supported"] is False
    assert saved["design_outside"] == ["l_mm 8 outside [100, 160]"]


def test_design_inside_training_data_says_yes(tmp_path, capsys):
    args = ["control", "simulate", "--plant", SHIPPED_MLP, "--duration", "0.3",
            "--out", str(tmp_path / "ctl"), "--json"]  # fmt: skip
    assert main(args) == 0
    payload = json.loads(capsys.readouterr().out)
    assert payload["design_supported"] is True and payload["design_outside"] == []


def test_design_outside_strict_refuses(tmp_path, capsys):
    args = ["control", "simulate", "--design", "8,6,2,2,5,8", "--plant", SHIPPED_MLP,
            "--strict", "--out", str(tmp_path / "ctl")]  # fmt: skip
    assert main(args) == 2
    assert "l_mm 8 outside [100, 160]" in one_error_line(capsys)


def test_identified_plant_with_a_controller_model_is_a_mismatch(tmp_path, capsys, fopdt):
    args = ["control", "simulate", "--plant", str(fopdt), "--model", SHIPPED_MLP,
            "--duration", "0.3", "--out", str(tmp_path / "ctl"), "--json"]  # fmt: skip
    assert main(args) == 0
    payload = json.loads(capsys.readouterr().out)
    assert payload["design"] == "100,6,2,2,5,8" and payload["model_from"] == "model"
    assert payload["design_supported"] is True
    assert payload["plant_description"].startswith(f"identified model {fopdt}")
