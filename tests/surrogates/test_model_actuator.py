"""The actuator a model is of travels with it: read from its file, passed to every check."""

import json

import numpy as np
import pytest

from softbend.actuators import ACTUATORS, SFRBA, Actuator, DesignParameter
from softbend.errors import SchemaError
from softbend.surrogates.features import outside_training_ranges, training_ranges
from softbend.surrogates.persistence import actuator_of, load_surrogate, save_surrogate
from softbend.surrogates.polynomial import PolynomialRegressor
from softbend.surrogates.schema import POLYNOMIAL_SCHEMA, RuleError

from .conftest import smooth_angle, table1_inputs

#: A stand-in actuator of two parameters and a pressure in kPa, with no plausible quantities.
CELLS = Actuator(
    name="cells",
    title="two cells",
    parameters=(
        DesignParameter("n_cells", "", 2, 5, kind="integer"),
        DesignParameter("width_mm", "mm", 1.0, 3.0),
    ),
    pressure_column="p_kpa",
    pressure_unit="kPa",
)


def _cells_rows(n: int) -> np.ndarray:
    rng = np.random.default_rng(0)
    return np.column_stack(
        [rng.integers(2, 6, n), rng.uniform(1.0, 3.0, n), rng.uniform(0.0, 80.0, n)]
    )


def test_a_recorded_registered_description_is_the_registered_one_with_its_data():
    assert actuator_of({"actuator": SFRBA.to_dict()}) is SFRBA
    assert SFRBA.quantities["pressure_mpa"] == "pressure_mpa"
    pneunet = ACTUATORS.get("pneunet")
    assert actuator_of({"actuator": pneunet.to_dict()}) is pneunet
    assert actuator_of({}) is SFRBA
    assert actuator_of({}, CELLS) is CELLS
    assert actuator_of({"actuator": CELLS.to_dict()}) == CELLS  # not registered: as recorded


def test_a_model_of_another_actuator_saves_and_loads_its_inputs_without_a_context(tmp_path):
    X = _cells_rows(60)
    model = PolynomialRegressor(degree=2).fit(X, X[:, 1] * X[:, 2] / 10)
    ranges = training_ranges(X, CELLS.features)
    assert list(ranges) == list(CELLS.features)
    path = save_surrogate(
        model,
        tmp_path / "cells.json",
        metadata={"actuator": CELLS.to_dict(), "training_ranges": ranges},
    )
    document = json.loads(path.read_text())
    assert document["features"] == ["n_cells", "width_mm", "p_kpa"]
    assert document["units"]["p_kpa"] == "kPa"
    saved = load_surrogate(path)
    assert saved.actuator == CELLS
    assert outside_training_ranges(saved.metadata["training_ranges"], [3, 2.0, 500.0]) == [
        f"p_kpa 500 outside [{ranges['p_kpa'][0]:g}, {ranges['p_kpa'][1]:g}]"
    ]


def test_the_plausible_ranges_checked_on_load_are_the_actuator_s_quantities(tmp_path):
    X = table1_inputs(200, 0)
    model = PolynomialRegressor(degree=2).fit(X, smooth_angle(X))
    ranges = training_ranges(X) | {"pressure_mpa": [0.0, 500.0]}
    metadata = {"actuator": SFRBA.to_dict(), "training_ranges": ranges}
    path = save_surrogate(model, tmp_path / "b.json", metadata=metadata)
    with pytest.raises(SchemaError, match=r"pressure_mpa: .*from -0.1013 to 2 MPa"):
        load_surrogate(path)
    # the same numbers for an actuator without quantities: finite and ordered is enough
    unchecked = Actuator(
        name="plain",
        title="paper B's columns, no plausible quantities",
        parameters=SFRBA.parameters,
    )
    metadata["actuator"] = unchecked.to_dict()
    path = save_surrogate(model, tmp_path / "plain.json", metadata=metadata)
    assert load_surrogate(path).actuator.quantities == {}


def test_a_schema_checks_the_state_against_the_actuator_it_is_given():
    X = _cells_rows(40)
    model = PolynomialRegressor(degree=1).fit(X, X[:, 2])
    state = {"n_features_in_": model.n_features_in_}
    POLYNOMIAL_SCHEMA.inputs(state, CELLS)
    with pytest.raises(RuleError, match=r"must be 7 \(the inputs l_mm, .*pressure_mpa\); got 3"):
        POLYNOMIAL_SCHEMA.inputs(state, SFRBA)
