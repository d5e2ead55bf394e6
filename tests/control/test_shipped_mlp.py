"""The loop of paper B with the shipped FEM-trained MLP as plant map and virtual sensor."""

import pytest

from softbend.control.controllers import BangBang, PressurePI, mlp_virtual_sensor
from softbend.control.experiments import run_metrics, simulate
from softbend.control.rig import AngleTable, SimulatedRig
from softbend.design import sfrba_design


@pytest.fixture(scope="module")
def mlp_loop():
    from softbend.transfer.base import load_base

    model = load_base()
    design = sfrba_design(100, 6, 2, 2, 5, 8)
    return model, design, AngleTable.from_surrogate(model, design)


def test_shipped_mlp_bang_bang_and_pi_track_a_step(mlp_loop):
    model, design, table = mlp_loop
    sensor = mlp_virtual_sensor(model, design)
    assert sensor(0.05) == pytest.approx(table(0.05), abs=1e-6)  # 0.05 is on the grid
    rig = SimulatedRig(table, seed=0)
    bang = run_metrics(simulate(rig, BangBang(sensor), "step:90", 3.0))
    pi = run_metrics(simulate(rig, PressurePI(table), "step:90", 3.0))
    # paper B's order: rise about 0.1 s, MAPE a few per cent
    assert 0.03 < bang["rise_s"] < 0.3 and bang["mape_pct"] < 10
    assert pi["mape_pct"] < bang["mape_pct"] and pi["switches"] < bang["switches"]
