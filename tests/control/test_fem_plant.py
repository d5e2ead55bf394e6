"""The FEM as the plant of a design outside Table 1: swept once, cached, its compliance used."""

from __future__ import annotations

import json

import numpy as np
import pytest

from softbend.control import fem_plant as fp
from softbend.control.plants import in_table1
from softbend.design import sfrba_design

OWN = sfrba_design(130, 7, 2.5, 3, 10, 9)


@pytest.fixture
def coarse(tmp_path, monkeypatch):
    """A private cache folder and a coarse mesh (seconds, not a minute)."""
    from softbend.fem import FEMOptions

    monkeypatch.setenv("SOFTBEND_CACHE_DIR", str(tmp_path))
    return FEMOptions(maxh_mm=8.0)


def test_table1_membership():
    assert in_table1(sfrba_design(100, 6, 2, 2, 5, 8))
    assert not in_table1(OWN)


def test_a_design_is_swept_once_then_read_from_the_cache(coarse, tmp_path, monkeypatch):
    curve = fp.fem_curve(OWN, coarse)
    entries = list((tmp_path / "fem-plants").glob("*.json"))
    assert len(entries) == 1 and entries[0].name.startswith(OWN.design_id)
    # Physics: the angle grows with pressure from ~0, the cavity swells (dV/dp > 0) and the
    # compliance is of the order of the cavity volume per 0.1 MPa.
    assert abs(curve.angle_deg[0]) < 15.0 and np.all(np.diff(curve.angle_deg) > 0)
    k = curve.compliance_mm3_per_mpa(0.2)
    assert k > 0 and 0.1 < k * 0.1 / OWN.cavity_volume_mm3 < 10

    def no_solve(*args, **kwargs):
        raise AssertionError("the cached curve must be used")

    monkeypatch.setattr("softbend.fem.simulate", no_solve)
    again = fp.fem_curve(OWN, coarse)
    np.testing.assert_array_equal(again.angle_deg, curve.angle_deg)
    table = again.table()
    assert table(0.0) == pytest.approx(curve.angle_deg[0], abs=1e-6)


@pytest.mark.slow
def test_a_damaged_cache_entry_is_solved_again(coarse, tmp_path):
    curve = fp.fem_curve(OWN, coarse)
    (entry,) = (tmp_path / "fem-plants").glob("*.json")
    entry.write_text(json.dumps({"design": OWN.as_dict(), "angle_deg": [1.0]}))
    again = fp.fem_curve(OWN, coarse)
    np.testing.assert_allclose(again.angle_deg, curve.angle_deg)
    assert json.loads(entry.read_text())["angle_deg"] == curve.angle_deg.tolist()


def test_control_simulate_uses_the_designs_own_sweep_and_compliance(monkeypatch, tmp_path, capsys):
    """A synthetic sweep stands in for the FEM: 600 deg/MPa, dV/dp 90 000 mm³/MPa."""
    from softbend.cli import main

    p = np.linspace(0.0, 0.3, 31)
    curve = fp.FEMCurve(OWN, p, 600.0 * p, p, np.full(p.size, 90_000.0), "reached 300°")
    calls = []

    def fake(design, *args, **kwargs):
        calls.append(design)
        return curve

    monkeypatch.setattr(fp, "fem_curve", fake)
    args = ["control", "simulate", "--plant", "fem", "--design", "130,7,2.5,3,10,9",
            "--duration", "2", "--json", "-o", str(tmp_path / "run")]  # fmt: skip
    assert main(args) == 0, capsys.readouterr().err
    payload = json.loads(capsys.readouterr().out)
    assert calls and all(d == OWN for d in calls)
    assert payload["rig"]["compliance_mm3_per_mpa"] == pytest.approx(90_000.0)
