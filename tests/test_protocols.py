"""The bending models answer softbend.models.BendingModel (built, not solved)."""

from __future__ import annotations

import inspect

import pytest

from softbend.models import BendingModel, SweepResult


def _models():
    from softbend.analytical import AnalyticalModel
    from softbend.fem import FEMModel, FEMOptions

    return {
        "analytical": AnalyticalModel(),
        "fem": FEMModel(),
        "fem-options": FEMModel(FEMOptions(maxh_mm=6.0), compiled=False),
    }


@pytest.mark.parametrize("key", ["analytical", "fem", "fem-options"])
def test_the_model_is_a_bending_model(key):
    model = _models()[key]
    assert isinstance(model, BendingModel)
    assert isinstance(model.name, str) and model.name == key.split("-")[0]
    sweep = inspect.signature(model.sweep)
    assert list(sweep.parameters)[:2] == ["design", "pressures_mpa"]
    hints = inspect.get_annotations(type(model).sweep, eval_str=True)
    assert hints["return"] is SweepResult


def test_the_fem_asks_for_one_design_per_task():
    models = _models()
    assert models["fem"].preferred_chunk_size == 1
    assert not hasattr(models["analytical"], "preferred_chunk_size")


def test_something_without_a_sweep_is_not_a_bending_model():
    class NoSweep:
        name = "none"

    assert not isinstance(NoSweep(), BendingModel)
