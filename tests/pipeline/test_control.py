"""Closed-loop control on the simulated rig and on the lab actuator, metrics written."""

from __future__ import annotations

import pandas as pd
import pytest

from softbend.control.study import STUDY_CONTROLLERS, STUDY_REFERENCES
from softbend.pipeline.control import CONTROL_DESIGN, run_control

from .conftest import Phases, pictures


@pytest.fixture(scope="module")
def control(tmp_path_factory):
    out = tmp_path_factory.mktemp("control")
    phases = Phases()
    return out, run_control(out, 0, phases, duration_s=1.5, refine_epochs=20), phases


def test_every_controller_runs_every_reference_three_times(control):
    _, result, phases = control
    for name in ("rig", "lab_fem_mlp", "lab_refined_mlp"):
        runs = {(r["controller"], r["reference"]) for r in result.summary[name]}
        assert runs == {(c, r) for c in STUDY_CONTROLLERS for r in STUDY_REFERENCES}, name
    assert result.nominal.settings["design"] == CONTROL_DESIGN
    assert result.nominal.settings["plant"] == "surrogate"
    assert result.mismatch.settings["plant"] == result.refined.settings["plant"] == "lab"
    assert result.duration_s == 1.5 and result.seed == 0
    assert set(phases.last) == {
        "control: rig",
        "control: lab, FEM-trained MLP",
        "control: lab, refined MLP",
    }
    assert phases.all_finished()


def test_the_predictive_controller_switches_less_than_bang_bang(control):
    _, result, _ = control
    step = STUDY_REFERENCES[0]
    assert result.nominal.metric("predictive", step, "switches") < result.nominal.metric(
        "bang-bang", step, "switches"
    )


def test_writes_the_metrics_but_no_figures(control):
    out, result, _ = control
    for name, path in result.files.items():
        table = pd.read_csv(path)
        assert len(table) == len(STUDY_CONTROLLERS) * len(STUDY_REFERENCES), name
        assert table.to_dict(orient="records")[0]["controller"] == STUDY_CONTROLLERS[0]
    assert pictures(out) == []
