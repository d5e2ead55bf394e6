"""Verification in rounds: a biased surrogate corrected by the FEM sweeps of its candidates.

The stand-in FEM is closed-form, ``angle = K · p · (n_cells + width_mm)`` (degrees,
MPa); the surrogate is a polynomial fitted to 80 % of it, so every design it puts at
the target bends a quarter more in the "FEM" and misses a 3° tolerance. Refined on
the FEM curves of the designs it proposed (residual-gp), it must find a design the
FEM confirms.
"""

from __future__ import annotations

import json

import pytest

from softbend.actuators import Actuator
from softbend.cli import main
from softbend.design_search.rounds import CURVES_FILE, rounds_summary, verify_in_rounds
from softbend.design_search.search import LoadedModel, find_designs
from softbend.design_search.spec import Specification, Target
from softbend.errors import InputError

from ..cli.conftest import one_error_line
from ..stand_ins import CELL_PARAMETERS, registered_family, stand_in_family, train_closed_form

K_DEG_PER_MPA = 1000.0
PARAMETERS = CELL_PARAMETERS[:2]  # n_cells, width_mm
#: The surrogate's bias: it learnt 80 % of the FEM's angle.
BIAS = 0.8

BIASED = stand_in_family(
    "biased",
    PARAMETERS,
    K_DEG_PER_MPA,
    title="stand-in actuator a surrogate underestimates",
    actuator_title="stand-in",
    reference={"n_cells": 3, "width_mm": 2.0},
    pmax_mpa=0.05,
    pstep_mpa=0.001,
)


@pytest.fixture(autouse=True)
def family():
    with registered_family(BIASED) as registered:
        yield registered


@pytest.fixture(scope="module")
def model(tmp_path_factory):
    """A polynomial of 80 % of the closed form (kPa), 0 to 50 kPa, on a 4 × 5 grid."""
    actuator = Actuator(
        name="biased-lab",
        title="stand-in, as a lab's table describes it",
        parameters=PARAMETERS,
        pressure_column="p_kpa",
        pressure_unit="kPa",
        fem_family="biased",
    )
    return train_closed_form(
        tmp_path_factory.mktemp("biased"),
        actuator,
        lambda n, w, p_mpa: BIAS * K_DEG_PER_MPA * p_mpa * (n + w),
    )


def _spec(loaded: LoadedModel) -> Specification:
    # 100° at 20 kPa: the FEM's n + w = 5, the surrogate's 6.25
    target = Target("angle_at", angle_deg=100.0, pressure_mpa=20.0, unit="kPa", tolerance_deg=3)
    return Specification(target, actuator=loaded.actuator, steps={"width_mm": 0.2})


def test_the_rounds_refine_a_biased_surrogate_until_the_fem_confirms_a_design(model, tmp_path):
    loaded = LoadedModel.load(model)
    spec = _spec(loaded)
    first = find_designs(loaded, spec, top=3)
    out = tmp_path / "rounds"
    result, last, rounds = verify_in_rounds(
        loaded, spec, first, verify=1, rounds=4, folder=out, top=3, workers=1
    )
    # round 0 on the biased surrogate: the FEM bends a quarter more than it said
    miss = rounds[0].verified[0]
    assert miss.fem_meets is False
    assert miss.fem_angle_deg == pytest.approx(miss.angle_deg / BIAS, rel=0.02)
    # a later round, on a refined surrogate, is confirmed by the FEM
    assert 1 < len(rounds) <= 5 and rounds[-1].met
    assert not any(r.met for r in rounds[:-1])
    best = rounds[-1].verified[0]
    n, w = best.design.as_array()
    assert abs(K_DEG_PER_MPA * 0.02 * (n + w) - 100.0) <= 3.0  # the closed form agrees
    assert abs(best.fem_angle_deg - 100.0) <= 3.0
    # every round's model is saved, and the refined one searched the last round
    assert last.path == str(out / f"round-{len(rounds) - 1}.json") == rounds[-1].model
    assert rounds[0].model == str(model)
    assert (out / CURVES_FILE).read_text().startswith("# synthetic: true\n")
    # no design is swept twice
    swept = [c.design.as_text() for r in rounds for c in r.verified]
    assert len(swept) == len(set(swept))
    # recorded in the result (search.json) and summarised
    assert result.to_dict()["rounds"] == [r.to_dict() for r in rounds]
    summary = rounds_summary(rounds)
    assert summary["met"] and summary["fem_sweeps"] == len(swept)
    json.dumps(result.to_dict(), allow_nan=False)


def test_no_rounds_is_one_verification_and_bad_counts_are_refused(model, tmp_path):
    loaded = LoadedModel.load(model)
    spec = _spec(loaded)
    result, last, rounds = verify_in_rounds(
        loaded, spec, find_designs(loaded, spec, top=3), verify=2, rounds=0, folder=tmp_path
    )
    assert len(rounds) == 1 and len(rounds[0].verified) == 2 and last is loaded
    assert result.rounds is None and not list(tmp_path.iterdir())
    for bad in ({"verify": 0, "rounds": 1}, {"verify": 1, "rounds": -1}):
        with pytest.raises(InputError) as error:
            verify_in_rounds(loaded, spec, result, folder=tmp_path, **bad)
        assert error.value.key in bad


def test_refine_rounds_over_the_cli_saves_the_refined_surrogate(model, tmp_path, capsys):
    out = tmp_path / "design"
    args = ["design", "find", "--model", str(model), "--angle", "100", "--at", "20",
            "--resolution", "width_mm=0.2", "--verify", "1", "--refine-rounds", "4",
            "--workers", "1", "--out", str(out), "--json"]  # fmt: skip
    assert main(args) == 0
    payload = json.loads(capsys.readouterr().out)
    assert payload["rounds"][-1]["verified"][0]["fem_meets"] is True
    assert payload["rounds"][0]["verified"][0]["fem_meets"] is False
    assert json.loads((out / "search.json").read_text())["rounds"] == payload["rounds"]
    assert (out / "rounds" / "round-1.json").is_file()
    # the refined surrogate is a saved model like any other
    predict = ["predict", str(out / "rounds" / "round-1.json"), "--design",
               "n_cells=2,width_mm=3", "--pressures", "20", "--json"]  # fmt: skip
    assert main(predict) == 0
    assert "angle" in capsys.readouterr().out


@pytest.mark.parametrize(
    ("extra", "needle"),
    [
        (["--refine-rounds", "2"], "--refine-rounds: applies to the verification"),
        (["--verify", "1", "--refine-rounds", "21"], "--refine-rounds: must be"),
    ],
)
def test_a_bad_refine_rounds_is_one_line(model, tmp_path, capsys, extra, needle):
    args = ["design", "find", "--model", str(model), "--angle", "100", "--at", "20",
            "--out", str(tmp_path / "d"), *extra]  # fmt: skip
    assert main(args) == 2
    assert needle in one_error_line(capsys)
