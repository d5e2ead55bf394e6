"""lab measure --design: the virtual lab measures a lab's own design (an eighth actuator)."""

from __future__ import annotations

import json

import numpy as np

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


def test_lab_measures_with_the_lab_s_own_material(tmp_path, capsys):
    # The silicone given whole (a materials fit of one's own tensile test) replaces the
    # shipped test's Yeoh fit: recorded in the header, and a softer silicone bends further.
    fits = tmp_path / "fits"
    assert main(["materials", "fit", "dragon-skin-10-medium", "--models", "yeoh",
                 "-o", str(fits)]) == 0  # fmt: skip
    base = ["lab", "measure", "--plant", "analytical", "--design", "130,7,2.5,3,10,9", "--json"]
    assert main([*base, "-o", str(tmp_path / "ds30.csv")]) == 0
    assert main([*base, "-o", str(tmp_path / "own.csv"), "--material", str(fits / "fit.json")]) == 0
    capsys.readouterr()
    own, ds30 = load_measurements(tmp_path / "own.csv"), load_measurements(tmp_path / "ds30.csv")
    assert own.metadata["lab.material"] == str(fits / "fit.json")
    assert "yeoh fit" in own.metadata["lab.material_source"]
    assert "lab.elastomer" not in own.metadata and "lab.elastomer" in ds30.metadata

    def at(data, p):
        return data.angle_deg[np.isclose(data.frame["pressure_mpa"].to_numpy(), p)][0]

    assert at(own, 0.05) > 1.2 * at(ds30, 0.05)  # Dragon Skin 10 is softer
    bad = [*base, "-o", str(tmp_path / "bad.csv"), "--material", "no-such-silicone"]
    assert main(bad) == 2
    err = capsys.readouterr().err.strip().splitlines()
    assert len(err) == 1 and "--material" in err[0] and "dragon-skin-30" in err[0]
