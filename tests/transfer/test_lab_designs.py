"""lab measure --design: the virtual lab measures a lab's own design (an eighth actuator)."""

from __future__ import annotations

import json

from softbend.cli import main
from softbend.transfer.measurements import load_measurements


def test_lab_measures_a_design_of_ones_own(tmp_path, capsys):
    out = tmp_path / "own.csv"
    args = ["lab", "measure", "-o", str(out), "--plant", "analytical", "--json",
            "--design", "130,7,2.5,3,10,9", "--design", "100,6,2,2,5,8",
            "--elastomer", "dragon-skin-20"]  # fmt: skip
    assert main(args) == 0, capsys.readouterr().err
    summary = json.loads(capsys.readouterr().out)
    assert [a["actuator_id"] for a in summary["actuators"]] == [
        "130,7,2.5,3,10,9", "100,6,2,2,5,8",
    ]  # fmt: skip
    data = load_measurements(out)
    assert data.metadata["lab.elastomer"] == "dragon-skin-20"
    own = data.subset(["130,7,2.5,3,10,9"])
    # Larger and softer than (100,6,2,2,5,8) at the same wall: it bends further at a pressure.
    assert own.angle_deg.max() > 90.0
    assert main(["lab", "measure", "-o", str(tmp_path / "x.csv"), "--design", "1,2"]) == 2
    assert "needs 6 values" in capsys.readouterr().err
