"""The control study: every controller on every reference, the plant as given."""

import pytest

from softbend.control.rig import AngleTable
from softbend.control.study import control_study
from softbend.design import sfrba_design


class Linear:
    """A surrogate stand-in: θ = 6° + 1200°/MPa·p on feature rows (pressure last)."""

    def predict(self, rows):
        return 6.0 + 1200.0 * rows[:, -1]


DESIGN = sfrba_design(100, 6, 2, 2, 5, 8)


def test_study_runs_every_pair_and_scores_it():
    study = control_study(
        Linear(), DESIGN, controllers=("bang-bang", "predictive"),
        references=("step:90", "triangle:0.2:90:20"), duration_s=3.0,
    )  # fmt: skip
    assert len(study.metrics) == 4 and len(study.runs) == 4
    assert study.settings["plant"] == "surrogate"
    step = study.metric("predictive", "step:90", "mape_pct")
    assert step < study.metric("bang-bang", "step:90", "mape_pct")
    assert (
        "delay_s" in study.metrics
        and study.metric("bang-bang", "triangle:0.2:90:20", "delay_s") > 0
    )


def test_a_plant_that_bends_more_shows_as_steady_state_error():
    stiff_model = Linear()
    soft_plant = AngleTable.from_callable(lambda p: 6.0 + 1380.0 * p)  # 15 % more
    nominal = control_study(stiff_model, DESIGN, controllers=("predictive",),
                            references=("step:90",), duration_s=3.0)  # fmt: skip
    mismatched = control_study(
        stiff_model, DESIGN, plant_table=soft_plant, plant="soft", controllers=("predictive",),
        references=("step:90",), duration_s=3.0,
    )  # fmt: skip
    assert mismatched.settings["plant"] == "soft"
    assert mismatched.metric("predictive", "step:90", "mape_pct") == pytest.approx(
        nominal.metric("predictive", "step:90", "mape_pct") + 14.0, abs=3.0
    )


def test_unknown_controller_is_one_error():
    with pytest.raises(ValueError, match=r"^controllers: Unknown controller 'pid'; known: b"):
        control_study(Linear(), DESIGN, controllers=("pid",), duration_s=1.0)
