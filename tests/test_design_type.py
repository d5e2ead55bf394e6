"""One design type: Design(actuator, values) for paper B's actuator, the PneuNet and any other."""

import hashlib
import pickle

import numpy as np
import pytest

from softbend.actuators import PNEUNET, SFRBA, Actuator, ActuatorError, Design, DesignParameter
from softbend.design import parse_sfrba, sfrba_design
from softbend.fem.families import get_family


def _sha(text: str) -> str:
    return hashlib.sha1(text.encode()).hexdigest()[:16]


def test_each_description_says_how_its_design_ids_are_made():
    paper_b = sfrba_design(100, 6, 2, 2, 5, 8)
    assert paper_b.design_id == _sha(",".join(f"{v:.6f}" for v in (100, 6, 2, 2, 5, 8)))
    pneunet = get_family("pneunet").design()
    named = ",".join(f"{k}={v:.6f}" for k, v in pneunet.values.items())
    assert pneunet.design_id == _sha(f"pneunet:{named}")
    assert isinstance(pneunet, Design) and pneunet.actuator is PNEUNET


def test_a_design_answers_by_name_in_order_and_in_any_pressure_unit():
    design = Design(SFRBA, dict(reversed(list(sfrba_design(100, 6, 2, 2, 5, 8).as_dict().items()))))
    assert design == parse_sfrba("100,6,2,2,5,8") and hash(design) == hash(
        parse_sfrba("100,6,2,2,5,8")
    )
    assert design.r_mm == 6.0 and list(design.as_dict()) == list(SFRBA.names)
    assert str(design) == design.as_text() == "100,6,2,2,5,8"
    kpa = Actuator(
        name="kpa-cell",
        title="a cell in kPa",
        parameters=(
            DesignParameter("n", "", 1, 5, kind="integer"),
            DesignParameter("layer", kind="categorical", levels=("paper", "fabric")),
        ),
        pressure_column="p_kpa",
        pressure_unit="kPa",
    )
    cell = Design.checked(kpa, [3, 1])
    np.testing.assert_allclose(cell.feature_rows([0.02], unit="MPa"), [[3.0, 1.0, 20.0]])
    np.testing.assert_allclose(cell.feature_rows([20.0]), [[3.0, 1.0, 20.0]])
    assert cell.record() == {"n": 3, "layer": "fabric"} and str(cell) == "n=3, layer=fabric"
    assert cell.as_text() == "n=3, layer=1"
    assert pickle.loads(pickle.dumps(cell)) == cell
    with pytest.raises(ActuatorError, match="n must be a whole number"):
        Design.checked(kpa, [2.5, 0])
    with pytest.raises(ActuatorError, match="missing"):
        Design(kpa, {"n": 1})


def test_paper_b_s_own_check_and_data_live_on_its_description():
    with pytest.raises(ValueError, match=r"^t_mm: must be less than r_mm"):
        Design.checked(SFRBA, [100, 6, 6, 2, 5, 8])
    assert SFRBA.short_names == ("l", "r", "t", "b", "phi", "lc")
    assert len(SFRBA.grid[0]) == 4 and SFRBA.design_ids == "values"
    with pytest.raises(ActuatorError, match="one entry per design parameter"):
        Actuator(name="x", title="x", parameters=SFRBA.parameters, short_names=("l",))


def test_a_saved_record_of_a_registered_description_is_that_description():
    assert Actuator.from_dict(SFRBA.to_dict()) is SFRBA
    assert Actuator.from_dict(PNEUNET.to_dict()) is PNEUNET
    changed = {**SFRBA.to_dict(), "title": "another"}
    other = Actuator.from_dict(changed)
    assert other != SFRBA and other.design_ids == "named"
