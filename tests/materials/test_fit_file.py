"""The fit.json of ``softbend materials fit`` and the model dicts: read back only when sound."""

import json

import pytest

from softbend.cli import main
from softbend.errors import SchemaError
from softbend.materials import (
    HyperelasticModel,
    LinearElastic,
    Material,
    NeoHookean,
    Yeoh,
    fit_models,
    load_shipped,
    model_from_dict,
)
from softbend.materials.presets import DRAGON_SKIN_30


@pytest.fixture(scope="module")
def fit_json(tmp_path_factory):
    out = tmp_path_factory.mktemp("fit")
    assert main(["materials", "fit", "--out", str(out), "--json"]) == 0
    return out / "fit.json"


def _load(path):
    from softbend.materials.fit import load_fit_json

    return load_fit_json(path)


def test_fit_json_reads_back_to_the_same_fits(fit_json):
    loaded = _load(fit_json)
    fitted = fit_models(load_shipped("dragon-skin-30"))
    assert list(loaded) == list(fitted)
    for name, result in fitted.items():
        assert loaded[name].to_dict() == result.to_dict()
        assert loaded[name].model == result.model


def _corrupt(source, target, change):
    data = json.loads(source.read_text(encoding="utf-8"))
    change(data)
    target.write_text(json.dumps(data), encoding="utf-8")
    return target


def _yeoh(data):
    return next(f for f in data["fits"] if f["model"] == "yeoh")


_CORRUPTIONS = [
    (
        "absurd constant",
        lambda d: _yeoh(d)["parameters"].update(c10_mpa=1e300),
        r"fits\[1\]\.parameters\.c10_mpa: must be a plausible material constant "
        r"\(-1000 to 1e\+06 MPa\); got 1e\+300",
    ),
    (
        "string constant",
        lambda d: _yeoh(d)["parameters"].update(c20_mpa="0.003"),
        r"fits\[1\]\.parameters\.c20_mpa: must be a finite number",
    ),
    (
        "missing constant",
        lambda d: _yeoh(d)["parameters"].pop("c10_mpa"),
        r"fits\[1\]\.parameters: 'yeoh' lacks the key\(s\) c10_mpa",
    ),
    (
        "negative modulus",
        lambda d: _yeoh(d)["parameters"].update(c10_mpa=-0.1),
        r"fits\[1\]\.parameters\.c10_mpa: must be a number in \(0, inf\)",
    ),
    (
        "shear modulus not the model's",
        lambda d: _yeoh(d).update(initial_shear_modulus_mpa=5.0),
        r"fits\[1\]\.initial_shear_modulus_mpa: must be .*got 5\.0",
    ),
    (
        "unknown model",
        lambda d: _yeoh(d).update(model="ogden"),
        r"fits\[1\]\.model: must be one of",
    ),
    (
        "r2 above 1",
        lambda d: _yeoh(d).update(r2=3.0),
        r"fits\[1\]\.r2: must be a number <= 1 or null",
    ),
    (
        "bool n_points",
        lambda d: _yeoh(d).update(n_points=True),
        r"fits\[1\]\.n_points: must be an integer",
    ),
    (
        "missing key",
        lambda d: _yeoh(d).pop("rmse_mpa"),
        r"fits\[1\]: 'fit' lacks the key\(s\) rmse_mpa",
    ),
    (
        "unknown bound",
        lambda d: _yeoh(d).update(at_bound=["mu_mpa"]),
        r"fits\[1\]\.at_bound: must be a list of names among c10_mpa",
    ),
    (
        "reversed stretch range",
        lambda d: _yeoh(d).update(stretch_min=9.0, stretch_max=2.0),
        r"fits\[1\]\.stretch_max: must satisfy 0 < stretch_min <= stretch_max",
    ),
    (
        "unknown top key",
        lambda d: d.update(extra=1),
        r"unknown key\(s\) 'extra' in '\(top level\)'",
    ),
    ("fits not a list", lambda d: d.update(fits={}), r": fits: must be a non-empty list"),
    (
        "best model a list",
        lambda d: d.update(best_model=["yeoh"]),
        r": best_model: must be null or one of the fitted models",
    ),
    (
        "best model not fitted",
        lambda d: d.update(best_model="ogden"),
        r": best_model: must be null or one of the fitted models",
    ),
]


@pytest.mark.parametrize(
    ("change", "match"), [pytest.param(c, m, id=name) for name, c, m in _CORRUPTIONS]
)
def test_a_hand_edited_fit_json_is_one_schema_error_naming_file_and_key(
    fit_json, tmp_path, change, match
):
    path = _corrupt(fit_json, tmp_path / "fit.json", change)
    with pytest.raises(SchemaError, match=match) as info:
        _load(path)
    assert str(info.value).startswith(str(path)) and "\n" not in str(info.value)


def test_a_bare_nan_is_refused_and_null_r2_reads_as_nan(fit_json, tmp_path):
    text = fit_json.read_text(encoding="utf-8")
    data = json.loads(text)
    _yeoh(data)["r2"] = None  # what json_text writes for a NaN R²
    path = tmp_path / "fit.json"
    path.write_text(json.dumps(data), encoding="utf-8")
    assert _load(path)["yeoh"].r2 != _load(path)["yeoh"].r2
    path.write_text(json.dumps(data).replace('"r2": null', '"r2": NaN', 1), encoding="utf-8")
    with pytest.raises(SchemaError, match=rf"{path} is not strict JSON: it holds NaN"):
        _load(path)


def test_a_deeply_nested_fit_json_is_a_schema_error_naming_the_key(tmp_path):
    path = tmp_path / "fit.json"
    path.write_text('{"fits": [], "test": ' + "[" * 5000 + "]" * 5000 + "}", encoding="utf-8")
    with pytest.raises(SchemaError) as info:
        _load(path)
    message = str(info.value)
    assert message.startswith(f"{path}, line 1: nested 5,001 levels deep under the key 'test'")
    assert "SOFTBEND_MAX_NESTING" in message


def test_a_fit_json_over_the_size_limit_is_refused(tmp_path, monkeypatch):
    from softbend.errors import LimitError

    monkeypatch.setenv("SOFTBEND_MAX_FILE_MIB", "1")
    path = tmp_path / "fit.json"
    path.write_text('{"fits": [], "files": {"x": "' + "y" * 2**21 + '"}}', encoding="utf-8")
    with pytest.raises(LimitError, match="SOFTBEND_MAX_FILE_MIB"):
        _load(path)


@pytest.mark.parametrize(
    ("data", "match"),
    [
        ({"model": "yeoh"}, r"'yeoh' lacks the key\(s\) c10_mpa"),
        (
            {"model": "neo-hookean", "c10_mpa": 1e300},
            r"^c10_mpa: must be a plausible material constant",
        ),
        ({"model": "neo-hookean", "c10_mpa": "0.1"}, r"^c10_mpa: must be a finite number"),
        ({"model": "neo-hookean", "c10_mpa": True}, r"^c10_mpa: must be a finite number"),
        ({"model": "arruda-boyce", "mu_mpa": 0.2}, r"lacks the key\(s\) lambda_m"),
        ([("model", "yeoh")], r"must be a mapping of constants"),
    ],
)
def test_model_dicts_with_missing_or_absurd_constants_are_schema_errors(data, match):
    with pytest.raises(SchemaError, match=match):
        model_from_dict(data)


def test_material_dicts_are_checked_before_use():
    good = DRAGON_SKIN_30.to_dict()
    for key in ("name", "model", "density_t_per_mm3"):
        broken = {k: v for k, v in good.items() if k != key}
        with pytest.raises(SchemaError, match=rf"'material' lacks the key\(s\) {key}"):
            Material.from_dict(broken)
    with pytest.raises(SchemaError, match=r"^density_t_per_mm3: must be a number \(tonne/mm³\)"):
        Material.from_dict({**good, "density_t_per_mm3": "1e-9"})
    with pytest.raises(SchemaError, match=r"lacks the key\(s\) nu"):
        LinearElastic.from_dict({"model": "linear-elastic", "e_mpa": 31076.0})
    with pytest.raises(SchemaError, match=r"^e_mpa: must be a plausible material constant"):
        LinearElastic.from_dict({"model": "linear-elastic", "e_mpa": 1e9, "nu": 0.3})
    assert Material.from_dict(good) == DRAGON_SKIN_30
    assert HyperelasticModel.from_dict({"model": "yeoh", "c10_mpa": 1}) == Yeoh(1.0)
    assert NeoHookean.from_dict({"c10_mpa": 0.11}) == NeoHookean(0.11)
