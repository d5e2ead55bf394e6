"""Surrogates built on surrogates: predictions, intervals, and save/load round trips."""

import json

import numpy as np
import pytest
from scipy.stats import norm
from sklearn.gaussian_process import GaussianProcessRegressor

from softbend.errors import SchemaError
from softbend.surrogates.corrected import (
    AffineCorrected,
    GPCorrected,
    MeanEnsemble,
    PressureScaled,
    gp_kernel,
)
from softbend.surrogates.persistence import (
    COMPOSITE_KINDS,
    kind_of,
    load_surrogate,
    save_surrogate,
    saved_kinds,
)
from softbend.surrogates.polynomial import PolynomialRegressor

from .conftest import smooth_angle, table1_inputs

# The GP's optimizer warns when a length scale reaches its bound ("input does not matter").
pytestmark = pytest.mark.filterwarnings("ignore::sklearn.exceptions.ConvergenceWarning")


@pytest.fixture(scope="module")
def data():
    X = table1_inputs(200, 0)
    return X, smooth_angle(X)


@pytest.fixture(scope="module")
def bases(data):
    X, y = data
    return [PolynomialRegressor(degree=d).fit(X, y) for d in (1, 2, 3)]


def _gp(base, X, y):
    theta = base.predict(X)
    Z = np.column_stack([X, theta])
    mean, scale = Z.mean(axis=0), Z.std(axis=0)
    inputs = (Z - mean) / scale
    gp = GaussianProcessRegressor(kernel=gp_kernel(8), normalize_y=True, random_state=0)
    gp.fit(inputs, y - theta)
    return GPCorrected(base, mean, scale, gp.kernel_.theta, inputs, y - theta), gp


@pytest.fixture(scope="module")
def composites(data, bases):
    X, y = data
    return {
        "affine-corrected": AffineCorrected(bases[0], 1.1, -2.0, 0.5),
        "gp-corrected": _gp(bases[0], X[:60], y[:60])[0],
        "ensemble": MeanEnsemble(bases, 0.25),
        "pressure-scaled": PressureScaled(bases[2], 1.2, 0.5),
    }


def test_every_composite_kind_is_saved(composites):
    assert set(COMPOSITE_KINDS) == set(composites) and set(COMPOSITE_KINDS) <= set(saved_kinds())
    for kind, model in composites.items():
        assert kind_of(model) == kind


def test_affine_is_scale_times_base_plus_offset(data, bases):
    X, _ = data
    model = AffineCorrected(bases[0], 1.1, -2.0, 0.5)
    np.testing.assert_allclose(model.predict(X), 1.1 * bases[0].predict(X) - 2.0, rtol=1e-14)
    lo, hi = model.predict_interval(X, 0.9)
    np.testing.assert_allclose(hi - lo, 2 * norm.ppf(0.95) * 0.5, rtol=1e-12)


def test_pressure_scaled_asks_the_base_at_the_scaled_pressure(data, bases):
    X, _ = data
    model = PressureScaled(bases[2], 1.2, 0.5)
    scaled = X.copy()
    scaled[:, -1] *= 1.2
    np.testing.assert_array_equal(model.predict(X), bases[2].predict(scaled))
    assert not np.allclose(model.predict(X), bases[2].predict(X))
    lo, hi = model.predict_interval(X, 0.9)
    np.testing.assert_allclose(hi - lo, 2 * norm.ppf(0.95) * 0.5, rtol=1e-12)
    for bad in (0.0, -1.0, float("nan")):
        with pytest.raises(ValueError, match="scale: must be"):
            PressureScaled(bases[2], bad, 0.5)


def test_gp_with_fixed_hyperparameters_predicts_as_the_optimized_gp(data, bases):
    X, y = data
    model, gp = _gp(bases[0], X[:60], y[:60])
    theta = bases[0].predict(X[60:])
    z = (np.column_stack([X[60:], theta]) - model.z_mean_) / model.z_scale_
    mean, std = gp.predict(z, return_std=True)
    got, got_std = model.predict(X[60:], return_std=True)
    np.testing.assert_allclose(got, theta + mean, rtol=0, atol=1e-9)
    np.testing.assert_allclose(got_std, std, rtol=1e-9)
    np.testing.assert_array_equal(model.kernel_theta_, gp.kernel_.theta)


def test_gp_correction_learns_the_base_error(data, bases):
    # A linear base misses the curvature; the GP on its error closes most of the gap.
    X, y = data
    model, _ = _gp(bases[0], X[:150], y[:150])
    base_err = np.abs(bases[0].predict(X[150:]) - y[150:]).mean()
    assert np.abs(model.predict(X[150:]) - y[150:]).mean() < 0.5 * base_err
    lo, hi = model.predict_interval(X[150:], 0.9)
    assert np.all(lo < hi)


def test_ensemble_is_the_members_mean_with_spread(data, bases):
    X, _ = data
    model = MeanEnsemble(bases, 0.0)
    predictions = np.array([b.predict(X) for b in bases])
    np.testing.assert_allclose(model.predict(X), predictions.mean(axis=0), rtol=1e-14)
    lo, hi = model.predict_interval(X, 0.9)
    half = norm.ppf(0.95) * predictions.std(axis=0, ddof=1)
    np.testing.assert_allclose(hi - lo, 2 * half, rtol=1e-12)
    with pytest.raises(ValueError, match="2 or more"):
        MeanEnsemble(bases[:1], 0.0)


@pytest.mark.parametrize("kind", COMPOSITE_KINDS)
def test_round_trip_predicts_the_same(kind, composites, data, tmp_path):
    X, _ = data
    model = composites[kind]
    path = save_surrogate(model, tmp_path / "m.json", metadata={"strategy": kind})
    saved = load_surrogate(path)
    assert saved.kind == kind and saved.metadata == {"strategy": kind}
    np.testing.assert_array_equal(saved.model.predict(X), model.predict(X))
    for a, b in zip(saved.model.predict_interval(X), model.predict_interval(X), strict=True):
        np.testing.assert_array_equal(a, b)


def test_nested_composites_round_trip(composites, data, tmp_path):
    X, _ = data
    nested = AffineCorrected(composites["ensemble"], 0.9, 1.0, 0.1)
    saved = load_surrogate(save_surrogate(nested, tmp_path / "n.json")).model
    np.testing.assert_array_equal(saved.predict(X), nested.predict(X))


def _edit(path, change):
    document = json.loads(path.read_text())
    change(document)
    path.write_text(json.dumps(document))
    return path


@pytest.mark.parametrize(
    ("kind", "change", "message"),
    [
        ("affine-corrected", lambda d: d["state"].pop("base"), "state key.*base.*missing"),
        ("affine-corrected", lambda d: d["state"].update(base=3), "base.*saved surrogate"),
        ("affine-corrected", lambda d: d["state"].update(residual_std_=-1.0), "residual_std_"),
        ("affine-corrected", lambda d: d["params"].update(a=1), "takes no params"),
        (
            "affine-corrected",
            lambda d: d["state"]["base"].update(kind="nope"),
            r"state\.base\.kind: .*unknown surrogate kind",
        ),
        (
            "affine-corrected",
            lambda d: d["state"]["base"]["state"].pop("coef_"),
            r"state\.base\.state: .*coef_",
        ),
        ("gp-corrected", lambda d: d["state"]["targets_"]["shape"].__setitem__(0, 1), "targets_"),
        ("gp-corrected", lambda d: d["state"].update(kernel_theta_=1.0), "kernel_theta_"),
        ("ensemble", lambda d: d["state"].update(members=d["state"]["members"][:1]), "2 or more"),
        ("pressure-scaled", lambda d: d["state"].update(scale_=0.0), "scale_"),
        ("pressure-scaled", lambda d: d["state"].pop("scale_"), "state key.*scale_.*missing"),
        (
            "ensemble",
            lambda d: d["state"]["members"][1]["state"].update(x_scale_=0),
            r"members\[1\].*x_scale_",
        ),
    ],
)
def test_bad_composite_file_is_one_clear_error(kind, change, message, composites, tmp_path):
    path = save_surrogate(composites[kind], tmp_path / "m.json")
    _edit(path, change)
    with pytest.raises(SchemaError, match=message) as err:
        load_surrogate(path)
    assert "\n" not in str(err.value) and str(path) in str(err.value)


def test_onnx_export_refuses_a_composite(composites):
    pytest.importorskip("onnx")
    from softbend.surrogates.onnx_export import to_onnx

    with pytest.raises(ValueError, match="no ONNX export"):
        to_onnx(composites["ensemble"])


# --- a correction's parameters are physically plausible, or the file is refused ------------------


def _set_item(key, index, value):
    def change(document):
        document["state"][key]["__ndarray__"][index] = value

    return change


_LOG_1E6 = float(np.log(1e6))


@pytest.mark.parametrize(
    ("change", "message"),
    [
        (_set_item("kernel_theta_", 1, 1e6), r"kernel_theta_.*length scale of l_mm inf"),
        (_set_item("kernel_theta_", 3, _LOG_1E6 + 0.01), r"length scale of t_mm 1\.01005e\+06"),
        (_set_item("kernel_theta_", 8, -20.0), r"length scale of the base's angle_deg 2\.06"),
        (_set_item("kernel_theta_", 0, 1e6), r"kernel_theta_.*constant inf .*at index 0"),
        (_set_item("kernel_theta_", 9, 1e6), r"kernel_theta_.*noise inf .*at index 9"),
        (_set_item("kernel_theta_", 9, -1e6), r"kernel_theta_.*noise 0 .*at index 9"),
        (_set_item("z_mean_", 0, 1e300), r"z_mean_.*1e\+300 for l_mm .*0 to 10000 mm"),
        (_set_item("z_mean_", 6, -5.0), r"z_mean_.*-5 for pressure_mpa .*-0\.1013 to 2 MPa"),
        (_set_item("z_scale_", 7, 1e9), r"z_scale_.*1e\+09 for the base's angle_deg"),
        (_set_item("targets_", 2, 1e300), r"targets_.*1e\+300 at index 2"),
    ],
    ids=[
        "length-scale-inf",
        "length-scale-above",
        "length-scale-below",
        "constant-inf",
        "noise-inf",
        "noise-zero",
        "mean-length",
        "mean-pressure",
        "scale-angle",
        "target",
    ],
)
def test_implausible_gp_parameters_are_refused_naming_the_file_and_key(
    change, message, composites, tmp_path
):
    path = save_surrogate(composites["gp-corrected"], tmp_path / "m.json")
    _edit(path, change)
    with pytest.raises(SchemaError, match=message) as err:
        load_surrogate(path)
    text = str(err.value)
    assert text.startswith(f"{path}: state.") and "\n" not in text
    assert "allowed" in text or "within" in text or "from" in text


def test_standardized_inputs_of_absurd_magnitude_are_refused(composites, tmp_path):
    path = save_surrogate(composites["gp-corrected"], tmp_path / "m.json")
    _edit(path, lambda d: d["state"]["inputs_"]["__ndarray__"][4].__setitem__(2, -1e7))
    with pytest.raises(SchemaError, match=r"inputs_.*magnitude at most 1e\+06; got -1e\+07 at"):
        load_surrogate(path)


def test_length_scales_at_the_ends_of_the_range_still_load_and_predict(composites, data, tmp_path):
    path = save_surrogate(composites["gp-corrected"], tmp_path / "m.json")
    theta = composites["gp-corrected"].kernel_theta_
    ends = [theta[0], *([_LOG_1E6] * 4), *([float(np.log(0.1))] * 4), theta[-1]]
    _edit(path, lambda d: d["state"]["kernel_theta_"].update(__ndarray__=ends))
    model = load_surrogate(path).model
    X, _ = data
    mean, std = model.predict(X, return_std=True)
    assert np.isfinite(mean).all() and np.isfinite(std).all()


@pytest.mark.parametrize(
    ("kind", "change", "message"),
    [
        (
            "affine-corrected",
            lambda d: d["state"].update(offset_=1e300),
            r"offset_: must be an angle offset from -3600 to 3600 degrees.*got 1e\+300",
        ),
        (
            "affine-corrected",
            lambda d: d["state"].update(residual_std_=1e300),
            r"residual_std_: must be a residual standard deviation from 0 to 3600",
        ),
        ("ensemble", lambda d: d["state"].update(residual_std_=4000.0), "residual_std_.*got 4000"),
        ("pressure-scaled", lambda d: d["state"].update(residual_std_=1e9), "residual_std_"),
    ],
    ids=["affine-offset", "affine-residual", "ensemble-residual", "pressure-scaled-residual"],
)
def test_implausible_correction_parameters_are_refused(kind, change, message, composites, tmp_path):
    path = save_surrogate(composites[kind], tmp_path / "m.json")
    _edit(path, change)
    with pytest.raises(SchemaError, match=message) as err:
        load_surrogate(path)
    assert str(err.value).startswith(f"{path}: state.")
