"""Paper B Fig. 2 pipeline: the Dragon Skin 30 fit and the FEM sweep of the Fig. 2 design."""

from __future__ import annotations

import numpy as np
import pandas as pd
import pytest

from softbend.design import parse_sfrba
from softbend.fem import FEMOptions
from softbend.pipeline.paper_b_fem import FIG2_DESIGN, run_fig2

from .conftest import Phases, pictures


@pytest.fixture(scope="module")
def fig2(tmp_path_factory):
    out = tmp_path_factory.mktemp("paper_b_fem")
    phases = Phases()
    result = run_fig2(out, phases, options=FEMOptions(maxh_mm=6.0), pmax_mpa=0.02)
    return out, result, phases


def test_yeoh_fits_dragon_skin_better_than_neo_hookean(fig2):
    _, result, _ = fig2
    fits = result.summary["dragon_skin_30_fit"]
    assert fits["yeoh"]["r2"] > fits["neo-hookean"]["r2"]
    assert result.summary["yeoh_r2"] == fits["yeoh"]["r2"] > 0.99
    assert all(f["rmse_mpa"] > 0 for f in fits.values())


def test_the_sweep_bends_with_pressure_and_gravity_only_at_zero(fig2):
    _, result, _ = fig2
    s = result.summary
    assert s["fem_design"] == str(result.design) == str(parse_sfrba(FIG2_DESIGN))
    fem, analytical = s["fem_angles_deg"], s["analytical_angles_deg"]
    assert set(fem) == set(analytical) == {"0", "0.02"}
    # The FEM carries gravity (a small angle at 0 MPa); the analytical model does not.
    assert fem["0.02"] > fem["0"] > 0.0
    assert analytical["0"] == 0.0 < analytical["0.02"]
    assert [row[0] for row in result.angles] == [0.0, 0.02]
    assert s["fem_wall_time_s"] > 0 and s["fem_stop_reason"]


def test_writes_the_sweep_table_and_keeps_the_shapes_but_draws_nothing(fig2):
    out, result, phases = fig2
    table = pd.read_csv(result.sweep.files["csv"])
    assert result.sweep.files["csv"] == out / "paper_b_fem" / "fem_sweep.csv"
    assert len(table) == len(result.sweep.result.pressure_mpa)
    pressures = result.sweep.shape_pressures_mpa
    assert pressures == sorted(pressures) and pressures[0] == 0.0
    assert pressures[-1] == pytest.approx(0.02)
    for _, outline in result.sweep.outlines:
        assert outline.ndim == 2 and outline.shape[1] == 2 and np.isfinite(outline).all()
        # The actuator is about as long as the design says (100 mm plus its cap).
        assert 90.0 < np.ptp(outline[:, 0]) < 130.0
    assert result.sweep.steps >= 1
    assert pictures(out) == []
    assert phases.all_finished()
