import json
import math
import subprocess
import sys
from datetime import datetime

import numpy as np
import pytest
import xgboost as xgb
from sklearn.exceptions import NotFittedError
from sklearn.linear_model import LinearRegression

from softbend import __version__
from softbend.errors import SchemaError
from softbend.surrogates.features import FEATURES, UNITS
from softbend.surrogates.mlp import NormalizedMLPRegressor
from softbend.surrogates.persistence import (
    BASE_KINDS,
    FORMAT,
    SCHEMA_VERSION,
    kind_of,
    load_surrogate,
    save_surrogate,
)
from softbend.surrogates.polynomial import PolynomialRegressor

from .conftest import smooth_angle as _angle
from .conftest import table1_inputs as _inputs


def _new(kind):
    return {
        "polynomial": lambda: PolynomialRegressor(degree=3),
        "mlp": lambda: NormalizedMLPRegressor(
            hidden_sizes=(8, 6), epochs=3, batch_size=64, seed=1, device="cpu"
        ),
        "xgboost": lambda: xgb.XGBRegressor(
            n_estimators=15, max_depth=4, tree_method="hist", random_state=0, n_jobs=1
        ),
    }[kind]()


@pytest.fixture(scope="module")
def fitted():
    X = _inputs(300, 0)
    y = _angle(X)
    return {kind: _new(kind).fit(X, y) for kind in BASE_KINDS}


def _same_params(a, b):
    pa, pb = a.get_params(), b.get_params()
    assert pa.keys() == pb.keys()
    for key, value in pa.items():
        if isinstance(value, float) and math.isnan(value):
            assert math.isnan(pb[key]), key
        else:
            assert value == pb[key] and type(value) is type(pb[key]), key


@pytest.mark.parametrize("kind", BASE_KINDS)
def test_save_load_predicts_bit_for_bit(fitted, tmp_path, kind):
    model = fitted[kind]
    path = save_surrogate(model, tmp_path / "sub" / "model.json")
    saved = load_surrogate(path)
    assert saved.kind == kind == kind_of(model)
    assert type(saved.model) is type(model)
    X = _inputs(500, 1)
    np.testing.assert_array_equal(saved.model.predict(X), model.predict(X))
    _same_params(saved.model, model)
    assert saved.model.n_features_in_ == 7


@pytest.mark.parametrize("kind", ["polynomial", "mlp"])
def test_fitted_arrays_keep_values_and_dtypes(fitted, tmp_path, kind):
    model = fitted[kind]
    loaded = load_surrogate(save_surrogate(model, tmp_path / "m.json")).model
    names = ["x_mean_", "x_scale_", "y_mean_", "y_scale_"]
    names += ["powers_", "coef_"] if kind == "polynomial" else ["coefs_", "intercepts_"]
    for name in names:
        ours, theirs = getattr(model, name), getattr(loaded, name)
        if isinstance(ours, list):
            assert isinstance(theirs, list) and len(theirs) == len(ours), name
        else:
            ours, theirs = [ours], [theirs]
        for a, b in zip(ours, theirs, strict=True):
            assert np.asarray(a).dtype == np.asarray(b).dtype, name
            np.testing.assert_array_equal(a, b)
    assert type(loaded.y_mean_) is type(model.y_mean_)
    x = _inputs(1, 2)[0]
    assert loaded.predictor()(x) == model.predictor()(x)


@pytest.mark.parametrize("kind", BASE_KINDS)
def test_saving_a_reloaded_model_writes_the_same_content(fitted, tmp_path, kind):
    first = save_surrogate(fitted[kind], tmp_path / "a.json", metadata={"cv": [1, 2]})
    loaded = load_surrogate(first)
    second = save_surrogate(loaded.model, tmp_path / "b.json", metadata=loaded.metadata)
    a, b = json.loads(first.read_text()), json.loads(second.read_text())
    a.pop("created_utc"), b.pop("created_utc")
    assert json.dumps(a) == json.dumps(b)


def test_json_float_repr_round_trips_float64_exactly():
    rng = np.random.default_rng(3)
    bits = rng.integers(0, 2**64, size=20000, dtype=np.uint64)
    values = bits.view(np.float64)
    values = values[np.isfinite(values)]
    special = [0.0, -0.0, 5e-324, -5e-324, 2.2250738585072014e-308, 1.7976931348623157e308]
    values = np.concatenate([values, special, rng.normal(size=1000), rng.random(1000) * 1e-9])
    back = np.array(json.loads(json.dumps(values.tolist())), dtype=np.float64)
    np.testing.assert_array_equal(back.view(np.uint64), values.view(np.uint64))


def test_file_is_one_json_with_header_and_metadata(fitted, tmp_path):
    metadata = {
        "data_hash": "0123456789abcdef",
        "metrics": {"r2": np.float64(0.995), "mape_pct": 1.8, "n": np.int64(300)},
        "cv": {"folds": 5, "scores": np.array([0.99, 0.98])},
    }
    path = save_surrogate(fitted["polynomial"], tmp_path / "m.json", metadata=metadata)
    document = json.loads(path.read_text(encoding="utf-8"))
    assert document["format"] == FORMAT
    assert document["schema_version"] == SCHEMA_VERSION
    assert document["kind"] == "polynomial"
    assert document["features"] == list(FEATURES)
    assert document["units"]["pressure_mpa"] == UNITS["pressure_mpa"] == "MPa"
    assert document["target"] == "angle_deg"
    assert document["softbend_version"] == __version__
    assert document["params"]["degree"] == 3
    assert len(document["state"]["coef_"]["__ndarray__"]) == 120  # C(10, 3) terms
    saved = load_surrogate(path)
    assert saved.metadata == {
        "data_hash": "0123456789abcdef",
        "metrics": {"r2": 0.995, "mape_pct": 1.8, "n": 300},
        "cv": {"folds": 5, "scores": [0.99, 0.98]},
    }
    assert saved.softbend_version == __version__
    assert datetime.fromisoformat(saved.created_utc).utcoffset().total_seconds() == 0
    assert list(path.parent.iterdir()) == [path]  # no temporary file left behind


def test_xgboost_booster_is_stored_as_json_text(fitted, tmp_path):
    model = fitted["xgboost"]
    document = json.loads(save_surrogate(model, tmp_path / "m.json").read_text())
    booster = json.loads(document["state"]["booster"])
    assert (
        booster["learner"]["attributes"]
        == json.loads(bytes(model.get_booster().save_raw("json")))["learner"]["attributes"]
    )
    assert math.isnan(document["params"]["missing"])


def _saved(fitted, tmp_path):
    path = save_surrogate(fitted["polynomial"], tmp_path / "m.json")
    return path, json.loads(path.read_text())


def _edit(document, change):
    document = json.loads(json.dumps(document))
    change(document)
    return json.dumps(document)


@pytest.mark.parametrize(
    ("change", "match"),
    [
        (lambda d: d.update(format="softbend.narx-gg-svr"), "not a softbend surrogate: format"),
        (lambda d: d.pop("format"), "not a softbend surrogate: format None"),
        (lambda d: d.update(schema_version=SCHEMA_VERSION + 1), "newer than this softbend"),
        (lambda d: d.update(schema_version="1"), "invalid schema_version"),
        (lambda d: d.pop("schema_version"), "invalid schema_version"),
        (lambda d: d.pop("state"), r"key\(s\) state missing"),
        (lambda d: d.pop("params"), r"key\(s\) params missing"),
        (lambda d: d.pop("kind"), r"key\(s\) kind missing"),
        (lambda d: d["state"].pop("coef_"), r"state key\(s\) coef_ missing"),
        (lambda d: d.update(kind="gaussian_process"), "unknown surrogate kind"),
        (lambda d: d.update(features=d["features"][::-1]), "surrogates map"),
        (lambda d: d["state"]["powers_"].update(shape=[3, 3]), "'powers_'.*its shape"),
        (lambda d: d["params"].update(nonsense=1), "unknown params key.*'nonsense'"),
        (lambda d: d.update(extra=1), r"unknown key\(s\) 'extra'"),
        (lambda d: d.update(features=7), "surrogates map"),
        (lambda d: d.update(created_utc=5), "'created_utc' must be a string"),
        (lambda d: d.update(state=[1, 2]), "'state' must be a JSON object"),
    ],
)
def test_bad_files_raise_schema_error_naming_the_file(fitted, tmp_path, change, match):
    path, document = _saved(fitted, tmp_path)
    path.write_text(_edit(document, change))
    with pytest.raises(SchemaError, match=match) as info:
        load_surrogate(path)
    assert str(path) in str(info.value)
    assert "\n" not in str(info.value)


@pytest.mark.parametrize(
    ("text", "match"),
    [("not json at all", "not valid JSON"), ("[1, 2]", "format 'list'"), ("{}", "format None")],
)
def test_non_surrogate_files_raise_schema_error(tmp_path, text, match):
    path = tmp_path / "m.json"
    path.write_text(text)
    with pytest.raises(SchemaError, match=match):
        load_surrogate(path)


def test_broken_xgboost_booster_raises_schema_error(fitted, tmp_path):
    path = save_surrogate(fitted["xgboost"], tmp_path / "m.json")
    document = json.loads(path.read_text())
    document["state"]["booster"] = "{not a booster"
    path.write_text(json.dumps(document))
    with pytest.raises(SchemaError, match=r"'booster' of the xgboost surrogate .* not valid JSON"):
        load_surrogate(path)


def test_missing_file_raises_file_not_found(tmp_path):
    with pytest.raises(FileNotFoundError, match="No saved surrogate"):
        load_surrogate(tmp_path / "absent.json")


class _Subclass(PolynomialRegressor):
    pass


@pytest.mark.parametrize(
    "model", [LinearRegression(), _Subclass(), xgb.XGBClassifier(), "polynomial"]
)
def test_unknown_model_types_are_refused(tmp_path, model):
    with pytest.raises(ValueError, match=r"PolynomialRegressor \('polynomial'\).*'xgboost'"):
        save_surrogate(model, tmp_path / "m.json")
    with pytest.raises(ValueError, match="must be one of"):
        kind_of(model)
    assert not (tmp_path / "m.json").exists()


@pytest.mark.parametrize("kind", BASE_KINDS)
def test_unfitted_models_are_refused(tmp_path, kind):
    with pytest.raises(NotFittedError, match="not fitted yet"):
        save_surrogate(_new(kind), tmp_path / "m.json")


def test_models_on_other_features_are_refused(tmp_path):
    X = np.random.default_rng(0).normal(size=(50, 3))
    model = PolynomialRegressor(degree=2).fit(X, X.sum(axis=1))
    with pytest.raises(ValueError, match="n_features_in_ = 3"):
        save_surrogate(model, tmp_path / "m.json")


def test_bad_metadata_and_params_are_refused_and_old_file_kept(fitted, tmp_path):
    path = save_surrogate(fitted["polynomial"], tmp_path / "m.json", metadata={"v": 1})
    before = path.read_bytes()
    with pytest.raises(ValueError, match="'metadata' of save_surrogate must be JSON"):
        save_surrogate(fitted["polynomial"], path, metadata={"f": object()})
    with pytest.raises(ValueError, match="string keys"):
        save_surrogate(fitted["polynomial"], path, metadata={1: "a"})
    with pytest.raises(ValueError, match="string keys"):
        save_surrogate(fitted["polynomial"], path, metadata=[("a", 1)])
    model = PolynomialRegressor(degree=2).fit(_inputs(60, 4), _angle(_inputs(60, 4)))
    model.alpha = lambda: 0.0
    with pytest.raises(ValueError, match="parameter 'alpha' of PolynomialRegressor"):
        save_surrogate(model, path)
    assert path.read_bytes() == before


def test_importing_persistence_stays_light():
    code = (
        "import sys, softbend.surrogates.persistence as p; "
        "print(sorted(m for m in ('torch', 'xgboost') if m in sys.modules))"
    )
    out = subprocess.run([sys.executable, "-c", code], capture_output=True, text=True, check=True)
    assert out.stdout.strip() == "[]"


def test_dataframe_fits_keep_feature_names_and_wrong_order_is_refused(tmp_path):
    import pandas as pd

    X = _inputs(120, 11)
    frame = pd.DataFrame(X, columns=list(FEATURES))
    model = xgb.XGBRegressor(n_estimators=5, max_depth=3, n_jobs=1).fit(frame, _angle(X))
    loaded = load_surrogate(save_surrogate(model, tmp_path / "m.json")).model
    assert list(loaded.feature_names_in_) == list(FEATURES)
    np.testing.assert_array_equal(loaded.predict(frame), model.predict(frame))
    shuffled = PolynomialRegressor(degree=1).fit(frame[list(FEATURES)[::-1]], _angle(X))
    with pytest.raises(ValueError, match="in this order"):
        save_surrogate(shuffled, tmp_path / "p.json")


def test_xgboost_early_stopping_round_trips(tmp_path):
    X, Xv = _inputs(200, 12), _inputs(80, 13)
    model = xgb.XGBRegressor(
        n_estimators=300, learning_rate=0.3, early_stopping_rounds=3, n_jobs=1, random_state=0
    ).fit(X, _angle(X), eval_set=[(Xv, _angle(Xv))], verbose=False)
    assert model.best_iteration < 299
    loaded = load_surrogate(save_surrogate(model, tmp_path / "m.json")).model
    assert loaded.best_iteration == model.best_iteration
    np.testing.assert_array_equal(loaded.predict(Xv), model.predict(Xv))


# --- hand-edited files: every value is checked against the kind's schema ---------------------


def _mlp_layer_removed(state):
    state["coefs_"].pop(1)
    state["intercepts_"].pop(1)


def _set_first(array_key, value, index=0):
    """Set one element of a saved array (first row of a 2-D one)."""

    def change(state):
        target = state[array_key]
        if isinstance(target, list):  # the MLP's list of layers
            target = target[index]
        nested = target["__ndarray__"]
        while isinstance(nested[0], list):
            nested = nested[0]
        nested[0] = value

    return change


_CORRUPTIONS = {
    "mlp": [
        ("nan weight", _set_first("coefs_", float("nan")), "coefs_.*item 0 must hold only finite"),
        ("inf bias", _set_first("intercepts_", float("inf"), 2), "intercepts_.*finite"),
        ("zero x scale", _set_first("x_scale_", 0.0), "x_scale_.*values > 0"),
        ("zero y scale", lambda s: s.update(y_scale_=0.0), "y_scale_.*> 0; got 0"),
        ("negative y scale", lambda s: s.update(y_scale_=-2.5), "y_scale_.*> 0"),
        ("nan y mean", lambda s: s.update(y_mean_=float("nan")), "y_mean_.*finite number"),
        ("string scale", lambda s: s.update(y_scale_="12.5"), "y_scale_.*a finite number"),
        ("layer removed", _mlp_layer_removed, "coefs_.*list of 3 2-D float64 arrays; got 2"),
        (
            "wrong layer shape",
            lambda s: s["coefs_"][2].update(__ndarray__=[[1.0]], shape=[1, 1]),
            "chained shapes",
        ),
        ("strings as weights", _set_first("coefs_", "0.5"), 'only finite numbers; got "0.5"'),
        (
            "list of strings",
            lambda s: s["x_mean_"].update(__ndarray__=["a"] * 7),
            "x_mean_.*only finite numbers",
        ),
        ("wrong dtype", lambda s: s["x_mean_"].update(dtype="str"), 'x_mean_.*got dtype "str"'),
        ("array as plain list", lambda s: s.update(x_scale_=[1.0] * 7), "x_scale_.*1-D float64"),
        ("unknown key", lambda s: s.update(predict="boom"), "unknown state key.*'predict'"),
        ("private key", lambda s: s.update(_plan=1), "unknown state key.*'_plan'"),
        ("7 features", lambda s: s.update(n_features_in_=3), "n_features_in_' must be 7"),
        ("bool feature count", lambda s: s.update(n_features_in_=True), "n_features_in_"),
        ("device", lambda s: s.update(device_="tpu"), "device_.*one of 'cpu', 'cuda'"),
    ],
    "polynomial": [
        ("nan coefficient", _set_first("coef_", float("nan")), "coef_.*finite"),
        ("zero x scale", _set_first("x_scale_", 0.0), "x_scale_.*values > 0"),
        ("zero y scale", lambda s: s.update(y_scale_=0), "y_scale_.*> 0"),
        ("string scale", lambda s: s.update(y_scale_="1"), "y_scale_.*a finite number"),
        (
            "term removed",
            lambda s: s["coef_"].update(
                __ndarray__=s["coef_"]["__ndarray__"][:-1], shape=[s["coef_"]["shape"][0] - 1]
            ),
            "coef_' must have shape",
        ),
        ("float powers", lambda s: s["powers_"].update(dtype="float64"), "powers_.*got dtype"),
        ("negative power", _set_first("powers_", -1), "powers_.*values >= 0"),
        ("no constant term", _set_first("powers_", 1), "complete exponent table"),
        (
            "list of strings",
            lambda s: s["coef_"].update(__ndarray__=["x"] * len(s["coef_"]["__ndarray__"])),
            "coef_.*only finite numbers",
        ),
        ("unknown key", lambda s: s.update(predict="boom"), "unknown state key.*'predict'"),
        (
            "feature names",
            lambda s: s.update(
                feature_names_in_={"__ndarray__": list("abcdefg"), "dtype": "str", "shape": [7]}
            ),
            "feature_names_in_' must be",
        ),
    ],
}


@pytest.mark.parametrize(
    ("kind", "change", "match"),
    [
        pytest.param(kind, change, match, id=f"{kind}-{name}")
        for kind, cases in _CORRUPTIONS.items()
        for name, change, match in cases
    ],
)
def test_hand_edited_state_is_refused_in_one_line_naming_file_and_key(
    fitted, tmp_path, kind, change, match
):
    path = save_surrogate(fitted[kind], tmp_path / "m.json")
    document = json.loads(path.read_text())
    change(document["state"])
    path.write_text(json.dumps(document))
    with pytest.raises(SchemaError, match=match) as info:
        load_surrogate(path)
    message = str(info.value)
    assert message.startswith(f"{path}: ") and "\n" not in message


def test_unknown_state_key_names_the_allowed_keys_and_is_never_set(fitted, tmp_path):
    path = save_surrogate(fitted["mlp"], tmp_path / "m.json")
    document = json.loads(path.read_text())
    document["state"]["predict"] = {"__ndarray__": [1.0], "dtype": "float64", "shape": [1]}
    path.write_text(json.dumps(document))
    with pytest.raises(SchemaError) as info:
        load_surrogate(path)
    message = str(info.value)
    assert "'predict'" in message and "allowed keys: n_features_in_" in message
    assert "coefs_, intercepts_" in message


@pytest.mark.parametrize(
    ("kind", "params", "match"),
    [
        ("polynomial", {"chunk_rows": "many"}, "params key 'chunk_rows'.*integer >= 1"),
        ("polynomial", {"degree": 0}, "params key 'degree'.*integer >= 1"),
        ("polynomial", {"alpha": float("nan")}, "params key 'alpha'"),
        ("mlp", {"hidden_sizes": [8]}, "params key 'hidden_sizes'.*two integers"),
        ("mlp", {"predict": 1}, "unknown params key.*'predict'"),
        ("xgboost", {"predict": 1}, "unknown params key.*'predict'"),
        ("xgboost", {"_Booster": 1}, "unknown params key.*'_Booster'"),
    ],
)
def test_hand_edited_params_are_refused(fitted, tmp_path, kind, params, match):
    path = save_surrogate(fitted[kind], tmp_path / "m.json")
    document = json.loads(path.read_text())
    document["params"].update(params)
    path.write_text(json.dumps(document))
    with pytest.raises(SchemaError, match=match) as info:
        load_surrogate(path)
    assert str(path) in str(info.value) and "\n" not in str(info.value)


@pytest.mark.parametrize(
    ("change", "match"),
    [
        (lambda s: s.update(extra="x"), "unknown state key.*'extra'.*allowed keys: booster"),
        (lambda s: s.update(booster=3), "booster.*as a string"),
        (
            lambda s: s.update(
                booster=s["booster"].replace('"base_weights":[', '"base_weights":[NaN,', 1)
            ),
            "finite numbers",
        ),
        (
            lambda s: s.update(
                booster=s["booster"].replace('"num_feature":"7"', '"num_feature":"5"')
            ),
            "7 surrogate inputs",
        ),
    ],
)
def test_hand_edited_xgboost_state_is_refused(fitted, tmp_path, change, match):
    path = save_surrogate(fitted["xgboost"], tmp_path / "m.json")
    document = json.loads(path.read_text())
    change(document["state"])
    path.write_text(json.dumps(document))
    with pytest.raises(SchemaError, match=match):
        load_surrogate(path)


def test_numpy_scalars_and_xgboost_extra_parameters_still_load(fitted, tmp_path):
    path = save_surrogate(fitted["polynomial"], tmp_path / "m.json")
    document = json.loads(path.read_text())
    document["state"]["y_scale_"] = {"__scalar__": 2.0, "dtype": "float64"}
    document["state"]["rank_"] = {"__scalar__": 120, "dtype": "int64"}
    document["params"]["degree"] = {"__scalar__": 3, "dtype": "int64"}
    path.write_text(json.dumps(document))
    model = load_surrogate(path).model
    assert model.y_scale_ == 2.0 and type(model.y_scale_) is np.float64
    X = _inputs(5, 3)
    assert np.isfinite(model.predict(X)).all()

    X = _inputs(100, 4)
    extra = xgb.XGBRegressor(n_estimators=3, n_jobs=1, max_cat_to_onehot=1, seed_per_iteration=True)
    extra.fit(X, _angle(X))
    loaded = load_surrogate(save_surrogate(extra, tmp_path / "x.json")).model
    assert loaded.get_params()["seed_per_iteration"] is True
    np.testing.assert_array_equal(loaded.predict(X), extra.predict(X))


def test_a_booster_xgboost_refuses_is_one_line(fitted, tmp_path):
    path = save_surrogate(fitted["xgboost"], tmp_path / "m.json")
    document = json.loads(path.read_text())
    booster = json.loads(document["state"]["booster"])
    booster["learner"]["gradient_booster"]["model"]["trees"][0]["base_weights"].append(1.0)
    document["state"]["booster"] = json.dumps(booster)
    path.write_text(json.dumps(document))
    with pytest.raises(SchemaError, match="cannot rebuild the xgboost surrogate") as info:
        load_surrogate(path)
    assert "\n" not in str(info.value) and "Stack trace" not in str(info.value)
