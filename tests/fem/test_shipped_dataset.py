"""The shipped Table 1 FEM dataset is what softbend's FEM computes today.

A design of the dataset is solved again with the default FEM options and every
output is compared: the number of outputs, the stop, and every angle and tip
position. Interpolated outputs depend slightly on the sequence of load steps
(any change to the solver's path, e.g. the chord steps, moves them by a few
hundredths of a degree: 0.064° at most on the designs below), so the tolerance
is 0.1° and 0.1 mm (the campaign's acceptance for a faster solver is 0.2° or 0.2 %).
"""

from __future__ import annotations

import numpy as np
import pytest

from softbend.campaign.backends import default_pressures_mpa
from softbend.datasets import table1_fem, table1_fem_designs
from softbend.design import sfrba_design
from softbend.fem import FEMOptions, simulate

ANGLE_TOL_DEG = 0.1
TIP_TOL_MM = 0.1


@pytest.fixture(scope="module")
def shipped():
    designs = table1_fem_designs()
    return designs[designs["status"] == "done"].reset_index(drop=True), table1_fem()


def _check_design(design_row, samples) -> None:
    design = sfrba_design(
        *(float(design_row[c]) for c in ("l_mm", "r_mm", "t_mm", "b_mm", "phi_deg", "lc_mm"))
    )
    assert design_row["options_sha256"] == FEMOptions().digest(), (
        "the shipped data were made with other FEM options than today's defaults"
    )
    rows = samples[samples["design_id"] == design.design_id].sort_values("pressure_mpa")
    result = simulate(design, default_pressures_mpa())
    assert result.stats["stop_reason"].split(" ")[:2] == design_row["stop_reason"].split(" ")[:2]
    assert len(result.pressure_mpa) == len(rows)
    np.testing.assert_array_equal(result.converged, rows["converged"].to_numpy())
    ok = result.converged
    np.testing.assert_allclose(result.pressure_mpa, rows["pressure_mpa"], atol=1e-12)
    np.testing.assert_allclose(
        result.angle_deg[ok], rows["angle_deg"].to_numpy()[ok], atol=ANGLE_TOL_DEG, rtol=0
    )
    for column in ("tip_x_mm", "tip_z_mm"):
        np.testing.assert_allclose(
            getattr(result, column)[ok], rows[column].to_numpy()[ok], atol=TIP_TOL_MM, rtol=0
        )


def test_the_quickest_shipped_design_solves_to_the_same_outputs(shipped):
    designs, samples = shipped
    _check_design(designs.loc[designs["wall_time_s"].idxmin()], samples)


@pytest.mark.slow
@pytest.mark.parametrize("quantile", [0.0, 0.25, 0.5, 0.75, 1.0])
def test_designs_across_the_space_solve_to_the_same_outputs(shipped, quantile):
    designs, samples = shipped
    # Spread over the table: the designs at these quantiles of their position in it.
    ordered = designs.sort_values(["l_mm", "r_mm", "t_mm", "b_mm", "phi_deg", "lc_mm"])
    row = ordered.iloc[round(quantile * (len(ordered) - 1))]
    _check_design(row, samples)
