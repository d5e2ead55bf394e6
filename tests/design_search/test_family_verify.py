"""--verify of an actuator whose description names an FEM family other than paper B's.

A stand-in family plays the FEM in closed form: ``angle = K · p · (n_cells + width_mm)``
(degrees, MPa), and its sweep stops where "neighbouring walls touch", at
``p_touch = 0.01 · width_mm + 0.0005`` MPa, with a stop reason as the PneuNet's.
The surrogate is a polynomial fitted to the same closed form in kPa over 0 to
50 kPa, every design swept to the end: it knows nothing of the walls touching,
as a surrogate trained on the swept range does not know where a sweep would stop.
"""

from __future__ import annotations

import dataclasses
import json
import math

import numpy as np
import pytest

from softbend.actuators import Actuator, Design
from softbend.cli import main
from softbend.design_search.search import find_designs
from softbend.design_search.spec import Specification, Target
from softbend.design_search.verify import verify_candidates, verify_family, verify_skipped
from softbend.errors import InputError
from softbend.fem.families import FEM_FAMILIES
from softbend.surrogates.persistence import load_surrogate

from ..cli.conftest import one_error_line
from ..stand_ins import CELL_PARAMETERS, registered_family, stand_in_family, train_closed_form

K_DEG_PER_MPA = 1000.0
PARAMETERS = CELL_PARAMETERS[:2]  # n_cells, width_mm


def touch_mpa(width_mm: float) -> float:
    """Where the stand-in's walls touch, MPa."""
    return 0.01 * width_mm + 0.0005


def fem_angle(n: float, width_mm: float, p_mpa: float) -> float:
    """The stand-in FEM's angle, degrees."""
    return K_DEG_PER_MPA * p_mpa * (n + width_mm)


TOUCHY = stand_in_family(
    "touchy",
    PARAMETERS,
    K_DEG_PER_MPA,
    title="stand-in actuator whose walls touch",
    actuator_title="stand-in",
    reference={"n_cells": 3, "width_mm": 2.0},
    pmax_mpa=0.05,
    pstep_mpa=0.001,
    cap=("width_mm", 2.5),  # refused: wider than 2.5 mm with 5 cells
    cap_slack=1e-9,
    touch_mpa=touch_mpa,
)


def _actuator(fem_family: str | None) -> Actuator:
    """The surrogate's description: pressures in kPa, the family named."""
    return Actuator(
        name="touchy-lab",
        title="stand-in, as a lab's table describes it",
        parameters=PARAMETERS,
        pressure_column="p_kpa",
        pressure_unit="kPa",
        fem_family=fem_family,
    )


@pytest.fixture(autouse=True)
def touchy():
    """The stand-in family, registered for the test and removed after it."""
    with registered_family(TOUCHY) as family:
        yield family


@pytest.fixture(scope="module")
def model(tmp_path_factory):
    return train_closed_form(tmp_path_factory.mktemp("touchy"), _actuator("touchy"), fem_angle)


@pytest.fixture(scope="module")
def unknown_family_model(tmp_path_factory):
    return train_closed_form(
        tmp_path_factory.mktemp("nosuch"), _actuator("nosuch-family"), fem_angle
    )


def _spec(model, angle: float, at_kpa: float) -> Specification:
    target = Target("angle_at", angle_deg=angle, pressure_mpa=at_kpa, unit="kPa")
    return Specification(target, actuator=load_surrogate(model).actuator)


def test_verify_sweeps_each_candidate_with_the_family_and_reports_the_stops(model, tmp_path):
    # 80° at 20 kPa: n + w = 4 ± 0.15; w = 1.9 touches at 19.5 kPa, before the pressure.
    result = find_designs(model, _spec(model, 80.0, 20.0), top=20, distinct=False)
    assert verify_skipped(result) is None
    db = tmp_path / "verify.duckdb"
    verified = verify_candidates(result, 20, backend="fem", workers=1, db_path=db)
    assert verified == result.candidates and len(verified) >= 3
    assert result.verified_by == {"backend": "fem", "family": "touchy", "designs": len(verified)}
    stopped = reached = 0
    for c in verified:
        n, w = c.design.as_array()
        assert c.pressure_mpa == 20.0  # the surrogate's unit, kPa
        if touch_mpa(w) < 0.020:
            stopped += 1
            assert math.isnan(c.fem_angle_deg) and c.fem_meets is False
            assert c.fem_stop == f"neighbouring walls touch at {touch_mpa(w) * 1000:.2f} kPa"
        else:
            reached += 1
            assert c.fem_stop is None
            assert c.fem_angle_deg == pytest.approx(fem_angle(n, w, 0.020))  # 20 kPa as MPa
            assert c.fem_angle_deg == pytest.approx(c.angle_deg, abs=1e-6)  # exact surrogate
            assert c.fem_meets == (abs(c.fem_angle_deg - 80.0) <= 3.0)
            p, _ = c.fem_curve
            assert p[-1] == pytest.approx(0.020)  # swept to the pressure checked, no further
    assert stopped and reached
    payload = json.loads(json.dumps(result.to_dict()))
    assert payload["verified"] == {"backend": "fem", "family": "touchy", "designs": len(verified)}
    stops = [c["fem_stop_reason"] for c in payload["candidates"]]
    assert any(s and "touch" in s for s in stops) and None in stops


def test_a_design_the_family_refuses_is_reported_not_swept(model):
    # 150° at 20 kPa: n + w = 7.5 ± 0.15, n = 5 and w 2.4 to 2.6; the family refuses w > 2.5.
    result = find_designs(model, _spec(model, 150.0, 20.0), top=10, distinct=False)
    verified = verify_candidates(result, 10, backend="fem", workers=1)
    widths = {round(c.design.as_array()[1], 6): c for c in verified}
    assert set(widths) == {2.4, 2.5, 2.6}
    refused = widths[2.6]
    assert math.isnan(refused.fem_angle_deg) and refused.fem_meets is False
    assert refused.fem_stop.startswith("the touchy family refuses the design: width_mm")
    assert widths[2.5].fem_meets and widths[2.5].fem_angle_deg == pytest.approx(150.0)


def test_another_backend_is_skipped_with_the_family_named(model):
    result = find_designs(model, _spec(model, 80.0, 20.0), top=2)
    assert verify_candidates(result, 2, backend="analytical") == []
    assert result.verify_skipped == (
        "the analytical backend does not model actuator touchy-lab (the FEM of its family "
        "touchy does: --backend fem)"
    )
    assert result.verified_by is None and all(c.fem_meets is None for c in result.candidates)


def test_a_family_no_softbend_simulates_is_one_clear_error(unknown_family_model, tmp_path, capsys):
    result = find_designs(unknown_family_model, _spec(unknown_family_model, 80.0, 20.0), top=2)
    with pytest.raises(InputError, match=r"FEM family 'nosuch-family'.*sfrba.*touchy") as info:
        verify_candidates(result, 1)
    assert info.value.key == "model"
    args = ["design", "find", "--model", str(unknown_family_model), "--angle", "80", "--at",
            "20", "--verify", "1", "-o", str(tmp_path / "out")]  # fmt: skip
    assert main(args) == 2
    line = one_error_line(capsys)
    assert "FEM family 'nosuch-family'" in line and "--verify cannot sweep" in line
    assert not (tmp_path / "out").exists()


def test_a_family_of_other_parameters_is_refused(model):
    other = dataclasses.replace(
        TOUCHY,
        title="stand-in with other parameters",
        actuator=Actuator(name="touchy", title="other", parameters=PARAMETERS[::-1]),
        reference={"width_mm": 2.0, "n_cells": 3},
    )
    FEM_FAMILIES.register("touchy", other, replace=True)
    space = _spec(model, 80.0, 20.0).space
    with pytest.raises(InputError, match="not those of the FEM family 'touchy'"):
        verify_family(space)


def test_the_cli_table_names_the_family_and_the_stops(model, tmp_path, capsys):
    out = tmp_path / "cli"
    args = ["design", "find", "--model", str(model), "--angle", "80", "--at", "20",
            "--neighbours", "--top", "6", "--verify", "6", "--workers", "1",
            "-o", str(out)]  # fmt: skip
    assert main(args) == 0
    text = capsys.readouterr().out
    assert "FEM family touchy" in text and "stopped" in text
    assert "neighbouring walls touch at 19.50 kPa" in text
    record = json.loads((out / "search.json").read_text())
    assert record["verified"]["family"] == "touchy"


def test_replace_stopped_verifies_the_next_candidates_until_k_reach_the_pressure(model):
    # 80° at 20 kPa: (3, 1.0) meets it exactly on the surrogate and touches at 10.5 kPa.
    result = find_designs(model, _spec(model, 80.0, 20.0), top=20, distinct=False)
    verified = verify_candidates(result, 2, backend="fem", workers=1, replace_stopped=True)
    assert verified == result.candidates[: len(verified)]  # in rank order, none skipped
    reached = [c for c in verified if c.fem_stop is None]
    stopped = [c for c in verified if c.fem_stop is not None]
    assert len(reached) == 2 and verified[-1] is reached[-1] and stopped
    assert all(touch_mpa(c.design.as_array()[1]) < 0.020 for c in stopped)
    assert all(touch_mpa(c.design.as_array()[1]) >= 0.020 for c in reached)
    assert result.verified_by["designs"] == len(verified)
    assert all(c.fem_meets is None for c in result.candidates[len(verified) :])


@pytest.mark.slow
def test_the_pneunet_fem_verifies_its_reference_design_as_its_own_sweep(tmp_path):
    # The real family end to end: the reference PneuNet at 5 kPa, checked by NGSolve.
    import softbend._torch  # noqa: F401  (before NGSolve)
    from softbend.design_search.search import Candidate, SearchResult
    from softbend.fem.families import get_family
    from softbend.models import default_pressures_mpa

    family = get_family("pneunet")
    actuator = family.actuator
    codes = tuple(float(family.reference[n]) for n in family.names)
    spec = Specification(
        Target("angle_at", angle_deg=10.0, pressure_mpa=0.005, unit=actuator.pressure_unit),
        actuator=actuator,
    )
    at = 0.005 / spec.space.to_mpa  # the model's unit
    candidate = Candidate(Design(actuator, codes), 10.0, at, 0.0, True, {})
    candidate.pressure_unit = actuator.pressure_unit
    result = SearchResult(spec, [candidate], True, {}, 1, 1, 0, np.empty((0, 1)), "", 0.0)
    (verified,) = verify_candidates(result, 1, workers=1, db_path=tmp_path / "v.duckdb")
    own = family.simulate(family.design(family.reference), default_pressures_mpa(0.005, 0.001))
    assert verified.fem_stop is None and result.verified_by["family"] == "pneunet"
    assert verified.fem_angle_deg == pytest.approx(float(own.angle_deg[-1]), abs=1e-6)
    assert verified.fem_angle_deg > 0.5  # it bends under 5 kPa
