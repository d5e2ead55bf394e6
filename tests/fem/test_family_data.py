"""What differs between FEM families is data on the family, read by one path."""

from __future__ import annotations

from types import SimpleNamespace

import numpy as np
import pytest

from softbend.campaign.family_schema import FamilySchema
from softbend.campaign.spaces import campaign_space, check_sampled_size, space_forms
from softbend.errors import InputError, LimitError
from softbend.fem.families import get_family
from softbend.fem.run import shape_steps


def test_each_family_parses_its_design_text_and_falls_back_to_its_reference():
    sfrba, pneunet = get_family("sfrba"), get_family("pneunet")
    assert str(sfrba.parse("100,6,2,2,5,10")) == str(sfrba.parse(None)) == "100,6,2,2,5,10"
    assert str(sfrba.parse("120,6,2,2,5,10")).startswith("120")
    design = pneunet.parse("n_chambers=3")
    assert str(design).startswith("n_chambers=3,")
    with pytest.raises(InputError, match="t_mm: must be less than r_mm"):
        sfrba.parse("100,6,7,2,5,10")


def test_mesh_study_defaults_and_campaign_grids_are_the_family_s():
    sfrba, pneunet = get_family("sfrba"), get_family("pneunet")
    assert sfrba.mesh_study_defaults() == ((6.0, 5.0, 4.0, 3.0), (0.0, 0.05, 0.1))
    assert pneunet.mesh_study_defaults() == ((3.0, 2.5, 2.0), (0.0, 0.004, 0.008, 0.012))
    grid = sfrba.campaign_pressures_mpa()
    assert (len(grid), grid[-1]) == (101, 0.5)  # paper B's 0-0.5 MPa by 0.005 MPa
    assert pneunet.campaign_pressures_mpa()[-1] == pytest.approx(pneunet.pmax_mpa)
    assert sfrba.campaign_pressures_mpa(0.1, 0.05).tolist() == [0.0, 0.05, 0.1]


def test_what_a_campaign_database_records_follows_the_family():
    assert FamilySchema.of("sfrba").actuator is None  # paper B's databases predate families
    assert FamilySchema.of(None) == FamilySchema.of("sfrba")
    recorded = FamilySchema.of("pneunet")
    assert recorded.actuator is not None and recorded.parameters == get_family("pneunet").names


def test_one_space_reader_for_every_family():
    sfrba, pneunet = get_family("sfrba"), get_family("pneunet")
    assert campaign_space(None, sfrba).n_designs == 972  # Table 1, paper B's default
    assert campaign_space("lhs:5", pneunet).n_designs == 5
    assert "grid" in space_forms(pneunet) and "table1" in space_forms(sfrba)
    with pytest.raises(InputError, match="must be given for the pneunet family"):
        campaign_space(None, pneunet)
    with pytest.raises(InputError, match="applies to the sampled spaces"):
        campaign_space("table1", sfrba, ["l=60:90"])
    with pytest.raises(LimitError, match="SOFTBEND_MAX_DESIGNS"):
        check_sampled_size("sobol:99999999999999999999")
    check_sampled_size("grid:3")  # known only with the family: checked by campaign_space


def test_shapes_are_taken_at_converged_steps_inside_the_reported_range():
    steps = [SimpleNamespace(pressure_mpa=p) for p in (0.0, 0.01, 0.02, 0.03, 0.04)]
    result = SimpleNamespace(
        pressure_mpa=np.array([0.0, 0.01, 0.02, 0.03]),
        converged=np.array([True, True, True, False]),
    )
    picked = [s.pressure_mpa for s in shape_steps(steps, result, 3)]
    assert picked == [0.0, 0.01, 0.02]  # 0.03 did not converge, 0.04 lies beyond it
    assert [s.pressure_mpa for s in shape_steps(steps, result, [0.02, 0.019])] == [0.02]
