"""A control run knows where its models hold: the supported pressure of the design, checked."""

from __future__ import annotations

import warnings

import pytest

from softbend.control.runs import simulate_control
from softbend.control.setup import beyond_support, prepare_control


def test_the_setup_records_the_pressure_the_shipped_mlp_was_trained_to():
    # Table 1's FEM sweep of (100,6,2,2,5,8) stops at 300° at 0.17 MPa: past it, no data.
    setup = prepare_control(supply_mpa=0.2)
    assert setup.supported_mpa == pytest.approx(0.17)
    assert len(setup.support_notes) == 1 and "up to 0.17 MPa only" in setup.support_notes[0]
    assert beyond_support(setup, 0.15) is None
    line = beyond_support(setup, 0.18)
    assert line is not None and "0.18 MPa" in line and "0.17 MPa" in line


def test_strict_refuses_a_supply_past_the_support_and_accepts_one_inside():
    with pytest.raises(ValueError, match=r"--strict.*0\.17 MPa"):
        prepare_control(supply_mpa=0.2, strict=True)
    setup = prepare_control(supply_mpa=0.17, strict=True)
    assert setup.support_notes == []


def test_a_run_that_reaches_past_the_support_warns_and_says_so(tmp_path):
    with pytest.warns(UserWarning, match="past the 0.17 MPa"):
        high = simulate_control(reference="step:295", duration_s=3.0)
    assert high.summary["support"]["beyond"] is True
    assert high.summary["support"]["max_pressure_mpa"] > 0.17
    with warnings.catch_warnings():
        warnings.simplefilter("error")  # a run that stays inside: no warning at all
        low = simulate_control(reference="step:60", duration_s=3.0)
    assert low.summary["support"]["beyond"] is False
    assert low.summary["support"]["max_pressure_mpa"] < 0.17


def test_a_loop_run_keeps_the_same_watch_on_where_its_model_holds():
    from softbend.control.runs import plan_loop

    with pytest.raises(ValueError, match=r"--strict.*0\.17 MPa"):
        plan_loop(supply_mpa=0.2, strict=True)
    plan = plan_loop(reference="step:295", duration_s=1.5, supply_mpa=0.2)
    with pytest.warns(UserWarning, match="past the 0.17 MPa"):
        high = plan.run()
    support = high.summary["support"]
    assert support["beyond"] is True and support["supported_mpa"] == pytest.approx(0.17)
    assert support["max_pressure_mpa"] > 0.17
    with warnings.catch_warnings():
        warnings.simplefilter("error")
        low = plan_loop(reference="step:60", duration_s=1.5, supply_mpa=0.2).run()
    assert low.summary["support"]["beyond"] is False
