import json

import numpy as np
import pytest
from sklearn.linear_model import LinearRegression

from softbend.errors import LimitError, SchemaError
from softbend.identification.narx import NARXRegressor
from softbend.identification.persistence import load_narx, save_narx
from softbend.identification.svr import GeneralizedGaussianSVR

pytestmark = pytest.mark.filterwarnings(
    "ignore::softbend.identification.kernels.ShapeClippedWarning"
)


def _system(seed):
    rng = np.random.default_rng(seed)
    u = np.repeat(rng.uniform(-1, 1, 40), 10)
    y = np.zeros_like(u)
    for t in range(2, u.size):
        y[t] = 0.7 * y[t - 1] - 0.1 * y[t - 2] + np.tanh(u[t]) + 0.2 * u[t - 1] ** 2
    return u[:, None], y


@pytest.mark.parametrize("shape", [None, 1.3])
def test_saved_model_reloads_bit_identically(tmp_path, shape):
    u, y = _system(0)
    model = NARXRegressor(estimator=GeneralizedGaussianSVR(shape=shape, epsilon=0.05))
    model.fit(u, y, groups=np.repeat([0, 1], u.shape[0] // 2))
    path = save_narx(model, tmp_path / "m.json", metadata={"output": "rho"})
    loaded, metadata = load_narx(path)
    u_test, y_test = _system(1)
    np.testing.assert_array_equal(model.simulate(u_test, y_test), loaded.simulate(u_test, y_test))
    np.testing.assert_array_equal(
        model.predict_one_step(u_test, y_test), loaded.predict_one_step(u_test, y_test)
    )
    assert metadata == {"output": "rho"}
    assert loaded.regressor_names_ == model.regressor_names_
    assert loaded.get_params()["output_lags"] == 2


def test_newer_schema_and_foreign_files_are_refused(tmp_path):
    u, y = _system(0)
    model = NARXRegressor().fit(u, y)
    path = save_narx(model, tmp_path / "m.json")
    data = json.loads(path.read_text())
    data["schema_version"] = 99
    path.write_text(json.dumps(data))
    with pytest.raises(SchemaError, match="schema version 99"):
        load_narx(path)
    path.write_text("{}")
    with pytest.raises(SchemaError, match="not a saved softbend NARX model"):
        load_narx(path)
    path.write_text("not json")
    with pytest.raises(SchemaError, match="not valid JSON"):
        load_narx(path)
    with pytest.raises(FileNotFoundError):
        load_narx(tmp_path / "missing.json")


def test_only_gg_svr_models_can_be_saved(tmp_path):
    u, y = _system(0)
    model = NARXRegressor(estimator=LinearRegression()).fit(u, y)
    with pytest.raises(ValueError, match="GeneralizedGaussianSVR"):
        save_narx(model, tmp_path / "m.json")


def test_unscaled_multi_input_models_without_current_input_round_trip(tmp_path):
    rng = np.random.default_rng(4)
    u = rng.uniform(-1, 1, (300, 2))
    y = np.convolve(u[:, 0] - 0.5 * u[:, 1], [0.5, 0.3, 0.1], mode="same")
    model = NARXRegressor(
        estimator=GeneralizedGaussianSVR(sigma=1.0, shape=2.0),
        output_lags=1,
        input_lags=3,
        include_current_input=False,
        scale=False,
    ).fit(u, y)
    loaded, _ = load_narx(save_narx(model, tmp_path / "m.json"))
    np.testing.assert_array_equal(model.predict_one_step(u, y), loaded.predict_one_step(u, y))


def _first_row(key):
    def change(data):
        data["estimator"][key][0] = [float("nan"), *data["estimator"][key][0][1:]]

    return change


_CORRUPTIONS = [
    (
        "nan dual coef",
        lambda d: d["estimator"]["dual_coef"].__setitem__(0, float("nan")),
        r"estimator.dual_coef\[0\]: must be a finite number",
    ),
    (
        "string dual coef",
        lambda d: d["estimator"]["dual_coef"].__setitem__(0, "0.5"),
        r"estimator.dual_coef\[0\]: must be a finite number",
    ),
    ("nan support vector", _first_row("support_vectors"), r"support_vectors\[0\]\[0\]"),
    (
        "support vector removed",
        lambda d: d["estimator"]["support_vectors"].pop(),
        "estimator.support_vectors: must be a list of",
    ),
    (
        "support vector column removed",
        lambda d: d["estimator"]["support_vectors"][0].pop(),
        r"estimator.support_vectors\[0\]: must be a list of 4 numbers",
    ),
    (
        "zero sigma",
        lambda d: d["estimator"].update(sigma=0.0),
        r"estimator.sigma: must be a number in \(0, inf\)",
    ),
    ("string sigma", lambda d: d["estimator"].update(sigma="1.0"), "estimator.sigma: must"),
    (
        "shape above 2",
        lambda d: d["estimator"].update(shape=3.0),
        r"estimator.shape: must be a number in \(0, 2\]",
    ),
    (
        "negative kernel scale",
        lambda d: d["estimator"].update(kernel_scale=-1.0),
        "estimator.kernel_scale: must",
    ),
    (
        "infinite intercept",
        lambda d: d["estimator"].update(intercept=float("inf")),
        "estimator.intercept: must",
    ),
    (
        "wrong feature count",
        lambda d: d["estimator"].update(n_features_in=5),
        "estimator.n_features_in: must be 4",
    ),
    ("other estimator", lambda d: d["estimator"].update({"class": "SVR"}), "estimator.class: must"),
    ("bad C", lambda d: d["estimator"]["params"].update(C=-1), "estimator.params.C: must"),
    (
        "bad moments_of",
        lambda d: d["estimator"]["params"].update(moments_of="pairs"),
        "estimator.params.moments_of: must be one of 'differences'",
    ),
    (
        "bad max_working_set",
        lambda d: d["estimator"]["params"].update(max_working_set=2),
        "estimator.params.max_working_set: must be an integer in \\[8, inf\\)",
    ),
    (
        "unknown estimator key",
        lambda d: d["estimator"].update(predict=1),
        "unknown key.*'predict' in 'estimator'; allowed keys: class",
    ),
    (
        "unknown svr param",
        lambda d: d["estimator"]["params"].update(kernel="rbf"),
        "unknown key.*'kernel' in 'estimator.params'",
    ),
    ("unknown top-level key", lambda d: d.update(extra=1), r"'extra' in '\(top level\)'"),
    ("missing key", lambda d: d["narx"].pop("max_lag"), "'narx' lacks the key.*max_lag"),
    (
        "lags and offsets disagree",
        lambda d: d["narx"].update(output_offsets=[1, 3]),
        "narx.output_offsets: must be \\[1, 2\\]",
    ),
    (
        "string lag",
        lambda d: d["narx"]["params"].update(output_lags="2"),
        "narx.params.output_lags: must be an integer in \\[1, inf\\)",
    ),
    (
        "zero scale",
        lambda d: d["narx"]["y_scaler"].update(scale=[0.0]),
        r"narx.y_scaler.scale\[0\]: must be a number in \(0, inf\)",
    ),
    (
        "nan mean",
        lambda d: d["narx"]["u_scaler"].update(mean=[float("nan")]),
        r"narx.u_scaler.mean\[0\]: must",
    ),
    (
        "scaler for two inputs",
        lambda d: d["narx"]["u_scaler"].update(mean=[0.0, 1.0]),
        "narx.u_scaler.mean: must be a list of 1 numbers",
    ),
    (
        "scaler without scaling",
        lambda d: d["narx"]["params"].update(scale=False),
        "narx.y_scaler: must be null",
    ),
    ("metadata not an object", lambda d: d.update(metadata=[1]), "metadata: must be a JSON"),
    ("not an object", lambda d: d["narx"].update(params=[2, 2]), "narx.params: must be a JSON"),
]


@pytest.mark.parametrize(
    ("change", "match"), [pytest.param(c, m, id=name) for name, c, m in _CORRUPTIONS]
)
def test_hand_edited_models_are_refused_in_one_line_naming_file_and_key(tmp_path, change, match):
    u, y = _system(0)
    path = save_narx(NARXRegressor().fit(u, y), tmp_path / "m.json")
    data = json.loads(path.read_text())
    change(data)
    path.write_text(json.dumps(data))
    with pytest.raises(SchemaError, match=match) as info:
        load_narx(path)
    message = str(info.value)
    assert message.startswith(f"{path}: ") and "\n" not in message


@pytest.mark.parametrize("text", ["[1, 2]", '"softbend.narx-gg-svr"', "null"])
def test_json_that_is_not_an_object_is_refused(tmp_path, text):
    path = tmp_path / "m.json"
    path.write_text(text)
    with pytest.raises(SchemaError, match="not a saved softbend NARX model") as info:
        load_narx(path)
    assert str(info.value).startswith(f"{path}: format: must be")


def test_version_1_files_load_with_the_reading_they_were_fitted_with(tmp_path):
    # Version 1 had no moments_of / max_working_set: its shapes came from the pooled
    # standardized components, which is what a refit of the loaded model must use.
    u, y = _system(0)
    model = NARXRegressor(estimator=GeneralizedGaussianSVR(shape=1.3)).fit(u, y)
    path = save_narx(model, tmp_path / "m.json")
    data = json.loads(path.read_text())
    assert data["schema_version"] == 2
    data["schema_version"] = 1
    for key in ("moments_of", "max_working_set"):
        del data["estimator"]["params"][key]
    path.write_text(json.dumps(data))
    loaded, _ = load_narx(path)
    params = loaded.estimator_.get_params()
    assert params["moments_of"] == "components" and params["max_working_set"] == 4096
    assert loaded.estimator_.shape_estimate_ is None
    u_test, y_test = _system(1)
    np.testing.assert_array_equal(model.simulate(u_test, y_test), loaded.simulate(u_test, y_test))
    # A version 2 file must carry the keys.
    data["schema_version"] = 2
    path.write_text(json.dumps(data))
    with pytest.raises(SchemaError, match=r"lacks the key.*moments_of"):
        load_narx(path)


# --- Saved NARX models: strict JSON out; absurd widths, deep nesting and huge lags refused in ---


@pytest.fixture(scope="module")
def saved(tmp_path_factory):
    rng = np.random.default_rng(0)
    u = np.repeat(rng.uniform(-1, 1, 30), 10)[:, None]
    y = np.tanh(u[:, 0]) + 0.05 * rng.standard_normal(u.shape[0])
    path = tmp_path_factory.mktemp("model") / "m.json"
    return save_narx(NARXRegressor().fit(u, y), path, metadata={"nrmse": float("nan")})


def _refuse(constant):
    raise ValueError(f"bare {constant}")


def test_the_saved_file_is_strict_json(saved):
    data = json.loads(saved.read_text(encoding="utf-8"), parse_constant=_refuse)
    assert data["metadata"] == {"nrmse": None}
    _, metadata = load_narx(saved)
    assert metadata == {"nrmse": None}


def _write(source, target, change):
    data = json.loads(source.read_text(encoding="utf-8"))
    change(data)
    target.write_text(json.dumps(data), encoding="utf-8")
    return target


@pytest.mark.parametrize(
    ("change", "match"),
    [
        pytest.param(
            lambda d: d["estimator"].update(sigma=1e-300),
            r"estimator.sigma: 1e-300 is not a plausible kernel width "
            r"\(allowed 1e-06 to 1e\+06\)",
            id="tiny sigma",
        ),
        pytest.param(
            lambda d: d["estimator"].update(sigma=1e300),
            r"estimator.sigma: 1e\+300 is not a plausible kernel width",
            id="huge sigma",
        ),
        pytest.param(
            lambda d: d["estimator"]["params"].update(sigma=5e7),
            r"estimator.params.sigma: 5e\+07 is not a plausible kernel width",
            id="huge sigma parameter",
        ),
        pytest.param(
            lambda d: d["estimator"].update(sigma=float("nan")),
            r"estimator.sigma: must be a number in \(0, inf\); got NaN",
            id="nan sigma",
        ),
        pytest.param(
            lambda d: d["narx"]["params"].update(output_lags=10**11),
            r"narx.output_offsets: must be a list of 100000000000 integers; got \[1, 2\]",
            id="huge lag",
        ),
        pytest.param(
            lambda d: d["narx"]["params"].update(input_lags=10**11),
            r"narx.input_offsets: must be a list of 100000000000 integers",
            id="huge input lag",
        ),
    ],
)
def test_absurd_kernel_widths_and_lags_are_schema_errors(saved, tmp_path, change, match):
    path = _write(saved, tmp_path / "m.json", change)
    with pytest.raises(SchemaError, match=match) as info:
        load_narx(path)
    assert str(info.value).startswith(f"{path}: ")


def test_a_deeply_nested_model_is_a_schema_error_naming_file_line_and_key(saved, tmp_path):
    text = saved.read_text(encoding="utf-8")
    nested = "[" * 50_000 + "]" * 50_000
    path = tmp_path / "m.json"
    path.write_text(text.replace('"metadata": {', f'"metadata": {{"deep": {nested},', 1))
    with pytest.raises(SchemaError) as info:
        load_narx(path)
    message = str(info.value)
    assert message.startswith(f"{path}, line ") and "under the key 'metadata'" in message
    assert "limit of 64 levels" in message and "SOFTBEND_MAX_NESTING" in message


def test_a_model_file_over_the_size_limit_is_refused(saved, tmp_path, monkeypatch):
    monkeypatch.setenv("SOFTBEND_MAX_FILE_MIB", "1")
    path = _write(saved, tmp_path / "m.json", lambda d: d["metadata"].update(pad="x" * 2**21))
    with pytest.raises(LimitError, match="SOFTBEND_MAX_FILE_MIB"):
        load_narx(path)
