"""predict_angles: a saved surrogate, a design and pressures to angles, extrapolation flagged."""

from __future__ import annotations

import json
import math

import numpy as np
import pytest

from softbend.design import sfrba_design
from softbend.errors import SchemaError
from softbend.surrogates.corrected import AffineCorrected, GPCorrected, gp_kernel
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
    design = sfrba_design(130, 8, 3, 3, 10, 10)
    result = predict_angles(path, design, [0.1, 0.05])
    np.testing.assert_array_equal(result.angle_deg, model.predict(design.feature_rows([0.1, 0.05])))
    assert result.outside_training_ranges == [] and result.has_training_ranges


def test_beyond_the_training_pressures_is_flagged_and_strict_refuses(saved):
    path, _ = saved
    design = sfrba_design(130, 8, 3, 3, 10, 10)
    result = predict_angles(path, design, [0.1, 0.45])
    assert len(result.outside_training_ranges) == 1
    assert result.outside_training_ranges[0].startswith("pressure_mpa 0.45 outside")
    with pytest.raises(ValueError, match=r"pressure_mpa 0\.45 outside"):
        predict_angles(path, design, [0.45], strict=True)


@pytest.mark.parametrize("pressures", [[], [-0.1], [float("nan")], [1, float("inf")]])
def test_bad_pressures_name_the_field(saved, pressures):
    with pytest.raises(ValueError, match="pressures_mpa: must be finite and >= 0"):
        predict_angles(saved[0], sfrba_design(130, 8, 3, 3, 10, 10), pressures)


def _rewrite(path, change):
    document = json.loads(path.read_text())
    change(document)
    path.write_text(json.dumps(document))
    return path


def test_a_nan_training_range_is_refused_on_load_not_silently_unchecked(saved):
    path, _ = saved
    _rewrite(path, lambda d: d["metadata"]["training_ranges"]["l_mm"].__setitem__(0, math.nan))
    with pytest.raises(SchemaError, match=r"metadata\.training_ranges\.l_mm: .*got \[NaN,") as info:
        predict_angles(path, sfrba_design(100, 8, 3, 3, 10, 10), [0.1], strict=True)
    assert str(info.value).startswith(str(path))


def test_a_non_finite_prediction_inside_the_training_ranges_names_the_model_file(tmp_path):
    X = table1_inputs(200, seed=3)
    base = PolynomialRegressor(degree=1).fit(X, smooth_angle(X))
    path = save_surrogate(
        AffineCorrected(base, 1e308, 0.0, 0.5),
        tmp_path / "overflow.json",
        metadata={"training_ranges": training_ranges(X)},
    )
    with pytest.raises(SchemaError, match="predicts a non-finite angle") as info:
        predict_angles(path, sfrba_design(130, 8, 3, 3, 10, 10), [0.2, 0.3])
    message = str(info.value)
    assert str(path) in message and "affine-corrected" in message and "0.2 MPa" in message


def test_a_non_finite_extrapolation_is_an_error_naming_file_and_inputs(saved):
    path, _ = saved
    with pytest.raises(ValueError, match="predicts a non-finite angle") as info:
        predict_angles(path, sfrba_design(130, 8, 3, 3, 10, 10), [0.1, 1e308])
    message = str(info.value)
    assert str(path) in message and "pressure_mpa 1e+308 outside" in message


def test_the_cli_refuses_a_gp_correction_that_would_predict_null(tmp_path, capsys):
    from sklearn.gaussian_process import GaussianProcessRegressor

    from softbend.cli import main

    X = table1_inputs(60, seed=4)
    base = PolynomialRegressor(degree=1).fit(X, smooth_angle(X))
    theta = base.predict(X)
    Z = np.column_stack([X, theta])
    mean, scale = Z.mean(axis=0), Z.std(axis=0)
    inputs, errors = (Z - mean) / scale, smooth_angle(X) - theta
    gp = GaussianProcessRegressor(kernel=gp_kernel(8), normalize_y=True, random_state=0)
    gp.fit(inputs, errors)
    model = GPCorrected(base, mean, scale, gp.kernel_.theta, inputs, errors)
    path = save_surrogate(model, tmp_path / "gp.json")
    args = ["predict", str(path), "--design", "130,8,3,3,10,10", "--pressures", "0.1", "--json"]
    assert main(args) == 0
    assert json.loads(capsys.readouterr().out)["angle_deg"][0] is not None
    _rewrite(path, lambda d: d["state"]["kernel_theta_"]["__ndarray__"].__setitem__(0, 1e6))
    assert main(args) == 2
    captured = capsys.readouterr()
    assert captured.out == ""
    err = captured.err.strip().splitlines()
    assert len(err) == 1 and str(path) in err[0] and "kernel_theta_" in err[0]


def test_the_shipped_mlp_predicts_bit_for_bit_as_its_estimator():
    from importlib.resources import files

    from softbend.surrogates.persistence import load_surrogate

    path = files("softbend") / "data" / "transfer" / "table1_fem_mlp.json"
    model = load_surrogate(path).model
    rng = np.random.default_rng(5)
    for design in (sfrba_design(100, 6, 2, 2, 5, 8), sfrba_design(130, 7, 2.5, 3, 10, 9)):
        pressures = np.concatenate([[0.05], rng.uniform(0.0, 0.2, 20)])
        result = predict_angles(path, design, pressures)
        expected = model.predict(design.feature_rows(pressures))
        assert result.angle_deg.tobytes() == expected.tobytes()
    assert result.kind == "mlp" and result.interval_deg is None
