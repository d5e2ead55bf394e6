"""predict_angles: a saved surrogate, a design and pressures to angles, extrapolation flagged."""

from __future__ import annotations

import numpy as np
import pytest

from softbend.design import SFRBADesign
from softbend.surrogates.features import training_ranges
from softbend.surrogates.persistence import save_surrogate
from softbend.surrogates.polynomial import PolynomialRegressor
from softbend.surrogates.predict import predict_angles

from .conftest import smooth_angle, table1_inputs


@pytest.fixture
def saved(tmp_path):
    X = table1_inputs(300, seed=1)
    X[:, 6] *= 0.4  # trained to 0.2 MPa only
    model = PolynomialRegressor(degree=3).fit(X, smooth_angle(X))
    return save_surrogate(
        model, tmp_path / "m.json", metadata={"training_ranges": training_ranges(X)}
    ), model


def test_angles_are_the_model_prediction(saved):
    path, model = saved
    design = SFRBADesign(130, 8, 3, 3, 10, 10)
    result = predict_angles(path, design, [0.1, 0.05])
    np.testing.assert_array_equal(result.angle_deg, model.predict(design.feature_rows([0.1, 0.05])))
    assert result.outside_training_ranges == [] and result.has_training_ranges


def test_beyond_the_training_pressures_is_flagged_and_strict_refuses(saved):
    path, _ = saved
    design = SFRBADesign(130, 8, 3, 3, 10, 10)
    result = predict_angles(path, design, [0.1, 0.45])
    assert len(result.outside_training_ranges) == 1
    assert result.outside_training_ranges[0].startswith("pressure_mpa 0.45 outside")
    with pytest.raises(ValueError, match=r"pressure_mpa 0\.45 outside"):
        predict_angles(path, design, [0.45], strict=True)


@pytest.mark.parametrize("pressures", [[], [-0.1], [float("nan")], [1, float("inf")]])
def test_bad_pressures_name_the_field(saved, pressures):
    with pytest.raises(ValueError, match="'pressure'"):
        predict_angles(saved[0], SFRBADesign(130, 8, 3, 3, 10, 10), pressures)
