import json
import math
import re
import subprocess
import sys
from datetime import datetime

import numpy as np
import pytest
import xgboost as xgb
from sklearn.exceptions import NotFittedError
from sklearn.linear_model import LinearRegression

from softbend import __version__
from softbend.errors import LimitError, SchemaError
from softbend.surrogates.families import MODEL_NAMES as BASE_KINDS
from softbend.surrogates.features import FEATURES, UNITS
from softbend.surrogates.mlp import NormalizedMLPRegressor
from softbend.surrogates.persistence import (
    FORMAT,
    SCHEMA_VERSION,
    SavedState,
    SavedSurrogate,
    kind_of,
    load_state,
    load_surrogate,
    save_surrogate,
    saved_kinds,
)
from softbend.surrogates.polynomial import PolynomialRegressor

from .conftest import smooth_angle as _angle
from .conftest import table1_inputs as _inputs


def _new(kind):
    return {
        "plr": lambda: PolynomialRegressor(degree=3),
        "mlp": lambda: NormalizedMLPRegressor(
            hidden_sizes=(8, 6), epochs=3, batch_size=64, seed=1, device="cpu"
        ),
        "xgb": lambda: xgb.XGBRegressor(
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


@pytest.mark.parametrize("kind", ["plr", "mlp"])
def test_fitted_arrays_keep_values_and_dtypes(fitted, tmp_path, kind):
    model = fitted[kind]
    loaded = load_surrogate(save_surrogate(model, tmp_path / "m.json")).model
    names = ["x_mean_", "x_scale_", "y_mean_", "y_scale_"]
    names += ["powers_", "coef_"] if kind == "plr" else ["coefs_", "intercepts_"]
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
    path = save_surrogate(fitted["plr"], tmp_path / "m.json", metadata=metadata)
    document = json.loads(path.read_text(encoding="utf-8"))
    assert document["format"] == FORMAT
    assert document["schema_version"] == SCHEMA_VERSION
    assert document["kind"] == "plr"
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
    model = fitted["xgb"]
    document = json.loads(save_surrogate(model, tmp_path / "m.json").read_text())
    booster = json.loads(document["state"]["booster"])
    assert (
        booster["learner"]["attributes"]
        == json.loads(bytes(model.get_booster().save_raw("json")))["learner"]["attributes"]
    )
    assert document["params"]["missing"] is None  # XGBoost's NaN default, as strict JSON
    assert math.isnan(load_surrogate(tmp_path / "m.json").model.get_params()["missing"])


def _saved(fitted, tmp_path):
    path = save_surrogate(fitted["plr"], tmp_path / "m.json")
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
        (lambda d: d["state"]["powers_"].update(shape=[3, 3]), "powers_: .*its shape"),
        (lambda d: d["params"].update(nonsense=1), "unknown params key.*'nonsense'"),
        (lambda d: d.update(extra=1), r"unknown key\(s\) 'extra'"),
        (lambda d: d.update(features=7), "surrogates map"),
        (lambda d: d.update(created_utc=5), "created_utc: must be a string"),
        (lambda d: d.update(state=[1, 2]), "state: must be a JSON object"),
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
    [
        ("not json at all", "not valid JSON"),
        ("[1, 2]", "format 'list'"),
        ("{}", "format None"),
        ('{"format": ' + "1" * 5000 + "}", "not valid JSON.*digits"),
    ],
)
def test_non_surrogate_files_raise_schema_error(tmp_path, text, match):
    path = tmp_path / "m.json"
    path.write_text(text)
    with pytest.raises(SchemaError, match=match):
        load_surrogate(path)


def test_broken_xgboost_booster_raises_schema_error(fitted, tmp_path):
    path = save_surrogate(fitted["xgb"], tmp_path / "m.json")
    document = json.loads(path.read_text())
    document["state"]["booster"] = "{not a booster"
    path.write_text(json.dumps(document))
    with pytest.raises(
        SchemaError, match=r"state\.booster: must be XGBoost's JSON model; not valid JSON"
    ):
        load_surrogate(path)


def test_missing_file_raises_file_not_found(tmp_path):
    with pytest.raises(FileNotFoundError, match="No saved surrogate"):
        load_surrogate(tmp_path / "absent.json")


class _Subclass(PolynomialRegressor):
    pass


@pytest.mark.parametrize("model", [LinearRegression(), _Subclass(), xgb.XGBClassifier(), "plr"])
def test_unknown_model_types_are_refused(tmp_path, model):
    with pytest.raises(ValueError, match=r"PolynomialRegressor \('plr'\).*'xgb'"):
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
    path = save_surrogate(fitted["plr"], tmp_path / "m.json", metadata={"v": 1})
    before = path.read_bytes()
    with pytest.raises(ValueError, match="metadata: must be JSON-serializable"):
        save_surrogate(fitted["plr"], path, metadata={"f": object()})
    with pytest.raises(ValueError, match="string keys"):
        save_surrogate(fitted["plr"], path, metadata={1: "a"})
    with pytest.raises(ValueError, match="string keys"):
        save_surrogate(fitted["plr"], path, metadata=[("a", 1)])
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
        ("zero x scale", _set_first("x_scale_", 0.0), r"x_scale_.*values in \(0, inf\)"),
        ("zero y scale", lambda s: s.update(y_scale_=0.0), r"y_scale_.*in \(0, inf\); got 0"),
        ("negative y scale", lambda s: s.update(y_scale_=-2.5), r"y_scale_.*in \(0, inf\)"),
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
        ("7 features", lambda s: s.update(n_features_in_=3), "n_features_in_: must be 7"),
        ("bool feature count", lambda s: s.update(n_features_in_=True), "n_features_in_"),
        ("device", lambda s: s.update(device_="tpu"), "device_.*one of 'cpu', 'cuda'"),
    ],
    "plr": [
        ("nan coefficient", _set_first("coef_", float("nan")), "coef_.*finite"),
        ("zero x scale", _set_first("x_scale_", 0.0), r"x_scale_.*values in \(0, inf\)"),
        ("zero y scale", lambda s: s.update(y_scale_=0), r"y_scale_.*in \(0, inf\)"),
        ("string scale", lambda s: s.update(y_scale_="1"), "y_scale_.*a finite number"),
        (
            "term removed",
            lambda s: s["coef_"].update(
                __ndarray__=s["coef_"]["__ndarray__"][:-1], shape=[s["coef_"]["shape"][0] - 1]
            ),
            "coef_: must have shape",
        ),
        ("float powers", lambda s: s["powers_"].update(dtype="float64"), "powers_.*got dtype"),
        ("negative power", _set_first("powers_", -1), r"powers_.*values in \[0, inf\)"),
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
            "feature_names_in_: must be",
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
        ("plr", {"chunk_rows": "many"}, r"params\.chunk_rows: .*integer in \[1, inf\)"),
        ("plr", {"degree": 0}, r"params\.degree: .*integer in \[1, inf\)"),
        ("plr", {"alpha": float("nan")}, r"params\.alpha: "),
        ("mlp", {"hidden_sizes": [8]}, r"params\.hidden_sizes: .*two integers"),
        ("mlp", {"predict": 1}, "unknown params key.*'predict'"),
        ("xgb", {"predict": 1}, "unknown params key.*'predict'"),
        ("xgb", {"_Booster": 1}, "unknown params key.*'_Booster'"),
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
    path = save_surrogate(fitted["xgb"], tmp_path / "m.json")
    document = json.loads(path.read_text())
    change(document["state"])
    path.write_text(json.dumps(document))
    with pytest.raises(SchemaError, match=match):
        load_surrogate(path)


def test_numpy_scalars_and_xgboost_extra_parameters_still_load(fitted, tmp_path):
    path = save_surrogate(fitted["plr"], tmp_path / "m.json")
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
    path = save_surrogate(fitted["xgb"], tmp_path / "m.json")
    document = json.loads(path.read_text())
    booster = json.loads(document["state"]["booster"])
    booster["learner"]["gradient_booster"]["model"]["trees"][0]["base_weights"].append(1.0)
    document["state"]["booster"] = json.dumps(booster)
    path.write_text(json.dumps(document))
    with pytest.raises(SchemaError, match="cannot rebuild the xgb surrogate") as info:
        load_surrogate(path)
    assert "\n" not in str(info.value) and "Stack trace" not in str(info.value)


# --- strict JSON: no bare NaN or Infinity in any saved file ------------------------------------


def _strict(text):
    """``text`` parsed by a strict JSON reader: NaN and Infinity are refused."""

    def refuse(constant):
        raise ValueError(f"not strict JSON: {constant}")

    return json.loads(text, parse_constant=refuse)


def _composites(fitted):
    from softbend.surrogates.corrected import (
        AffineCorrected,
        GPCorrected,
        MeanEnsemble,
        PressureScaled,
        gp_kernel,
    )

    base = fitted["plr"]
    X = _inputs(30, 21)
    theta = base.predict(X)
    Z = np.column_stack([X, theta])
    mean, scale = Z.mean(axis=0), Z.std(axis=0)
    inputs = (Z - mean) / scale
    errors = _angle(X) - theta
    return {
        "affine-corrected": AffineCorrected(base, 1.1, -2.0, 0.5),
        "gp-corrected": GPCorrected(base, mean, scale, gp_kernel(8).theta, inputs, errors),
        "ensemble": MeanEnsemble([fitted["plr"], fitted["mlp"], fitted["xgb"]], 0.25),
        "pressure-scaled": PressureScaled(fitted["xgb"], 1.2, 0.5),
    }


def test_every_kind_saves_strict_json_and_reloads_bit_for_bit(fitted, tmp_path):
    from softbend.surrogates.table import TableRegressor

    X = _inputs(120, 0)
    table = TableRegressor(n_restarts=0).fit(X, _angle(X))
    models = {**fitted, **_composites(fitted), "table": table}
    assert set(models) == set(saved_kinds())
    X = _inputs(200, 22)
    for kind, model in models.items():
        path = save_surrogate(model, tmp_path / f"{kind}.json", metadata={"r2": float("nan")})
        document = _strict(path.read_text())
        assert document["kind"] == kind
        assert document["metadata"] == {"r2": None}
        loaded = load_surrogate(path).model
        np.testing.assert_array_equal(loaded.predict(X), model.predict(X))


def test_non_finite_parameters_and_diagnostics_are_tagged_and_restored(fitted, tmp_path):
    X = _inputs(80, 23)
    poly = PolynomialRegressor(degree=2).fit(X, _angle(X)).set_params(max_memory_mb=math.inf)
    text = save_surrogate(poly, tmp_path / "p.json").read_text()
    assert _strict(text)["params"]["max_memory_mb"] == {"__float__": "inf"}
    assert load_surrogate(tmp_path / "p.json").model.max_memory_mb == float("inf")

    mlp = load_surrogate(save_surrogate(fitted["mlp"], tmp_path / "a.json")).model
    mlp.loss_curve_ = [0.5, float("nan"), float("inf"), -float("inf")]
    document = _strict(save_surrogate(mlp, tmp_path / "m.json").read_text())
    assert document["state"]["loss_curve_"][1:] == [
        {"__float__": "nan"},
        {"__float__": "inf"},
        {"__float__": "-inf"},
    ]
    curve = load_surrogate(tmp_path / "m.json").model.loss_curve_
    assert curve[0] == 0.5 and math.isnan(curve[1]) and curve[2:] == [math.inf, -math.inf]


def test_xgboost_missing_is_null_and_a_file_with_a_bare_nan_still_loads(fitted, tmp_path):
    model = fitted["xgb"]
    path = save_surrogate(model, tmp_path / "m.json")
    assert '"missing": null' in path.read_text()
    X = _inputs(300, 24)
    # A file written before: Python's JSON dialect, "missing": NaN.
    old = tmp_path / "old.json"
    old.write_text(path.read_text().replace('"missing": null', '"missing": NaN'))
    assert '"missing": NaN' in old.read_text()
    for file in (path, old):
        loaded = load_surrogate(file).model
        assert math.isnan(loaded.get_params()["missing"])
        np.testing.assert_array_equal(loaded.predict(X), model.predict(X))
        _same_params(loaded, model)


@pytest.mark.parametrize(
    ("missing", "ok"),
    [(-999.0, True), (0, True), ({"__float__": "nan"}, True), ("abc", False), (True, False)],
)
def test_xgboost_missing_must_be_a_number_or_null(fitted, tmp_path, missing, ok):
    path = save_surrogate(fitted["xgb"], tmp_path / "m.json")
    document = json.loads(path.read_text())
    document["params"]["missing"] = missing
    path.write_text(json.dumps(document))
    if ok:
        assert np.isfinite(load_surrogate(path).model.predict(_inputs(5, 25))).all()
        return
    with pytest.raises(SchemaError, match=r"params\.missing: .*a number or null") as info:
        load_surrogate(path)
    assert str(path) in str(info.value)


# --- nesting: bounded before anything recurses -------------------------------------------------


def _nested(document, depth):
    """``document`` wrapped ``depth`` times in affine corrections, as one JSON text."""
    head = {key: value for key, value in document.items() if key != "state"}
    head.update(kind="affine-corrected", params={}, metadata={})
    state = {"scale_": 1.0, "offset_": 0.0, "residual_std_": 0.5, "base": 0}
    opening = json.dumps({**head, "state": state})
    before, after = opening.rsplit("0}}", 1)[0], "}}" + opening.rsplit("0}}", 1)[1]
    inner = json.dumps(document)
    return before * depth + inner + after * depth


@pytest.mark.parametrize("shape", ["corrections", "arrays"])
def test_a_file_nested_beyond_the_parser_is_one_schema_error(fitted, tmp_path, shape):
    _, document = _saved(fitted, tmp_path)
    path = tmp_path / "deep.json"
    text = _nested(document, 20_000) if shape == "corrections" else "[" * 10**5 + "]" * 10**5
    path.write_text(text)
    with pytest.raises(SchemaError, match="nests too deeply to be read") as info:
        load_surrogate(path)
    assert str(info.value).startswith(str(path)) and "SOFTBEND_MAX_NESTING" in str(info.value)


def test_a_file_nested_beyond_the_limit_is_a_limit_error_naming_it(fitted, tmp_path, monkeypatch):
    _, document = _saved(fitted, tmp_path)
    path = tmp_path / "deep.json"
    path.write_text(_nested(document, 50))
    with pytest.raises(LimitError, match=r"deep\.json is 10\d levels.*SOFTBEND_MAX_NESTING"):
        load_surrogate(path)
    monkeypatch.setenv("SOFTBEND_MAX_NESTING", "1000")
    with pytest.raises(SchemaError, match="surrogates nest at most 4 deep"):
        load_surrogate(path)
    path.write_text(_nested(document, 2))  # within both: loads
    model = load_surrogate(path).model
    np.testing.assert_array_equal(
        model.predict(_inputs(5, 26)), fitted["plr"].predict(_inputs(5, 26))
    )


# --- training ranges: checked on load -----------------------------------------------------------


def _with_ranges(fitted, tmp_path, change):
    from softbend.surrogates.features import training_ranges

    ranges = training_ranges(_inputs(300, 0))
    path = save_surrogate(fitted["plr"], tmp_path / "m.json", metadata={"training_ranges": ranges})
    document = json.loads(path.read_text())
    change(document["metadata"]["training_ranges"])
    path.write_text(json.dumps(document))
    return path


@pytest.mark.parametrize(
    ("change", "match"),
    [
        (lambda r: r["l_mm"].__setitem__(0, float("nan")), r"training_ranges\.l_mm: .*got \[NaN, "),
        (lambda r: r["l_mm"].__setitem__(1, float("inf")), r"training_ranges\.l_mm: .*Infinity\]"),
        (
            lambda r: r.update(r_mm=[10.0, 6.0]),
            r"training_ranges\.r_mm: .*low <= high.*\[10.0, 6.0\]",
        ),
        (lambda r: r.update(t_mm=["2", "4"]), r"training_ranges\.t_mm: .*two finite numbers"),
        (lambda r: r.update(b_mm=[2.0]), r"training_ranges\.b_mm: .*\[low, high\]"),
        (lambda r: r.update(b_mm=None), r"training_ranges\.b_mm: .*got null"),
        (lambda r: r.update(lc_mm=[True, 12.0]), r"training_ranges\.lc_mm: "),
        (
            lambda r: r.update(pressure_mpa=[0.0, 500.0]),
            r"training_ranges\.pressure_mpa: .*from -0.1013 to 2 MPa.*\[0.0, 500.0\]",
        ),
        (
            lambda r: r.update(phi_deg=[5.0, 1e9]),
            r"training_ranges\.phi_deg: .*from 0 to 90 deg \(a plausible fiber winding angle\)",
        ),
        (lambda r: r.pop("l_mm"), r"each input l_mm.*got no range for l_mm"),
        (lambda r: r.update(length=[1, 2]), r"got unknown input\(s\) 'length'"),
        (lambda r: r.update(l_mm=[100, 10**400]), r"training_ranges\.l_mm: .*got \[100, 1000"),
    ],
    ids=[
        "nan-low",
        "inf-high",
        "low-above-high",
        "strings",
        "one-number",
        "null",
        "bool",
        "implausible-pressure",
        "implausible-angle",
        "missing-input",
        "unknown-input",
        "huge-integer",
    ],
)
def test_bad_training_ranges_are_refused_naming_the_file_and_field(fitted, tmp_path, change, match):
    path = _with_ranges(fitted, tmp_path, change)
    with pytest.raises(SchemaError, match=match) as info:
        load_surrogate(path)
    message = str(info.value)
    assert message.startswith(f"{path}: metadata.training_ranges") and "\n" not in message


@pytest.mark.parametrize("ranges", [[1, 2], None, "l_mm"])
def test_training_ranges_that_are_not_an_object_are_refused(fitted, tmp_path, ranges):
    path = save_surrogate(fitted["plr"], tmp_path / "m.json", metadata={"training_ranges": ranges})
    with pytest.raises(SchemaError, match="training_ranges: must be an object of"):
        load_surrogate(path)


def test_integer_training_ranges_still_load(fitted, tmp_path):
    path = _with_ranges(fitted, tmp_path, lambda r: r.update(l_mm=[100, 160]))
    assert load_surrogate(path).metadata["training_ranges"]["l_mm"] == [100, 160]


# --- other header and state fields read without validation before ------------------------------


@pytest.mark.parametrize(
    ("change", "match"),
    [
        (lambda d: d.update(kind=["plr"]), r'unknown surrogate kind \["plr"\]'),
        (lambda d: d.update(kind={"a": 1}), "unknown surrogate kind"),
        (lambda d: d.update(kind=None), "unknown surrogate kind null"),
        (lambda d: d["units"].update(pressure_mpa="kPa"), 'units: must be .*got "kPa"'),
        (lambda d: d["units"].pop("l_mm"), "units: must be .*got none for 'l_mm'"),
        (lambda d: d["units"].update(extra="mm"), "units: must be .*for 'extra'"),
        (lambda d: d.update(format=["x"] * 1000), r"format \[\"x\", .*\.\.\., expected"),
        (
            lambda d: d.update(schema_version=[1]),
            r"schema_version: must be an integer from 1 to 2.*; got \[1\]",
        ),
        (lambda d: d["params"].update(degree=2), "params.degree: must be the highest"),
        (lambda d: d["state"].update(rank_=10**6), "rank_: must be at most the number of terms"),
        (lambda d: d["state"].update(y_scale_=10**400), "y_scale_: .*within float64; got 1000"),
    ],
    ids=[
        "kind-list",
        "kind-object",
        "kind-null",
        "units-kpa",
        "units-missing",
        "units-extra",
        "format-long-list",
        "schema-version-list",
        "degree-vs-powers",
        "rank-vs-terms",
        "huge-integer",
    ],
)
def test_more_bad_header_and_state_values_are_schema_errors(fitted, tmp_path, change, match):
    path, document = _saved(fitted, tmp_path)
    path.write_text(_edit(document, change))
    with pytest.raises(SchemaError, match=match) as info:
        load_surrogate(path)
    assert str(path) in str(info.value) and "\n" not in str(info.value)


def test_mlp_hidden_sizes_must_match_the_weights(fitted, tmp_path):
    path = save_surrogate(fitted["mlp"], tmp_path / "m.json")
    document = json.loads(path.read_text())
    document["params"]["hidden_sizes"] = {"__tuple__": [60, 60]}
    path.write_text(json.dumps(document))
    with pytest.raises(SchemaError, match=r"hidden_sizes: must be the layer sizes .*\[8, 6\]"):
        load_surrogate(path)
    document["params"].pop("hidden_sizes")  # the default (60, 60) does not match either
    path.write_text(json.dumps(document))
    with pytest.raises(SchemaError, match="hidden_sizes: must be the layer sizes"):
        load_surrogate(path)


@pytest.mark.parametrize(
    ("change", "match"),
    [
        (
            lambda d: d["params"].update(n_jobs={"__scalar__": 1, "dtype": "datetime64"}),
            "params: cannot be read",
        ),
        (
            lambda d: d["params"].update(n_jobs={"__float__": "lots"}),
            "params: cannot be read",
        ),
        (lambda d: d["params"].update(n_jobs="many"), "cannot rebuild the xgb surrogate"),
        (
            lambda d: d["state"].update(
                booster=d["state"]["booster"].replace(
                    '"feature_names":[]', '"feature_names":["a","b","c","d","e","f","g"]'
                )
            ),
            "must be fitted on the columns l_mm",
        ),
        (
            lambda d: d["state"].update(
                booster=re.sub(
                    r'"base_score":"[^"]*"', '"base_score":"[NaN]"', d["state"]["booster"]
                )
            ),
            "booster predicts nan",
        ),
    ],
    ids=["datetime-dtype", "bad-float-tag", "n-jobs-string", "feature-names", "nan-base-score"],
)
def test_xgboost_values_read_only_when_predicting_fail_on_load(fitted, tmp_path, change, match):
    path = save_surrogate(fitted["xgb"], tmp_path / "m.json")
    document = json.loads(path.read_text())
    change(document)
    path.write_text(json.dumps(document))
    with pytest.raises(SchemaError, match=match) as info:
        load_surrogate(path)
    assert str(info.value).startswith(f"{path}: ") and "\n" not in str(info.value)


# --- schema version 1: the kinds named otherwise are read as their families ------------------


def _as_version_1(document, kind):
    """``document`` as softbend wrote it with schema version 1: ``kind`` named the old way."""
    return {**document, "schema_version": 1, "kind": kind}


@pytest.mark.parametrize(("family", "old"), [("plr", "polynomial"), ("xgb", "xgboost")])
def test_a_version_1_file_loads_as_its_family(fitted, tmp_path, family, old):
    path = save_surrogate(fitted[family], tmp_path / "new.json")
    document = json.loads(path.read_text())
    assert (document["kind"], document["schema_version"]) == (family, SCHEMA_VERSION) == (family, 2)
    old_path = tmp_path / "old.json"
    old_path.write_text(json.dumps(_as_version_1(document, old)))
    saved = load_surrogate(old_path)
    assert saved.kind == family == kind_of(saved.model)
    X = _inputs(50, 31)
    np.testing.assert_array_equal(saved.model.predict(X), fitted[family].predict(X))
    # the old name is a migration, not a second name: a version 2 file must use the family's
    old_path.write_text(json.dumps({**document, "kind": old}))
    with pytest.raises(
        SchemaError, match=rf"kind: must be one of 'plr'.*; got the unknown surrogate kind '{old}'"
    ):
        load_surrogate(old_path)


def test_a_version_1_composite_migrates_its_inner_surrogates(fitted, tmp_path):
    from softbend.surrogates.corrected import AffineCorrected, MeanEnsemble

    model = AffineCorrected(MeanEnsemble([fitted["plr"], fitted["xgb"]], 0.2), 1.1, -2.0, 0.5)
    document = json.loads(save_surrogate(model, tmp_path / "m.json").read_text())
    members = document["state"]["base"]["state"]["members"]
    members[0] = _as_version_1(members[0], "polynomial")
    members[1] = _as_version_1(members[1], "xgboost")
    path = tmp_path / "old.json"
    path.write_text(json.dumps({**document, "schema_version": 1}))
    loaded = load_surrogate(path).model
    assert [kind_of(m) for m in loaded.base.members_] == ["plr", "xgb"]
    X = _inputs(50, 32)
    np.testing.assert_array_equal(loaded.predict(X), model.predict(X))


def test_the_shipped_version_1_mlp_still_loads():
    from importlib.resources import files

    path = files("softbend") / "data" / "transfer" / "table1_fem_mlp.json"
    assert json.loads(path.read_text())["schema_version"] == 1
    saved = load_surrogate(path)
    assert saved.kind == "mlp" and type(saved.model).__name__ == "NormalizedMLPRegressor"
    assert np.isfinite(saved.model.predict(_inputs(5, 33))).all()


def test_a_family_without_storage_is_not_saved_and_its_kind_not_read(fitted, tmp_path):
    from softbend.surrogates.families import FAMILIES, Family

    toy = Family("no-storage", "toy", {"quick": ({},), "paper": ({},)}, lambda p, s: None)
    path = save_surrogate(fitted["plr"], tmp_path / "m.json")
    document = json.loads(path.read_text())
    path.write_text(json.dumps({**document, "kind": "no-storage"}))
    FAMILIES.register("no-storage", toy)
    try:
        assert "no-storage" not in saved_kinds()
        with pytest.raises(SchemaError, match="unknown surrogate kind 'no-storage'"):
            load_surrogate(path)
    finally:
        FAMILIES.unregister("no-storage")


# --- load_state: a saved MLP's validated arrays, its estimator not built ---------------------


def test_load_state_gives_the_arrays_load_surrogate_sets(fitted, tmp_path):
    path = save_surrogate(fitted["mlp"], tmp_path / "m.json", metadata={"note": "x"})
    state = load_state(path, ("mlp",))
    model = load_surrogate(path).model
    assert isinstance(state, SavedState) and state.kind == "mlp"
    assert state.metadata == {"note": "x"} and state.params == model.get_params(deep=False)
    for key, value in state.state.items():
        if isinstance(value, list) and value and isinstance(value[0], np.ndarray):
            for a, b in zip(value, getattr(model, key), strict=True):
                assert a.dtype == b.dtype and a.tobytes() == b.tobytes()
        elif isinstance(value, np.ndarray):
            assert value.dtype == getattr(model, key).dtype
            assert value.tobytes() == getattr(model, key).tobytes()
        else:
            assert value == getattr(model, key), key


def test_load_state_builds_other_kinds_and_files_it_cannot_check_alone(fitted, tmp_path):
    path = save_surrogate(fitted["plr"], tmp_path / "plr.json")
    assert isinstance(load_state(path, ("mlp",)), SavedSurrogate)
    path = save_surrogate(fitted["mlp"], tmp_path / "mlp.json")
    assert isinstance(load_state(path, ()), SavedSurrogate)
    document = json.loads(path.read_text())
    document["params"].pop("epochs")  # the estimator's default fills it in
    path.write_text(json.dumps(document))
    saved = load_state(path, ("mlp",))
    assert isinstance(saved, SavedSurrogate) and saved.model.epochs == 1000


@pytest.mark.parametrize(
    ("change", "match"),
    [pytest.param(change, match, id=name) for name, change, match in _CORRUPTIONS["mlp"]]
    + [
        pytest.param(lambda s: s.pop("coefs_"), r"state key\(s\) coefs_ missing", id="missing-key"),
    ],
)
def test_load_state_refuses_a_bad_mlp_as_load_surrogate_does(fitted, tmp_path, change, match):
    path = save_surrogate(fitted["mlp"], tmp_path / "m.json")
    document = json.loads(path.read_text())
    change(document["state"])
    path.write_text(json.dumps(document))
    with pytest.raises(SchemaError, match=match) as info:
        load_state(path, ("mlp",))
    with pytest.raises(SchemaError) as reference:
        load_surrogate(path)
    assert str(info.value) == str(reference.value)


@pytest.mark.parametrize(
    "change",
    [
        lambda d: d["params"].update(hidden_sizes={"__tuple__": [60, 60]}),
        lambda d: d["params"].update(epochs=0),
        lambda d: d["params"].update(device="tpu"),
        lambda d: d["metadata"].update(training_ranges={"l_mm": [1, 2]}),
    ],
    ids=["hidden-sizes", "epochs", "device", "training-ranges"],
)
def test_load_state_refuses_bad_mlp_params_as_load_surrogate_does(fitted, tmp_path, change):
    path = save_surrogate(fitted["mlp"], tmp_path / "m.json")
    document = json.loads(path.read_text())
    change(document)
    path.write_text(json.dumps(document))
    with pytest.raises(SchemaError) as info:
        load_state(path, ("mlp",))
    with pytest.raises(SchemaError) as reference:
        load_surrogate(path)
    assert str(info.value) == str(reference.value)
