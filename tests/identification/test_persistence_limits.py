"""Saved NARX models: strict JSON out; absurd widths, deep nesting and huge lags refused in."""

import json

import numpy as np
import pytest

from softbend.errors import LimitError, SchemaError
from softbend.identification.narx import NARXRegressor
from softbend.identification.persistence import load_narx, save_narx

pytestmark = pytest.mark.filterwarnings(
    "ignore::softbend.identification.kernels.ShapeClippedWarning"
)


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
